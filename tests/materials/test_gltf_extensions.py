"""KHR_materials_specular and KHR_materials_clearcoat on glphong.GltfPBR (glphong/materials/gltf_extensions.py) against
an independent float64 transcription of the extensions' own text, written here and sharing nothing with glphong:

- Appendix B: ``D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2)``, ``V = 1 / (2 (|n.v| sqrt(alpha^2 + (1 -
  alpha^2)(n.l)^2) + |n.l| sqrt(alpha^2 + (1 - alpha^2)(n.v)^2)))``, ``specular_brdf = V D``,
  ``metal_brdf = conductor_fresnel(f0 = baseColor, specular_brdf) = (c + (1 - c)(1 - |v.h|)^5) V D``;
- KHR_materials_specular's ``fresnel_mix(f0_color, ior, weight, base, layer)``: ``f0 = min(((1 - ior)/(1 + ior))^2
  f0_color, 1)``, ``fr = f0 + (1 - f0)(1 - |v.h|)^5``, ``(1 - weight max_value(fr)) base + weight fr layer``;
- KHR_materials_clearcoat's ``fresnel_coat(normal, ior = 1.5, weight, base, layer)``: ``fr = f0 + (1 - f0)(1 -
  |v.normal|)^5``, ``mix(base, layer, weight fr)``, ``layer = specular_brdf(alpha = clearcoatRoughness^2)``; with
  ``clearcoatNormalTexture`` the coat's ``normal`` is glTF's normal texture rule on the unperturbed frame, ``normalize(t
  (s m.x) + b (s m.y) + n m.z)``, ``m = 2 texel - 1``, its Fresnel on ``clampedDot(normal, v)`` and its lobe times
  ``normal.l`` (0 where ``normal.l`` or ``normal.v <= 0``), the base's times ``n.l``.
"""
import json
import warnings

import numpy as np
import pytest

import glphong
from glphong.materials import ShadingFrame
from glphong.testing import assert_twin_matches, evaluate

Z = np.array([0.0, 0.0, 1.0])


def specification(n, l, v, base_color, metallic, roughness, specular=1.0, specular_color=(1.0, 1.0, 1.0),
                  clearcoat=0.0, clearcoat_roughness=0.0, ior=1.5, planted=None, clearcoat_normal=None,
                  clearcoat_normal_strength=1.0):
    """``coated_material (n.l)`` by the extensions' formulas, float64, (N, 3); ``planted`` one of three usual mistakes
    (test_the_comparison_catches_the_usual_mistakes)."""
    h = l + v
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    nl, nv, nh, vh = (np.sum(a * b, -1) for a, b in ((n, l), (n, v), (n, h), (v, h)))

    def specular_brdf(alpha, nh=nh, nv=nv, nl=nl):
        a2 = alpha ** 2
        with np.errstate(divide="ignore", invalid="ignore"):
            d = a2 / (np.pi * (nh ** 2 * (a2 - 1) + 1) ** 2)
        d = np.where(a2 == 0, 0.0, d)  # the delta of roughness 0 meets no direction pair with nonzero measure
        vis = 1 / (2 * (np.abs(nv) * np.sqrt(a2 + (1 - a2) * nl ** 2) + np.abs(nl) * np.sqrt(a2 + (1 - a2) * nv ** 2)))
        return (vis * d)[:, None]

    c = np.asarray(base_color, np.float64)[None, :]
    layer = specular_brdf(roughness ** 2)
    diffuse = c / np.pi
    f0 = np.minimum(((1 - ior) / (1 + ior)) ** 2 * np.asarray(specular_color, np.float64)[None, :], 1.0)
    fr = f0 + (1 - f0) * ((1 - np.abs(vh)) ** 5)[:, None]
    if planted == "f90 = 1":  # the weight on f0 alone
        fr = specular * f0 + (1 - specular * f0) * ((1 - np.abs(vh)) ** 5)[:, None]
        specular = 1.0
    fr_max = fr if planted == "diffuse by 1 - F_d per channel" else np.max(fr, axis=1, keepdims=True)
    dielectric = (1 - specular * fr_max) * diffuse + specular * fr * layer
    metal = (c + (1 - c) * ((1 - np.abs(vh)) ** 5)[:, None]) * layer
    material = (1 - metallic) * dielectric + metallic * metal
    coat_f0 = ((1 - 1.5) / (1 + 1.5)) ** 2
    coat_cos = np.abs(vh) if planted == "coat Fresnel on v.h" else np.abs(nv)
    coat_lobe = specular_brdf(clearcoat_roughness ** 2) * nl[:, None]
    if clearcoat_normal is not None:  # the coat's own normal on the frame (x, y, n)
        m = 2.0 * np.asarray(clearcoat_normal, np.float64) - 1.0
        s = clearcoat_normal_strength
        nc = np.array([1.0, 0.0, 0.0]) * s * m[0] + np.array([0.0, 1.0, 0.0]) * s * m[1] + n * m[2]
        nc = nc / np.linalg.norm(nc, axis=-1, keepdims=True)
        lc, vc, hc = (np.sum(nc * a, -1) for a in (l, v, h))
        coat_cos = np.maximum(vc, 0.0)
        coat_lobe = np.where(((lc > 0) & (vc > 0))[:, None],
                             specular_brdf(clearcoat_roughness ** 2, hc, vc, lc) * lc[:, None], 0.0)
    coat_fr = (coat_f0 + (1 - coat_f0) * (1 - coat_cos) ** 5)[:, None]
    return (1 - clearcoat * coat_fr) * material * nl[:, None] + clearcoat * coat_fr * coat_lobe


def _pairs(count, seed, max_angle=1.45):
    """``(l, v)``, each (count, 3): unit vectors uniform in solid angle within ``max_angle`` of the normal +z."""
    rng = np.random.default_rng(seed)
    z = rng.uniform(np.cos(max_angle), 1.0, (2, count))
    azimuth = rng.uniform(-np.pi, np.pi, (2, count))
    sine = np.sqrt(1.0 - z * z)
    l, v = np.stack([sine * np.cos(azimuth), sine * np.sin(azimuth), z], axis=-1)
    return l, v


def _twin(material, l, v):
    """The float64 twin's response at the float64 directions (no float32 rounding: the transcription's inputs), in the
    frame (x, y, z)."""
    (term,) = material.components
    frame = ShadingFrame(np.tile(Z, (len(l), 1)), np.tile([1.0, 0.0, 0.0], (len(l), 1)), np.tile([0.0, 1.0, 0.0], (len(l), 1)))
    return term.response(frame, l, v, l[:, 2].copy(), term.values())


def _f32(x):
    return np.asarray(np.float32(x), np.float64)


MATERIALS = {  # name: GltfPBR arguments
    "specular 0.5 coloured": dict(base_color=(0.9, 0.5, 0.1), metallic=0.0, roughness=0.3, specular=0.5,
                                  specular_color=(1.0, 0.5, 0.25)),
    "specular colour clamped": dict(base_color=(0.2, 0.5, 0.9), metallic=0.4, roughness=0.5, specular=1.0,
                                    specular_color=(30.0, 2.0, 0.0)),
    "specular 0": dict(base_color=(0.9, 0.5, 0.1), metallic=0.0, roughness=0.3, specular=0.0),
    "specular ior 2.4": dict(base_color=(0.9, 0.5, 0.1), metallic=0.2, roughness=0.7, specular=0.8,
                             specular_color=(0.5, 1.0, 1.5), ior=2.4),
    "clearcoat 1 rough 0.05": dict(base_color=(0.8, 0.1, 0.1), metallic=0.0, roughness=0.6, clearcoat=1.0,
                                   clearcoat_roughness=0.05),
    "clearcoat 0.5 rough 1 metal": dict(base_color=(0.9, 0.6, 0.3), metallic=1.0, roughness=0.2, clearcoat=0.5,
                                        clearcoat_roughness=1.0),
    "clearcoat 1 rough 0": dict(base_color=(0.8, 0.1, 0.1), metallic=0.0, roughness=0.4, clearcoat=1.0),
    "both": dict(base_color=(0.3, 0.6, 0.2), metallic=0.3, roughness=0.4, specular=0.7, specular_color=(1.5, 1.0, 0.5),
                 clearcoat=0.8, clearcoat_roughness=0.2),
    "coat normal tilted": dict(base_color=(0.8, 0.1, 0.1), metallic=0.0, roughness=0.5, clearcoat=1.0,
                               clearcoat_roughness=0.1, clearcoat_normal=(0.8, 0.35, 0.8)),
    "coat normal scaled 2.5": dict(base_color=(0.3, 0.6, 0.2), metallic=0.7, roughness=0.3, specular=0.6, clearcoat=0.7,
                                   clearcoat_roughness=0.3, clearcoat_normal=(0.3, 0.6, 0.9),
                                   clearcoat_normal_strength=2.5),
}


def _expected(arguments, l, v, planted=None):
    values = {k: (_f32(x) if k not in ("specular_color", "base_color", "clearcoat_normal")
                  else np.float32(x).astype(np.float64))
              for k, x in arguments.items()}
    return specification(np.broadcast_to(Z, l.shape), l, v, **values, planted=planted)


@pytest.mark.parametrize("name", sorted(MATERIALS))
def test_twin_equals_the_extensions_in_float64(name):
    arguments = MATERIALS[name]
    material = glphong.GltfPBR(**arguments)
    assert material.extensions() == tuple(e for e in ("specular", "clearcoat", "clearcoat_normal")
                                          if any(k.startswith(e) for k in arguments))
    l, v = _pairs(600, seed=len(name))
    np.testing.assert_allclose(_twin(material, l, v), _expected(arguments, l, v), rtol=1e-11, atol=1e-300)


@pytest.mark.parametrize("planted", ["coat Fresnel on v.h", "diffuse by 1 - F_d per channel", "f90 = 1"])
def test_the_comparison_catches_the_usual_mistakes(planted):
    """The comparison above fails for the formulas one is tempted to write instead, planted in the transcription: each
    differs from the twin by far more than the comparison's tolerance."""
    arguments = MATERIALS["both"] | {"specular_color": (30.0, 1.0, 0.5)}
    l, v = _pairs(300, seed=5)
    wrong = _expected(arguments, l, v, planted)
    twin = _twin(glphong.GltfPBR(**arguments), l, v)
    assert np.max(np.abs(wrong - twin) / np.max(twin, axis=1, keepdims=True)) > 1e-3


def test_neutral_values_are_the_core_material_and_its_program():
    """specular 1, specular_color 1 and clearcoat 0 are the core: no extension, no define, the core's uniforms, the
    response bit for bit; any other value puts the extension's define in the program key."""
    from glphong.shaders.key import program_key

    lights = [glphong.PointLight((0.0, 0.0, 2.0), 10.0)]
    core = glphong.GltfPBR(0.5, 0.2, 0.5)
    neutral = glphong.GltfPBR(0.5, 0.2, 0.5, specular=1.0, specular_color=1.0, clearcoat=0.0, clearcoat_roughness=0.7)
    assert neutral.extensions() == () and program_key(neutral, lights, None) == program_key(core, lights, None)
    assert {q.name for q in core.active_params()} == {"base_color", "metallic", "roughness", "emissive", "occlusion",
                                                      "ior"}
    l, v = _pairs(200, seed=9)
    np.testing.assert_array_equal(_twin(neutral, l, v), _twin(core, l, v))
    for arguments, defines in ((dict(specular=0.9), {"GLTF_PBR_SPECULAR"}), (dict(clearcoat=0.1), {"GLTF_PBR_CLEARCOAT"}),
                               (dict(specular_color=(1, 1, 0.5), clearcoat=1.0),
                                {"GLTF_PBR_SPECULAR", "GLTF_PBR_CLEARCOAT"})):
        key = program_key(glphong.GltfPBR(0.5, 0.2, 0.5, **arguments), lights, None)
        assert {name for name, _ in key.defines() if name in ("GLTF_PBR_SPECULAR", "GLTF_PBR_CLEARCOAT")} == defines


@pytest.mark.parametrize("name", sorted(MATERIALS))
def test_gpu_within_the_twins_band(name, glphong_backend):
    material = glphong.GltfPBR(**MATERIALS[name])
    assert_twin_matches(material, n=400, backend=glphong_backend)
    assert_gpu_near_transcription(material, lambda l, v: _expected(MATERIALS[name], l, v), glphong_backend)


def assert_gpu_near_transcription(material, expected, backend, tolerance=3e-3):
    """The GPU within ``tolerance`` of the largest channel of ``expected(l, v)`` (the transcription at the float32
    directions the GPU is given) for 300 pairs within 1.3 rad of the normal (also used by test_gltf_anisotropy.py)."""
    l, v = _pairs(300, seed=11, max_angle=1.3)
    l32, v32 = l.astype(np.float32).astype(float), v.astype(np.float32).astype(float)
    l32 /= np.linalg.norm(l32, axis=1, keepdims=True)
    v32 /= np.linalg.norm(v32, axis=1, keepdims=True)
    gpu = evaluate(material, l, v, backend=backend).astype(np.float64)
    want = expected(l32, v32)
    scale = np.maximum(np.max(want, axis=1, keepdims=True), 1e-6 * want.max())  # a coat normal may black out a row
    rel = np.abs(gpu - want) / scale
    assert np.all(np.isfinite(gpu)) and rel.max() < tolerance, rel.max()


def _sphere_scene(material, lights, ambient=None):
    from glphong import primitives

    camera = glphong.PerspectiveCamera.look_at((0.0, -1.2, 1.5), (0.0, 0.0, 0.45), up=(0.0, 0.0, 1.0))
    pose = np.eye(4)
    pose[2, 3] = 0.5
    scene = glphong.Scene(camera, lights, ambient=None if ambient is None else glphong.AmbientLight(ambient))
    scene.add(primitives.sphere(4, radius=0.5), material, pose=pose)
    return scene


LIGHTS = {
    "point": lambda: [glphong.PointLight((1.2, -0.2, 1.2), 20.0)],
    "spot and directional": lambda: [glphong.SpotLight((1.2, -0.2, 1.2), (-1.2, 0.2, -0.7), 20.0, 0.5, 0.9),
                                     glphong.DirectionalLight((-0.3, 0.5, -1.0), 2.0)],
    "rect": lambda: [glphong.RectLight((0.6, -0.6, 1.6), (0.3, 0.0, 0.0), (0.0, 0.3, 0.0), radiance=20.0)],
    "environment": lambda: [glphong.EnvironmentLight(np.concatenate([np.full((3, 16, 3), 3.0),
                                                                     np.full((5, 16, 3), 0.3)], axis=0))],
}


@pytest.mark.parametrize("lights", sorted(LIGHTS))
def test_renders_verify_under_every_light_kind(lights, glphong_backend, glphong_make_renderer):
    material = glphong.GltfPBR(**MATERIALS["both"])
    report = glphong.verify(_sphere_scene(material, LIGHTS[lights](), ambient=0.05),
                            glphong_make_renderer(64, 64, glphong_backend), exact=False)
    assert report.covered_pixels > 900 and report.passed, report.summary()


def test_textured_extensions_verify(glphong_backend, glphong_make_renderer):
    rng = np.random.default_rng(12)
    image = rng.integers(0, 256, (16, 16, 3), dtype=np.uint8)
    material = glphong.GltfPBR((0.6, 0.4, 0.3), 0.2, 0.5,
                               specular=glphong.Texture(image, 0.9, srgb=False, channel="r"),
                               specular_color=glphong.Texture(image[::-1], (1.0, 1.5, 0.5)),
                               clearcoat=glphong.Texture(image[:, ::-1], 1.0, srgb=False, channel="r"),
                               clearcoat_roughness=glphong.Texture(image, 0.5, srgb=False, channel="g"))
    assert material.extensions() == ("specular", "clearcoat")
    report = glphong.verify(_sphere_scene(material, LIGHTS["point"]()), glphong_make_renderer(64, 64, glphong_backend))
    assert report.covered_pixels > 900 and report.passed, report.summary()


PLANTED = {  # text of gltf_pbr.glsl, planted text: each in the extensions' code only
    "coat Fresnel f0 0.05": ("return 0.04 + 0.96 * y;", "return 0.05 + 0.95 * y;"),
    "coat Fresnel to the fourth": ("float y = (y1 * y1) * (y1 * y1) * y1;", "float y = (y1 * y1) * (y1 * y1);"),
    "specular f90 = 1": ("return dielectric_f0 + (specular - dielectric_f0) * x;",
                         "return dielectric_f0 + (1.0 - dielectric_f0) * x;"),
    "diffuse by the mean of F_d": ("float fd_max = max(fd.r, max(fd.g, fd.b));", "float fd_max = (fd.r + fd.g + fd.b) / 3.0;"),
    "coat roughness not squared": ("float alpha_c = u_gltf_pbr_clearcoat_roughness * u_gltf_pbr_clearcoat_roughness;",
                                   "float alpha_c = u_gltf_pbr_clearcoat_roughness;"),
}


def assert_planted_error_fails(old, new, material, monkeypatch, make_renderer):
    """The sphere of test_renders_verify_under_every_light_kind (point light) with ``old`` replaced by ``new`` in
    gltf_pbr.glsl: ``verify`` fails (also used by test_gltf_sheen.py)."""
    from glphong.shaders import assembly

    original = assembly.model_source
    source = original(glphong.materials.gltf_pbr.GltfPBR)
    assert old in source[0]
    monkeypatch.setattr(assembly, "model_source", lambda cls: (source[0].replace(old, new),) + tuple(source[1:])
                        if cls is glphong.materials.gltf_pbr.GltfPBR else original(cls))
    report = glphong.verify(_sphere_scene(material, LIGHTS["point"]()), make_renderer(64, 64, "egl"))
    assert not report.passed and report.outside_count > 0, report.summary()


@pytest.mark.parametrize("planted", sorted(PLANTED))
def test_planted_errors_fail(planted, monkeypatch, glphong_make_renderer):
    material = glphong.GltfPBR(**{**MATERIALS["both"], "specular_color": (3.0, 1.0, 0.5), "clearcoat": 1.0})
    assert_planted_error_fails(*PLANTED[planted], material, monkeypatch, glphong_make_renderer)


def _coat_normal_material():
    """A coat with a textured normal (random tilts up to about 50 degrees, scale 0.8) over a dielectric."""
    rng = np.random.default_rng(21)
    texel = np.concatenate([rng.integers(40, 216, (16, 16, 2)), np.full((16, 16, 1), 230)], axis=2).astype(np.uint8)
    return glphong.GltfPBR((0.7, 0.2, 0.1), 0.0, 0.6, clearcoat=1.0, clearcoat_roughness=0.15,
                           clearcoat_normal=glphong.Texture(texel, 1.0, srgb=False), clearcoat_normal_strength=0.8)


def test_coat_normal_texture_verifies(glphong_backend, glphong_make_renderer):
    material = _coat_normal_material()
    assert material.extensions() == ("clearcoat", "clearcoat_normal") and "tangent" in material.needs
    report = glphong.verify(_sphere_scene(material, LIGHTS["point"]()), glphong_make_renderer(64, 64, glphong_backend))
    assert report.covered_pixels > 900 and report.passed, report.summary()


COAT_NORMAL_PLANTED = {  # the coat's own normal ignored; its Fresnel on the shading normal
    "coat on the shading normal": ("bool c_valid = microfacet_geometry(n_c, wi, wo,",
                                   "bool c_valid = microfacet_geometry(f.n, wi, wo,"),
    "coat Fresnel on n.v": ("gltf_clearcoat_fresnel(max(dot(n_c, wo), 0.0))", "gltf_clearcoat_fresnel(n_dot_v)"),
}


@pytest.mark.parametrize("planted", sorted(COAT_NORMAL_PLANTED))
def test_coat_normal_planted_errors_fail(planted, monkeypatch, glphong_make_renderer):
    assert_planted_error_fails(*COAT_NORMAL_PLANTED[planted], _coat_normal_material(), monkeypatch,
                               glphong_make_renderer)


def test_stability_cases_pass(session_gl):
    """The extensions' stability cases (grazing view, roughness 0 and 1, specular 0 and 1, a clamped f0): the GPU
    within the band of the mpmath oracle (the extensions' formulas, gltf_extensions_oracle), finite."""
    from glphong.checks.stability import CASES, run_stability

    cases = [c for c in CASES if c.group in ("gltf specular", "gltf clearcoat")]
    assert len(cases) >= 25
    report = run_stability(context=session_gl, cases=cases)
    assert [r.case for r in report.rows if not r.passed] == [], report.format_table()
    assert report.nan_count == 0 and report.inf_count == 0


def test_clearcoat_with_emission_warns():
    with pytest.warns(UserWarning, match="does not darken the emission"):
        glphong.GltfPBR(0.5, 0.0, 0.5, emissive=1.0, clearcoat=0.5)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        glphong.GltfPBR(0.5, 0.0, 0.5, emissive=1.0, specular=0.5)


# --------------------------------------------------------------------------- files
def _gltf(tmp_path, extensions, normal=None, images=None, used=()):
    """A glTF file of one textured quad whose material carries ``extensions`` (and ``extensionsUsed``)."""
    import base64
    import io

    from PIL import Image

    positions = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
    normals = np.tile(np.array([0, 0, 1], np.float32), (4, 1))
    uvs = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], np.float32)
    indices = np.array([0, 1, 2, 0, 2, 3], np.uint16)
    blob = positions.tobytes() + normals.tobytes() + uvs.tobytes() + indices.tobytes()
    views = [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 48},
             {"buffer": 0, "byteOffset": 96, "byteLength": 32}, {"buffer": 0, "byteOffset": 128, "byteLength": 12}]
    accessors = [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0],
                  "max": [1, 1, 0]}, {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
                 {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
                 {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}]
    document = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
                "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3,
                                            "material": 0}]}],
                "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.4, 0.3, 1.0], "metallicFactor": 0.0,
                                                        "roughnessFactor": 0.5}, "extensions": extensions}],
                "accessors": accessors, "bufferViews": views,
                "buffers": [{"byteLength": len(blob),
                             "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
                "extensionsUsed": sorted(extensions) + list(used)}
    if normal is not None:
        document["materials"][0]["normalTexture"] = {"index": normal}
    if images:
        document["images"], document["textures"] = [], []
        for k, pixels in enumerate(images):
            png = io.BytesIO()
            Image.fromarray(pixels).save(png, format="PNG")
            document["images"].append({"uri": "data:image/png;base64," + base64.b64encode(png.getvalue()).decode()})
            document["textures"].append({"source": k})
    path = tmp_path / "coated.gltf"
    path.write_text(json.dumps(document))
    return path


def test_files_load_with_their_textures_and_save_back(tmp_path):
    rng = np.random.default_rng(13)
    rgba = rng.integers(0, 256, (8, 8, 4), dtype=np.uint8)
    rgb = rng.integers(0, 256, (8, 8, 3), dtype=np.uint8)
    extensions = {"KHR_materials_specular": {"specularFactor": 0.7, "specularColorFactor": [1.0, 2.0, 0.5],
                                             "specularTexture": {"index": 0}, "specularColorTexture": {"index": 1}},
                  "KHR_materials_clearcoat": {"clearcoatFactor": 0.9, "clearcoatTexture": {"index": 1},
                                              "clearcoatRoughnessFactor": 0.3, "clearcoatRoughnessTexture": {"index": 1}}}
    path = _gltf(tmp_path, extensions, images=[rgba, rgb])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # both applied: no warning about unapplied extensions
        material = glphong.load_scene(path, light_units="radiometric", lights=[]).objects[0].material
    assert material.extensions() == ("specular", "clearcoat")
    assert material.specular.scale == 0.7 and material.specular.channel == "r"
    # the specular strength is the texture's alpha (a grey image of it), linear
    np.testing.assert_allclose(material.specular.texture.levels[0][::-1, :, 0], rgba[..., 3] / 255.0, atol=2e-3)
    np.testing.assert_array_equal(material.specular_color.scale, (1.0, 2.0, 0.5))
    assert (material.clearcoat.scale, material.clearcoat.channel) == (0.9, "r")
    assert (material.clearcoat_roughness.scale, material.clearcoat_roughness.channel) == (0.3, "g")
    out = tmp_path / "saved.gltf"
    glphong.save_gltf(glphong.load_scene(path, light_units="radiometric", lights=[]), out)
    written = json.loads(out.read_text())["materials"][0]["extensions"]
    assert written["KHR_materials_specular"]["specularFactor"] == 0.7
    assert written["KHR_materials_specular"]["specularColorFactor"] == [1.0, 2.0, 0.5]
    assert "specularColorTexture" in written["KHR_materials_specular"]
    coat = written["KHR_materials_clearcoat"]
    assert (coat["clearcoatFactor"], coat["clearcoatRoughnessFactor"]) == (0.9, 0.3)
    assert "clearcoatTexture" in coat and "clearcoatRoughnessTexture" in coat
    again = glphong.load_scene(out, light_units="radiometric", lights=[]).objects[0].material
    assert again.extensions() == ("specular", "clearcoat") and again.clearcoat.scale == 0.9


def test_files_disabled_coat_and_coat_normals(tmp_path):
    """clearcoatFactor 0 disables the layer; clearcoatNormalTexture without a base normalTexture is the coat's own
    normal (with its scale; written back); over a normalTexture too, the coat's normal on the unperturbed frame
    (test_gltf_coat_normal.py); out-of-range factors are refused with their JSON path."""
    path = _gltf(tmp_path, {"KHR_materials_clearcoat": {"clearcoatFactor": 0.0, "clearcoatRoughnessFactor": 0.5}})
    assert glphong.load_scene(path, light_units="radiometric", lights=[]).objects[0].material.extensions() == ()
    rgb = np.full((4, 4, 3), 128, np.uint8)
    rgb[..., 0] = 200
    path = _gltf(tmp_path, {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatNormalTexture":
                                                        {"index": 0, "scale": 0.5}}}, images=[rgb])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        scene = glphong.load_scene(path, light_units="radiometric", lights=[])
    material = scene.objects[0].material
    assert material.extensions() == ("clearcoat", "clearcoat_normal") and "tangent" in material.needs
    assert material.clearcoat_normal_strength == 0.5 and material.normal_map is None
    np.testing.assert_allclose(material.clearcoat_normal.texture.levels[0][0, 0], rgb[0, 0] / 255.0, atol=1e-3)  # linear
    out = tmp_path / "saved.gltf"
    glphong.save_gltf(scene, out)
    document = json.loads(out.read_text())
    assert document["materials"][0]["extensions"]["KHR_materials_clearcoat"]["clearcoatNormalTexture"]["scale"] == 0.5
    del document["materials"][0]["extras"]
    out.write_text(json.dumps(document))
    again = glphong.load_scene(out, light_units="radiometric", lights=[]).objects[0].material
    assert again.extensions() == ("clearcoat", "clearcoat_normal") and again.clearcoat_normal_strength == 0.5
    path = _gltf(tmp_path, {"KHR_materials_specular": {"specularFactor": 1.5}})
    with pytest.raises(glphong.filesafety.SceneFileError,
                       match=r"materials\[0\]\.extensions\.KHR_materials_specular\.specularFactor"):
        glphong.load_scene(path, light_units="radiometric", lights=[])


def test_files_coat_normal_scale_and_tangent_frame_refused_by_json_path(tmp_path):
    """clearcoatNormalTexture.scale beyond glphong's bounds of clearcoat_normal_strength (|scale| <= 1e4, the
    parameter's definition) or not a number is refused with its JSON path; a coat normal on a mesh with neither TANGENT
    nor TEXCOORD (no tangent frame) is refused naming KHR_materials_clearcoat's clearcoatNormalTexture."""
    rgb = np.full((4, 4, 3), 128, np.uint8)
    for scale in (1e6, -2e4, "1"):
        path = _gltf(tmp_path, {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatNormalTexture":
                                                            {"index": 0, "scale": scale}}}, images=[rgb])
        with pytest.raises(glphong.filesafety.SceneFileError, match=r"coated\.gltf: materials\[0\]\.extensions\."
                           r"KHR_materials_clearcoat\.clearcoatNormalTexture\.scale: expected a .*number"):
            glphong.load_scene(path, light_units="radiometric", lights=[])
    path = _gltf(tmp_path, {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatNormalTexture":
                                                        {"index": 0, "scale": 1e4}}}, images=[rgb])
    assert glphong.load_scene(path, light_units="radiometric",
                              lights=[]).objects[0].material.clearcoat_normal_strength == 1e4  # the bound itself
    # a file's coat normal is a texture, which gives its mesh uvs and so a tangent frame; a file's material on a mesh
    # without one (the loader's error for what the scene refuses) names the extensions needing it: both here
    from glphong import primitives
    from glphong.formats.gltf_material_extensions import tangent_frame_error
    from glphong.scene.geometry import MeshData

    sphere = primitives.sphere(2)
    bare = MeshData(sphere.positions, sphere.normals, sphere.indices)  # no uvs, no tangents
    material = glphong.GltfPBR(0.5, 0.0, 0.5, clearcoat=1.0, clearcoat_normal=(0.7, 0.4, 0.9),
                               anisotropy_strength=0.5)
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0, -3, 0), (0, 0, 0), up=(0, 0, 1)), [])
    with pytest.raises(ValueError) as refused:
        scene.add(bare, material, name="quad")
    error = tangent_frame_error(path, refused.value, material, bare, "quad", 3)
    assert isinstance(error, glphong.filesafety.SceneFileError)
    assert error.where == ("materials[3].extensions.KHR_materials_clearcoat.clearcoatNormalTexture, "
                           "materials[3].extensions.KHR_materials_anisotropy")
    assert "uses KHR_materials_clearcoat.clearcoatNormalTexture, KHR_materials_anisotropy (materials[3]), which " \
           "needs the mesh's tangent frame" in error.message
    other = ValueError("not an extension's")  # a material needing no tangent: the scene's error as it is
    assert tangent_frame_error(path, other, glphong.GltfPBR(0.5, 0.0, 0.5, clearcoat=1.0), bare, "quad", 3) is other


def test_a_coat_is_declared_and_measured_not_reciprocal():
    """The coat's Fresnel is on n.v alone: a coated material's properties say it is not reciprocal, and the analysis
    measures as much; the specular extension keeps the core's reciprocity (F_d on v.h)."""
    from glphong.analysis import properties

    coated = properties(glphong.GltfPBR(0.5, 0.0, 0.4, clearcoat=1.0, clearcoat_roughness=0.1), theta_i=[0.5])
    assert not coated.reciprocal and coated.reciprocity_error > 1e-4 and "reciprocal" not in coated.disagreements
    specular = properties(glphong.GltfPBR(0.5, 0.0, 0.4, specular=0.5, specular_color=(1.0, 0.2, 3.0)),
                          theta_i=[0.5])  # one albedo: the energy question is the core's, not asked here
    assert specular.reciprocal and "reciprocal" not in specular.disagreements
    assert glphong.GltfPBR.properties.reciprocal  # the class: the core's


def test_texture_transform_covers_the_extensions_textures(tmp_path):
    """KHR_texture_transform on an extension's textures moves the mesh's uvs like a core texture's; one that differs
    from the core textures' is named in a warning and none is applied."""
    rgb = np.full((4, 4, 3), 200, np.uint8)
    shift = {"KHR_texture_transform": {"offset": [0.25, 0.0]}}
    coat = {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatTexture": {"index": 0, "extensions": shift}},
            "KHR_materials_specular": {"specularColorTexture": {"index": 0, "extensions": shift}}}
    path = _gltf(tmp_path, coat, images=[rgb], used=("KHR_texture_transform",))
    uvs = glphong.load_scene(path, light_units="radiometric", lights=[]).objects[0].mesh.uvs
    np.testing.assert_allclose(uvs[:, 0], [0.25, 1.25, 1.25, 0.25], atol=1e-12)
    document = json.loads(path.read_text())
    document["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    path.write_text(json.dumps(document))
    with pytest.warns(UserWarning, match="different KHR_texture_transforms"):
        scene = glphong.load_scene(path, light_units="radiometric", lights=[])
    np.testing.assert_allclose(scene.objects[0].mesh.uvs[:, 0], [0.0, 1.0, 1.0, 0.0], atol=1e-12)


def test_roughness_zero_at_grazing_light_and_view(glphong_backend):
    """Roughness 0 (the core's and the coat's, the coat's default) with l and v grazing and crossed: D is the delta, 0
    here; float32 (n.l)^2 underflows, so V's r_l = r_v = 0 would make 0/0 (the GPU gave 2.1e37 for the core and
    FLT_MAX for the coat before the roughness-0 rule): the GPU's response is the twin's, tiny and finite."""
    wi = [[0.5830193758010864, -0.8124582171440125, 1.3896630405750907e-25],
          [-0.9944632649421692, -0.10508492588996887, 1.1386841872121635e-29]]
    wo = [[0.4666494131088257, 0.8844423890113831, 9.66713723623345e-22],
          [-0.5094205141067505, 0.8605177402496338, 5.398353130354245e-27]]
    for material in (glphong.GltfPBR((0.8, 0.1, 0.1), 0.0, 0.0), glphong.GltfPBR((0.8, 0.1, 0.1), 0.0, 0.4, clearcoat=1.0)):
        gpu = evaluate(material, wi, wo, backend=glphong_backend).astype(np.float64)
        twin = evaluate(material, wi, wo, twin=True)
        assert np.all(twin < 1e-20) and np.all(np.abs(gpu - twin) <= 1e-6 * np.abs(twin) + 1e-37), (gpu, twin)
        # the twin in float32, as the band evaluates it: the same rule, so 0 or tiny, never the NaN of 0 * inf
        l, v = (np.asarray(d, np.float64) / np.linalg.norm(d, axis=1, keepdims=True) for d in (wi, wo))
        l32, v32 = l.astype(np.float32), v.astype(np.float32)
        (term,) = material.components
        single = term.response(ShadingFrame(np.tile(np.float32([0, 0, 1]), (2, 1))), l32, v32, l32[:, 2].copy(),
                               term.values())
        assert np.all(np.isfinite(single)) and np.all(np.abs(single) <= 1e-20), single
