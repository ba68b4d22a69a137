"""Point, spot and directional lights behind a volume (KHR_materials_volume, issue 41): the glTF Sample Viewer's
punctual loop (glsl/transmission_thin.glsl's gltf_volume_exit, gltf_volume_exit_attenuation and
gltf_volume_diffuse_attenuation, the loops of glphong.shaders.generated, the twin glphong.checks.transmission_lights).

Independent checks: an orthographic camera looks down -z at a transmissive quad (normal +z, at z = 0.5, its node
scaled ``S = (1, 1, 2)``) with nothing behind it, lit from below only, so ``n.v = 1`` and the refracted ray goes
straight down whatever the ior: the exit point is ``x - T S_z n`` (``T`` the thickness).  A light travelling +z is
mirrored onto the view, ``h' = n``, ``v.h' = 1``, and the specification's thin-wall BTDF is ``(1 - m) t c (1 - f0) D
V (n.l')`` with ``D V (n.l') = 1 / (4 pi r^4)`` (``alpha = r^2``), times ``E`` at the exit point and Beer-Lambert
``a^(T S_z / d)`` (``a`` the attenuation colour, ``d`` its distance).  A directional light's ``E`` is the same
everywhere; a point light of power ``P`` straight below the pixel at distance ``h`` is seen from the exit point at
``h - T S_z``: ``E' = P / (4 pi (h - T S_z)^2)``.  The diffuse transmission's ``(1 - m) (1 - t) dt (c_dt / pi) (1 -
f0) E`` takes the light at the surface itself, times ``a^(T mean(S) / d)`` (the Sample Viewer's
``diffuseTransmissionThickness``).
"""
import numpy as np
import pytest

import glphong
from glphong import primitives
from glphong.materials import gltf_pbr
from glphong.materials.gltf_transmission import (gltf_volume_diffuse_attenuation, gltf_volume_exit,
                                                 gltf_volume_exit_attenuation)
from glphong.shaders import assembly, generated
from glphong.shaders.builders import program_key

SIZE = 32  # px; the view spans [-1, 1] m
PIXEL = (15, 16)  # (row, column): its centre is (X0, X0) on the quad
X0 = 0.03125
SCALE = np.array([1.0, 1.0, 2.0])
C, M, T_, R = np.array([0.7, 0.8, 0.9]), 0.2, 0.8, 0.3
THICKNESS, COLOUR, DISTANCE = 0.15, np.array([0.9, 0.5, 0.2]), 0.4
F0 = 0.04  # ior 1.5


def _scene(glass, light):
    camera = glphong.OrthographicCamera.look_at((0.0, 0.0, 5.0), (0.0, 0.0, 0.0), ymag=1.0)
    scene = glphong.Scene(camera, [light])
    pose = np.diag([*SCALE, 1.0])
    pose[2, 3] = 0.5
    scene.add(primitives.plane(1.0), glass, pose=pose, name="glass")
    return scene


def _glass(volume=True, **extra):
    kw = dict(thickness=THICKNESS, attenuation_color=tuple(COLOUR), attenuation_distance=DISTANCE) if volume else {}
    return glphong.GltfPBR(tuple(C), M, R, transmission=T_, **kw, **extra)


def _btdf_peak():
    """``(1 - m) t c (1 - f0) D V (n.l')`` at ``h' = n`` [1/sr]."""
    return (1.0 - M) * T_ * C * (1.0 - F0) / (4.0 * np.pi * R ** 4)


def test_a_directional_light_behind_a_volume_is_the_thin_walls_times_beer_lambert(glphong_backend,
                                                                                 glphong_make_renderer):
    renderer = glphong_make_renderer(SIZE, SIZE, glphong_backend)
    light = glphong.DirectionalLight((0.0, 0.0, 1.0), 0.5)
    thin, volume = (renderer.render(_scene(_glass(v), light)).radiance[12:20, 12:20].reshape(-1, 3)
                    for v in (False, True))
    attenuation = COLOUR ** (THICKNESS * SCALE[2] / DISTANCE)
    np.testing.assert_allclose(thin, np.broadcast_to(_btdf_peak() * 0.5, thin.shape), rtol=5e-6)
    np.testing.assert_allclose(volume, thin * attenuation, rtol=5e-6)
    report = glphong.verify(_scene(_glass(), light), renderer)
    assert report.passed and report.transmission.pixels.sum() > 200, report.summary()


def test_a_point_light_behind_a_volume_is_seen_from_the_exit_point(glphong_backend, glphong_make_renderer):
    """The point light 0.4 m below the pixel: 0.1 m below the exit point (T S_z = 0.3 m), E' 16 times E; the
    diffuse transmission (dt 0.6, its colour c_dt) takes E at the surface and the thickness's mean path."""
    renderer = glphong_make_renderer(SIZE, SIZE, glphong_backend)
    power, height = 0.3, 0.4
    light = glphong.PointLight((X0, X0, 0.5 - height), power)
    dt, c_dt = 0.6, np.array([1.0, 0.9, 0.5])
    glass = _glass(diffuse_transmission=dt, diffuse_transmission_color=tuple(c_dt))
    pixel = renderer.render(_scene(glass, light)).radiance[PIXEL]
    irradiance = power / (4.0 * np.pi * height ** 2)
    exit_irradiance = power / (4.0 * np.pi * (height - THICKNESS * SCALE[2]) ** 2)
    through = _btdf_peak() * exit_irradiance * COLOUR ** (THICKNESS * SCALE[2] / DISTANCE)
    diffuse = (1.0 - M) * (1.0 - T_) * dt * c_dt / np.pi * (1.0 - F0) * irradiance \
        * COLOUR ** (THICKNESS * SCALE.mean() / DISTANCE)
    np.testing.assert_allclose(pixel, through + diffuse, rtol=5e-6)
    report = glphong.verify(_scene(glass, light), renderer)
    assert report.passed, report.summary()


def test_the_twins_exit_and_attenuations_against_snells_law():
    """Oblique incidence (Snell: sin theta_t = sin theta_i / ior), a node scaled by 1.5 on every axis: the exit is
    the refracted direction times T 1.5, the attenuations a^(1.5 T / d) for both (the mean of a uniform scale)."""
    theta_i, ior, thickness, scale = np.radians(50.0), 1.4, 0.2, np.full(3, 1.5)
    n = np.array([[0.0, 0.0, 1.0]])
    wo = np.array([[np.sin(theta_i), 0.0, np.cos(theta_i)]])
    theta_t = np.arcsin(np.sin(theta_i) / ior)
    expected = thickness * 1.5 * np.array([-np.sin(theta_t), 0.0, -np.cos(theta_t)])
    np.testing.assert_allclose(gltf_volume_exit(n, wo, ior, thickness, scale)[0], expected, rtol=1e-13, atol=1e-15)
    for value in (gltf_volume_exit_attenuation(n, wo, ior, thickness, scale, COLOUR, DISTANCE),
                  gltf_volume_diffuse_attenuation(np.array([thickness]), scale, COLOUR, DISTANCE)):
        np.testing.assert_allclose(value[0], COLOUR ** (1.5 * thickness / DISTANCE), rtol=1e-13)
    assert np.allclose(gltf_volume_diffuse_attenuation(np.array([thickness]), SCALE, COLOUR, DISTANCE),
                       COLOUR ** (thickness * 4.0 / 3.0 / DISTANCE), rtol=1e-13)


@pytest.mark.parametrize("extra", [{}, {"diffuse_transmission": 0.5, "roughness": 0.6},
                                   {"dispersion": 0.5, "roughness": 0.05}])
def test_a_volume_sphere_lit_from_behind_verifies(extra, glphong_backend, glphong_make_renderer,
                                                  lights_behind_scene):
    """A point, a spot and a directional light behind a glass sphere (and one in front), its node scaled 1.2."""
    kw = {"roughness": 0.3} | extra
    glass = glphong.GltfPBR((0.9, 0.8, 0.6), 0.1, ior=1.5, transmission=0.8, thickness=0.3,
                            attenuation_color=(0.9, 0.5, 0.3), attenuation_distance=0.5, **kw)
    base = lights_behind_scene(primitives.sphere(3, 0.35), glass)
    scene = glphong.Scene(base.camera, base.lights)
    floor, sphere = base.objects
    scene.add(floor.mesh, floor.material, pose=floor.pose, name="floor")
    scene.add(sphere.mesh, glass, pose=np.diag([1.2, 1.2, 1.2, 1.0]), name="glass")
    report = glphong.verify(scene, glphong_make_renderer(48, 40, glphong_backend))
    assert report.passed and report.transmission.pixels.sum() > 150, report.summary()


def test_shadowed_lights_behind_a_volume_take_the_visibility_at_the_surface(glphong_backend, glphong_make_renderer):
    """Shadowed point and directional lights behind a lone glass quad: nothing occludes them (the quad's own depth
    in their maps, the visibility 1), so the frame equals the unshadowed one, and verify (which twins the shadowed
    lights behind a transmissive surface with the visibility at it: tests/test_transmission_shadows.py) passes."""
    camera = glphong.PerspectiveCamera.look_at((0.3, -0.4, 2.5), (0.0, 0.0, 0.0))
    frames = []
    for shadows in (False, True):
        scene = glphong.Scene(camera, [glphong.PointLight((0.2, 0.1, -0.6), 5.0, shadows=shadows),
                                       glphong.DirectionalLight((0.1, 0.2, 1.0), 1.5, shadows=shadows)])
        scene.add(primitives.plane(1.5), _glass(diffuse_transmission=0.3), name="glass")
        renderer = glphong_make_renderer(48, 40, glphong_backend)
        frames.append(renderer.render(scene).radiance)
        report = glphong.verify(scene, renderer)
        assert report.passed, report.summary()
    lit = frames[0].max(axis=-1) > 0
    assert lit.sum() > 700
    np.testing.assert_allclose(frames[1][lit], frames[0][lit], rtol=1e-6, atol=1e-7 * frames[0].max())


def _keys(material):
    return [program_key(material, lights, None) for lights in ({"point": 2, "directional": 1, "spot": 1},
                                                              {"directional": 1})]


def test_programs_without_a_volume_are_unchanged(monkeypatch):
    """Without GLTF_PBR_VOLUME the light loops are those of a model that declares no exits, byte for byte; with it
    they differ (the exits are there)."""
    others = [gltf_pbr.GltfPBR((0.9, 0.8, 0.6), 0.2, 0.3, **kw) for kw in
              ({}, {"transmission": 0.9}, {"diffuse_transmission": 0.5},
               {"transmission": 0.5, "diffuse_transmission": 0.5}, {"diffuse_transmission": 0.5, "thickness": 0.2})]
    volume = _glass(diffuse_transmission=0.5)
    assert "volume" in volume.extensions() and not any("volume" in m.extensions() for m in others)
    before = {id(m): [generated.lights_chunk(k) for k in _keys(m)] for m in others + [volume]}
    monkeypatch.setattr(gltf_pbr.GltfPBR, "behind_exits", ())
    for m in others:
        assert [generated.lights_chunk(k) for k in _keys(m)] == before[id(m)]
    assert all("gltf_volume_exit" in chunk for chunk in before[id(volume)])
    assert [generated.lights_chunk(k) for k in _keys(volume)] != before[id(volume)]


PLANTED = {  # name: (chunk, old, new)
    "no attenuation": ("transmission_thin",
                       "return gltf_volume_attenuation(length(gltf_volume_exit(f, wo)), gltf_pbr_attenuation());",
                       "return vec3(1.0);"),
    "half the diffuse path": ("transmission_thin",
                              "return gltf_volume_attenuation(gltf_pbr_thickness() * scale, gltf_pbr_attenuation());",
                              "return gltf_volume_attenuation(gltf_pbr_thickness() * scale * 0.5, "
                              "gltf_pbr_attenuation());"),
}


@pytest.mark.parametrize("planted", ["no move"] + sorted(PLANTED))
def test_planted_volume_light_errors_fail_verify(planted, monkeypatch, glphong_make_renderer, lights_behind_scene):
    if planted == "no move":  # the loops take the light at the surface, still attenuated
        exits = generated._behind_exits
        monkeypatch.setattr(generated, "_behind_exits", lambda key: {
            through: (None, attenuation) for through, (_, attenuation) in exits(key).items()})
    else:
        chunk, old, new = PLANTED[planted]
        original = assembly.chunk_source
        assert old in original(chunk)
        monkeypatch.setattr(assembly, "chunk_source",
                            lambda name: original(name).replace(old, new) if name == chunk else original(name))
    glass = glphong.GltfPBR((0.9, 0.8, 0.6), 0.1, 0.4, ior=1.5, transmission=0.6, thickness=0.3,
                            attenuation_color=(0.9, 0.5, 0.3), attenuation_distance=0.5, diffuse_transmission=0.5)
    report = glphong.verify(lights_behind_scene(primitives.sphere(3, 0.35), glass), glphong_make_renderer(48, 40, "egl"))
    assert not report.passed and report.outside_count > 0, report.summary()
