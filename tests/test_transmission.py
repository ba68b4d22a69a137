"""KHR_materials_transmission (thin walls) over the opaque scene (glphong.gpu.transmission, docs/transmission.md).

Independent checks: an orthographic camera looks down -z at a transmissive quad (normal +z) over a Lambert plane,
under a directional light travelling along -z, so ``n.l = n.v = n.h = v.h = 1`` everywhere on the quad and the
specification's formulas reduce to closed forms written here: Schlick's ``F = f0 = ((ior - 1)/(ior + 1))^2``,
the diffuse ``(1 - F)(1 - t) c / pi E``, what is transmitted ``(1 - F) t c L_behind`` with ``L_behind = k_d E`` (the
Lambert plane), times ``1 - m``, and for roughness ``r`` Appendix B's specular peak ``((1 - m) F + m c) D V (n.l) E``
with ``D = 1/(pi alpha^2)``, ``V = 1/4`` (``alpha = r^2``).  The filtered lookup of a uniform background is that background.
"""
import json
import warnings

import numpy as np
import pytest

import glphong
from glphong import primitives
from glphong.checks.transmission_twin import background_lookup
from glphong.materials.gltf_transmission import background_levels, gltf_volume_ray
from glphong.scene.geometry import MeshData
from glphong.shaders.assembly import assemble, effective_source

SIZE = 32  # px; the view spans [-1, 1] m
E = 2.0  # W/m^2, the directional light's irradiance
K_D = 0.6  # the Lambert plane's k_d [1/sr]: L_behind = k_d E


def _scene(glass, light=None, background=True, side=1.0):
    camera = glphong.OrthographicCamera.look_at((0.0, 0.0, 5.0), (0.0, 0.0, 0.0), ymag=1.0)
    scene = glphong.Scene(camera, [light or glphong.DirectionalLight((0.0, 0.0, -1.0), E)])
    if background:
        scene.add(primitives.plane(4.0), glphong.Lambert(K_D), name="floor")
    if glass is not None:
        pose = np.eye(4)
        pose[2, 3] = 0.5
        scene.add(primitives.plane(side), glass, pose=pose, name="glass")
    return scene


def _closed_form(c, m, t, ior, roughness=0.0):
    """The quad's radiance at normal view and light (module docstring), (3,)."""
    c = np.asarray(c, float)
    f0 = ((ior - 1.0) / (ior + 1.0)) ** 2
    diffuse = (1.0 - f0) * (1.0 - t) * c / np.pi * E
    transmitted = (1.0 - f0) * t * c * K_D * E
    alpha = roughness ** 2
    lobe = E / (4.0 * np.pi * alpha ** 2) if roughness > 0 else 0.0  # D V (n.l) E at the peak
    return (1.0 - m) * (diffuse + transmitted + f0 * lobe) + m * c * lobe  # the metal's Fresnel is c at v.h = 1


@pytest.mark.parametrize("c, m, t, ior", [((0.8, 0.9, 1.0), 0.0, 1.0, 1.5), ((0.3, 0.6, 0.9), 0.3, 0.6, 2.0),
                                          ((1.0, 1.0, 1.0), 0.0, 0.25, 1.0)])
def test_a_thin_quad_of_roughness_0_transmits_the_closed_form(c, m, t, ior, glphong_backend, glphong_make_renderer):
    renderer = glphong_make_renderer(SIZE, SIZE, glphong_backend)
    scene = _scene(glphong.GltfPBR(c, m, 0.0, ior=ior, transmission=t))
    frame = renderer.render(scene)
    inner = frame.radiance[SIZE // 2 - 6:SIZE // 2 + 6, SIZE // 2 - 6:SIZE // 2 + 6].reshape(-1, 3)
    np.testing.assert_allclose(inner, np.broadcast_to(_closed_form(c, m, t, ior), inner.shape), rtol=2e-6, atol=1e-7)
    report = glphong.verify(scene, renderer)
    assert report.passed, report.summary()
    assert report.transmission.pixels.sum() == (SIZE // 2) ** 2 and not report.transmission.rough.any()


@pytest.mark.parametrize("roughness", [0.3, 1.0])
def test_rough_transmission_of_a_uniform_background_is_the_closed_form(roughness, glphong_backend,
                                                                       glphong_make_renderer):
    renderer = glphong_make_renderer(SIZE, SIZE, glphong_backend)
    c = (0.7, 0.8, 0.9)
    scene = _scene(glphong.GltfPBR(c, 0.0, roughness, transmission=0.8))
    frame = renderer.render(scene)
    inner = frame.radiance[SIZE // 2 - 6:SIZE // 2 + 6, SIZE // 2 - 6:SIZE // 2 + 6].reshape(-1, 3)
    np.testing.assert_allclose(inner, np.broadcast_to(_closed_form(c, 0.0, 0.8, 1.5, roughness), inner.shape),
                               rtol=2e-6)
    report = glphong.verify(scene, renderer)
    assert report.passed and report.transmission.rough.sum() == (SIZE // 2) ** 2, report.summary()


@pytest.mark.parametrize("roughness", [0.0, 0.3, 1.0])
def test_a_light_behind_the_surface_shines_through_its_lobe(roughness, glphong_backend, glphong_make_renderer):
    """A directional light travelling +z, behind the quad: mirrored through the surface it arrives along the view,
    so ``h = n``, ``v.h = 1`` and the BTDF is ``(1 - m) t c (1 - f0) D V`` with ``D = 1/(pi alpha^2)``, ``V = 1/4``,
    times ``E_behind`` (0 at roughness 0: a delta); the floor below faces away from it."""
    renderer = glphong_make_renderer(SIZE, SIZE, glphong_backend)
    c, m, t, behind = (0.7, 0.8, 0.9), 0.2, 0.8, 0.5
    scene = _scene(glphong.GltfPBR(c, m, roughness, transmission=t))
    scene.add_light(glphong.DirectionalLight((0.0, 0.0, 1.0), behind))
    frame = renderer.render(scene)
    inner = frame.radiance[SIZE // 2 - 6:SIZE // 2 + 6, SIZE // 2 - 6:SIZE // 2 + 6].reshape(-1, 3)
    through = (1.0 - m) * t * np.asarray(c) * 0.96 / (4.0 * np.pi * roughness ** 4) * behind if roughness else 0.0
    expected = _closed_form(c, m, t, 1.5, roughness) + through
    np.testing.assert_allclose(inner, np.broadcast_to(expected, inner.shape), rtol=5e-6)
    report = glphong.verify(scene, renderer)
    assert report.passed, report.summary()


def _quad_glass(roughness):
    """A glass quad of 1.5 m at ``roughness`` and its material, for the `lights_behind_scene` fixture."""
    return primitives.plane(1.5, segments=4), glphong.GltfPBR((0.9, 0.8, 0.6), 0.2, roughness, transmission=0.9)


@pytest.mark.parametrize("roughness", [0.05, 0.3, 0.8])
def test_point_spot_and_directional_lights_behind_verify(roughness, glphong_backend, glphong_make_renderer,
                                                         lights_behind_scene):
    renderer = glphong_make_renderer(48, 40, glphong_backend)
    report = glphong.verify(lights_behind_scene(*_quad_glass(roughness)), renderer)
    assert report.passed and report.transmission.pixels.sum() > 700, report.summary()


@pytest.mark.parametrize("roughness", [0.0, 0.2, 0.6])
def test_a_glass_sphere_over_a_lit_floor_verifies(roughness, glphong_backend, glphong_make_renderer):
    """Perspective view, a point and a spot light, a two-sided closed mesh: the nearest face transmits the floor."""
    camera = glphong.PerspectiveCamera.look_at((0.4, -2.0, 1.6), (0.0, 0.0, 0.2))
    scene = glphong.Scene(camera, [glphong.PointLight((1.0, -1.0, 2.0), 40.0),
                                   glphong.SpotLight((-1.0, 0.0, 2.0), (0.5, 0.0, -1.0), 3.0)])
    rng = np.random.default_rng(3)
    floor = primitives.plane(3.0, segments=8)
    colours = rng.uniform(0.1, 1.0, (len(floor.positions), 3))
    scene.add(MeshData(floor.positions, floor.normals, floor.indices, colors=colours),
              glphong.Lambert(glphong.VertexColors(0.5)), name="floor")
    pose = np.eye(4)
    pose[2, 3] = 0.4
    scene.add(primitives.sphere(3, 0.4), glphong.GltfPBR((0.9, 0.8, 0.6), 0.1, roughness, ior=1.4, transmission=0.9),
              pose=pose, name="glass")
    report = glphong.verify(scene, glphong_make_renderer(48, 40, glphong_backend))
    assert report.passed and report.transmission.pixels.sum() > 200, report.summary()


@pytest.mark.parametrize("distance, colour", [(0.5, (0.9, 0.5, 0.2)), (float(np.finfo(np.float32).max),
                                                                      (0.1, 0.1, 0.1))])
def test_a_volume_slab_attenuates_by_beer_lambert(distance, colour, glphong_backend, glphong_make_renderer):
    """Normal incidence: the refracted ray goes straight down, through ``thickness`` times the node's z scale (2), and
    its exit projects onto the pixel itself; the background is uniform.  ``L_t = (1 - F) t c a^(2 T / d) L_behind``;
    FLT_MAX, the specification's infinite distance, attenuates nothing."""
    renderer = glphong_make_renderer(SIZE, SIZE, glphong_backend)
    c, t, thickness = (0.8, 0.9, 1.0), 0.9, 0.15
    glass = glphong.GltfPBR(c, 0.0, 0.0, transmission=t, thickness=thickness, attenuation_color=colour,
                            attenuation_distance=distance)
    assert glass.extensions() == ("transmission", "volume")
    scene = _scene(None)
    pose = np.diag([1.0, 1.0, 2.0, 1.0])
    pose[2, 3] = 0.5
    scene.add(primitives.plane(1.0), glass, pose=pose, name="glass")
    frame = renderer.render(scene)
    inner = frame.radiance[SIZE // 2 - 6:SIZE // 2 + 6, SIZE // 2 - 6:SIZE // 2 + 6].reshape(-1, 3)
    through = np.asarray(colour) ** (2.0 * thickness / distance) if distance < 1e30 else np.ones(3)
    f0 = 0.04
    expected = (1.0 - f0) * np.asarray(c) * ((1.0 - t) * E / np.pi + t * through * K_D * E)
    np.testing.assert_allclose(inner, np.broadcast_to(expected, inner.shape), rtol=5e-6)
    report = glphong.verify(scene, renderer)
    assert report.passed and report.transmission.pixels.sum() == (SIZE // 2) ** 2, report.summary()


@pytest.mark.parametrize("roughness, dispersion", [(0.0, 0.0), (0.0, 20.0), (0.4, 1.0)])
def test_a_glass_volume_refracts_and_disperses_and_verifies(roughness, dispersion, glphong_backend,
                                                            glphong_make_renderer):
    glass = glphong.GltfPBR((0.9, 0.8, 0.6), 0.0, roughness, ior=1.5, transmission=0.9, thickness=0.3,
                            attenuation_color=(0.9, 0.5, 0.3), attenuation_distance=0.5, dispersion=dispersion)
    scene = _sphere_scene(glass, scale=1.5)
    report = glphong.verify(scene, glphong_make_renderer(48, 40, glphong_backend))
    assert report.passed and report.transmission.pixels.sum() > 400, report.summary()
    if dispersion and not roughness:  # the channels see different places: a grey floor turns coloured
        grey = _sphere_scene(glphong.GltfPBR(1.0, 0.0, 0.0, transmission=1.0, thickness=0.3, dispersion=dispersion),
                             scale=1.5, grey=True)
        out = glphong.verify(grey, glphong_make_renderer(48, 40, glphong_backend)).gpu[report.transmission.pixels]
        assert np.max(np.abs(out[:, 0] - out[:, 2])) > 1e-2



def test_a_dispersion_past_glass_keeps_the_red_ior_at_1_and_verifies(glphong_backend, glphong_make_renderer):
    """dispersion 60 at ior 1.5 puts the red channel's ``ior - (ior - 1) 0.025 dispersion`` at 0.75: kept at 1 (no
    total internal reflection, no NaN at the sphere's grazing rim), on the GPU and in the twin."""
    glass = glphong.GltfPBR((0.9, 0.8, 0.6), 0.0, 0.0, ior=1.5, transmission=0.9, thickness=0.3, dispersion=60.0)
    report = glphong.verify(_sphere_scene(glass, scale=1.5), glphong_make_renderer(48, 40, glphong_backend))
    assert report.passed and np.isfinite(report.gpu).all() and report.transmission.pixels.sum() > 400, report.summary()


@pytest.mark.parametrize("extension", ["transmission", "diffuse_transmission"])
def test_lights_behind_a_wall_of_ior_1e4_verify(extension, glphong_backend, glphong_make_renderer,
                                                lights_behind_scene):
    """At ior 1e4 ``1 - F`` cancels in float32 (``f0`` within 4e-4 of 1): the lights behind get that rounding in their
    band, as the background's weight has it (it failed by 8.2e-5 relative before)."""
    wall = glphong.GltfPBR((0.9, 0.8, 0.6), 0.2, 0.3, ior=1e4, **{extension: 0.9})
    renderer = glphong_make_renderer(48, 40, glphong_backend)
    report = glphong.verify(lights_behind_scene(primitives.plane(1.5, segments=4), wall), renderer)
    assert report.passed and report.transmission.pixels.sum() > 700, report.summary()

def _sphere_scene(glass, scale=1.0, grey=False):
    """A perspective view of a glass sphere over a floor of random vertex colours (grey ones with ``grey``)."""
    camera = glphong.PerspectiveCamera.look_at((0.4, -2.0, 1.6), (0.0, 0.0, 0.2))
    scene = glphong.Scene(camera, [glphong.PointLight((1.0, -1.0, 2.0), 40.0)])
    floor = primitives.plane(3.0, segments=8)
    colours = np.random.default_rng(3).uniform(0.1, 1.0, (len(floor.positions), 3))
    colours = colours[:, :1].repeat(3, axis=1) if grey else colours
    scene.add(MeshData(floor.positions, floor.normals, floor.indices, colors=colours),
              glphong.Lambert(glphong.VertexColors(0.5)), name="floor")
    pose = np.diag([scale, scale, scale, 1.0])
    pose[2, 3] = 0.4
    scene.add(primitives.sphere(3, 0.4), glass, pose=pose, name="glass")
    return scene


def test_a_textured_transmission_verifies(glphong_backend, glphong_make_renderer):
    image = np.linspace(0.0, 1.0, 64).reshape(8, 8, 1) * np.ones((1, 1, 3))
    glass = glphong.GltfPBR((0.8, 0.9, 1.0), 0.0, 0.0, transmission=glphong.Texture(image, 0.9, srgb=False,
                                                                                     channel="r"))
    report = glphong.verify(_scene(glass), glphong_make_renderer(SIZE, SIZE, glphong_backend))
    assert report.passed and report.transmission.pixels.sum() == (SIZE // 2) ** 2, report.summary()
    block = glphong.GltfPBR((0.8, 0.9, 1.0), 0.0, 0.1, transmission=1.0, attenuation_color=(0.5, 0.7, 0.9),
                            thickness=glphong.Texture(image, 0.4, srgb=False, channel="g"), attenuation_distance=0.3)
    scene = _sphere_scene(block, scale=1.5)
    sphere = scene.objects[1].mesh
    uvs = 0.5 + 0.5 * sphere.positions[:, :2] / np.abs(sphere.positions).max()
    textured = glphong.Scene(scene.camera, scene.lights)
    textured.add(scene.objects[0].mesh, scene.objects[0].material, name="floor")
    textured.add(MeshData(sphere.positions, sphere.normals, sphere.indices, uvs=uvs), block, pose=scene.objects[1].pose,
                 name="glass")
    report = glphong.verify(textured, glphong_make_renderer(48, 40, glphong_backend))
    assert report.passed and report.transmission.pixels.sum() > 400, report.summary()


def test_the_opaque_scene_is_drawn_as_without_the_transmissive_objects(glphong_make_renderer):
    """Bit for bit outside the transmissive pixels; an opaque GltfPBR's program holds none of the transmission."""
    renderer = glphong_make_renderer(SIZE, SIZE, "egl")
    with_glass = _scene(glphong.GltfPBR((0.8, 0.9, 1.0), 0.0, 0.2, transmission=1.0))
    alone = _scene(None)
    glass = renderer.render(with_glass, passes=("radiance", "instance"))
    outside = glass.instance != with_glass.objects[1].instance_id
    assert outside.sum() == SIZE * SIZE - (SIZE // 2) ** 2
    np.testing.assert_array_equal(glass.radiance[outside], renderer.render(alone).radiance[outside])
    opaque = _scene(glphong.GltfPBR((0.8, 0.9, 1.0), 0.0, 0.2))

    def source(scene):
        key = renderer.program_key(scene, scene.objects[1])
        return effective_source(assemble(key.fragment_chunks(), key.defines(), key.generated_chunks(),
                                         key.extensions()))

    declared = ("uniform float u_gltf_pbr_transmission;", "uniform float u_gltf_pbr_diffuse_transmission;",
                "uniform vec3 u_gltf_pbr_diffuse_transmission_color;")  # the model's params, unread
    text = source(opaque)
    for line in declared:
        text = text.replace(line, "")
    assert "transmission" not in text
    assert "gltf_transmission_radiance" in source(with_glass)


def test_the_pyramid_and_its_lookup_against_closed_forms():
    """2x2 box means of a linear ramp are the ramp at the blocks' centres, so the trilinear lookup of the pyramid is
    the ramp wherever its footprint stays inside the image; of a constant, the constant."""
    height, width = 32, 64
    x = (np.arange(width) + 0.5) / width
    y = (np.arange(height) + 0.5) / height
    ramp = (2.0 * x[None, :] + 3.0 * y[:, None])[..., None] * np.ones(3)
    levels = background_levels(ramp)
    assert [level.shape[:2] for level in levels] == [(32, 64), (16, 32), (8, 16), (4, 8), (2, 4), (1, 2), (1, 1)]
    uv = np.array([[0.5, 0.5], [0.45, 0.55], [0.6, 0.4]])
    for lod in (0.0, 0.5, 1.0, 2.7):
        value, low, high = background_lookup(levels, uv, np.full(len(uv), lod))
        np.testing.assert_allclose(value[:, 0], 2.0 * uv[:, 0] + 3.0 * uv[:, 1], rtol=1e-12)
        assert np.all(low <= value) and np.all(value <= high)
    constant = background_levels(np.full((5, 7, 3), 0.25))
    assert [level.shape[:2] for level in constant] == [(5, 7), (2, 3), (1, 1)]
    np.testing.assert_array_equal(background_lookup(constant, uv, np.array([0.3, 1.5, 9.0]))[0], 0.25)


PLANTED = {"Fresnel on the complement of n.v": ("gltf_transmission_fresnel(ior, dot(n, wo))",
                                                "gltf_transmission_fresnel(ior, 1.0 - dot(n, wo))"),
           "background without base colour": ("return c * ((1.0 - m) * t *", "return vec3((1.0 - m) * t *"),
           "lod from alpha": ("return u_transmission_levels * roughness *",
                              "return u_transmission_levels * roughness * roughness *")}
PLANTED_VOLUME = {"refraction ratio inverted": ("refract(-wo, n, 1.0 / eta)", "refract(-wo, n, eta)"),
                  "attenuation exponent inverted": ("vec3(d / attenuation.w)", "vec3(attenuation.w / d)"),
                  "node scale left out": ("thickness * scale;", "thickness;"),
                  "dispersion's sign": ("vec3 behind = vec3(gltf_volume_light(x, n, wo, max(ior - half_spread, 1.0)",
                                        "vec3 behind = vec3(gltf_volume_light(x, n, wo, max(ior + half_spread, 1.0)")}
PLANTED_LIGHTS = {"the light not mirrored": ("vec3 mirrored = wi + (2.0 * n_dot_l) * f.n;",
                                             "vec3 mirrored = -wi;"),
                  "Fresnel for 1 - Fresnel": ("* u_gltf_pbr_transmission * (1.0 - fresnel_max)",
                                              "* u_gltf_pbr_transmission * fresnel_max"),
                  "alpha unsquared": ("float alpha = u_gltf_pbr_roughness * u_gltf_pbr_roughness;\n    float lobe",
                                      "float alpha = u_gltf_pbr_roughness;\n    float lobe")}


@pytest.mark.parametrize("planted", sorted(PLANTED_LIGHTS))
def test_planted_light_errors_fail(planted, monkeypatch, glphong_make_renderer, lights_behind_scene):
    _plant(*PLANTED_LIGHTS[planted], monkeypatch)
    report = glphong.verify(lights_behind_scene(*_quad_glass(0.3)), glphong_make_renderer(48, 40, "egl"))
    assert not report.passed and report.outside_count > 0, report.summary()


def _plant(old, new, monkeypatch):
    from glphong.shaders import assembly

    original = assembly.chunk_source
    assert old in original("transmission_thin")
    monkeypatch.setattr(assembly, "chunk_source", lambda name: original(name).replace(old, new)
                        if name == "transmission_thin" else original(name))


@pytest.mark.parametrize("planted", sorted(PLANTED_VOLUME))
def test_planted_volume_errors_fail(planted, monkeypatch, glphong_make_renderer):
    _plant(*PLANTED_VOLUME[planted], monkeypatch)
    glass = glphong.GltfPBR((0.9, 0.8, 0.6), 0.0, 0.0, transmission=1.0, thickness=0.3, attenuation_color=(0.9, 0.5, 0.3),
                            attenuation_distance=0.5, dispersion=20.0)
    report = glphong.verify(_sphere_scene(glass, scale=1.5), glphong_make_renderer(48, 40, "egl"))
    assert not report.passed and report.outside_count > 0, report.summary()


@pytest.mark.parametrize("planted", sorted(PLANTED))
def test_planted_errors_fail(planted, monkeypatch, glphong_make_renderer):
    from glphong.shaders import assembly

    old, new = PLANTED[planted]
    original = assembly.chunk_source
    assert old in original("transmission_thin")
    monkeypatch.setattr(assembly, "chunk_source", lambda name: original(name).replace(old, new)
                        if name == "transmission_thin" else original(name))
    camera = glphong.PerspectiveCamera.look_at((0.0, -1.5, 2.0), (0.0, 0.0, 0.3))
    rng = np.random.default_rng(5)
    floor = primitives.plane(3.0, segments=8)
    scene = glphong.Scene(camera, [glphong.PointLight((1.0, -1.0, 2.0), 40.0)])
    scene.add(MeshData(floor.positions, floor.normals, floor.indices,
                               colors=rng.uniform(0.1, 1.0, (len(floor.positions), 3))),
              glphong.Lambert(glphong.VertexColors(0.5)))
    pose = np.eye(4)
    pose[2, 3] = 0.3
    scene.add(primitives.sphere(3, 0.5), glphong.GltfPBR((0.9, 0.5, 0.3), 0.0, 0.3, transmission=1.0), pose=pose)
    report = glphong.verify(scene, glphong_make_renderer(40, 40, "egl"))
    assert not report.passed and report.outside_count > 0, report.summary()


def test_options_that_cannot_draw_it_are_refused_by_name(glphong_make_renderer):
    glass = glphong.GltfPBR(0.9, 0.0, 0.0, transmission=1.0)
    scene = _scene(glass)
    for options, pattern in (({"samples": 2}, "samples=2"), ({"shading": "vertex"}, "shading='vertex'"),
                             ({"specialise": False}, "specialise=False")):
        with pytest.raises(ValueError, match=rf"'glass' is transmissive .* {pattern}"):
            glphong_make_renderer(SIZE, SIZE, "egl", **options).render(scene)
    renderer = glphong_make_renderer(SIZE, SIZE, "egl")
    blended = _scene(glass)  # drawn with a blended object beside it (tests/test_transmission_blend.py)
    blended.add(primitives.plane(1.0), glphong.Lambert(0.5, alpha_blend=glphong.AlphaBlend(0.5)))
    assert renderer.render(blended).blend_layers == 1
    assert renderer.render(_no_light(glass), passes=("depth",)).depth.max() > 0  # (no light: test_transmission_pass)
    for light in (glphong.RectLight((0.0, 0.0, -1.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), radiance=1.0),
                  glphong.EnvironmentLight(np.ones((4, 8)))):  # transmitted through their samples (issue 41)
        assert np.isfinite(renderer.render(_scene(glass, light)).radiance).all()  # test_transmission_extended.py
    with pytest.raises(ValueError, match="exact=True"):
        glphong.verify(scene, renderer, exact=True)
    shadowed = _scene(glass, glphong.DirectionalLight((0.0, 0.0, -1.0), E, shadows=True))
    report = glphong.verify(shadowed, renderer)  # twinned (tests/test_transmission_shadows.py): the floor behind the
    inner = slice(SIZE // 2 - 6, SIZE // 2 + 6)  # glass lies in the glass's own full shadow, as the GPU's maps hold it
    assert report.passed and not report.transmission.transmitted[inner, inner].any(), report.summary()


def _no_light(glass):
    scene = glphong.Scene(glphong.OrthographicCamera.look_at((0.0, 0.0, 5.0), (0.0, 0.0, 0.0)))
    scene.add(primitives.plane(1.0), glass, name="glass")
    return scene


def _gltf_file(tmp_path, extensions, images=()):
    """A one-quad glTF file whose material carries ``extensions`` (the extension tests' writer)."""
    import importlib.util
    import pathlib

    spec = importlib.util.spec_from_file_location("_gltf_extension_tests", pathlib.Path(__file__).parent / "materials"
                                                  / "test_gltf_extensions.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module._gltf(tmp_path, extensions, images=list(images) or None)


def test_files_load_with_their_texture_and_save_back(tmp_path):
    rgba = np.random.default_rng(2).integers(0, 256, (8, 8, 4), dtype=np.uint8)
    path = _gltf_file(tmp_path, {"KHR_materials_transmission": {"transmissionFactor": 0.8,
                                                                 "transmissionTexture": {"index": 0}}}, [rgba])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # applied: no warning
        material = glphong.load_scene(path, light_units="radiometric", lights=[]).objects[0].material
    assert material.extensions() == ("transmission",)
    assert material.transmission.scale == 0.8 and material.transmission.channel == "r"
    np.testing.assert_allclose(material.transmission.texture.levels[0][::-1, :, 0], rgba[..., 0] / 255.0, atol=2e-3)
    out = tmp_path / "saved.gltf"
    glphong.save_gltf(glphong.load_scene(path, light_units="radiometric", lights=[]), out)
    written = json.loads(out.read_text())["materials"][0]["extensions"]["KHR_materials_transmission"]
    assert written["transmissionFactor"] == 0.8 and "transmissionTexture" in written
    again = glphong.load_scene(out, light_units="radiometric", lights=[]).objects[0].material
    assert again.extensions() == ("transmission",) and again.transmission.scale == 0.8


def test_files_without_transmission_and_bad_factors(tmp_path):
    path = _gltf_file(tmp_path, {"KHR_materials_transmission": {}})
    assert glphong.load_scene(path, light_units="radiometric", lights=[]).objects[0].material.extensions() == ()
    for bad, field in (({"transmissionFactor": 1.5}, "transmissionFactor"),
                       ({"transmissionFactor": "a"}, "transmissionFactor"),
                       ({"transmissionTexture": {"index": 4}}, "transmissionTexture")):
        path = _gltf_file(tmp_path, {"KHR_materials_transmission": bad})
        with pytest.raises(glphong.filesafety.SceneFileError,
                           match=rf"materials\[0\]\.extensions\.KHR_materials_transmission\.{field}"):
            glphong.load_scene(path, light_units="radiometric", lights=[])


def test_every_layer_over_either_transmission_is_kept_and_loaded_from_files(tmp_path):
    """Diffuse transmission takes the coat, sheen, specular and film (tests/materials/
    test_gltf_diffuse_transmission_layers.py), and a file's surface loads with them, without a warning.  Over
    KHR_materials_transmission every layer is drawn (tests/test_transmission_layers.py): the specular, sheen, coat
    (on its own normal too) and film; a file's glass keeps them, without a warning."""
    for layer, keywords in (("clearcoat", {"clearcoat": 1.0}), ("sheen", {"sheen_color": 0.5}),
                            ("specular", {"specular": 0.5}), ("iridescence", {"iridescence": 1.0})):
        assert layer in glphong.GltfPBR(0.5, 0.0, 0.2, diffuse_transmission=0.5, **keywords).extensions()
        assert layer in glphong.GltfPBR(0.5, 0.0, 0.2, transmission=0.5, **keywords).extensions()
    assert "clearcoat_normal" in glphong.GltfPBR(0.5, 0.0, 0.2, transmission=0.5, clearcoat=1.0,
                                                 clearcoat_normal=(0.7, 0.4, 0.9)).extensions()  # drawn
    layers = {"KHR_materials_clearcoat": {"clearcoatFactor": 1.0},
              "KHR_materials_iridescence": {"iridescenceFactor": 1.0},
              "KHR_materials_specular": {"specularFactor": 0.5}}
    path = _gltf_file(tmp_path, {"KHR_materials_transmission": {"transmissionFactor": 1.0}} | layers)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        material = glphong.load_scene(path, light_units="radiometric", lights=[]).objects[0].material
    assert material.extensions() == ("specular", "clearcoat", "transmission", "iridescence")
    path = _gltf_file(tmp_path, {"KHR_materials_diffuse_transmission": {"diffuseTransmissionFactor": 1.0}} | layers)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        material = glphong.load_scene(path, light_units="radiometric", lights=[]).objects[0].material
    assert material.extensions() == ("specular", "clearcoat", "iridescence", "diffuse_transmission")


def test_volume_and_dispersion_load_from_files_and_save_back(tmp_path):
    rgba = np.random.default_rng(4).integers(0, 256, (8, 8, 4), dtype=np.uint8)
    extensions = {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                  "KHR_materials_volume": {"thicknessFactor": 0.25, "thicknessTexture": {"index": 0},
                                           "attenuationDistance": 0.75, "attenuationColor": [0.9, 0.6, 0.3]},
                  "KHR_materials_dispersion": {"dispersion": 0.4}}
    path = _gltf_file(tmp_path, extensions, [rgba])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # applied: no warning
        material = glphong.load_scene(path, light_units="radiometric", lights=[]).objects[0].material
    assert material.extensions() == ("transmission", "volume", "dispersion")
    assert material.thickness.scale == 0.25 and material.thickness.channel == "g"
    np.testing.assert_allclose(material.thickness.texture.levels[0][::-1, :, 1], rgba[..., 1] / 255.0, atol=2e-3)
    assert material.attenuation_distance == 0.75 and material.dispersion == 0.4
    np.testing.assert_array_equal(material.attenuation_color, [0.9, 0.6, 0.3])
    out = tmp_path / "saved.gltf"
    glphong.save_gltf(glphong.load_scene(path, light_units="radiometric", lights=[]), out)
    written = json.loads(out.read_text())["materials"][0]["extensions"]
    assert written["KHR_materials_volume"]["thicknessFactor"] == 0.25
    assert "thicknessTexture" in written["KHR_materials_volume"]
    assert written["KHR_materials_dispersion"] == {"dispersion": 0.4}
    again = glphong.load_scene(out, light_units="radiometric", lights=[]).objects[0].material
    assert again.extensions() == ("transmission", "volume", "dispersion") and again.attenuation_distance == 0.75
    # no attenuationDistance: the specification's +Infinity, held as FLT_MAX and not written back
    path = _gltf_file(tmp_path, {"KHR_materials_transmission": {"transmissionFactor": 1.0},
                                 "KHR_materials_volume": {"thicknessFactor": 0.5}})
    scene = glphong.load_scene(path, light_units="radiometric", lights=[])
    assert scene.objects[0].material.attenuation_distance == float(np.finfo(np.float32).max)
    glphong.save_gltf(scene, out)
    assert "attenuationDistance" not in json.loads(out.read_text())["materials"][0]["extensions"]["KHR_materials_volume"]


@pytest.mark.parametrize("extension, bad, field", [
    ("KHR_materials_volume", {"thicknessFactor": -1.0}, "thicknessFactor"),
    ("KHR_materials_volume", {"thicknessFactor": 1.0, "attenuationDistance": 0.0}, "attenuationDistance"),
    ("KHR_materials_volume", {"thicknessFactor": 1.0, "attenuationColor": [0.5, 1.5, 0.5]}, r"attenuationColor\[1\]"),
    ("KHR_materials_volume", {"thicknessTexture": {"index": 9}}, "thicknessTexture"),
    ("KHR_materials_dispersion", {"dispersion": -0.5}, "dispersion")])
def test_bad_volumes_are_refused_with_their_json_path(extension, bad, field, tmp_path):
    path = _gltf_file(tmp_path, {"KHR_materials_transmission": {"transmissionFactor": 1.0}, extension: bad})
    with pytest.raises(glphong.filesafety.SceneFileError, match=rf"materials\[0\]\.extensions\.{extension}\.{field}"):
        glphong.load_scene(path, light_units="radiometric", lights=[])


@pytest.mark.parametrize("incidence", [0.0, 30.0, 60.0, 89.0])
def test_the_volume_approximation_falls_short_of_a_slab_by_cos_theta_t(incidence):
    """docs/transmission.md's statement: through a slab of thickness T the true emerging ray is displaced from the
    incident line by T sin(theta_i - theta_t) / cos(theta_t) (Snell's law, written here); the volume's ray ends at
    T sin(theta_i - theta_t) from it."""
    ior, thickness = 1.5, 0.2
    theta_i = np.radians(incidence)
    theta_t = np.arcsin(np.sin(theta_i) / ior)
    wo = np.array([[np.sin(theta_i), 0.0, np.cos(theta_i)]])
    ray = gltf_volume_ray(np.array([[0.0, 0.0, 1.0]]), wo, ior, thickness, np.ones(3))[0]
    incident = -wo[0]
    off_line = np.linalg.norm(ray - (ray @ incident) * incident)
    true = thickness * np.sin(theta_i - theta_t) / np.cos(theta_t)
    assert off_line == pytest.approx(true * np.cos(theta_t), abs=1e-15)
    assert np.linalg.norm(ray) == pytest.approx(thickness)
