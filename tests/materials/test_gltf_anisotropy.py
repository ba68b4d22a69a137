"""KHR_materials_anisotropy on glphong.GltfPBR (glphong/materials/gltf_anisotropy.py) against an independent float64
transcription of the extension's README, written here and sharing nothing with glphong:

- ``direction = u_AnisotropyRotation = (cos r, sin r)``; with a texture ``direction = mat2(c, s, -s, c)
  normalize(2 tex.rg - 1)``, ``anisotropy = strength tex.b``; ``T = normalize(TBN (direction, 0))``, ``B =
  normalize(cross(n, T))``;
- ``at = mix(alphaRoughness, 1, anisotropy^2)``, ``ab = alphaRoughness``;
- ``D_GGX_anisotropic = a2 w2^2 / pi``, ``a2 = at ab``, ``w2 = a2 / dot(f, f)``, ``f = (ab T.h, at B.h, a2 n.h)``;
- ``V_GGX_anisotropic = clamp(0.5 / (n.l |(at T.v, ab B.v, n.v)| + n.v |(at T.l, ab B.l, n.l)|), 0, 1)``;
- that ``V D`` in place of Appendix B's ``specular_brdf`` in the dielectric's ``fresnel_mix`` and the metal's
  ``conductor_fresnel``, times ``n.l``.
"""
import importlib.util
import json
import pathlib
import warnings

import numpy as np
import pytest

import glphong
from glphong.testing import assert_twin_matches

_SPEC = importlib.util.spec_from_file_location("_gltf_extension_tests", pathlib.Path(__file__).with_name(
    "test_gltf_extensions.py"))
_EXT = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(_EXT)  # its helpers: the planted-error check, the file of one quad

Z = np.array([0.0, 0.0, 1.0])
X = np.array([1.0, 0.0, 0.0])
Y = np.array([0.0, 1.0, 0.0])


def specification(n, t, b, l, v, base_color, metallic, roughness, anisotropy_strength=0.0, anisotropy_rotation=0.0,
                  anisotropy_direction=None, ior=1.5, planted=None):
    """``material (n.l)`` by the extension's text, float64, (N, 3); ``anisotropy_direction`` the texture's texel (or
    None: no texture); ``planted`` one of the usual mistakes (test_the_comparison_catches_the_usual_mistakes)."""
    dot = lambda a, c: np.sum(a * c, axis=-1)  # noqa: E731
    h = (l + v) / np.linalg.norm(l + v, axis=-1, keepdims=True)
    rotation = -anisotropy_rotation if planted == "rotation clockwise" else anisotropy_rotation
    u = np.array([np.cos(rotation), np.sin(rotation)])
    if anisotropy_direction is None:
        direction = u
    else:
        d = np.asarray(anisotropy_direction, np.float64)[:2] * 2.0 - 1.0
        d = d / np.linalg.norm(d)
        direction = np.array([[u[0], -u[1]], [u[1], u[0]]]) @ d  # GLSL's mat2(u.x, u.y, -u.y, u.x) * d
    aniso_t = direction[0] * t + direction[1] * b
    aniso_t /= np.linalg.norm(aniso_t, axis=-1, keepdims=True)
    aniso_b = np.cross(n, aniso_t)
    aniso_b /= np.linalg.norm(aniso_b, axis=-1, keepdims=True)
    alpha = roughness ** 2
    s2 = anisotropy_strength if planted == "strength not squared" else anisotropy_strength ** 2
    at = alpha * (1 - s2) + 1.0 * s2
    ab = alpha
    if planted == "at and ab swapped":
        at, ab = ab, at
    a2 = at * ab
    f = np.stack([ab * dot(aniso_t, h), at * dot(aniso_b, h), a2 * dot(n, h)], axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        w2 = a2 / dot(f, f)
        d = np.where(a2 == 0, 0.0, a2 * w2 * w2 / np.pi)  # the delta of roughness 0 meets no pair with nonzero measure
    nl, nv = dot(n, l), dot(n, v)
    ggx_v = nl * np.sqrt((at * dot(aniso_t, v)) ** 2 + (ab * dot(aniso_b, v)) ** 2 + nv ** 2)
    ggx_l = nv * np.sqrt((at * dot(aniso_t, l)) ** 2 + (ab * dot(aniso_b, l)) ** 2 + nl ** 2)
    vis = 0.5 / (ggx_v + ggx_l)
    vis = vis if planted == "V unclamped" else np.clip(vis, 0.0, 1.0)
    layer = (vis * d)[:, None]
    c = np.asarray(base_color, np.float64) * np.ones(3)
    x = ((1 - np.abs(dot(v, h))) ** 5)[:, None]
    f0 = ((1 - ior) / (1 + ior)) ** 2
    fr = f0 + (1 - f0) * x
    dielectric = (1 - fr) * c / np.pi + fr * layer
    metal = (c + (1 - c) * x) * layer
    return ((1 - metallic) * dielectric + metallic * metal) * nl[:, None]


_pairs, _twin, _f32 = _EXT._pairs, _EXT._twin, _EXT._f32  # directions; the twin in the frame (x, y, z); float32 values


MATERIALS = {  # name: GltfPBR arguments
    "strength 0.8 dielectric": dict(base_color=(0.9, 0.5, 0.1), metallic=0.0, roughness=0.3, anisotropy_strength=0.8),
    "strength 1 metal rough 0.05": dict(base_color=(0.9, 0.6, 0.3), metallic=1.0, roughness=0.05,
                                        anisotropy_strength=1.0),
    "strength 0.3 rough 1": dict(base_color=(0.2, 0.5, 0.9), metallic=0.4, roughness=1.0, anisotropy_strength=0.3),
    "rough 0 strength 0.7": dict(base_color=(0.8, 0.1, 0.1), metallic=0.5, roughness=0.0, anisotropy_strength=0.7),
    "rotated 0.7": dict(base_color=(0.3, 0.6, 0.2), metallic=0.6, roughness=0.2, anisotropy_strength=0.9,
                        anisotropy_rotation=0.7),
    "texel and rotation": dict(base_color=(0.3, 0.6, 0.2), metallic=0.8, roughness=0.25, anisotropy_strength=0.6,
                               anisotropy_rotation=-2.0, anisotropy_direction=(0.2, 0.9, 1.0)),
    "ior 2 rotated by pi/2": dict(base_color=(0.9, 0.9, 0.9), metallic=0.0, roughness=0.4, anisotropy_strength=1.0,
                                  anisotropy_rotation=np.pi / 2, ior=2.0),
}


def _expected(arguments, l, v, planted=None):
    values = {k: (_f32(x) if k not in ("base_color", "anisotropy_direction") else np.float32(x).astype(np.float64))
              for k, x in arguments.items()}
    shape = l.shape
    return specification(np.broadcast_to(Z, shape), np.broadcast_to(X, shape), np.broadcast_to(Y, shape), l, v,
                         **values, planted=planted)


@pytest.mark.parametrize("name", sorted(MATERIALS))
def test_twin_equals_the_extension_in_float64(name):
    arguments = MATERIALS[name]
    material = glphong.GltfPBR(**arguments)
    assert material.extensions() == ("anisotropy",) and "tangent" in material.needs
    l, v = _pairs(600, seed=len(name))
    np.testing.assert_allclose(_twin(material, l, v), _expected(arguments, l, v), rtol=1e-10, atol=1e-300)


@pytest.mark.parametrize("planted", ["strength not squared", "at and ab swapped", "rotation clockwise", "V unclamped"])
def test_the_comparison_catches_the_usual_mistakes(planted):
    """The comparison above fails for the formulas one is tempted to write instead, planted in the transcription (V
    unclamped where the clamp acts: smooth, l and v grazing)."""
    arguments = MATERIALS["texel and rotation"] if planted != "V unclamped" else \
        dict(base_color=0.5, metallic=1.0, roughness=0.05, anisotropy_strength=0.3)
    l, v = _pairs(400, seed=5) if planted != "V unclamped" else _pairs(400, seed=5, max_angle=1.55)
    if planted == "V unclamped":  # near the mirror direction at grazing incidence
        v = l * np.array([-1.0, -1.0, 1.0])
        v[:, 0] += 0.002
        v /= np.linalg.norm(v, axis=1, keepdims=True)
        keep = l[:, 2] < 0.08
        l, v = l[keep], v[keep]
        assert len(l) > 10
    wrong = _expected(arguments, l, v, planted)
    twin = _twin(glphong.GltfPBR(**arguments), l, v)
    assert np.max(np.abs(wrong - twin) / np.max(twin, axis=1, keepdims=True)) > 1e-3


def test_strength_zero_is_the_core_material_its_program_and_needs():
    """anisotropy_strength 0 (the default) is the core: no extension, no define, no tangent needed, the core's
    uniforms and response bit for bit; any strength puts GLTF_PBR_ANISOTROPY and the tangent frame in the program."""
    from glphong.shaders.key import program_key

    lights = [glphong.PointLight((0.0, 0.0, 2.0), 10.0)]
    core = glphong.GltfPBR(0.5, 0.2, 0.5)
    neutral = glphong.GltfPBR(0.5, 0.2, 0.5, anisotropy_strength=0.0, anisotropy_rotation=1.0,
                              anisotropy_direction=(0.0, 1.0, 0.5))
    assert neutral.extensions() == () and neutral.needs == ("view",) == glphong.GltfPBR.needs
    assert program_key(neutral, lights, None) == program_key(core, lights, None)
    l, v = _pairs(200, seed=9)
    np.testing.assert_array_equal(_twin(neutral, l, v), _twin(core, l, v))
    anisotropic = glphong.GltfPBR(0.5, 0.2, 0.5, anisotropy_strength=0.4)
    key = program_key(anisotropic, lights, None)
    assert ("GLTF_PBR_ANISOTROPY", "1") in key.defines() and key.has_tangent
    assert not program_key(core, lights, None).has_tangent
    assert {"anisotropy_strength", "anisotropy_rotation", "anisotropy_direction"} <= \
        {q.name for q in anisotropic.active_params()}
    assert not {"anisotropy_strength"} & {q.name for q in core.active_params()}


def test_the_definition_check_accepts_the_tangent_only_under_its_define():
    """f.t under ``#if defined(GLTF_PBR_ANISOTROPY)`` is the anisotropic instance's need (structural_needs); the same
    read outside the define is refused, as for any model whose needs lack 'tangent'."""
    from glphong.definitions import material_checks
    from glphong.definitions.params import MaterialDefinitionError
    from glphong.definitions.registry import model_source
    from glphong.definitions.source import strip_comments

    cls = glphong.materials.gltf_pbr.GltfPBR
    code = strip_comments(model_source(cls)[0])
    assert "f.t" in code
    material_checks._check_needs(cls, code)
    planted = code.replace("    float x1 = max(1.0 - v_dot_h, 0.0);", "    float x1 = max(1.0 - v_dot_h + f.t.x, 0.0);")
    assert planted != code
    with pytest.raises(MaterialDefinitionError, match="'tangent'"):
        material_checks._check_needs(cls, planted)


def test_a_mesh_without_a_tangent_frame_is_refused_by_name():
    from glphong import primitives
    from glphong.scene.geometry import MeshData

    sphere = primitives.sphere(2)
    bare = MeshData(sphere.positions, sphere.normals, sphere.indices)  # no uvs, no tangents
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0, -3, 0), (0, 0, 0), up=(0, 0, 1)), [])
    scene.add(bare, glphong.GltfPBR(0.5, 0.0, 0.5))  # isotropic: no tangent needed
    with pytest.raises(ValueError, match="'gltf_pbr' needs a tangent frame"):
        scene.add(bare, glphong.GltfPBR(0.5, 0.0, 0.5, anisotropy_strength=0.5))


@pytest.mark.parametrize("name", sorted(MATERIALS))
def test_gpu_within_the_twins_band(name, glphong_backend):
    material = glphong.GltfPBR(**MATERIALS[name])
    assert_twin_matches(material, n=400, backend=glphong_backend)
    if MATERIALS[name]["roughness"] >= 0.2:  # the thin lobes: the band above, not a fixed tolerance
        _EXT.assert_gpu_near_transcription(material, lambda l, v: _expected(MATERIALS[name], l, v), glphong_backend)


def _sphere_scene(material, lights):
    return _EXT._sphere_scene(material, lights, ambient=0.05)


LIGHTS = {
    "point": lambda: [glphong.PointLight((1.2, -0.2, 1.2), 20.0)],
    "rect": lambda: [glphong.RectLight((0.6, -0.6, 1.6), (0.3, 0.0, 0.0), (0.0, 0.3, 0.0), radiance=20.0)],
    "environment": lambda: [glphong.EnvironmentLight(np.concatenate([np.full((3, 16, 3), 3.0),
                                                                     np.full((5, 16, 3), 0.3)], axis=0))],
}
BRUSHED = dict(base_color=(0.9, 0.7, 0.5), metallic=1.0, roughness=0.25, anisotropy_strength=0.9,
               anisotropy_rotation=0.4, clearcoat=0.5, clearcoat_roughness=0.1)


@pytest.mark.parametrize("lights", sorted(LIGHTS))
def test_renders_verify(lights, glphong_backend, glphong_make_renderer):
    report = glphong.verify(_sphere_scene(glphong.GltfPBR(**BRUSHED), LIGHTS[lights]()),
                            glphong_make_renderer(64, 64, glphong_backend), exact=False)
    assert report.covered_pixels > 900 and report.passed, report.summary()


def test_textured_anisotropy_verifies(glphong_backend, glphong_make_renderer):
    rng = np.random.default_rng(12)
    image = rng.integers(0, 256, (16, 16, 3), dtype=np.uint8)
    material = glphong.GltfPBR((0.6, 0.4, 0.3), 0.7, 0.3,
                               anisotropy_strength=glphong.Texture(image, 0.9, srgb=False, channel="b"),
                               anisotropy_direction=glphong.Texture(image, 1.0, srgb=False), anisotropy_rotation=0.3)
    assert material.extensions() == ("anisotropy",)
    report = glphong.verify(_sphere_scene(material, LIGHTS["point"]()), glphong_make_renderer(64, 64, glphong_backend))
    assert report.covered_pixels > 900 and report.passed, report.summary()


PLANTED = {  # text of gltf_pbr.glsl, planted text: each in the anisotropy's code only
    "strength not squared": ("float at = alpha * (1.0 - strength * strength) + strength * strength;",
                             "float at = alpha * (1.0 - strength) + strength;"),
    "rotation clockwise": ("float rx = c * dx - s * dy;\n    float ry = s * dx + c * dy;",
                           "float rx = c * dx + s * dy;\n    float ry = -s * dx + c * dy;"),
    "B along n x t": ("ok = safe_normalize(cross(n, aniso_t), aniso_b, len);", "ok = safe_normalize(cross(n, t), aniso_b, len);"),
}


@pytest.mark.parametrize("planted", sorted(PLANTED))
def test_planted_errors_fail(planted, monkeypatch, glphong_make_renderer):
    material = glphong.GltfPBR(**{**BRUSHED, "anisotropy_rotation": 0.8, "anisotropy_strength": 0.6})
    _EXT.assert_planted_error_fails(*PLANTED[planted], material, monkeypatch, glphong_make_renderer)


def test_stability_cases_pass(session_gl):
    """The anisotropy's stability cases (strength 0.5 and 1, roughness 0 to 1 at the peak and off it, rotations,
    grazing view to n.v = 1e-20, grazing light where V's clamp acts): the GPU within the band of the mpmath oracle
    (the extension's formulas as written, gltf_anisotropy_oracle), finite."""
    from glphong.checks.stability import CASES, run_stability

    cases = [c for c in CASES if c.group == "gltf anisotropy"]
    assert len(cases) >= 23
    report = run_stability(context=session_gl, cases=cases)
    assert [r.case for r in report.rows if not r.passed] == [], report.format_table()
    assert report.nan_count == 0 and report.inf_count == 0


# --------------------------------------------------------------------------- files
def test_files_load_with_their_texture_and_save_back(tmp_path):
    """The factors and the texture (rg the direction, b the strength, linear) load; a file without TANGENT takes the
    tangents computed from its UVs (the specification's rule); save_gltf writes the extension back (and names it in
    extensionsUsed), and the file loads again to the same material."""
    rng = np.random.default_rng(13)
    rgb = rng.integers(0, 256, (8, 8, 3), dtype=np.uint8)
    extensions = {"KHR_materials_anisotropy": {"anisotropyStrength": 0.6, "anisotropyRotation": 7.0,
                                               "anisotropyTexture": {"index": 0}}}
    path = _EXT._gltf(tmp_path, extensions, images=[rgb])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # applied: no warning about an unapplied extension
        scene = glphong.load_scene(path, light_units="radiometric", lights=[])
    material = scene.objects[0].material
    assert material.extensions() == ("anisotropy",) and scene.objects[0].mesh.has_tangents
    assert (material.anisotropy_strength.scale, material.anisotropy_strength.channel) == (0.6, "b")
    assert material.anisotropy_direction.texture is material.anisotropy_strength.texture
    np.testing.assert_allclose(material.anisotropy_rotation, 7.0 - 2.0 * np.pi, atol=1e-12)  # the same angle
    np.testing.assert_allclose(material.anisotropy_direction.texture.levels[0][::-1], rgb / 255.0, atol=1e-3)  # linear (sRGB: 0.5 for 0.74)
    out = tmp_path / "saved.gltf"
    glphong.save_gltf(scene, out)
    document = json.loads(out.read_text())
    written = document["materials"][0]["extensions"]["KHR_materials_anisotropy"]
    assert written["anisotropyStrength"] == 0.6 and "anisotropyTexture" in written
    np.testing.assert_allclose(written["anisotropyRotation"], 7.0 - 2.0 * np.pi, atol=1e-12)
    assert "KHR_materials_anisotropy" in document["extensionsUsed"]
    del document["materials"][0]["extras"]  # as another writer would have it: the extension alone
    out.write_text(json.dumps(document))
    again = glphong.load_scene(out, light_units="radiometric", lights=[]).objects[0].material
    assert again.extensions() == ("anisotropy",) and again.anisotropy_strength.scale == 0.6
    np.testing.assert_array_equal(again.anisotropy_direction.texture.levels[0], material.anisotropy_direction.texture.levels[0])



@pytest.mark.parametrize("direction", [(0.2, 0.9, 1.0), (0.5, 0.1, 0.3), (0.5, 0.5, 1.0), (1.0, 0.5, 1.0)])
def test_a_constant_direction_is_written_as_its_rotation(tmp_path, direction):
    """The file's direction is a texture's rg (none: the tangent), so a constant ``anisotropy_direction`` is written
    as its angle added to ``anisotropyRotation``: the JSON alone, read by glphong as another viewer reads it, gives
    the same rotated frame (T, B) within float64 rounding, and round trip with glphong's extras the same material; a
    zero direction (0.5, 0.5) takes the tangent, as the shader does."""
    from glphong.materials.gltf_anisotropy import gltf_anisotropy_frame

    material = glphong.GltfPBR(0.5, 0.0, 0.4, anisotropy_strength=0.7, anisotropy_rotation=0.6,
                               anisotropy_direction=direction)
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0, 0, 3), (0, 0, 0)), [])
    scene.add(glphong.primitives.sphere(1), material)
    out = tmp_path / "saved.gltf"
    glphong.save_gltf(scene, out)
    assert glphong.load_scene(out, light_units="radiometric", lights=[]).objects[0].material.anisotropy_direction == \
        material.anisotropy_direction  # glphong's extras: the material itself
    document = json.loads(out.read_text())
    written = document["materials"][0]["extensions"]["KHR_materials_anisotropy"]
    assert "anisotropyTexture" not in written
    del document["materials"][0]["extras"]  # the extension alone
    out.write_text(json.dumps(document))
    again = glphong.load_scene(out, light_units="radiometric", lights=[]).objects[0].material
    np.testing.assert_array_equal(np.asarray(again.anisotropy_direction, np.float64)[:2], (1.0, 0.5))  # the tangent
    frame = np.random.default_rng(5).normal(size=(3, 3))
    n, t, b = (v[None, :] for v in np.linalg.qr(frame)[0].T)
    expected = gltf_anisotropy_frame(n, t, b, direction, 0.6)
    got = gltf_anisotropy_frame(n, t, b, again.anisotropy_direction, again.anisotropy_rotation)
    for e, g in zip(expected, got):
        np.testing.assert_allclose(g, e, atol=1e-12)
    if direction[:2] != (0.5, 0.5) and direction[:2] != (1.0, 0.5):  # planted: the rotation without the angle
        wrong = gltf_anisotropy_frame(n, t, b, (1.0, 0.5, 1.0), 0.6)
        assert np.abs(wrong[0] - expected[0]).max() > 0.1

def test_files_default_strength_bad_factors_and_no_tangent_frame(tmp_path):
    """anisotropyStrength 0 (the default) is isotropic; an out-of-range strength or a non-finite rotation is refused
    with its JSON path; a mesh with neither TANGENT nor UVs cannot have the tangent frame the extension needs: refused,
    naming the object and the need."""
    path = _EXT._gltf(tmp_path, {"KHR_materials_anisotropy": {"anisotropyRotation": 1.0}})
    assert glphong.load_scene(path, light_units="radiometric", lights=[]).objects[0].material.extensions() == ()
    for field, value in (("anisotropyStrength", 1.5), ("anisotropyStrength", -0.1), ("anisotropyRotation", "1")):
        path = _EXT._gltf(tmp_path, {"KHR_materials_anisotropy": {field: value}})
        with pytest.raises(glphong.filesafety.SceneFileError,
                           match=rf"materials\[0\]\.extensions\.KHR_materials_anisotropy\.{field}"):
            glphong.load_scene(path, light_units="radiometric", lights=[])
    path = _EXT._gltf(tmp_path, {"KHR_materials_anisotropy": {"anisotropyStrength": 0.5}})
    document = json.loads(path.read_text())
    del document["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"]
    path.write_text(json.dumps(document))
    with pytest.raises(glphong.filesafety.SceneFileError, match=r"uses KHR_materials_anisotropy \(materials\[0\]\), "
                       r"which needs the mesh's tangent frame.*neither TANGENT nor TEXCOORD"):
        glphong.load_scene(path, light_units="radiometric", lights=[])


def test_declared_and_measured_anisotropic_and_reciprocal():
    """An anisotropic material's properties say it is not isotropic, and the analysis measures as much; it stays
    reciprocal (D and V are symmetric in l and v); the class and a strength-0 instance are the core's (isotropic)."""
    from glphong.analysis import properties

    measured = properties(glphong.GltfPBR(0.5, 1.0, 0.3, anisotropy_strength=0.8, anisotropy_rotation=0.3),
                          theta_i=[0.5])  # one albedo: the energy question is the core's, not asked here
    assert not measured.isotropic and measured.reciprocal, measured
    assert "isotropic" not in measured.disagreements and "reciprocal" not in measured.disagreements
    assert glphong.GltfPBR.properties.isotropic and glphong.GltfPBR(0.5, 1.0, 0.3).properties.isotropic
