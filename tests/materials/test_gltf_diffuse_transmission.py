"""KHR_materials_diffuse_transmission on glphong.GltfPBR (glphong/materials/gltf_diffuse_transmission.py) against an
independent float64 transcription of the extension's text (KhronosGroup/glTF, extensions/2.0/Khronos/
KHR_materials_diffuse_transmission/README.md)::

    dielectric_brdf = fresnel_mix(ior, base = mix(diffuse_brdf(baseColor), diffuse_btdf(diffuseTransmissionColor),
                                                  diffuseTransmission), layer = specular_brdf(roughness^2))

``diffuse_brdf(color) = color/pi`` with view and light on one side, ``diffuse_btdf(color) = color/pi`` on opposite
sides, ``fresnel_mix = (1 - F) base + F layer`` with Schlick's ``F`` at the half vector (for a light behind, the
mirrored light's, as the glTF Sample Viewer takes it).  An orthographic camera looks down -z at a thin quad (normal
+z): the view is ``v = +z`` at every pixel, so the closed forms below hold on the whole quad.
"""
import importlib.util
import json
import pathlib
import warnings

import numpy as np
import pytest

import glphong
from glphong import primitives

SIZE = 32


def _scene(material, lights, floor=False):
    camera = glphong.OrthographicCamera.look_at((0.0, 0.0, 5.0), (0.0, 0.0, 0.0), ymag=1.0)
    scene = glphong.Scene(camera, lights)
    if floor:
        pose = np.eye(4)
        pose[2, 3] = -1.0
        scene.add(primitives.plane(4.0), glphong.Lambert(0.5), pose=pose, name="floor")
    scene.add(primitives.plane(1.0), material, name="leaf")
    return scene


def _specification(c, m, roughness, ior, dt, c_dt, e_front, theta_behind, e_behind):
    """The quad's radiance (3,) from the README's formulas: a directional light along -z in front (irradiance
    ``e_front``: ``l = v = h = n``) and one behind at ``theta_behind`` from -n (``e_behind``)."""
    c, c_dt = np.asarray(c, float), np.asarray(c_dt, float)
    f0 = ((ior - 1.0) / (ior + 1.0)) ** 2
    alpha = roughness ** 2
    specular = 1.0 / (4.0 * np.pi * alpha ** 2) if roughness > 0 else 0.0  # D V at h = n
    front_base = (1.0 - dt) * c / np.pi  # mix(brdf, btdf, dt) with the light on the viewer's side
    front = ((1.0 - m) * ((1.0 - f0) * front_base + f0 * specular) + m * c * specular) * e_front
    cos_l = np.cos(theta_behind)  # |n.l|
    mirrored = np.array([np.sin(theta_behind), 0.0, cos_l])
    h = (mirrored + [0.0, 0.0, 1.0]) / np.linalg.norm(mirrored + [0.0, 0.0, 1.0])
    fresnel = f0 + (1.0 - f0) * (1.0 - h[2]) ** 5
    behind = (1.0 - m) * (1.0 - fresnel) * dt * c_dt / np.pi * cos_l * e_behind  # the layer is a BRDF: 0 behind
    return front + behind


def _lights(e_front, theta_behind, e_behind):
    lights = [glphong.DirectionalLight((0.0, 0.0, -1.0), e_front)] if e_front else []
    if e_behind:  # travelling away from the viewer's side: it lights the quad's back
        lights.append(glphong.DirectionalLight((-np.sin(theta_behind), 0.0, np.cos(theta_behind)), e_behind))
    return lights


CASES = {"front only": ((0.8, 0.6, 0.3), 0.0, 0.5, 1.5, 0.4, (1.0, 0.5, 0.2), 2.0, 0.0, 0.0),
         "behind, normal": ((0.8, 0.6, 0.3), 0.0, 0.5, 1.5, 0.7, (1.0, 0.5, 0.2), 0.0, 0.0, 3.0),
         "behind at 60 degrees, metallic 0.3": ((0.5, 0.7, 0.9), 0.3, 0.3, 2.0, 1.0, (0.2, 0.9, 0.4), 0.0, 1.05, 4.0),
         "both sides": ((0.9, 0.9, 0.9), 0.1, 0.8, 1.3, 0.5, (0.9, 0.2, 0.2), 1.0, 0.5, 2.0)}


@pytest.mark.parametrize("name", sorted(CASES))
def test_the_quad_is_the_specification_and_verifies(name, glphong_backend, glphong_make_renderer):
    c, m, r, ior, dt, c_dt, e_front, theta, e_behind = CASES[name]
    material = glphong.GltfPBR(c, m, r, ior=ior, diffuse_transmission=dt, diffuse_transmission_color=c_dt)
    assert material.extensions() == ("diffuse_transmission",)
    renderer = glphong_make_renderer(SIZE, SIZE, glphong_backend)
    scene = _scene(material, _lights(e_front, theta, e_behind))
    inner = renderer.render(scene).radiance[SIZE // 2 - 6:SIZE // 2 + 6, SIZE // 2 - 6:SIZE // 2 + 6].reshape(-1, 3)
    f32 = [np.float32(a).astype(float) for a in (ior, dt)]
    expected = _specification(c, m, r, f32[0], f32[1], c_dt, e_front, theta, e_behind)
    np.testing.assert_allclose(inner, np.broadcast_to(expected, inner.shape), rtol=2e-5)
    report = glphong.verify(scene, renderer)
    assert report.passed, report.summary()


def test_the_comparison_catches_the_usual_mistakes():
    """The specification's transcription differs where the base colour tints the BTDF, where 1 - F is left out, and
    where the light in front is not darkened by 1 - dt: each by more than 5 % here."""
    c, m, r, ior, dt, c_dt, _, theta, e = CASES["behind at 60 degrees, metallic 0.3"]
    right = _specification(c, m, r, ior, dt, c_dt, 0.0, theta, e)
    tinted = _specification(c, m, r, ior, dt, np.asarray(c_dt) * c, 0.0, theta, e)
    assert np.max(np.abs(tinted - right) / right.max()) > 0.05
    f0 = ((ior - 1) / (ior + 1)) ** 2
    assert np.max(np.abs(right / (1 - f0) - right) / right.max()) > 0.05  # 1 - F at v.h' < 1 is below 1 - f0
    c, m, r, ior, dt, c_dt, e_front, _, _ = CASES["front only"]
    front = _specification(c, m, 0.0, ior, dt, c_dt, e_front, 0.0, 0.0)
    assert np.max(np.abs(_specification(c, m, 0.0, ior, 0.0, c_dt, e_front, 0.0, 0.0) - front) / front.max()) > 0.05


def _leaf_scene(lights_behind_scene, textured=False, material=None):
    """A diffusely transmitting quad (a leaf) in the transmission tests' scene of lights on both sides
    (`lights_behind_scene`, tests/conftest.py)."""
    dt, color = 0.8, (0.3, 0.9, 0.2)
    if textured:
        image = np.random.default_rng(7).integers(0, 256, (16, 16, 3), dtype=np.uint8)
        dt = glphong.Texture(image, 0.9, srgb=False, channel="g")
        color = glphong.Texture(image[::-1], (1.0, 0.8, 0.6))
    material = material or glphong.GltfPBR((0.9, 0.8, 0.6), 0.2, 0.4, diffuse_transmission=dt,
                                           diffuse_transmission_color=color)
    return lights_behind_scene(primitives.plane(1.5, segments=4), material, name="leaf")


@pytest.mark.parametrize("textured", [False, True])
def test_point_spot_and_directional_lights_behind_verify(textured, glphong_backend, glphong_make_renderer,
                                                         lights_behind_scene):
    renderer = glphong_make_renderer(48, 40, glphong_backend)
    report = glphong.verify(_leaf_scene(lights_behind_scene, textured), renderer)
    assert report.passed and report.transmission.pixels.sum() > 700, report.summary()


def test_with_transmission_both_verify(glphong_backend, glphong_make_renderer, lights_behind_scene):
    """KHR_materials_transmission overrides the diffuse transmission by its weight (1 - t), as the README combines
    them; the glass's background and lights behind are drawn by the same pass."""
    scene = _leaf_scene(lights_behind_scene, material=glphong.GltfPBR((0.9, 0.8, 0.6), 0.1, 0.3, transmission=0.5,
                                                                       diffuse_transmission=0.6))
    report = glphong.verify(scene, glphong_make_renderer(48, 40, glphong_backend))
    assert report.passed, report.summary()


PLANTED = {"1 - F for F": ("* (1.0 - fresnel_max) * n_dot_l);", "* fresnel_max * n_dot_l);"),
           "the light not mirrored": ("    vec3 mirrored = wi + (2.0 * n_dot_l) * f.n;\n    float n_dot_v, n_dot_h, "
                                      "v_dot_h, tan2;\n    bool valid = microfacet_geometry(f.n, mirrored, wo, n_dot_l, "
                                      "n_dot_v, n_dot_h, v_dot_h, tan2);\n    vec3 fresnel",
                                      "    vec3 mirrored = -wi;\n    float n_dot_v, n_dot_h, v_dot_h, tan2;\n    bool "
                                      "valid = microfacet_geometry(f.n, mirrored, wo, n_dot_l, n_dot_v, n_dot_h, "
                                      "v_dot_h, tan2);\n    vec3 fresnel"),
           "front not darkened": ("    diffuse *= 1.0 - u_gltf_pbr_diffuse_transmission;\n", "")}


@pytest.mark.parametrize("planted", sorted(PLANTED))
def test_planted_errors_fail(planted, monkeypatch, glphong_make_renderer, lights_behind_scene):
    from glphong.shaders import assembly

    old, new = PLANTED[planted]
    original = assembly.model_source
    source = original(glphong.materials.gltf_pbr.GltfPBR)
    assert source[0].count(old) == 1
    monkeypatch.setattr(assembly, "model_source", lambda cls: (source[0].replace(old, new),) + tuple(source[1:])
                        if cls is glphong.materials.gltf_pbr.GltfPBR else original(cls))
    report = glphong.verify(_leaf_scene(lights_behind_scene), glphong_make_renderer(48, 40, "egl"))
    assert not report.passed and report.outside_count > 0, report.summary()


def test_no_diffuse_transmission_is_the_core_material_and_its_program():
    from glphong.shaders.key import program_key

    lights = [glphong.PointLight((0.0, 0.0, 2.0), 10.0)]
    core = glphong.GltfPBR(0.5, 0.2, 0.5)
    neutral = glphong.GltfPBR(0.5, 0.2, 0.5, diffuse_transmission=0.0, diffuse_transmission_color=(0.1, 0.2, 0.3))
    assert neutral.extensions() == () and program_key(neutral, lights, None) == program_key(core, lights, None)
    key = program_key(glphong.GltfPBR(0.5, 0.2, 0.5, diffuse_transmission=0.1), lights, None)
    assert "GLTF_PBR_DIFFUSE_TRANSMISSION" in {name for name, _ in key.defines()}


def test_area_and_environment_lights_behind_are_drawn_and_verified(glphong_make_renderer):
    """An area light and an environment light behind the leaf shine through it by their weighted directions
    (docs/transmission.md; the closed forms and the method's error: tests/test_transmission_extended.py): the
    leaf's back-lit pixels are not black, and verify passes (exact=False: the lights' methods)."""
    leaf = glphong.GltfPBR(0.5, 0.0, 0.5, diffuse_transmission=0.5)
    renderer = glphong_make_renderer(SIZE, SIZE, "egl")
    for light in (glphong.RectLight((0.0, 0.0, -1.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), radiance=1.0),
                  glphong.EnvironmentLight(np.ones((4, 8)))):
        scene = _scene(leaf, [light])
        frame = renderer.render(scene)
        assert np.isfinite(frame.radiance).all() and frame.radiance[frame.coverage > 0].max() > 0, type(light)
        report = glphong.verify(scene, renderer)
        assert report.passed, report.summary()
    for other in (dict(clearcoat=1.0), dict(sheen_color=0.5), dict(specular=0.5), dict(iridescence=1.0)):
        glphong.GltfPBR(0.5, 0.0, 0.5, diffuse_transmission=0.5, **other)  # drawn (test_gltf_diffuse_transmission_layers)


# --------------------------------------------------------------------------- files
def _gltf(tmp_path, extensions, images=()):
    spec = importlib.util.spec_from_file_location("_gltf_extension_tests_dt", pathlib.Path(__file__).with_name(
        "test_gltf_extensions.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module._gltf(tmp_path, extensions, images=list(images) or None,
                        used=("KHR_materials_diffuse_transmission",))


def test_files_load_with_their_textures_and_save_back(tmp_path):
    rgba = np.random.default_rng(19).integers(0, 256, (8, 8, 3), dtype=np.uint8)
    extensions = {"KHR_materials_diffuse_transmission": {
        "diffuseTransmissionFactor": 0.6, "diffuseTransmissionTexture": {"index": 0},
        "diffuseTransmissionColorFactor": [1.0, 0.9, 0.85], "diffuseTransmissionColorTexture": {"index": 0}}}
    path = _gltf(tmp_path, extensions, images=[rgba])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # applied: no warning
        material = glphong.load_scene(path, light_units="radiometric", lights=[]).objects[0].material
    assert material.extensions() == ("diffuse_transmission",)
    assert material.diffuse_transmission.scale == 0.6 and material.diffuse_transmission.channel == "r"
    np.testing.assert_allclose(material.diffuse_transmission_color.scale, (1.0, 0.9, 0.85))
    out = tmp_path / "saved.gltf"
    glphong.save_gltf(glphong.load_scene(path, light_units="radiometric", lights=[]), out)
    written = json.loads(out.read_text())["materials"][0]["extensions"]["KHR_materials_diffuse_transmission"]
    assert written["diffuseTransmissionFactor"] == pytest.approx(0.6)
    assert written["diffuseTransmissionColorFactor"] == pytest.approx([1.0, 0.9, 0.85])
    assert "diffuseTransmissionColorTexture" in written
    assert "KHR_materials_transmission" not in json.loads(out.read_text())["materials"][0]["extensions"]
    again = glphong.load_scene(out, light_units="radiometric", lights=[]).objects[0].material
    assert again.extensions() == ("diffuse_transmission",)


def test_files_untextured_default_and_bad_factors(tmp_path):
    path = _gltf(tmp_path, {"KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": 0.25}})
    material = glphong.load_scene(path, light_units="radiometric", lights=[]).objects[0].material
    assert material.diffuse_transmission == 0.25 and material.diffuse_transmission_color == (1.0, 1.0, 1.0)
    path = _gltf(tmp_path, {"KHR_materials_diffuse_transmission": {"diffuseTransmissionColorFactor": [1, 0, 0]}})
    assert glphong.load_scene(path, light_units="radiometric", lights=[]).objects[0].material.extensions() == ()
    for bad, field in (({"diffuseTransmissionFactor": 1.5}, "diffuseTransmissionFactor"),
                       ({"diffuseTransmissionFactor": 0.5, "diffuseTransmissionColorFactor": [1, -1, 0]},
                        "diffuseTransmissionColorFactor"),
                       ({"diffuseTransmissionTexture": {"index": 7}}, "diffuseTransmissionTexture")):
        path = _gltf(tmp_path, {"KHR_materials_diffuse_transmission": bad})
        with pytest.raises(glphong.filesafety.SceneFileError,
                           match=rf"materials\[0\]\.extensions\.KHR_materials_diffuse_transmission\.{field}"):
            glphong.load_scene(path, light_units="radiometric", lights=[])
