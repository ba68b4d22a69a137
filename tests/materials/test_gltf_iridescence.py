"""KHR_materials_iridescence on glphong.GltfPBR (glphong/materials/gltf_iridescence.py) against an independent float64
transcription of the extension's own text (KhronosGroup/glTF, extensions/2.0/Khronos/KHR_materials_iridescence/
README.md), written here from its sample code:

- ``iridescent_fresnel``: ``IorToFresnel0``, ``Fresnel0ToIor(baseF0 + 0.0001)``, ``F_Schlick``, Snell's ``cosTheta2``,
  the phases ``phi12``/``phi21``/``phi23``, ``OPD = 2 iridescenceIor thickness cosTheta2``, the compound terms and the
  loop ``m = 1, 2`` over ``evalSensitivity`` with the README's ``XYZ_TO_REC709`` as GLSL's column-major ``mat3``;
- ``metal_brdf = mix(conductor_fresnel(base_f0, specular_brdf), specular_brdf F_iridescence(baseColor), iridescence)``;
- ``dielectric_brdf = mix(fresnel_mix(ior, base, specular_brdf), rgb_mix(base, specular_brdf, F_iridescence),
  iridescence)``, and with KHR_materials_specular ``rgb_mix(base, specular_brdf, mix(specular_weight fr,
  F_iridescence(specular_weight base_f0), iridescence))``; the Fresnel's angle ``v.h`` (Appendix B's).
"""
import importlib.util
import json
import pathlib
import warnings

import numpy as np
import pytest

import glphong
from glphong.testing import assert_twin_matches, evaluate

_SPEC = importlib.util.spec_from_file_location("_gltf_extension_tests_iridescence", pathlib.Path(__file__).with_name(
    "test_gltf_extensions.py"))
_EXT = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(_EXT)  # its helpers: the core's transcription, direction pairs, the twin, scenes, files

#: the README's const mat3 XYZ_TO_REC709, its nine numbers in the order written (GLSL fills columns first)
_MAT3 = (3.2404542, -0.9692660, 0.0556434, -1.5371385, 1.8760108, -0.2040259, -0.4985314, 0.0415560, 1.0572252)


def eval_sensitivity(opd, shift, planted=None):
    """The README's ``evalSensitivity``: opd (N,), shift (N, 3) -> (N, 3)."""
    phase = 2.0 * np.pi * opd * 1.0e-9
    val = np.array([5.4856e-13, 4.4201e-13, 5.2481e-13])
    pos = np.array([1.6810e+06, 1.7953e+06, 2.2084e+06])
    var = np.array([4.3278e+09, 9.3046e+09, 6.6121e+09])
    xyz = val * np.sqrt(2.0 * np.pi * var) * np.cos(pos * phase[:, None] + shift) * np.exp(-phase[:, None] ** 2 * var)
    xyz[:, 0] += 9.7470e-14 * np.sqrt(2.0 * np.pi * 4.5282e+09) * np.cos(2.2399e+06 * phase + shift[:, 0]) \
        * np.exp(-4.5282e+09 * phase ** 2)
    xyz /= 1.0685e-7
    matrix = np.array(_MAT3).reshape(3, 3) if planted == "matrix read by rows" else np.array(_MAT3).reshape(3, 3).T
    return np.einsum("ij,nj->ni", matrix, xyz)


def iridescent_fresnel(outside_ior, iridescence_ior, base_f0, thickness, cos_theta1, planted=None):
    """The README's ``iridescent_fresnel``; base_f0 (N, 3), cos_theta1 (N,) -> (N, 3)."""
    def ior_to_fresnel0(transmitted, incident):
        return ((transmitted - incident) / (transmitted + incident)) ** 2

    def fresnel0_to_ior(f0):
        return (1.0 + np.sqrt(f0)) / (1.0 - np.sqrt(f0))

    def f_schlick(f0, cos):
        return f0 + (1.0 - f0) * (1.0 - cos) ** 5

    sin_theta2_sq = (outside_ior / iridescence_ior) ** 2 * (1.0 - cos_theta1 ** 2)
    cos_theta2_sq = 1.0 - sin_theta2_sq
    cos_theta2 = np.sqrt(np.maximum(cos_theta2_sq, 0.0))
    r0 = ior_to_fresnel0(iridescence_ior, outside_ior)
    r12 = f_schlick(r0, cos_theta1)[:, None]
    t121 = 1.0 - r12
    phi12 = np.pi if iridescence_ior < outside_ior else 0.0
    phi21 = np.pi - phi12
    base_ior = fresnel0_to_ior(np.minimum(base_f0 + 0.0001, 0.9999))  # the README's guard; the min: glphong's
    r1 = ior_to_fresnel0(base_ior, iridescence_ior)
    r23 = f_schlick(r1, cos_theta2[:, None])
    phi23 = np.where(base_ior < iridescence_ior, np.pi, 0.0)
    cos_opd = cos_theta1 if planted == "OPD on cos theta1" else cos_theta2
    opd = 2.0 * iridescence_ior * thickness * cos_opd
    phi = phi21 + phi23
    r123 = np.clip(r12 * r23, 1e-5, 0.9999)
    r123_root = np.sqrt(r123)
    rs = t121 ** 2 * r23 / (1.0 - r123)
    total = r12 + rs
    cm = rs - t121
    for m in (1, 2):
        cm = cm * r123_root
        total = total + cm * 2.0 * eval_sensitivity(m * opd, m * phi, planted)
    return np.where((cos_theta2_sq < 0.0)[:, None], 1.0, np.maximum(total, 0.0))


def specification(l, v, arguments, planted=None):
    """``material (n.l)`` by the README's formulas, float64, (N, 3) (n = +z)."""
    a = dict(specular=1.0, specular_color=(1.0, 1.0, 1.0), ior=1.5, iridescence_ior=float(np.float32(1.3)),  # a uniform
             iridescence_thickness_minimum=100.0, iridescence_thickness_maximum=400.0, iridescence_thickness_mix=1.0) \
        | arguments
    h = (l + v) / np.linalg.norm(l + v, axis=1, keepdims=True)
    nl, nv, nh, vh = l[:, 2], v[:, 2], h[:, 2], np.abs(np.sum(v * h, axis=1))
    cos1 = nv if planted == "Fresnel on n.v" else vh
    alpha = a["roughness"] ** 2
    a2 = alpha ** 2
    specular_brdf = (a2 / (np.pi * (nh ** 2 * (a2 - 1) + 1) ** 2)
                     / (2 * (nv * np.sqrt(a2 + (1 - a2) * nl ** 2) + nl * np.sqrt(a2 + (1 - a2) * nv ** 2))))[:, None]
    c = np.broadcast_to(np.asarray(a["base_color"], np.float64), (len(l), 3))
    base = c / np.pi
    x = ((1 - vh) ** 5)[:, None]
    d = a["iridescence_thickness_minimum"] + (a["iridescence_thickness_maximum"]
                                              - a["iridescence_thickness_minimum"]) * a["iridescence_thickness_mix"]
    w = a["iridescence"]
    f0 = ((1 - a["ior"]) / (1 + a["ior"])) ** 2

    def rgb_mix(rgb_alpha):
        weight = rgb_alpha if planted == "diffuse by 1 - F per channel" else np.max(rgb_alpha, axis=1, keepdims=True)
        return (1 - weight) * base + rgb_alpha * specular_brdf

    metal = (1 - w) * (c + (1 - c) * x) * specular_brdf \
        + w * specular_brdf * iridescent_fresnel(1.0, a["iridescence_ior"], c, d, cos1, planted)
    if "specular" in arguments or "specular_color" in arguments:
        base_f0 = np.minimum(f0 * np.asarray(a["specular_color"], np.float64), 1.0)[None, :]
        fr = base_f0 + (1 - base_f0) * x
        f_ir = iridescent_fresnel(1.0, a["iridescence_ior"], np.broadcast_to(a["specular"] * base_f0, (len(l), 3)), d,
                                  cos1, planted)
        dielectric = rgb_mix((1 - w) * a["specular"] * fr + w * f_ir)
    else:
        fd = f0 + (1 - f0) * x
        f_ir = iridescent_fresnel(1.0, a["iridescence_ior"], np.full((len(l), 3), f0), d, cos1, planted)
        dielectric = (1 - w) * ((1 - fd) * base + fd * specular_brdf) + w * rgb_mix(f_ir)
    return ((1 - a["metallic"]) * dielectric + a["metallic"] * metal) * nl[:, None]


def _f32(arguments):
    return {k: np.asarray(a, np.float32).astype(np.float64) if isinstance(a, tuple) else float(np.float32(a))
            for k, a in arguments.items()}


MATERIALS = {
    "soap film on a dielectric": dict(base_color=(0.05, 0.05, 0.08), metallic=0.0, roughness=0.3, iridescence=1.0),
    "film 600 nm, ior 1.8, on a metal": dict(base_color=(0.9, 0.6, 0.3), metallic=1.0, roughness=0.35,
                                             iridescence=0.8, iridescence_ior=1.8, iridescence_thickness_maximum=600.0),
    "film ior 2.5 above the base's, mixed": dict(base_color=(0.4, 0.7, 0.2), metallic=0.4, roughness=0.5,
                                                  iridescence=0.6, iridescence_ior=2.5,
                                                  iridescence_thickness_minimum=300.0,
                                                  iridescence_thickness_maximum=100.0, iridescence_thickness_mix=0.3),
    "with KHR_materials_specular": dict(base_color=(0.5, 0.3, 0.6), metallic=0.2, roughness=0.4, iridescence=1.0,
                                        specular=0.6, specular_color=(1.0, 3.0, 0.5), iridescence_ior=1.45,
                                        iridescence_thickness_maximum=250.0),
    "white metal (the guard), thin film": dict(base_color=(1.0, 1.0, 0.95), metallic=1.0, roughness=0.25,
                                               iridescence=1.0, iridescence_thickness_maximum=40.0),
}


@pytest.mark.parametrize("name", sorted(MATERIALS))
def test_twin_equals_the_extension_in_float64(name):
    arguments = MATERIALS[name]
    material = glphong.GltfPBR(**arguments)
    assert "iridescence" in material.extensions()
    l, v = _EXT._pairs(600, seed=len(name), max_angle=1.5)
    np.testing.assert_allclose(_EXT._twin(material, l, v), specification(l, v, _f32(arguments)), rtol=1e-9,
                               atol=1e-300)


@pytest.mark.parametrize("planted", ["Fresnel on n.v", "OPD on cos theta1", "matrix read by rows",
                                     "diffuse by 1 - F per channel"])
def test_the_comparison_catches_the_usual_mistakes(planted):
    """The Sample Viewer's angle (n.v), the README draft's OPD (cos theta1), the matrix by rows, the diffuse weighted
    per channel: each differs from the twin by more than 1e-3 of the largest value."""
    arguments = MATERIALS["film ior 2.5 above the base's, mixed"]
    l, v = _EXT._pairs(600, seed=3, max_angle=1.5)
    wrong = specification(l, v, _f32(arguments), planted)
    twin = _EXT._twin(glphong.GltfPBR(**arguments), l, v)
    assert np.max(np.abs(wrong - twin) / np.max(np.abs(twin), axis=1, keepdims=True)) > 1e-3


def test_no_film_is_the_core_material_and_its_program():
    from glphong.shaders.key import program_key

    lights = [glphong.PointLight((0.0, 0.0, 2.0), 10.0)]
    core = glphong.GltfPBR(0.5, 0.2, 0.5)
    neutral = glphong.GltfPBR(0.5, 0.2, 0.5, iridescence=0.0, iridescence_ior=2.0, iridescence_thickness_maximum=50.0)
    assert neutral.extensions() == () and program_key(neutral, lights, None) == program_key(core, lights, None)
    l, v = _EXT._pairs(200, seed=9)
    np.testing.assert_array_equal(_EXT._twin(neutral, l, v), _EXT._twin(core, l, v))
    key = program_key(glphong.GltfPBR(0.5, 0.2, 0.5, iridescence=0.1), lights, None)
    assert "GLTF_PBR_IRIDESCENCE" in {name for name, _ in key.defines()}


def test_the_fresnel_at_its_extremes():
    """Thickness 0, a film of ior 1 (the outside's), grazing and normal angles, base_f0 0 and 1: finite, in [0, 1.1],
    and equal to the transcription; at thickness 0 on a dielectric the film's Fresnel is not the base's (the
    README's truncated Airy sum at zero path difference): the difference is stated in docs/gltf_extensions.md."""
    from glphong.materials.gltf_pbr import gltf_iridescence_fresnel

    cos = np.array([1.0, 0.7, 0.3, 1e-3, 1e-8, 0.0])
    for ior in (1.0, 1.3, 2.5):
        for thickness in (0.0, 1.0, 400.0, 1e5):
            for f0 in (0.0, 0.04, 0.5, 0.9999, 1.0):
                base = np.full((len(cos), 3), f0)
                twin = gltf_iridescence_fresnel(1.0, ior, base, thickness, cos)
                assert np.all(np.isfinite(twin)) and twin.min() >= 0 and twin.max() < 1.1, (ior, thickness, f0)
                np.testing.assert_allclose(twin, iridescent_fresnel(1.0, ior, base, thickness, cos), rtol=1e-12,
                                           atol=1e-15)
                twin32 = gltf_iridescence_fresnel(np.float32(1), np.float32(ior), base.astype(np.float32),
                                                  np.float32(thickness), cos.astype(np.float32))
                assert twin32.dtype == np.float32 and np.all(np.isfinite(twin32))


def test_the_glsl_fresnel_at_its_extremes(glphong_backend):
    """gltf_iridescence_fresnel itself on the GPU (float32) at the extremes of the test above and a film of ior 100:
    finite and within 2e-5 of the float64 twin (3.8e-6 measured; 2.2e-4 with the README's 1 - cos1^2, at ior 1,
    1e5 nm, cos1 = 1e-3)."""
    from glphong.core.glsl_files import glsl_root
    from glphong.materials.gltf_pbr import gltf_iridescence_fresnel
    from glphong.testing import glsl_function

    uniforms = "".join(f"uniform float u_gltf_pbr_{name};\n" for name in (
        "iridescence", "iridescence_ior", "iridescence_thickness_minimum", "iridescence_thickness_maximum",
        "iridescence_thickness_mix", "specular")) + "uniform vec3 u_gltf_pbr_specular_color;\n"
    source = uniforms + (glsl_root() / "materials" / "gltf_iridescence.glsl").read_text()
    fresnel = glsl_function(source, "gltf_iridescence_fresnel", defines={"GLTF_PBR_IRIDESCENCE": "1"},
                            backend=glphong_backend)
    grid = np.array(np.meshgrid([1.0, 1.3, 2.5, 100.0], [0.0, 1.0, 400.0, 1200.0, 1e5], [0.0, 0.04, 0.5, 0.9999, 1.0],
                                [1.0, 0.7, 0.3, 1e-3, 1e-8, 0.0])).reshape(4, -1).astype(np.float32)
    ior, thickness, f0, cos = grid
    base = np.repeat(f0[:, None], 3, axis=1)
    gpu = np.asarray(fresnel(np.ones_like(ior), ior, base, thickness, cos), np.float64)
    twin = gltf_iridescence_fresnel(1.0, ior.astype(np.float64), base.astype(np.float64), thickness.astype(np.float64),
                                    cos.astype(np.float64))
    assert np.all(np.isfinite(gpu)) and np.abs(gpu - twin).max() < 2e-5, np.abs(gpu - twin).max()


@pytest.mark.parametrize("name", sorted(MATERIALS))
def test_gpu_within_the_twins_band_and_near_the_transcription(name, glphong_backend):
    material = glphong.GltfPBR(**MATERIALS[name])
    assert_twin_matches(material, n=400, backend=glphong_backend)
    l, v = (a.astype(np.float32).astype(np.float64) for a in _EXT._pairs(300, seed=11, max_angle=1.3))
    expected = specification(*(a / np.linalg.norm(a, axis=1, keepdims=True) for a in (l, v)), _f32(MATERIALS[name]))
    gpu = evaluate(material, l, v, backend=glphong_backend).astype(np.float64)
    assert np.all(np.isfinite(gpu)) and np.max(np.abs(gpu - expected) / expected.max(axis=1, keepdims=True)) < 3e-3


def _textured():
    image = np.random.default_rng(23).integers(0, 256, (16, 16, 3), dtype=np.uint8)
    return glphong.GltfPBR((0.3, 0.3, 0.4), 0.3, 0.4, iridescence=glphong.Texture(image, 0.9, srgb=False, channel="r"),
                           iridescence_thickness_mix=glphong.Texture(image[::-1], 1.0, srgb=False, channel="g"),
                           iridescence_thickness_minimum=150.0, iridescence_thickness_maximum=700.0)


@pytest.mark.parametrize("lights, textured", [("point", True), ("point", False), ("spot and directional", False),
                                              ("rect", False), ("environment", False)])
def test_renders_verify(lights, textured, glphong_backend, glphong_make_renderer):
    material = _textured() if textured else glphong.GltfPBR(**MATERIALS["film ior 2.5 above the base's, mixed"])
    assert material.extensions() == ("iridescence",)
    scene = _EXT._sphere_scene(material, _EXT.LIGHTS[lights](), ambient=0.05)
    report = glphong.verify(scene, glphong_make_renderer(64, 64, glphong_backend), exact=textured)
    assert report.covered_pixels > 900 and report.passed, report.summary()


PLANTED = {  # text of gltf_iridescence.glsl (read before gltf_pbr.glsl in the model's chunk), planted text
    "OPD on cos theta1": ("float opd = 2.0 * film_ior * thickness * cos_theta2;",
                          "float opd = 2.0 * film_ior * thickness * cos_theta1;"),
    "second order dropped": ("i += cm * (2.0 * gltf_iridescence_sensitivity(2.0 * opd, 2.0 * phi));", ""),
    "metal's film on f0 0.04": ("gltf_iridescence_fresnel(1.0, ior, c, thickness, v_dot_h)",
                                "gltf_iridescence_fresnel(1.0, ior, film_f0, thickness, v_dot_h)"),
}


@pytest.mark.parametrize("planted", sorted(PLANTED))
def test_planted_errors_fail(planted, monkeypatch, glphong_make_renderer):
    _EXT.assert_planted_error_fails(*PLANTED[planted], glphong.GltfPBR(**MATERIALS["film 600 nm, ior 1.8, on a metal"]),
                                    monkeypatch, glphong_make_renderer)


def test_stability_cases_pass(session_gl):
    """Thickness 0 and 1e5 nm, films of ior 1 and 2.5, a white metal, iridescence 0.5 with the specular extension,
    grazing view to n.v = 1e-20 and grazing light: the GPU within the band of the mpmath oracle (the README's text,
    gltf_iridescence_oracle), finite."""
    from glphong.checks.stability import CASES, run_stability

    report = run_stability(context=session_gl, cases=[c for c in CASES if c.group == "gltf iridescence"])
    failed = [r.case for r in report.rows if not r.passed]
    assert len(report.rows) >= 25 and failed == [] and report.nan_count == report.inf_count == 0, report.format_table()


def test_the_sensitivity_fit_is_within_its_stated_error():
    """The README's closed form against a float64 spectral integral of the same Airy reflectance against the CIE 1931
    colour matching functions (benchmarks/gltf_iridescence_spectral.py): within the error docs/gltf_extensions.md
    states (0.01 absolute for thickness 100 to 800 nm, a film of ior 1.3 over f0 0.04) and not exact (above 1e-4)."""
    spec = importlib.util.spec_from_file_location("_spectral", pathlib.Path(__file__).parents[2] / "benchmarks"
                                                  / "gltf_iridescence_spectral.py")
    spectral = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(spectral)
    from glphong.materials.gltf_pbr import gltf_iridescence_fresnel

    cos = np.linspace(0.05, 1.0, 20)
    for thickness in (100.0, 250.0, 400.0, 800.0):
        closed = gltf_iridescence_fresnel(1.0, 1.3, np.full((len(cos), 3), 0.04), thickness, cos)
        brute = spectral.spectral_fresnel(1.0, 1.3, np.full(3, 0.04), thickness, cos)
        error = np.abs(closed - brute).max()
        assert 1e-4 < error < spectral.STATED_ERROR, (thickness, error)


# --------------------------------------------------------------------------- files
def test_files_load_with_their_textures_and_save_back(tmp_path):
    rng = np.random.default_rng(19)
    rgb = rng.integers(0, 256, (8, 8, 3), dtype=np.uint8)
    extensions = {"KHR_materials_iridescence": {"iridescenceFactor": 0.8, "iridescenceTexture": {"index": 0},
                                                "iridescenceIor": 1.6, "iridescenceThicknessMinimum": 150.0,
                                                "iridescenceThicknessMaximum": 650.0,
                                                "iridescenceThicknessTexture": {"index": 0}}}
    path = _EXT._gltf(tmp_path, extensions, images=[rgb])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # applied: no warning
        material = glphong.load_scene(path, light_units="radiometric", lights=[]).objects[0].material
    assert material.extensions() == ("iridescence",)
    assert material.iridescence.scale == 0.8 and material.iridescence.channel == "r"
    assert material.iridescence_thickness_mix.scale == 1.0 and material.iridescence_thickness_mix.channel == "g"
    assert (material.iridescence_ior, material.iridescence_thickness_minimum,
            material.iridescence_thickness_maximum) == (1.6, 150.0, 650.0)
    np.testing.assert_allclose(material.iridescence.texture.levels[0][::-1, :, 1], rgb[..., 1] / 255.0, atol=2e-3)
    out = tmp_path / "saved.gltf"
    glphong.save_gltf(glphong.load_scene(path, light_units="radiometric", lights=[]), out)
    written = json.loads(out.read_text())["materials"][0]["extensions"]["KHR_materials_iridescence"]
    assert written["iridescenceFactor"] == pytest.approx(0.8) and written["iridescenceIor"] == pytest.approx(1.6)
    assert written["iridescenceThicknessMinimum"] == 150.0 and written["iridescenceThicknessMaximum"] == 650.0
    assert "iridescenceTexture" in written and "iridescenceThicknessTexture" in written
    again = glphong.load_scene(out, light_units="radiometric", lights=[]).objects[0].material
    assert again.extensions() == ("iridescence",) and again.iridescence.scale == pytest.approx(0.8)
    assert again.iridescence_thickness_mix.channel == "g" and again.iridescence_ior == pytest.approx(1.6)



@pytest.mark.parametrize("channel, scale", [("r", 1.0), ("g", 0.5)])
def test_a_thickness_texture_the_file_cannot_carry_is_named(tmp_path, channel, scale):
    """iridescenceThicknessTexture is read on its green channel, unscaled: a thickness texture on another channel or
    with another scale is not written to the extension (glphong's extras keep it), with a warning naming it; the
    file's own (green, 1) is written without one."""
    image = np.random.default_rng(3).integers(0, 256, (8, 8, 3), dtype=np.uint8)
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0, 0, 3), (0, 0, 0)), [])
    mix = glphong.Texture(image, scale, srgb=False, channel=channel)
    scene.add(glphong.primitives.sphere(1), glphong.GltfPBR(0.5, 0.0, 0.5, iridescence=1.0, iridescence_thickness_mix=mix))
    with pytest.warns(UserWarning, match=rf"iridescence_thickness_mix texture \(channel '{channel}', scale {scale:g}\) "
                      "is written in glphong's extras only"):
        glphong.save_gltf(scene, tmp_path / "saved.gltf")
    written = json.loads((tmp_path / "saved.gltf").read_text())["materials"][0]["extensions"]
    assert "iridescenceThicknessTexture" not in written["KHR_materials_iridescence"]
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0, 0, 3), (0, 0, 0)), [])
    mix = glphong.Texture(image, 1.0, srgb=False, channel="g")
    scene.add(glphong.primitives.sphere(1), glphong.GltfPBR(0.5, 0.0, 0.5, iridescence=1.0, iridescence_thickness_mix=mix))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        glphong.save_gltf(scene, tmp_path / "saved.gltf")
    written = json.loads((tmp_path / "saved.gltf").read_text())["materials"][0]["extensions"]
    assert "iridescenceThicknessTexture" in written["KHR_materials_iridescence"]

def test_files_untextured_defaults_disabled_and_bad_factors(tmp_path):
    path = _EXT._gltf(tmp_path, {"KHR_materials_iridescence": {"iridescenceFactor": 1.0}})
    material = glphong.load_scene(path, light_units="radiometric", lights=[]).objects[0].material
    assert (material.iridescence, material.iridescence_ior, material.iridescence_thickness_minimum,
            material.iridescence_thickness_maximum, material.iridescence_thickness_mix) == (1.0, 1.3, 100.0, 400.0, 1.0)
    saved = tmp_path / "saved.gltf"
    scene = glphong.Scene(glphong.PerspectiveCamera.look_at((0, 0, 3), (0, 0, 0)), [])
    scene.add(glphong.primitives.sphere(1), glphong.GltfPBR(0.5, 0.0, 0.5, iridescence=1.0, iridescence_thickness_mix=0.5))
    glphong.save_gltf(scene, saved)
    written = json.loads(saved.read_text())["materials"][0]["extensions"]["KHR_materials_iridescence"]
    assert written["iridescenceThicknessMaximum"] == 250.0  # mix(100, 400, 0.5): the file has no such factor
    path = _EXT._gltf(tmp_path, {"KHR_materials_iridescence": {"iridescenceIor": 1.8}})
    assert glphong.load_scene(path, light_units="radiometric", lights=[]).objects[0].material.extensions() == ()
    for bad, field in (({"iridescenceFactor": 1.5}, "iridescenceFactor"),
                       ({"iridescenceFactor": 1.0, "iridescenceIor": 0.5}, "iridescenceIor"),
                       ({"iridescenceFactor": 1.0, "iridescenceThicknessMaximum": -1.0}, "iridescenceThicknessMaximum"),
                       ({"iridescenceThicknessTexture": {"index": 7}}, "iridescenceThicknessTexture")):
        path = _EXT._gltf(tmp_path, {"KHR_materials_iridescence": bad})
        with pytest.raises(glphong.filesafety.SceneFileError,
                           match=rf"materials\[0\]\.extensions\.KHR_materials_iridescence\.{field}"):
            glphong.load_scene(path, light_units="radiometric", lights=[])


def test_iridescence_is_declared_and_measured_reciprocal():
    """The film's Fresnel is on v.h (symmetric in l and v): the material stays reciprocal, as declared."""
    from glphong.analysis import properties

    material = glphong.GltfPBR(**MATERIALS["film ior 2.5 above the base's, mixed"])
    assert material.properties.reciprocal
    report = properties(material, theta_i=[0.5])  # one albedo: the energy question is not asked here
    assert report.reciprocal, report


def test_the_models_chunk_reads_the_film_first_and_names_both_files():
    """`GlslFile(..., before=...)`: the chunk is gltf_iridescence.glsl then gltf_pbr.glsl, and its label says where
    each begins (a compile error's line counts from the first)."""
    import re

    from glphong.core.glsl_files import glsl_root
    from glphong.definitions.registry import model_source

    text, label, first, _ = model_source(glphong.GltfPBR)
    starts = dict(re.findall(r"(materials/\w+\.glsl) \(from line (\d+)\)", label))
    assert list(starts) == ["materials/gltf_iridescence.glsl", "materials/gltf_pbr.glsl"] and first == 1
    lines = text.split("\n")
    for name, start in starts.items():
        own = (glsl_root() / name).read_text().rstrip("\n").split("\n")
        assert lines[int(start) - 1:int(start) - 1 + len(own)] == own, name
