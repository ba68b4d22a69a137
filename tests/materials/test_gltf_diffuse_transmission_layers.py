"""KHR_materials_specular, _sheen, _clearcoat and _iridescence over KHR_materials_diffuse_transmission (glsl/materials/gltf_pbr.glsl's
``gltf_diffuse_transmission_response``, glphong/materials/gltf_diffuse_transmission.py) against a float64
transcription of the specifications (the transcription of tests/test_transmission_layers.py, its module docstring):
the diffuse BTDF is in ``fresnel_mix``'s base, so a light behind the surface is weighted by ``1 - max3(F(v.h'))``
with KHR_materials_specular's ``F = mix(min(f0 specularColor, 1) specular, specular, (1 - |v.h'|)^5)``; the sheen
scales the base by ``max(min(1 - max3(sheenColor) E(n.v), 1 - max3(sheenColor) E(n.l)), 0)``; the coat by ``1 -
clearcoat F_c(n.v)``, ``F_c = 0.04 + 0.96 (1 - n.v)^5``; the sheen's and the coat's lobes (BRDFs) add nothing behind;
the film's ``rgb_mix`` weights the base by ``1 - max3(mix(F, F_iridescence(film_f0 = min(f0 specularColor, 1)
specular), iridescence))`` (tests/materials/test_gltf_iridescence.py's transcription of F_iridescence).
"""
import importlib.util
import pathlib
import warnings

import numpy as np
import pytest

import glphong
from glphong import primitives
from glphong.materials.gltf_diffuse_transmission import gltf_diffuse_transmission_response

_SPEC = importlib.util.spec_from_file_location("_transmission_layers_spec_dt",
                                               pathlib.Path(__file__).parents[1] / "test_transmission_layers.py")
LAYERS = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(LAYERS)
SIZE = 32

#: the layers on the leaf (each with a non-grey specular colour, whose max3(F) differs from every channel's)
LAYER = {"specular": dict(specular=0.7, specular_color=(1.0, 3.0, 12.0)),
         "sheen": dict(sheen_color=(0.3, 0.9, 0.5), sheen_roughness=0.35),
         "clearcoat": dict(clearcoat=0.6, clearcoat_roughness=0.2)}
LAYER["film"] = dict(iridescence=0.6, iridescence_ior=1.8, iridescence_thickness_maximum=500.0)
LAYER["all"] = LAYER["specular"] | LAYER["sheen"] | LAYER["clearcoat"]
LAYER["film and specular"] = LAYER["film"] | LAYER["specular"]


def specification(n_dot_v, n_dot_l, v_dot_h, c_dt, m, dt, ior, layers):
    """``(1 - m) dt (c_dt / pi) (1 - max3(F(v.h'))) n.l keep`` (module docstring), (N, 3), from ``layers`` (`LAYER`)."""
    specular, color = layers.get("specular", 1.0), layers.get("specular_color", (1.0, 1.0, 1.0))
    f = np.stack([LAYERS.specular_fresnel(x, ior, specular, color) for x in v_dot_h])
    if "iridescence" in layers:  # thickness = mix(minimum, maximum, 1) = maximum
        w, film_f0 = layers["iridescence"], np.minimum(((ior - 1.0) / (ior + 1.0)) ** 2 * np.asarray(color), 1.0) * specular
        irid = np.stack([LAYERS._IRIDESCENCE.iridescent_fresnel(1.0, layers["iridescence_ior"], film_f0[None],
                                                                layers["iridescence_thickness_maximum"],
                                                                np.array([x]))[0] for x in v_dot_h])
        f = (1.0 - w) * f + w * irid
    f = f.max(axis=1)
    keep = np.ones_like(n_dot_v)
    if "sheen_color" in layers:
        s_max, r_s = max(layers["sheen_color"]), layers["sheen_roughness"]
        keep = np.maximum(np.minimum(1.0 - s_max * LAYERS.sheen_albedo(n_dot_v, r_s),
                                     1.0 - s_max * LAYERS.sheen_albedo(n_dot_l, r_s)), 0.0)
    if "clearcoat" in layers:
        keep = keep * (1.0 - layers["clearcoat"] * (0.04 + 0.96 * (1.0 - n_dot_v) ** 5))
    return (1.0 - m) * dt * np.asarray(c_dt) / np.pi * ((1.0 - f) * n_dot_l * keep)[:, None]


def _twin_layers(layers):
    """`gltf_diffuse_transmission_response`'s ``specular`` and ``layers`` arguments from `LAYER`'s keywords."""
    specular = (layers["specular"], np.asarray(layers["specular_color"])) if "specular" in layers else None
    keywords = {k: np.asarray(v) if k == "sheen_color" else v for k, v in layers.items()
                if k in ("sheen_color", "sheen_roughness", "clearcoat")}
    film = {"iridescence": layers["iridescence"], "iridescence_ior": layers["iridescence_ior"],
            "thickness": layers["iridescence_thickness_maximum"]} if "iridescence" in layers else None
    return specular, keywords, film


@pytest.mark.parametrize("layer", sorted(LAYER))
def test_the_twin_is_the_specifications_at_random_directions(layer):
    """Random views and lights behind: the twin against the transcription to 1e-12, and the transcription apart from
    the refused-era formula (grey F, no layers) by more than 1 %."""
    rng = np.random.default_rng(23)
    n, wo, wi = LAYERS._views_and_lights_behind(rng, 200)
    n_dot_l = -wi[:, 2]
    n_dot_v, v_dot_h, _, _ = LAYERS._mirrored_ggx(wi, wo, n_dot_l, 0.5)
    c_dt, m, dt, ior = np.array([0.3, 0.9, 0.2]), 0.2, 0.8, 1.4
    got = gltf_diffuse_transmission_response(n, wi, wo, n_dot_l, c_dt, m, 0.0, dt, ior, *_twin_layers(LAYER[layer]))
    expected = specification(n_dot_v, n_dot_l, v_dot_h, c_dt, m, dt, ior, LAYER[layer])
    np.testing.assert_allclose(got, expected, rtol=1e-12)
    bare = specification(n_dot_v, n_dot_l, v_dot_h, c_dt, m, dt, ior, {})
    assert np.max(np.abs(bare - expected)) > 0.01 * np.max(expected)


def _quad(material, theta, e_behind):
    """The leaf quad (normal +z) seen along -z by an orthographic camera (v = +z everywhere), lit only from behind by
    a directional light at ``theta`` [rad] from -n."""
    camera = glphong.OrthographicCamera.look_at((0.0, 0.0, 5.0), (0.0, 0.0, 0.0), ymag=1.0)
    light = glphong.DirectionalLight((-np.sin(theta), 0.0, np.cos(theta)), e_behind)
    scene = glphong.Scene(camera, [light])
    scene.add(primitives.plane(1.0), material, name="leaf")
    return scene


@pytest.mark.parametrize("layer", sorted(LAYER))
def test_the_quad_lit_from_behind_is_the_specifications_and_verifies(layer, glphong_backend, glphong_make_renderer):
    c_dt, m, r, ior, dt, theta, e = (0.2, 0.9, 0.4), 0.1, 0.4, 1.5, 0.8, 1.0, 3.0
    material = glphong.GltfPBR((0.9, 0.8, 0.6), m, r, ior=ior, diffuse_transmission=dt, diffuse_transmission_color=c_dt,
                               **LAYER[layer])
    renderer = glphong_make_renderer(SIZE, SIZE, glphong_backend)
    scene = _quad(material, theta, e)
    inner = renderer.render(scene).radiance[SIZE // 2 - 6:SIZE // 2 + 6, SIZE // 2 - 6:SIZE // 2 + 6].reshape(-1, 3)
    mirrored = np.array([np.sin(theta), 0.0, np.cos(theta)])
    h = (mirrored + [0.0, 0.0, 1.0]) / np.linalg.norm(mirrored + [0.0, 0.0, 1.0])
    f32 = {k: float(np.float32(v)) for k, v in LAYER[layer].items() if not isinstance(v, tuple)}
    expected = e * specification(np.ones(1), np.array([np.cos(theta)]), h[2:], c_dt, m, float(np.float32(dt)), ior,
                                 LAYER[layer] | f32)[0]
    np.testing.assert_allclose(inner, np.broadcast_to(expected, inner.shape), rtol=5e-5)
    report = glphong.verify(scene, renderer)
    assert report.passed, report.summary()


def _leaf(lights_behind_scene, **layers):
    material = glphong.GltfPBR((0.9, 0.8, 0.6), 0.2, 0.4, diffuse_transmission=0.8,
                               diffuse_transmission_color=(0.3, 0.9, 0.2), **layers)
    return lights_behind_scene(primitives.plane(1.5, segments=4), material, name="leaf")


@pytest.mark.parametrize("layer", sorted(LAYER))
def test_lights_on_both_sides_verify(layer, glphong_backend, glphong_make_renderer, lights_behind_scene):
    report = glphong.verify(_leaf(lights_behind_scene, **LAYER[layer]), glphong_make_renderer(48, 40, glphong_backend))
    assert report.passed and report.transmission.pixels.sum() > 700, report.summary()


def test_textured_specular_colour_and_a_coat_on_its_own_normal_verify(glphong_backend, glphong_make_renderer,
                                                                      lights_behind_scene):
    image = np.random.default_rng(5).integers(0, 256, (16, 16, 3), dtype=np.uint8)
    normal = np.random.default_rng(6).integers(90, 166, (8, 8, 3), dtype=np.uint8)
    normal[..., 2] = 255
    scene = _leaf(lights_behind_scene, specular=0.8, specular_color=glphong.Texture(image, (1.0, 2.0, 4.0)),
                  sheen_color=(0.5, 0.4, 0.3), sheen_roughness=0.6, clearcoat=0.7,
                  clearcoat_normal=glphong.Texture(normal, srgb=False))
    report = glphong.verify(scene, glphong_make_renderer(48, 40, glphong_backend))
    assert report.passed, report.summary()


#: GLSL errors planted in gltf_diffuse_transmission_response: (old, new, the layer that shows it)
PLANTED = {"the grey F for the specular's": ("vec3 fresnel = gltf_transmission_fresnel(u_gltf_pbr_ior, v_dot_h);",
                                             "vec3 fresnel = fresnel_schlick(vec3(0.04), v_dot_h);", "specular"),
           "the film's weight ignored": ("fresnel = mix(fresnel, film, u_gltf_pbr_iridescence);", "fresnel = film;",
                                         "film"),
           "the layers left out": ("value * gltf_transmission_layers(f, wo, n_dot_v, n_dot_l) : vec3(0.0);\n}\n#endif\n"
                                   "\n#if defined(GLTF_PBR_VOLUME)", "value : vec3(0.0);\n}\n#endif\n\n"
                                   "#if defined(GLTF_PBR_VOLUME)", "all")}


@pytest.mark.parametrize("planted", sorted(PLANTED))
def test_planted_errors_fail_verify(planted, monkeypatch, glphong_make_renderer, lights_behind_scene):
    from glphong.shaders import assembly

    old, new, layer = PLANTED[planted]
    original = assembly.model_source
    source = original(glphong.materials.gltf_pbr.GltfPBR)
    assert source[0].count(old) == 1
    monkeypatch.setattr(assembly, "model_source", lambda cls: (source[0].replace(old, new),) + tuple(source[1:])
                        if cls is glphong.materials.gltf_pbr.GltfPBR else original(cls))
    report = glphong.verify(_leaf(lights_behind_scene, **LAYER[layer]), glphong_make_renderer(48, 40, "egl"))
    assert not report.passed and report.outside_count > 0, report.summary()


def test_files_keep_specular_sheen_coat_and_film(tmp_path):
    spec = importlib.util.spec_from_file_location("_gltf_extension_tests_dtl", pathlib.Path(__file__).with_name(
        "test_gltf_extensions.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    extensions = {"KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": 0.6},
                  "KHR_materials_specular": {"specularFactor": 0.5}, "KHR_materials_clearcoat": {"clearcoatFactor": 0.4},
                  "KHR_materials_sheen": {"sheenColorFactor": [0.5, 0.5, 0.5]}}
    film = extensions | {"KHR_materials_iridescence": {"iridescenceFactor": 1.0}}
    path = module._gltf(tmp_path, film, used=tuple(film))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # applied: no warning
        material = glphong.load_scene(path, light_units="radiometric", lights=[]).objects[0].material
    assert set(material.extensions()) == {"diffuse_transmission", "specular", "clearcoat", "sheen", "iridescence"}
