"""KHR_materials_specular, _sheen and _clearcoat over KHR_materials_transmission (glsl/transmission_thin.glsl,
glphong/materials/gltf_transmission.py, docs/transmission.md) against an independent float64 transcription of the
specifications' formulas, written here and sharing nothing with glphong but the sheen's shipped albedo table:

- KHR_materials_transmission: ``dielectric_brdf = fresnel_mix(base = mix(diffuse_brdf(c), specular_btdf(alpha) c, t),
  layer = specular_brdf(alpha))``; a thin wall of roughness 0 lets the radiance behind it through along the view ray;
  a light behind it meets ``specular_btdf``, the GGX ``D V`` of the light mirrored through the surface, ``alpha = r^2``;
- KHR_materials_specular: ``fresnel_mix(base, layer) = (1 - max3(F)) base + F layer``, ``F = mix(dielectric_f0,
  dielectric_f90, (1 - |v.h|)^5)``, ``dielectric_f0 = min(f0 specularColor, 1) specular``, ``dielectric_f90 =
  specular``, ``f0 = ((ior - 1)/(ior + 1))^2``: the transmitted part is in ``base``, so it takes ``1 - max3(F)``;
- KHR_materials_sheen: ``sheen_layer = sheen_brdf + base min(1 - max3(sheenColor) E(n.v), 1 - max3(sheenColor)
  E(n.l))``, ``E`` the sheen's directional albedo (glphong's shipped table, read here at its knot ``cos = 1``,
  ``sheenRoughness = 1``); the Charlie lobe is 0 at ``n.h = 1``;
- KHR_materials_clearcoat: ``mix(sheen_layer, clearcoat_brdf, clearcoat F_c(n.v))``, ``F_c = 0.04 + 0.96 (1 -
  n.v)^5``; the coat's lobe of roughness 0 is a delta (0 for a directional light).

An orthographic camera looks at a transmissive quad (normal +z) over a Lambert plane under a directional light
travelling along -z, so every pixel of the quad has the same geometry.
"""
import importlib.util
import json
import pathlib
import warnings

import numpy as np
import pytest

import glphong
from glphong import primitives
from glphong.materials import gltf_pbr
from glphong.shaders import assembly
from glphong.materials.gltf_sheen_table import SHEEN_ALBEDO
from glphong.materials.gltf_transmission import gltf_transmission_response, gltf_transmission_weight
from glphong.testing.glsl_source import functions

SIZE = 32  # px; the view spans [-1, 1] m
E = 2.0  # W/m^2, the directional light's irradiance
K_D = 0.6  # the Lambert plane's k_d [1/sr]: L_behind = k_d E
E_SHEEN = SHEEN_ALBEDO[16][32]  # E(cos = 1, sheenRoughness = 1): the table's knot


def _scene(glass, theta=0.0, behind=None):
    """The quad seen at ``theta`` [rad] from its normal (about y), a directional light ``behind`` [W/m^2] shining
    through it along +z where given."""
    target = np.array([0.0, 0.0, 0.5])
    eye = target + 5.0 * np.array([np.sin(theta), 0.0, np.cos(theta)])
    camera = glphong.OrthographicCamera.look_at(tuple(eye), tuple(target), ymag=1.0)
    scene = glphong.Scene(camera, [glphong.DirectionalLight((0.0, 0.0, -1.0), E)])
    if behind:
        scene.add_light(glphong.DirectionalLight((0.0, 0.0, 1.0), behind))
    scene.add(primitives.plane(6.0), glphong.Lambert(K_D), name="floor")
    pose = np.eye(4)
    pose[2, 3] = 0.5
    scene.add(primitives.plane(1.0), glass, pose=pose, name="glass")
    return scene


def specular_fresnel(v_dot_h, ior=1.5, specular=1.0, specular_color=(1.0, 1.0, 1.0)):
    """KHR_materials_specular's ``F`` (module docstring), (3,)."""
    f0 = ((ior - 1.0) / (ior + 1.0)) ** 2
    dielectric_f0 = np.minimum(f0 * np.asarray(specular_color, float), 1.0) * specular
    return dielectric_f0 + (specular - dielectric_f0) * (1.0 - abs(v_dot_h)) ** 5


def specification(c, m, t, roughness, theta=0.0, behind=0.0, specular=1.0, specular_color=(1.0, 1.0, 1.0),
                  sheen=0.0, clearcoat=0.0, coat_normal=(0.0, 0.0, 1.0), film=None):
    """The quad's radiance by the specifications (module docstring), (3,): the light in front (``l = +z``), the
    floor's ``K_D E`` seen through, a light ``behind`` travelling +z (its mirror arrives along ``l = +z``); ``sheen``
    ``max3(sheenColor)`` at sheenRoughness 1 (normal view only: ``E`` at the knot ``cos = 1``); ``coat_normal`` the
    coat's unit normal ``n_c`` (its lobe of roughness 0 a delta: 0 for a directional light; its ``F_c`` on ``max(n_c.v,
    0)``); ``film`` KHR_materials_iridescence's ``iridescence``, ``ior`` and ``thickness`` [nm]: every dielectric ``F``
    becomes ``mix(F, F_iridescence(specular min(f0 specularColor, 1)), iridescence)`` and the metal's ``mix(c + (1 -
    c) (1 - v.h)^5, F_iridescence(c), iridescence)`` (the README's ``iridescent_fresnel``, transcribed in
    tests/materials/test_gltf_iridescence.py), the light let through weighted by ``1 - max3`` of it."""
    c = np.asarray(c, float)
    v = np.array([np.sin(theta), 0.0, np.cos(theta)])
    n_dot_v = v[2]
    h = (v + np.array([0.0, 0.0, 1.0])) / np.linalg.norm(v + np.array([0.0, 0.0, 1.0]))
    v_dot_h, n_dot_h = v @ h, h[2]
    alpha = roughness ** 2
    if alpha > 0:
        d = alpha ** 2 / (np.pi * (n_dot_h ** 2 * (alpha ** 2 - 1.0) + 1.0) ** 2)
        vis = 1.0 / (2.0 * (n_dot_v * np.sqrt(alpha ** 2 + (1 - alpha ** 2)) + np.sqrt(alpha ** 2 + (1 - alpha ** 2)
                                                                                        * n_dot_v ** 2)))
        lobe = d * vis  # D V, times n.l = 1
    else:
        lobe = 0.0  # a delta: a directional light meets it with zero measure
    f_light = specular_fresnel(v_dot_h, specular=specular, specular_color=specular_color)
    f_view = specular_fresnel(n_dot_v, specular=specular, specular_color=specular_color)
    metal_f = c + (1.0 - c) * (1.0 - v_dot_h) ** 5
    if film:
        def iridescent(cos, base):
            return _IRIDESCENCE.iridescent_fresnel(1.0, film["ior"], np.atleast_2d(base), film["thickness"],
                                                   np.array([cos]))[0]

        film_f0 = np.minimum(((1.5 - 1.0) / (1.5 + 1.0)) ** 2 * np.asarray(specular_color, float), 1.0) * specular
        w = film["iridescence"]
        f_light, f_view, metal_f = ((1.0 - w) * f + w * iridescent(cos, base) for f, cos, base in
                                    ((f_light, v_dot_h, film_f0), (f_view, n_dot_v, film_f0), (metal_f, v_dot_h, c)))
    metal = metal_f * lobe
    front = ((1.0 - m) * ((1.0 - t) * (1.0 - f_light.max()) * c / np.pi + f_light * lobe) + m * metal) * E
    through = (1.0 - m) * t * (1.0 - f_view.max()) * c * K_D * E
    lit_behind = (1.0 - m) * t * (1.0 - f_light.max()) * c * lobe * behind  # the mirrored light: the same h
    sheen_scaling = 1.0 - sheen * E_SHEEN if sheen else 1.0  # min(.., ..) of n.v = n.l = 1
    coat = 1.0 - clearcoat * (0.04 + 0.96 * (1.0 - max(np.dot(coat_normal, v), 0.0)) ** 5)
    return (front + through + lit_behind) * sheen_scaling * coat


_IRIDESCENCE_SPEC = importlib.util.spec_from_file_location(
    "_gltf_iridescence_tests_layers", pathlib.Path(__file__).parent / "materials" / "test_gltf_iridescence.py")
_IRIDESCENCE = importlib.util.module_from_spec(_IRIDESCENCE_SPEC)
_IRIDESCENCE_SPEC.loader.exec_module(_IRIDESCENCE)  # the README's iridescent_fresnel, transcribed there

LAYERS = {"specular": {"specular": 0.6, "specular_color": (1.0, 8.0, 30.0)},  # f0 sc clamped at 1 in blue
          "sheen": {"sheen_color": (0.8, 0.3, 0.5), "sheen_roughness": 1.0},
          "clearcoat": {"clearcoat": 0.7},
          "all": {"specular": 0.8, "specular_color": (2.0, 0.5, 1.0), "sheen_color": (0.2, 0.6, 0.4),
                  "sheen_roughness": 1.0, "clearcoat": 0.5}}


def _expected(c, m, t, roughness, layer, theta=0.0, behind=0.0):
    keywords = LAYERS[layer]
    return specification(c, m, t, roughness, theta, behind, keywords.get("specular", 1.0),
                         keywords.get("specular_color", (1.0, 1.0, 1.0)), max(keywords.get("sheen_color", (0.0,))),
                         keywords.get("clearcoat", 0.0))


def _inner(frame, half_width=6, half_height=6):
    return frame.radiance[SIZE // 2 - half_height:SIZE // 2 + half_height,
                          SIZE // 2 - half_width:SIZE // 2 + half_width].reshape(-1, 3)


@pytest.mark.parametrize("layer", sorted(LAYERS))
@pytest.mark.parametrize("roughness", [0.0, 0.3])
def test_layers_over_transmission_are_the_specifications_at_normal_view(layer, roughness, glphong_backend,
                                                                         glphong_make_renderer):
    renderer = glphong_make_renderer(SIZE, SIZE, glphong_backend)
    c, m, t, behind = (0.7, 0.8, 0.9), 0.2, 0.8, 0.5
    scene = _scene(glphong.GltfPBR(c, m, roughness, transmission=t, **LAYERS[layer]), behind=behind)
    inner = _inner(renderer.render(scene))
    expected = _expected(c, m, t, roughness, layer, behind=behind)
    np.testing.assert_allclose(inner, np.broadcast_to(expected, inner.shape), rtol=5e-6)
    report = glphong.verify(scene, renderer)
    assert report.passed and report.transmission.pixels.sum() >= 200, report.summary()


@pytest.mark.parametrize("layer", ["specular", "clearcoat"])
@pytest.mark.parametrize("roughness", [0.0, 0.4])
def test_layers_over_transmission_are_the_specifications_at_an_oblique_view(layer, roughness, glphong_backend,
                                                                             glphong_make_renderer):
    """60 degrees from the normal: the view's Fresnel (n.v = 0.5) weights what is seen through, the light's (v.h =
    cos 30 degrees) the diffuse and the lobes, the light behind's mirror arriving as the one in front; the coat's F_c
    on n.v, also over the light behind (n.l = 1)."""
    renderer = glphong_make_renderer(SIZE, SIZE, glphong_backend)
    c, m, t, theta, behind = (0.3, 0.6, 0.9), 0.1, 0.7, np.radians(60.0), 0.5
    scene = _scene(glphong.GltfPBR(c, m, roughness, transmission=t, **LAYERS[layer]), theta=theta, behind=behind)
    inner = _inner(renderer.render(scene), half_width=2, half_height=5)
    expected = _expected(c, m, t, roughness, layer, theta=theta, behind=behind)
    np.testing.assert_allclose(inner, np.broadcast_to(expected, inner.shape), rtol=1e-5)
    report = glphong.verify(scene, renderer)
    assert report.passed, report.summary()


def coat_normal(texel, scale=1.0):
    """KHR_materials_clearcoat's clearcoatNormalTexture on the quad's frame ``t = +x``, ``b = +y``, ``n = +z`` (its
    UVs' tangent frame): ``normalize(t (s m.x) + b (s m.y) + n m.z)``, ``m = 2 texel - 1``."""
    m = 2.0 * np.asarray(texel, np.float64) - 1.0
    q = np.array([scale * m[0], scale * m[1], m[2]])
    return q / np.linalg.norm(q)


@pytest.mark.parametrize("roughness", [0.0, 0.4])
def test_a_coat_on_its_own_normal_over_transmission_is_the_specifications(roughness, glphong_backend,
                                                                         glphong_make_renderer):
    """The coat's own normal n_c (a constant texel, tilted toward the view) weights what is seen through the glass,
    the light in front and the light behind by 1 - clearcoat F_c(n_c.v): n_c.v = 0.91 where n.v = 0.5, so the
    transcription on n differs from it by 2 %, 400 times the comparison's tolerance."""
    renderer = glphong_make_renderer(SIZE, SIZE, glphong_backend)
    c, m, t, theta, behind, texel = (0.3, 0.6, 0.9), 0.1, 0.7, np.radians(60.0), 0.5, (0.8, 0.35, 0.8)
    glass = glphong.GltfPBR(c, m, roughness, transmission=t, clearcoat=0.7, clearcoat_normal=texel)
    assert "clearcoat_normal" in glass.extensions()
    scene = _scene(glass, theta=theta, behind=behind)
    gbuffer = renderer.gbuffer(scene)
    np.testing.assert_array_equal(gbuffer.tangent[SIZE // 2, SIZE // 2], (1.0, 0.0, 0.0, 1.0))  # t = +x, b = +y
    inner = _inner(renderer.render(scene), half_width=2, half_height=5)
    texel32 = np.float32(texel).astype(np.float64)
    expected = specification(c, m, t, roughness, theta, behind, clearcoat=0.7, coat_normal=coat_normal(texel32))
    np.testing.assert_allclose(inner, np.broadcast_to(expected, inner.shape), rtol=1e-5)
    on_n = specification(c, m, t, roughness, theta, behind, clearcoat=0.7)
    assert np.min(np.abs(on_n / expected - 1.0)) > 1e-2
    report = glphong.verify(scene, renderer)
    assert report.passed and report.transmission.pixels.sum() >= 100, report.summary()


FILM = {"iridescence": 0.75, "iridescence_ior": 1.75, "iridescence_thickness_maximum": 600.0}  # float32 exact


@pytest.mark.parametrize("specular", [False, True])
@pytest.mark.parametrize("roughness", [0.0, 0.4])
@pytest.mark.parametrize("theta", [0.0, 60.0])
def test_a_film_over_transmission_is_the_specifications(theta, roughness, specular, glphong_backend,
                                                         glphong_make_renderer):
    """KHR_materials_iridescence over the glass: the film's F' = mix(F, F_iridescence, iridescence) weights the
    light in front, the background seen through (at n.v) and the light behind (at v.h' of its mirror) by 1 -
    max3(F'), to 1e-5 against the transcription (which differs from the one without the film by more than 1 %)."""
    renderer = glphong_make_renderer(SIZE, SIZE, glphong_backend)
    c, m, t, behind = (0.3, 0.6, 0.9), 0.1, 0.7, 0.5
    spec = {"specular": 0.6, "specular_color": (1.0, 8.0, 30.0)} if specular else {}
    glass = glphong.GltfPBR(c, m, roughness, transmission=t, **spec, **FILM)
    assert {"transmission", "iridescence"} <= set(glass.extensions())
    scene = _scene(glass, theta=np.radians(theta), behind=behind)
    inner = _inner(renderer.render(scene), half_width=2 if theta else 6, half_height=5 if theta else 6)
    keywords = dict(specular=spec.get("specular", 1.0), specular_color=spec.get("specular_color", (1.0, 1.0, 1.0)))
    expected = specification(c, m, t, roughness, np.radians(theta), behind, **keywords,
                             film={"iridescence": 0.75, "ior": 1.75, "thickness": 600.0})
    np.testing.assert_allclose(inner, np.broadcast_to(expected, inner.shape), rtol=1e-5)
    assert np.min(np.abs(specification(c, m, t, roughness, np.radians(theta), behind, **keywords) / expected - 1.0)) \
        > 1e-2
    report = glphong.verify(scene, renderer)
    assert report.passed and report.transmission.pixels.sum() >= 100, report.summary()


def test_a_textured_film_over_transmission_verifies(glphong_backend, glphong_make_renderer):
    """The film's weight and thickness and the specular colour (its base) textured: F' is not monotone in them, so
    the band is the twin's first-order one (glphong.checks.transmission_twin); verify passes."""
    image = np.random.default_rng(6).uniform(0.0, 1.0, (8, 8, 3))
    glass = glphong.GltfPBR((0.8, 0.9, 1.0), 0.0, 0.0, transmission=0.9, specular=0.8,
                            specular_color=glphong.Texture(image, 2.0, srgb=False),
                            iridescence=glphong.Texture(image[::-1], 0.9, srgb=False, channel="r"),
                            iridescence_thickness_mix=glphong.Texture(image[:, ::-1], 1.0, srgb=False, channel="g"),
                            iridescence_thickness_maximum=900.0)
    report = glphong.verify(_scene(glass, theta=0.3, behind=0.5), glphong_make_renderer(SIZE, SIZE, glphong_backend))
    assert report.passed and report.transmission.pixels.sum() > 100, report.summary()


def _mirrored_ggx(wi, wo, n_dot_l, r):
    """The specification's GGX ``D`` and ``V`` for the light ``wi`` behind the surface (normal +z) mirrored through it,
    transcribed in float64: ``(n.v, v.h', D, V)``, each (N,), for roughness ``r``."""
    mirrored = wi * np.array([1.0, 1.0, -1.0])
    h = (mirrored + wo) / np.linalg.norm(mirrored + wo, axis=1, keepdims=True)
    n_dot_v, n_dot_h, v_dot_h = wo[:, 2], h[:, 2], np.sum(wo * h, axis=1)
    a2 = (r * r) ** 2
    d = a2 / (np.pi * (n_dot_h ** 2 * (a2 - 1.0) + 1.0) ** 2)
    vis = 1.0 / (2.0 * (n_dot_v * np.sqrt(a2 + (1 - a2) * n_dot_l ** 2)
                        + n_dot_l * np.sqrt(a2 + (1 - a2) * n_dot_v ** 2)))
    return n_dot_v, v_dot_h, d, vis


def _views_and_lights_behind(rng, count):
    """``(n, wo, wi)``, each (count, 3): the normal +z, random unit views in front (``wo.z >= 0.05`` before
    normalising) and random unit directions toward lights behind the surface (``wi.z <= -0.05``)."""
    n = np.tile([0.0, 0.0, 1.0], (count, 1))
    wo = rng.normal(size=(count, 3))
    wo[:, 2] = np.abs(wo[:, 2]) + 0.05
    wo /= np.linalg.norm(wo, axis=1, keepdims=True)
    wi = rng.normal(size=(count, 3))
    wi[:, 2] = -np.abs(wi[:, 2]) - 0.05
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    return n, wo, wi


def test_the_twins_film_over_transmission_is_the_specifications_at_random_directions():
    """`gltf_transmission_response` and `gltf_transmission_weight` with the film (float64) against the transcription
    at random views, lights behind and thicknesses: 1 - max3(mix(F, F_iridescence, iridescence)) at v.h' and n.v."""
    rng = np.random.default_rng(12)
    count = 300
    n, wo, wi = _views_and_lights_behind(rng, count)
    n_dot_l = -wi[:, 2]
    c, m, t, r, ior = np.array([0.7, 0.5, 0.9]), 0.2, 0.8, 0.4, 1.4
    specular, color = 0.7, np.array([1.0, 3.0, 12.0])
    film = {"iridescence": 0.6, "iridescence_ior": rng.uniform(1.1, 2.2, count),
            "thickness": rng.uniform(50.0, 1200.0, count)}
    got = gltf_transmission_response(n, wi, wo, n_dot_l, c, m, t, r, ior, (specular, color), film=film)
    n_dot_v, v_dot_h, d, vis = _mirrored_ggx(wi, wo, n_dot_l, r)
    film_f0 = np.minimum(((ior - 1.0) / (ior + 1.0)) ** 2 * color, 1.0) * specular

    def one_minus(cos):
        f = np.stack([specular_fresnel(x, ior, specular, color) for x in cos])
        irid = np.stack([_IRIDESCENCE.iridescent_fresnel(1.0, film["iridescence_ior"][i], film_f0[None],
                                                         film["thickness"][i], cos[i:i + 1])[0] for i in range(count)])
        return 1.0 - np.max(0.4 * f + 0.6 * irid, axis=1), 1.0 - np.max(f, axis=1)

    with_film, without = one_minus(v_dot_h)
    assert np.max(np.abs(with_film - without)) > 0.05
    expected = (1.0 - m) * t * c * (with_film * d * vis * n_dot_l)[:, None]
    np.testing.assert_allclose(got, expected, rtol=1e-11)
    weight = gltf_transmission_weight(n_dot_v, c, m, t, ior, specular, color, film)
    np.testing.assert_allclose(weight, (1.0 - m) * t * c * one_minus(n_dot_v)[0][:, None], rtol=1e-11)


NORMAL_MAP = glphong.NormalMap(np.full((4, 4, 3), (200, 90, 230), np.uint8), 1.3)
COAT_NORMALS = {"coat normal": dict(clearcoat_normal=(0.8, 0.35, 0.8)),
                "coat normal over a normal map": dict(clearcoat_normal=(0.8, 0.35, 0.8), normal_map=NORMAL_MAP),
                "textured coat normal over a normal map": dict(
                    clearcoat_normal=glphong.Texture(np.random.default_rng(8).uniform(0.25, 0.75, (8, 8, 3))
                                                     * (1.0, 1.0, 0.4) + (0.0, 0.0, 0.6), 1.0, srgb=False),
                    clearcoat_normal_strength=0.8, normal_map=NORMAL_MAP),
                "the unperturbed normal under a normal map": dict(normal_map=NORMAL_MAP)}


#: the glass of `lights_behind_scene` here
SPHERE = primitives.sphere(3, 0.6)

GLASS = dict(transmission=0.9, specular=0.7, specular_color=(1.0, 0.5, 2.0), sheen_color=(0.6, 0.4, 0.2),
             sheen_roughness=0.4, clearcoat=0.6, clearcoat_roughness=0.2)


@pytest.mark.parametrize("name", sorted(COAT_NORMALS))
def test_glass_with_a_coat_on_its_own_normal_verifies(name, glphong_backend, glphong_make_renderer,
                                                      lights_behind_scene):
    glass = glphong.GltfPBR((0.9, 0.8, 0.6), 0.1, 0.3, **GLASS, **COAT_NORMALS[name])
    assert "clearcoat_normal" in glass.extensions() and "transmission" in glass.extensions()
    report = glphong.verify(lights_behind_scene(SPHERE, glass), glphong_make_renderer(48, 40, glphong_backend))
    assert report.passed and report.transmission.pixels.sum() > 300, report.summary()


@pytest.mark.parametrize("roughness", [0.0, 0.3])
def test_layered_glass_under_lights_on_both_sides_verifies(roughness, glphong_backend, glphong_make_renderer,
                                                          lights_behind_scene):
    scene = lights_behind_scene(SPHERE, glphong.GltfPBR((0.9, 0.8, 0.6), 0.1, roughness, **GLASS))
    report = glphong.verify(scene, glphong_make_renderer(48, 40, glphong_backend))
    assert report.passed and report.transmission.pixels.sum() > 300, report.summary()


def test_a_textured_specular_colour_and_sheen_over_transmission_verify(glphong_backend, glphong_make_renderer):
    image = np.random.default_rng(6).uniform(0.0, 1.0, (8, 8, 3))
    glass = glphong.GltfPBR((0.8, 0.9, 1.0), 0.0, 0.2, transmission=0.9, specular=0.8,
                            specular_color=glphong.Texture(image, 2.0, srgb=False),
                            sheen_color=glphong.Texture(image[::-1], 0.7, srgb=False), sheen_roughness=0.5,
                            clearcoat=glphong.Texture(image[:, ::-1], 0.8, srgb=False, channel="r"))
    report = glphong.verify(_scene(glass, theta=0.3, behind=0.5), glphong_make_renderer(SIZE, SIZE, glphong_backend))
    assert report.passed and report.transmission.pixels.sum() > 100, report.summary()


PLANTED = {"specular left out of the transmitted Fresnel": (
               "vec3 fresnel = u_gltf_pbr_specular * fresnel_schlick(min(r * r * u_gltf_pbr_specular_color, vec3(1.0)), "
               "c);", "vec3 fresnel = fresnel_schlick(vec3(r * r), c);"),
           "sheen's albedo scaling left out": ("    keep = gltf_sheen_scaling(n_dot_v, n_dot_l);", "    keep = 1.0;"),
           "sheen's scaling on n.v alone": ("    keep = gltf_sheen_scaling(n_dot_v, n_dot_l);",
                                            "    keep = gltf_sheen_scaling(n_dot_v, n_dot_v);"),
           "coat left out": ("    keep *= 1.0 - u_gltf_pbr_clearcoat * gltf_clearcoat_fresnel(n_dot_v);", ""),
           "layers left out of the lights behind": (
               "return valid ? value * gltf_transmission_layers(f, wo, n_dot_v, n_dot_l) : vec3(0.0);",
               "return valid ? value : vec3(0.0);")}


#: errors planted where the layers need a material of their own: (old, new, the material's extra keywords)
PLANTED_ON = {"coat on the shading normal": ("gltf_clearcoat_fresnel(max(dot(gltf_clearcoat_normal(f), wo), 0.0))",
                                             "gltf_clearcoat_fresnel(max(dot(f.n, wo), 0.0))",
                                             COAT_NORMALS["coat normal over a normal map"]),
              "film's weight ignored": ("fresnel = mix(fresnel, film, u_gltf_pbr_iridescence);", "fresnel = film;",
                                        FILM),
              "film on the core's f0, not the specular's": (
                  "vec3 film_f0 = min(r * r * u_gltf_pbr_specular_color, vec3(1.0)) * u_gltf_pbr_specular;",
                  "vec3 film_f0 = vec3(r * r);", FILM)}


@pytest.mark.parametrize("planted", sorted(PLANTED) + sorted(PLANTED_ON))
def test_planted_layer_errors_fail_verify(planted, monkeypatch, glphong_make_renderer, lights_behind_scene):
    """Each planted error in transmission_thin.glsl (or the functions it shares with gltf_pbr.glsl) fails verify: the layers' on the layered glass, the coat's F_c on
    n instead of its own n_c over a normal-mapped glass, the film's over a filmed one."""
    old, new, extra = PLANTED[planted] + ({},) if planted in PLANTED else PLANTED_ON[planted]
    original, model = assembly.chunk_source, assembly.model_source
    source = model(gltf_pbr.GltfPBR)  # gltf_transmission_fresnel and _layers are in gltf_pbr.glsl (diffuse's too)
    in_thin = original("transmission_thin").count(old)
    assert in_thin == 1 or (in_thin == 0 and source[0].count(old) == 1)
    monkeypatch.setattr(assembly, "chunk_source", lambda name: original(name).replace(old, new)
                        if name == "transmission_thin" else original(name))
    if not in_thin:
        monkeypatch.setattr(assembly, "model_source", lambda cls: (source[0].replace(old, new),) + tuple(source[1:])
                            if cls is gltf_pbr.GltfPBR else model(cls))
    roughness = 0.3 if planted in PLANTED else 0.0  # the background's band of a rough lookup would hide the coat's
    scene = lights_behind_scene(SPHERE, glphong.GltfPBR((0.9, 0.8, 0.6), 0.1, roughness, **GLASS, **extra))
    report = glphong.verify(scene, glphong_make_renderer(48, 40, "egl"))
    assert not report.passed and report.outside_count > 0, report.summary()


def sheen_albedo(cos, roughness):
    """E of the shipped table (17 rows of sheenRoughness j/16 by 33 columns of cos = (i/32)^2), bilinear in sqrt(cos)
    and the roughness, as the table's own docstring states (written here, not glphong's lookup)."""
    table = np.asarray(SHEEN_ALBEDO, np.float64)
    u = np.sqrt(np.clip(cos, 0.0, 1.0)) * 32.0
    w = np.clip(roughness, 0.0, 1.0) * 16.0
    i, j = np.minimum(np.floor(u).astype(int), 31), min(int(np.floor(w)), 15)
    s, t = u - i, w - j
    row = lambda k: table[k, i] * (1.0 - s) + table[k, i + 1] * s  # noqa: E731
    return row(j) * (1.0 - t) + row(j + 1) * t


def test_the_twins_btdf_and_weight_are_the_specifications_at_random_directions():
    """`gltf_transmission_response` and `gltf_transmission_weight` (float64) against the transcription: random views
    and lights behind, KHR_materials_specular's F at v.h' of the mirrored light, the sheen's scaling on E(n.v) and
    E(|n.l|), the coat's F_c at n.v."""
    rng = np.random.default_rng(11)
    count = 200
    n, wo, wi = _views_and_lights_behind(rng, count)
    n_dot_l = -wi[:, 2]
    c, m, t, r, ior = np.array([0.7, 0.5, 0.9]), 0.2, 0.8, 0.4, 1.4
    specular, color, clearcoat = 0.7, np.array([1.0, 3.0, 12.0]), 0.6
    sheen_color, sheen_roughness = np.array([0.3, 0.9, 0.5]), 0.35
    got = gltf_transmission_response(n, wi, wo, n_dot_l, c, m, t, r, ior, (specular, color),
                                     {"clearcoat": clearcoat, "sheen_color": sheen_color,
                                      "sheen_roughness": sheen_roughness})
    n_dot_v, v_dot_h, d, vis = _mirrored_ggx(wi, wo, n_dot_l, r)
    f = np.stack([specular_fresnel(x, ior, specular, color) for x in v_dot_h])
    coat = 1.0 - clearcoat * (0.04 + 0.96 * (1.0 - n_dot_v) ** 5)
    sheen = np.maximum(np.minimum(1.0 - 0.9 * sheen_albedo(n_dot_v, sheen_roughness),
                                  1.0 - 0.9 * sheen_albedo(n_dot_l, sheen_roughness)), 0.0)
    assert np.ptp(sheen_albedo(n_dot_l, sheen_roughness) - sheen_albedo(n_dot_v, sheen_roughness)) > 0.1
    expected = (1.0 - m) * t * c * ((1.0 - f.max(axis=1)) * d * vis * n_dot_l * coat * sheen)[:, None]
    np.testing.assert_allclose(got, expected, rtol=1e-12)
    weight = gltf_transmission_weight(n_dot_v, c, m, t, ior, specular, color)
    f_view = np.stack([specular_fresnel(x, ior, specular, color) for x in n_dot_v])
    np.testing.assert_allclose(weight, (1.0 - m) * t * c * (1.0 - f_view.max(axis=1))[:, None], rtol=1e-12)


def test_every_function_of_the_transmission_chunk_has_a_twin_of_its_name_in_the_models_module():
    """docs/design.md: the numpy twin mirrors the GLSL function by function, with the same names; the model's module
    (glphong.materials.gltf_pbr) re-exports transmission_thin.glsl's twins as it does its own chunk's."""
    names = set(functions(assembly.chunk_source("transmission_thin")))
    assert {"gltf_transmission_sample", "gltf_volume_light", "gltf_transmission_background",
            "gltf_transmission_radiance"} <= names
    shared = {"gltf_transmission_layers", "gltf_transmission_fresnel"}  # in gltf_pbr.glsl: diffuse transmission's too
    assert shared <= set(functions(assembly.model_source(gltf_pbr.GltfPBR)[0])) and not shared & names
    names |= shared
    assert not [name for name in sorted(names) if not callable(getattr(gltf_pbr, name, None))]


def _gltf_file(tmp_path, extensions, images=(), normal=None):
    """A one-quad glTF file whose material carries ``extensions`` (the extension tests' writer)."""
    spec = importlib.util.spec_from_file_location("_gltf_extension_tests", pathlib.Path(__file__).parent / "materials"
                                                  / "test_gltf_extensions.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module._gltf(tmp_path, extensions, normal=normal, images=list(images) or None)


def test_files_keep_specular_sheen_and_coat_over_transmission_with_the_coats_own_normal(tmp_path):
    layers = {"KHR_materials_transmission": {"transmissionFactor": 0.9},
              "KHR_materials_specular": {"specularFactor": 0.6, "specularColorFactor": [1.0, 2.0, 0.5]},
              "KHR_materials_sheen": {"sheenColorFactor": [0.5, 0.4, 0.3], "sheenRoughnessFactor": 0.7},
              "KHR_materials_clearcoat": {"clearcoatFactor": 0.8}}
    path = _gltf_file(tmp_path, layers)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # applied: no warning
        scene = glphong.load_scene(path, light_units="radiometric", lights=[])
    assert scene.objects[0].material.extensions() == ("specular", "clearcoat", "sheen", "transmission")
    out = tmp_path / "saved.gltf"
    glphong.save_gltf(scene, out)
    written = json.loads(out.read_text())["materials"][0]["extensions"]
    assert set(layers) <= set(written) and written["KHR_materials_specular"]["specularFactor"] == 0.6
    again = glphong.load_scene(out, light_units="radiometric", lights=[]).objects[0].material
    assert again.extensions() == ("specular", "clearcoat", "sheen", "transmission")
    rgba = np.random.default_rng(2).integers(0, 256, (8, 8, 4), dtype=np.uint8)
    own = layers | {"KHR_materials_clearcoat": {"clearcoatFactor": 0.8, "clearcoatNormalTexture": {"index": 0}}}
    with_coat_normal = ("specular", "clearcoat", "clearcoat_normal", "sheen", "transmission")
    for extensions, normal in ((own, None), (own, 0), (layers, 0)):  # the coat's own normal, over a normalTexture too
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # the coat on its own normal (the unperturbed one without a texture): drawn
            material = glphong.load_scene(_gltf_file(tmp_path, extensions, [rgba], normal=normal),
                                          light_units="radiometric", lights=[]).objects[0].material
        assert material.extensions() == with_coat_normal and "unperturbed" in material.needs
        assert (material.normal_map is not None) == (normal is not None)
        assert (getattr(material.clearcoat_normal, "texture", None) is not None) == (extensions is own)
