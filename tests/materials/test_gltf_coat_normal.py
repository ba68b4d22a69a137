"""KHR_materials_clearcoat's coat normal over a normal-mapped base (glphong/materials/gltf_coat_normal.py): the
extension's text, transcribed here in float64 and sharing nothing with glphong but the base's Appendix B transcription
of test_gltf_extensions.py:

- the base's normal is glTF's normal texture rule on the unperturbed frame ``(t, b, n)`` (the interpolated normal and
  the tangent made orthogonal to it): ``n' = normalize(t (s m.x) + b (s m.y) + n m.z)``, ``m = 2 texel - 1``;
- "clearcoatNormalTexture: ... If not given, no normal mapping is applied to the clear coat layer, even if normal
  mapping is applied to the base material": the coat's normal is the same rule with the coat's texel and scale on the
  same unperturbed frame (``n`` itself without one), never the base's ``n'``;
- ``coated = mix(material(n') (n'.l), layer(n_c) (n_c.l), clearcoat F_c)``, ``F_c = 0.04 + 0.96 (1 - n_c.v)^5``,
  ``layer`` Appendix B's ``V D`` with ``alpha = clearcoat_roughness^2`` on ``n_c`` (0 where ``n_c.l`` or ``n_c.v <=
  0``).
"""
import importlib.util
import json
import pathlib
import warnings

import numpy as np
import pytest

import glphong
from glphong.materials import ShadingFrame

_SPEC = importlib.util.spec_from_file_location("_gltf_extension_tests", pathlib.Path(__file__).with_name(
    "test_gltf_extensions.py"))
_EXT = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(_EXT)  # its Appendix B transcription, its sphere, the planted-error check, the file of a quad

X, Y, Z = np.eye(3)
BASE = dict(base_color=(0.7, 0.3, 0.1), metallic=0.2, roughness=0.5)
COAT = dict(clearcoat=0.9, clearcoat_roughness=0.2)


def _mapped(texel, scale, t, b, n):
    """glTF's normal texture rule on the frame ``(t, b, n)``: ``normalize(t (s m.x) + b (s m.y) + n m.z)``."""
    m = 2.0 * np.asarray(texel, np.float64) - 1.0
    q = t * (scale * m[..., 0:1]) + b * (scale * m[..., 1:2]) + n * m[..., 2:3]
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def coated(t, b, n, l, v, base_texel, base_scale, coat_texel, coat_scale, planted=None):
    """The extension's ``coated`` times the lights' cosines, float64 (N, 3), on the unperturbed frame ``(t, b, n)``
    (each (N, 3)); ``planted='coat on the mapped normal'``: the coat's texel on the base's perturbed frame instead."""
    dot = lambda a, c: np.sum(a * c, axis=-1)  # noqa: E731
    base_n = _mapped(base_texel, base_scale, t, b, n)
    material = _EXT.specification(base_n, l, v, **{k: np.float32(x).astype(np.float64) for k, x in BASE.items()})
    frame_n = n
    if planted == "coat on the mapped normal":
        frame_n = base_n
        t = t - dot(t, base_n)[:, None] * base_n
        t = t / np.linalg.norm(t, axis=-1, keepdims=True)
        b = np.cross(base_n, t)
    coat_n = _mapped(np.broadcast_to(coat_texel, n.shape), coat_scale, t, b, frame_n)
    h = (l + v) / np.linalg.norm(l + v, axis=-1, keepdims=True)
    cl, cv, ch = dot(coat_n, l), dot(coat_n, v), dot(coat_n, h)
    a2 = float(np.float32(COAT["clearcoat_roughness"])) ** 4
    d = a2 / (np.pi * (ch ** 2 * (a2 - 1) + 1) ** 2)
    vis = 1 / (2 * (np.abs(cv) * np.sqrt(a2 + (1 - a2) * cl ** 2) + np.abs(cl) * np.sqrt(a2 + (1 - a2) * cv ** 2)))
    layer = np.where((cl > 0) & (cv > 0), vis * d * cl, 0.0)
    weight = float(np.float32(COAT["clearcoat"])) * (0.04 + 0.96 * (1 - np.maximum(cv, 0.0)) ** 5)
    return (1 - weight)[:, None] * material + (weight * layer)[:, None]


def _material(coat_texel=None, coat_scale=1.0, base_image=None, base_scale=1.3):
    """A coated GltfPBR with a normal map of ``base_image`` (default: one constant texel) and the coat's texel (None:
    none given, the unperturbed normal)."""
    image = np.full((4, 4, 3), (200, 90, 230), np.uint8) if base_image is None else base_image
    extra = {} if coat_texel is None else dict(clearcoat_normal=coat_texel, clearcoat_normal_strength=coat_scale)
    return glphong.GltfPBR(**BASE, **COAT, **extra, normal_map=glphong.NormalMap(image, base_scale))


CASES = {  # name: (coat texel or None, coat scale)
    "coat texel tilted": ((0.8, 0.35, 0.8), 1.0),
    "coat texel scaled 2": ((0.3, 0.6, 0.9), 2.0),
    "no coat texel: the unperturbed normal": (None, 1.0),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_twin_equals_the_extension_in_float64(name):
    """The twin given the mapped frame and the unperturbed one (``f.unperturbed``, as `shade_inputs` gives it) equals
    the transcription, at random base texels and direction pairs; the transcription with the coat on the mapped normal
    differs from it by far more than the comparison's tolerance."""
    coat_texel, coat_scale = CASES[name]
    material = _material(coat_texel, coat_scale)
    assert material.extensions() == ("clearcoat", "clearcoat_normal")
    assert {"tangent", "unperturbed"} <= set(material.needs)
    rng = np.random.default_rng(len(name))
    count = 800
    base_texel = np.concatenate([rng.uniform(0.15, 0.85, (count, 2)), rng.uniform(0.75, 1.0, (count, 1))], axis=1)
    t, b, n = (np.tile(a, (count, 1)) for a in (X, Y, Z))
    mapped = _mapped(base_texel, 1.3, t, b, n)
    mapped_t = X - mapped[:, :1] * mapped  # the frame the shader builds on the mapped normal (the coat must not use)
    mapped_t /= np.linalg.norm(mapped_t, axis=-1, keepdims=True)
    l, v = _EXT._pairs(count, seed=3, max_angle=1.3)
    keep = (np.sum(mapped * l, -1) > 0) & (np.sum(mapped * v, -1) > 0)  # the light loop's gate on the shading normal
    assert keep.sum() > 0.7 * count
    frame = ShadingFrame(mapped, mapped_t, np.cross(mapped, mapped_t), unperturbed=ShadingFrame(n, t, b))
    (term,) = material.components
    twin = term.response(frame, l, v, np.sum(mapped * l, -1), term.values())[keep]
    want = coated(t, b, n, l, v, base_texel, 1.3, (0.5, 0.5, 1.0) if coat_texel is None else
                  np.float32(coat_texel).astype(np.float64), coat_scale)[keep]
    np.testing.assert_allclose(twin, want, rtol=1e-11, atol=1e-300)
    wrong = coated(t, b, n, l, v, base_texel, 1.3, (0.5, 0.5, 1.0) if coat_texel is None else
                   np.float32(coat_texel).astype(np.float64), coat_scale, planted="coat on the mapped normal")[keep]
    assert np.max(np.abs(wrong - twin) / np.max(twin, axis=1, keepdims=True)) > 1e-2


def _scene(material, lights):
    return _EXT._sphere_scene(material, lights)


@pytest.mark.parametrize("name", sorted(CASES))
def test_gpu_equals_the_transcription_per_pixel(name, glphong_backend, glphong_make_renderer):
    """The render of a coated sphere with a constant base normal texel, against the transcription at each pixel from
    the G-buffer's point, unperturbed normal and tangent (glTF's frame built from them here): within 2e-3 of the
    pixel's largest channel; ``verify`` passes; the G-buffer's unperturbed normal is not the mapped one."""
    coat_texel, coat_scale = CASES[name]
    material = _material(coat_texel, coat_scale)
    irradiance, direction = 2.0, np.array([-0.6, 0.5, -1.0])
    scene = _scene(material, [glphong.DirectionalLight(direction, irradiance)])
    renderer = glphong_make_renderer(64, 64, glphong_backend)
    radiance = renderer.render(scene).radiance.astype(np.float64)
    gbuffer = renderer.gbuffer(scene)
    assert gbuffer.unperturbed is not None
    mask = gbuffer.mask
    n = gbuffer.unperturbed[mask].astype(np.float64)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    tangent = gbuffer.tangent[mask].astype(np.float64)
    t = tangent[:, :3] - np.sum(tangent[:, :3] * n, -1)[:, None] * n
    t /= np.linalg.norm(t, axis=-1, keepdims=True)
    b = np.sign(tangent[:, 3:4]) * np.cross(n, t)
    base_texel = np.array([200, 90, 230]) / 255.0
    mapped = _mapped(np.broadcast_to(base_texel, n.shape), 1.3, t, b, n)
    assert np.min(np.sum(mapped * gbuffer.normal[mask], -1)) > 1 - 1e-5  # the G-buffer's normal is the mapped one
    assert np.max(np.linalg.norm(mapped - n, axis=-1)) > 0.3  # and it is far from the unperturbed
    eye = np.array([0.0, -1.2, 1.5])
    v = eye - gbuffer.position[mask]
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    l = np.broadcast_to(-direction / np.linalg.norm(direction), v.shape)
    lit = (np.sum(mapped * l, -1) > 1e-3) & (np.sum(mapped * v, -1) > 1e-3)
    want = irradiance * coated(t, b, n, l, v, base_texel, 1.3, (0.5, 0.5, 1.0) if coat_texel is None else
                               np.float32(coat_texel).astype(np.float64), coat_scale)
    want = np.where(lit[:, None], want, 0.0)
    gpu = radiance[mask]
    scale = np.maximum(np.max(want, axis=1, keepdims=True), 1e-3 * want.max())
    inside = lit & (np.abs(np.sum(mapped * l, -1)) > 1e-2) & (np.abs(np.sum(mapped * v, -1)) > 1e-2)
    assert inside.sum() > 500
    assert np.max((np.abs(gpu - want) / scale)[inside]) < 2e-3
    report = glphong.verify(scene, renderer)
    assert report.covered_pixels > 900 and report.passed, report.summary()


def _textured_material():
    """Random base and coat normal textures (tilts up to about 50 degrees)."""
    rng = np.random.default_rng(21)
    coat = np.concatenate([rng.integers(40, 216, (16, 16, 2)), np.full((16, 16, 1), 230)], axis=2).astype(np.uint8)
    base = np.concatenate([rng.integers(30, 226, (16, 16, 2)), np.full((16, 16, 1), 200)], axis=2).astype(np.uint8)
    return _material(glphong.Texture(coat, 1.0, srgb=False), 0.8, base_image=base)


def test_textured_coat_and_base_normals_verify(glphong_backend, glphong_make_renderer):
    report = glphong.verify(_scene(_textured_material(), _EXT.LIGHTS["point"]()),
                            glphong_make_renderer(64, 64, glphong_backend))
    assert report.covered_pixels > 900 and report.passed, report.summary()


def test_gpu_coat_on_the_mapped_normal_fails(monkeypatch, glphong_make_renderer):
    """gltf_pbr.glsl's coat on the shading (mapped) frame instead of the unperturbed one: verify fails."""
    _EXT.assert_planted_error_fails("ShadingFrame g = unperturbed_frame;", "ShadingFrame g = f;", _textured_material(),
                                    monkeypatch, glphong_make_renderer)


def test_twin_coat_on_the_mapped_normal_fails(monkeypatch, glphong_make_renderer):
    """The twin's coat on the mapped frame (``f.unperturbed`` ignored): verify fails, so the GPU's coat is not on it."""
    from glphong.materials import gltf_coat_normal

    monkeypatch.setattr(gltf_coat_normal, "unperturbed_frame", lambda f: f)
    report = glphong.verify(_scene(_textured_material(), _EXT.LIGHTS["point"]()), glphong_make_renderer(64, 64, "egl"))
    assert not report.passed and report.outside_count > 0, report.summary()


def test_only_a_coat_over_a_normal_map_needs_the_unperturbed_plane(glphong_make_renderer):
    """The 'unperturbed' need, like 'tangent' and 'uv': in the program key and the G-buffer only where a material
    needs it (a coat over a normal map), not for a normal map alone, a coat alone or a coat normal alone."""
    from glphong.shaders.binding import binding

    normal_map = glphong.NormalMap(np.full((4, 4, 3), (200, 90, 230), np.uint8))
    renderer = glphong_make_renderer(32, 32, "egl")
    for material, needed in ((glphong.GltfPBR(**BASE, normal_map=normal_map), False),
                             (glphong.GltfPBR(**BASE, **COAT), False),
                             (glphong.GltfPBR(**BASE, **COAT, clearcoat_normal=(0.8, 0.35, 0.8)), False),
                             (glphong.GltfPBR(**BASE, **COAT, normal_map=normal_map), True)):
        scene = _scene(material, _EXT.LIGHTS["point"]())
        key = binding(scene).program_key(scene.objects[0])
        assert key.has_unperturbed is needed and ("HAS_UNPERTURBED", "1" if needed else "0") in key.defines()
        assert ("unperturbed" in binding(scene).gbuffer_needs()) is needed
        assert (renderer.gbuffer(scene).unperturbed is not None) is needed


def test_files_with_both_normal_textures_load_exactly_and_round_trip(tmp_path):
    """A file's normalTexture and clearcoatNormalTexture load without a warning, both kept (the coat's with its
    scale), and save_gltf writes both back; a coat without its own normal texture over a normalTexture keeps the
    unperturbed normal, also without a warning."""
    rgb = np.full((4, 4, 3), 128, np.uint8)
    rgb[..., 0] = 200
    path = _EXT._gltf(tmp_path, {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatNormalTexture":
                                                             {"index": 1, "scale": 0.5}}},
                      normal=0, images=[rgb, rgb[::-1, :, ::-1].copy()])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        scene = glphong.load_scene(path, light_units="radiometric", lights=[])
    material = scene.objects[0].material
    assert material.extensions() == ("clearcoat", "clearcoat_normal") and "unperturbed" in material.needs
    assert material.normal_map is not None and material.clearcoat_normal_strength == 0.5
    np.testing.assert_allclose(material.clearcoat_normal.texture.levels[0][0, 0], rgb[0, 0, ::-1] / 255.0, atol=1e-3)
    out = tmp_path / "saved.gltf"
    glphong.save_gltf(scene, out)
    document = json.loads(out.read_text())
    saved = document["materials"][0]
    assert "normalTexture" in saved
    assert saved["extensions"]["KHR_materials_clearcoat"]["clearcoatNormalTexture"]["scale"] == 0.5
    del saved["extras"]  # glphong's own record of the material: the file's fields alone
    out.write_text(json.dumps(document))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        again = glphong.load_scene(out, light_units="radiometric", lights=[]).objects[0].material
    assert again.extensions() == ("clearcoat", "clearcoat_normal") and again.normal_map is not None
    assert again.clearcoat_normal_strength == 0.5
    np.testing.assert_array_equal(again.clearcoat_normal.texture.levels[0], material.clearcoat_normal.texture.levels[0])
    np.testing.assert_array_equal(again.normal_map.texture.levels[0], material.normal_map.texture.levels[0])
    path = _EXT._gltf(tmp_path, {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0}}, normal=0, images=[rgb])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        material = glphong.load_scene(path, light_units="radiometric", lights=[]).objects[0].material
    assert material.extensions() == ("clearcoat", "clearcoat_normal") and material.normal_map is not None
    np.testing.assert_array_equal(material.clearcoat_normal, (0.5, 0.5, 1.0))  # the unperturbed normal


def test_over_transmission_the_coat_keeps_its_own_normal_and_files_load_it_without_a_warning(tmp_path):
    """KHR_materials_transmission draws the coat on its own normal (transmission_thin.glsl weights the light let
    through by 1 - clearcoat F_c(n_c.v); tests/test_transmission_layers.py renders it): a coat over a normal map and
    transmission keeps the unperturbed normal and needs the 'unperturbed' plane, as without transmission, and a file
    with a clearcoatNormalTexture, or a normalTexture alone, loads it without a warning."""
    normal_map = glphong.NormalMap(np.full((4, 4, 3), (200, 90, 230), np.uint8))
    material = glphong.GltfPBR(**BASE, **COAT, transmission=0.5, normal_map=normal_map)
    assert material.extensions() == ("clearcoat", "clearcoat_normal", "transmission")
    assert {"tangent", "unperturbed"} <= set(material.needs)
    rgb = np.full((4, 4, 3), 128, np.uint8)
    rgb[..., 0] = 200
    for coat in ({"clearcoatFactor": 1.0}, {"clearcoatFactor": 1.0, "clearcoatNormalTexture": {"index": 0}}):
        path = _EXT._gltf(tmp_path, {"KHR_materials_clearcoat": coat,
                                     "KHR_materials_transmission": {"transmissionFactor": 0.5}}, normal=0, images=[rgb])
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            material = glphong.load_scene(path, light_units="radiometric", lights=[]).objects[0].material
        assert material.extensions() == ("clearcoat", "clearcoat_normal", "transmission")
        assert material.normal_map is not None
        assert (getattr(material.clearcoat_normal, "texture", None) is not None) == ("clearcoatNormalTexture" in coat)


def test_a_g_buffer_of_every_plane_is_refused_by_name(glphong_make_renderer):
    """A coat over a normal map with vertex colours, a texture, shadows and the 'object' plane of the frame passes
    would need 9 planes, more than a draw writes: a ValueError naming them (not a program that fails to link)."""
    from glphong import primitives
    from glphong.scene.geometry import MeshData

    rng = np.random.default_rng(1)
    material = glphong.GltfPBR(glphong.Texture(rng.integers(0, 256, (8, 8, 3), dtype=np.uint8), 1.0,
                                               vertex_colors=True), 0.0, 0.5, **COAT,
                               normal_map=glphong.NormalMap(np.full((4, 4, 3), (200, 90, 230), np.uint8)))
    sphere = primitives.sphere(3, radius=0.5)
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0.0, -1.2, 1.5), (0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0)),
                          [glphong.PointLight((1.2, -0.2, 1.2), 20.0, shadows=True)])
    scene.add(MeshData(sphere.positions, sphere.normals, sphere.indices, uvs=sphere.uvs,
                       colors=np.full((len(sphere.positions), 3), 0.8, np.float32)), material)
    renderer = glphong_make_renderer(16, 16, "egl")
    assert renderer.gbuffer(scene).unperturbed is not None  # 8 planes: drawn
    with pytest.raises(ValueError, match=r"9 planes \(position, normal, tangent, uv, color, lod, face, object, "
                                         r"unperturbed\), more than the 8 one draw writes"):
        renderer.gbuffer(scene, planes=("object",))
