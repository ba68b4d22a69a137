"""KHR_materials_sheen on glphong.GltfPBR (glphong/materials/gltf_sheen.py) against an independent float64 transcription
of the extension's own text (KhronosGroup/glTF, extensions/2.0/Khronos/KHR_materials_sheen/README.md), written here:

- ``alpha_g = sheenRoughness^2``, ``sheen_distribution = (2 + 1/alpha_g) pow(1 - (n.h)^2, 1/(2 alpha_g)) / (2 pi)``;
- ``sheen_visibility = 1 / ((1 + lambda_sheen(n.v) + lambda_sheen(n.l)) (4 n.v n.l))``, the README's ``l(x)`` fit;
- ``sheen_material = sheenColor sheen_brdf + material sheen_albedo_scaling``, ``sheen_albedo_scaling = min(1 -
  max3(sheenColor) E(n.v), 1 - max3(sheenColor) E(n.l))``, clamped at 0 (glphong's decision, docs/gltf_extensions.md),
  the coat over it; ``E`` the shipped table, interpolated here by scipy (the table itself is checked against fresh
  integrals of the same transcription by scipy's adaptive quadrature).
"""
import importlib.util
import json
import pathlib
import re
import warnings

import numpy as np
import pytest

import glphong
from glphong.testing import assert_twin_matches, evaluate

_SPEC = importlib.util.spec_from_file_location("_gltf_extension_tests", pathlib.Path(__file__).with_name(
    "test_gltf_extensions.py"))
_EXT = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(_EXT)  # its helpers: the core's transcription, direction pairs, the twin, scenes, files


def _fit(x, alpha):
    t = (1 - alpha) ** 2
    a = 21.5473 * (1 - t) + 25.3245 * t
    b = 3.82987 * (1 - t) + 3.32435 * t
    c = 0.19823 * (1 - t) + 0.16801 * t
    d = -1.97760 * (1 - t) + -1.27393 * t
    e = -4.32054 * (1 - t) + -4.85967 * t
    return a / (1 + b * x ** c) + d * x + e


def _lambda_sheen(cos, alpha):
    x = np.abs(cos)
    return np.where(x < 0.5, np.exp(_fit(x, alpha)), np.exp(2 * _fit(0.5, alpha) - _fit(1 - x, alpha)))


def sheen_brdf(nl, nv, nh, roughness, planted=None):
    """The README's ``D V``, float64, (N,); 0 for roughness 0 (the delta at n.h = 0, met by no pair here)."""
    alpha = roughness if planted == "alpha_g = roughness" else roughness ** 2
    if alpha == 0:
        return np.zeros_like(nl)
    d = (2 + 1 / alpha) * (1 - nh ** 2) ** (1 / (2 * alpha)) / (2 * np.pi)
    one = 0.0 if planted == "visibility without 1 +" else 1.0
    return d / ((one + _lambda_sheen(nv, alpha) + _lambda_sheen(nl, alpha)) * (4 * nv * nl))


def albedo_table_lookup(x, roughness):
    """E from the shipped table: bilinear in (sqrt(n.v), roughness) on its grid (scipy's interpolator)."""
    from scipy.interpolate import RegularGridInterpolator

    from glphong.materials.gltf_sheen_table import SHEEN_ALBEDO

    grid = RegularGridInterpolator((np.arange(17) / 16, np.arange(33) / 32), np.asarray(SHEEN_ALBEDO, np.float64))
    return grid(np.stack(np.broadcast_arrays(np.clip(roughness, 0, 1), np.sqrt(np.clip(x, 0, 1))), -1))


def specification(l, v, arguments, planted=None):
    """The sheen over the core (and under the coat): ``(N, 3)`` times n.l, from the README's formulas."""
    core = {k: a for k, a in arguments.items() if not k.startswith(("sheen", "clearcoat"))}
    base = _EXT.specification(np.broadcast_to(_EXT.Z, l.shape), l, v, **core)  # the core's transcription, times n.l
    h = (l + v) / np.linalg.norm(l + v, axis=1, keepdims=True)
    nl, nv, nh = l[:, 2], v[:, 2], h[:, 2]
    color = np.broadcast_to(np.asarray(arguments["sheen_color"], np.float64), 3)
    r = float(arguments.get("sheen_roughness", 0.0))
    m = color.max()
    e_v, e_l = albedo_table_lookup(nv, r), albedo_table_lookup(nl, r)
    scaling = 1 - m * e_v if planted == "scaling on n.v only" else np.minimum(1 - m * e_v, 1 - m * e_l)
    if planted != "scaling not clamped":
        scaling = np.maximum(scaling, 0.0)
    out = base * scaling[:, None] + color[None, :] * (sheen_brdf(nl, nv, nh, r, planted) * nl)[:, None]
    if arguments.get("clearcoat", 0.0):
        coat_fr = 0.04 + 0.96 * (1 - nv) ** 5
        w = float(arguments["clearcoat"]) * coat_fr
        a2 = float(arguments["clearcoat_roughness"]) ** 4
        d = a2 / (np.pi * (nh ** 2 * (a2 - 1) + 1) ** 2)
        vis = 1 / (2 * (nv * np.sqrt(a2 + (1 - a2) * nl ** 2) + nl * np.sqrt(a2 + (1 - a2) * nv ** 2)))
        out = (1 - w)[:, None] * out + (w * d * vis * nl)[:, None]
    return out


def _f32(arguments):
    return {k: np.float32(a).astype(np.float64) if k not in ("sheen_color", "base_color") else
            np.asarray(a, np.float32).astype(np.float64) for k, a in arguments.items()}


MATERIALS = {
    "velvet rough 0.5": dict(base_color=(0.3, 0.05, 0.1), metallic=0.0, roughness=0.8, sheen_color=(1.0, 0.6, 0.7),
                             sheen_roughness=0.5),
    "sheen rough 1 metal": dict(base_color=(0.9, 0.6, 0.3), metallic=1.0, roughness=0.3, sheen_color=0.4,
                                sheen_roughness=1.0),
    "sheen rough 0.1 (E > 1 at grazing)": dict(base_color=(0.5, 0.5, 0.5), metallic=0.2, roughness=0.5,
                                                sheen_color=(0.9, 0.9, 1.0), sheen_roughness=0.1),
    "sheen rough 0": dict(base_color=(0.5, 0.4, 0.3), metallic=0.0, roughness=0.5, sheen_color=1.0),
    "sheen off the grid, coated": dict(base_color=(0.2, 0.5, 0.3), metallic=0.0, roughness=0.6,
                                       sheen_color=(0.7, 0.3, 0.2), sheen_roughness=0.37, clearcoat=0.7,
                                       clearcoat_roughness=0.2),
}


@pytest.mark.parametrize("name", sorted(MATERIALS))
def test_twin_equals_the_extension_in_float64(name):
    arguments = MATERIALS[name]
    material = glphong.GltfPBR(**arguments)
    assert "sheen" in material.extensions()
    l, v = _EXT._pairs(600, seed=len(name), max_angle=1.5)
    np.testing.assert_allclose(_EXT._twin(material, l, v), specification(l, v, _f32(arguments)), rtol=1e-9,
                               atol=1e-300)


@pytest.mark.parametrize("planted", ["alpha_g = roughness", "visibility without 1 +", "scaling on n.v only",
                                     "scaling not clamped"])
def test_the_comparison_catches_the_usual_mistakes(planted):
    arguments = MATERIALS["sheen rough 0.1 (E > 1 at grazing)"]
    l, v = _EXT._pairs(600, seed=3, max_angle=1.55)
    wrong = specification(l, v, _f32(arguments), planted)
    twin = _EXT._twin(glphong.GltfPBR(**arguments), l, v)
    assert np.max(np.abs(wrong - twin) / np.max(np.abs(twin), axis=1, keepdims=True)) > 1e-3


def test_neutral_sheen_is_the_core_material_and_its_program():
    from glphong.shaders.key import program_key

    lights = [glphong.PointLight((0.0, 0.0, 2.0), 10.0)]
    core = glphong.GltfPBR(0.5, 0.2, 0.5)
    neutral = glphong.GltfPBR(0.5, 0.2, 0.5, sheen_color=0.0, sheen_roughness=0.6)
    assert neutral.extensions() == () and program_key(neutral, lights, None) == program_key(core, lights, None)
    l, v = _EXT._pairs(200, seed=9)
    np.testing.assert_array_equal(_EXT._twin(neutral, l, v), _EXT._twin(core, l, v))
    key = program_key(glphong.GltfPBR(0.5, 0.2, 0.5, sheen_color=0.1), lights, None)
    assert "GLTF_PBR_SHEEN" in {name for name, _ in key.defines()}


def test_the_glsl_table_is_the_shipped_table():
    from glphong.materials.gltf_sheen_table import SHEEN_ALBEDO

    from glphong.core.glsl_files import glsl_root

    text = (glsl_root() / "materials" / "gltf_pbr.glsl").read_text()  # the chunk the programs read, where installed
    body = re.search(r"const float GLTF_SHEEN_E\[561\] = float\[\]\((.*?)\);", text, re.S).group(1)
    glsl = np.array([float(x) for x in body.replace("\n", " ").split(",")], np.float32)
    np.testing.assert_array_equal(glsl, np.asarray(SHEEN_ALBEDO, np.float32).ravel())


@pytest.mark.parametrize("x, roughness", [(1 / 1024, 1 / 16), (1 / 64, 1 / 16), (0.25, 0.25), (0.5625, 0.5),
                                          (1.0, 1.0), ((20 / 32) ** 2, 0.8125)])
def test_the_table_is_the_integral_of_the_specifications_lobe(x, roughness):
    """Entries of the table against scipy's adaptive quadrature of the transcription above (a different rule from
    the generator's Gauss-Legendre panels): within 1e-6 relative (the float32 rounding of the table is 6e-8)."""
    from scipy import integrate

    from glphong.materials.gltf_sheen_table import SHEEN_ALBEDO

    s_v = np.sqrt(1 - x * x)

    def integrand(phi, mu):
        s_l = np.sqrt(1 - mu * mu)
        h = np.array([s_l * np.cos(phi) + s_v, s_l * np.sin(phi), mu + x])
        return sheen_brdf(np.array(mu), np.array(x), np.array(h[2] / np.linalg.norm(h)), roughness) * mu

    value = 2 * integrate.dblquad(integrand, 0, 1, 0, np.pi, epsabs=1e-12, epsrel=1e-10)[0]
    entry = SHEEN_ALBEDO[round(roughness * 16)][round(np.sqrt(x) * 32)]
    assert abs(entry - value) <= 1e-6 * value, (entry, value)
    if roughness == 1 / 16 and x < 0.01:
        assert value > 2.5  # E exceeds 1 at grazing view for small roughness: the scaling's clamp acts


@pytest.mark.parametrize("name", sorted(MATERIALS))
def test_gpu_within_the_twins_band(name, glphong_backend):
    material = glphong.GltfPBR(**MATERIALS[name])
    assert_twin_matches(material, n=400, backend=glphong_backend)
    l, v = _EXT._pairs(300, seed=11, max_angle=1.3)
    l32, v32 = l.astype(np.float32).astype(float), v.astype(np.float32).astype(float)
    l32 /= np.linalg.norm(l32, axis=1, keepdims=True)
    v32 /= np.linalg.norm(v32, axis=1, keepdims=True)
    gpu = evaluate(material, l, v, backend=glphong_backend).astype(np.float64)
    expected = specification(l32, v32, _f32(MATERIALS[name]))
    rel = np.abs(gpu - expected) / np.max(expected, axis=1, keepdims=True)
    assert np.all(np.isfinite(gpu)) and rel.max() < 3e-3, rel.max()


@pytest.mark.parametrize("lights", ["point", "spot and directional", "rect", "environment"])
def test_renders_verify(lights, glphong_backend, glphong_make_renderer):
    material = glphong.GltfPBR(**MATERIALS["sheen off the grid, coated"])
    report = glphong.verify(_EXT._sphere_scene(material, _EXT.LIGHTS[lights](), ambient=0.05),
                            glphong_make_renderer(64, 64, glphong_backend), exact=False)
    assert report.covered_pixels > 900 and report.passed, report.summary()


def test_textured_sheen_verifies(glphong_backend, glphong_make_renderer):
    rng = np.random.default_rng(21)
    image = rng.integers(0, 256, (16, 16, 3), dtype=np.uint8)
    material = glphong.GltfPBR((0.4, 0.1, 0.2), 0.0, 0.7, sheen_color=glphong.Texture(image, (1.0, 0.8, 0.9)),
                               sheen_roughness=glphong.Texture(image[::-1], 0.6, srgb=False, channel="g"))
    assert material.extensions() == ("sheen",)
    report = glphong.verify(_EXT._sphere_scene(material, _EXT.LIGHTS["point"]()),
                            glphong_make_renderer(64, 64, glphong_backend))
    assert report.covered_pixels > 900 and report.passed, report.summary()


PLANTED = {  # text of gltf_pbr.glsl, planted text
    "sheen roughness not squared": ("float alpha_g = u_gltf_pbr_sheen_roughness * u_gltf_pbr_sheen_roughness;",
                                    "float alpha_g = u_gltf_pbr_sheen_roughness;"),
    "E on n.v only": ("1.0 - sc_max * gltf_sheen_albedo(n_dot_l, u_gltf_pbr_sheen_roughness)), 0.0);",
                      "1.0 - sc_max * gltf_sheen_albedo(n_dot_v, u_gltf_pbr_sheen_roughness)), 0.0);"),
}


@pytest.mark.parametrize("planted", sorted(PLANTED))
def test_planted_errors_fail(planted, monkeypatch, glphong_make_renderer):
    _EXT.assert_planted_error_fails(*PLANTED[planted], glphong.GltfPBR(**MATERIALS["velvet rough 0.5"]), monkeypatch,
                                    glphong_make_renderer)


def test_stability_cases_pass(session_gl):
    from glphong.checks.stability import CASES, run_stability

    cases = [c for c in CASES if c.group == "gltf sheen"]
    assert len(cases) >= 15
    report = run_stability(context=session_gl, cases=cases)
    assert [r.case for r in report.rows if not r.passed] == [], report.format_table()


def test_files_load_with_their_textures_and_save_back(tmp_path):
    rng = np.random.default_rng(17)
    rgba = rng.integers(0, 256, (8, 8, 4), dtype=np.uint8)
    extensions = {"KHR_materials_sheen": {"sheenColorFactor": [0.9, 0.5, 0.25], "sheenColorTexture": {"index": 0},
                                          "sheenRoughnessFactor": 0.6, "sheenRoughnessTexture": {"index": 0}}}
    path = _EXT._gltf(tmp_path, extensions, images=[rgba])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # applied: no warning
        material = glphong.load_scene(path, light_units="radiometric", lights=[]).objects[0].material
    assert material.extensions() == ("sheen",)
    np.testing.assert_array_equal(material.sheen_color.scale, [0.9, 0.5, 0.25])
    assert material.sheen_roughness.scale == 0.6 and material.sheen_roughness.channel == "r"
    # the sheen roughness is the texture's alpha (a grey image of it), linear
    np.testing.assert_allclose(material.sheen_roughness.texture.levels[0][::-1, :, 0], rgba[..., 3] / 255.0, atol=2e-3)
    out = tmp_path / "saved.gltf"
    glphong.save_gltf(glphong.load_scene(path, light_units="radiometric", lights=[]), out)
    written = json.loads(out.read_text())["materials"][0]["extensions"]["KHR_materials_sheen"]
    assert written["sheenColorFactor"] == pytest.approx([0.9, 0.5, 0.25]) and written["sheenRoughnessFactor"] == 0.6
    assert "sheenColorTexture" in written
    again = glphong.load_scene(out, light_units="radiometric", lights=[]).objects[0].material
    assert again.extensions() == ("sheen",) and again.sheen_roughness.scale == 0.6


def test_files_disabled_sheen_and_bad_factors(tmp_path):
    path = _EXT._gltf(tmp_path, {"KHR_materials_sheen": {"sheenRoughnessFactor": 0.5}})
    assert glphong.load_scene(path, light_units="radiometric", lights=[]).objects[0].material.extensions() == ()
    for bad, field in (({"sheenColorFactor": [0.5, 1.5, 0.0]}, "sheenColorFactor"),
                       ({"sheenColorFactor": [1, 1, 1], "sheenRoughnessFactor": -0.1}, "sheenRoughnessFactor"),
                       ({"sheenColorTexture": {"index": 7}}, "sheenColorTexture")):
        path = _EXT._gltf(tmp_path, {"KHR_materials_sheen": bad})
        with pytest.raises(glphong.filesafety.SceneFileError,
                           match=rf"materials\[0\]\.extensions\.KHR_materials_sheen\.{field}"):
            glphong.load_scene(path, light_units="radiometric", lights=[])


def test_sheen_is_declared_and_measured_reciprocal():
    from glphong.analysis import properties

    sheen = properties(glphong.GltfPBR(0.5, 0.0, 0.4, sheen_color=(1.0, 0.5, 0.5), sheen_roughness=0.4),
                       theta_i=[0.5])  # one albedo: the energy question is asked elsewhere
    assert sheen.reciprocal and "reciprocal" not in sheen.disagreements
