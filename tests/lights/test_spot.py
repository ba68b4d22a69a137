"""The spot light (glphong.SpotLight): KHR_lights_punctual's falloff against its closed form on a plane, at the
cone's edges too, on both backends; the range window; its files and its key.

The closed form is the specification's own arithmetic in float64, ``clamp(cos(theta) s + o, 0, 1)^2 I / d^2``
(`glphong.lights.spot.spot_falloff`), from the G-buffer's float32 positions and the float32 light position and
axis the GPU receives: nothing of glphong's GLSL or twin.  The GPU must lie within the float32 band's widths
around it (the band of `glphong.verify`, moved onto the closed form), widened by what one float32 rounding of
``cos(outer)`` and ``cos(inner)`` moves the falloff by (the closed form reads the angles in float64).
"""
import numpy as np
import pytest

import glphong
from glphong import primitives
from glphong.checks import reference
from glphong.checks.tolerances import radiance_band
from glphong.lights.spot import spot_falloff
from glphong.shaders.key import light_keys
from glphong.shaders.binding import binding

EPS32 = 2.0 ** -24


def _plane_scene(light, kd=1.0):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0), yfov=1.2)
    scene = glphong.Scene(camera, [light])
    scene.add(primitives.plane(4.0, segments=4), glphong.Lambert(kd))
    return scene


def _closed_form(light, points):
    """The specification's E (n . wi) on the plane z = 0 (n = +z), float64, and the falloff g per point."""
    position = np.asarray(light.position, dtype=np.float32).astype(np.float64)
    axis = np.asarray(light.direction, dtype=np.float32).astype(np.float64)
    to_light = position - points
    d = np.linalg.norm(to_light, axis=-1)
    wi = to_light / d[:, None]
    cos_theta = -(wi @ axis) / np.linalg.norm(axis)
    falloff = spot_falloff(cos_theta, light.inner_cone_angle, light.outer_cone_angle)
    intensity = np.asarray(light.intensity, dtype=np.float32).astype(np.float64)
    return intensity * (falloff / d ** 2 * wi[:, 2])[:, None], np.sqrt(falloff), d, wi[:, 2]


CONES = [  # (inner, outer): a soft cone, a hard one, inner = outer, a tiny inner and pi/2
    (0.2, 0.5), (0.45, 0.5), (0.4, 0.4), (0.0, 0.05), (0.3, np.pi / 2)]


@pytest.mark.parametrize("inner, outer", CONES)
def test_plane_matches_the_closed_form(inner, outer, glphong_backend, glphong_make_renderer):
    light = glphong.SpotLight((0.1, -0.2, 1.0), (0.15, 0.1, -1.0), 3.0, inner_cone_angle=inner, outer_cone_angle=outer)
    scene = _plane_scene(light)
    renderer = glphong_make_renderer(192, 192, glphong_backend)
    gbuffer = renderer.gbuffer(scene)
    frame = renderer.render(scene)
    mask = gbuffer.mask
    points = gbuffer.position[mask].astype(np.float64)
    closed, g, d, n_dot_l = _closed_form(light, points)
    gpu = frame.radiance[mask].astype(np.float64)
    twin = reference.shade(scene, gbuffer)[mask]
    low, high = radiance_band(scene, gbuffer)
    low, high = low[mask], high[mask]
    s = 1.0 / max(0.001, np.cos(inner) - np.cos(outer))
    # one float32 rounding of cos(outer) (as 1 - cos(outer)) and of s moves g by up to s * 2 eps + g * eps
    dg = s * 2 * EPS32 + g * EPS32
    intensity = float(np.float32(light.intensity[0]))
    rounding = (intensity * (2 * g * dg + dg * dg) / d ** 2 * np.abs(n_dot_l))[:, None]
    inside = (gpu >= closed - (twin - low) - rounding) & (gpu <= closed + (high - twin) + rounding)
    assert inside.all(), (f"{int((~inside).any(axis=1).sum())} of {len(gpu)} pixels off the closed form; worst "
                          f"{np.max(np.abs(gpu - closed)[~inside])}")
    edge = (g > 0) & (g < 0.05)
    # (a cone of pi/2 ends at the light's own horizon, which the plane below it never reaches)
    assert edge.sum() > (20 if 0.1 < outer < 1.0 and outer - inner > 0.01 else 0) or outer > 1.0, "the render must cover the cone's edge"
    assert np.all(gpu[g == 0] == 0) or outer >= np.pi / 2  # beyond the cone: exactly dark
    assert (g >= 1).sum() > 100 or inner < 0.01  # inside the inner cone: full intensity
    assert glphong.verify(scene, renderer).passed


def test_the_falloff_is_the_specifications():
    """KHR_lights_punctual's numbers: full inside the inner cone, 0 beyond the outer, the square between; the
    twin's chord form gives them to float64 rounding."""
    light = glphong.SpotLight((0.0, 0.0, 1.0), (0.0, 0.0, -1.0), 1.0, 0.3, 0.6)
    theta = np.array([0.0, 0.29, 0.3, 0.45, 0.6, 0.61, 1.2])
    x = np.stack([np.tan(theta), np.zeros_like(theta), np.zeros_like(theta)], axis=1)  # points on z = 0
    s = 1.0 / (np.cos(0.3) - np.cos(0.6))
    expected = np.clip((np.cos(theta) - np.cos(0.6)) * s, 0, 1) ** 2 * np.cos(theta) ** 2  # E = f I / d^2, d = 1/cos
    _, _, e = light.incident(x, light.values())
    np.testing.assert_allclose(e[:, 0], expected, rtol=2e-6, atol=1e-12)
    np.testing.assert_allclose(spot_falloff(np.cos(theta), 0.3, 0.6), np.clip((np.cos(theta) - np.cos(0.6)) * s, 0, 1) ** 2)


@pytest.mark.parametrize("kind", ["point", "spot"])
def test_range_window_is_the_specifications_not_its_square(kind, glphong_backend, glphong_make_renderer):
    """``E clamp(1 - (d/range)^4, 0, 1)``: three.js and Filament square the window; glphong does not."""
    make = {"point": lambda r: glphong.PointLight((0.0, 0.0, 1.0), 4 * np.pi * 3.0, range=r),
            "spot": lambda r: glphong.SpotLight((0.0, 0.0, 1.0), (0.0, 0.0, -1.0), 3.0, 0.0, 1.5, range=r)}[kind]
    windowed, plain = _plane_scene(make(2.0)), _plane_scene(make(None))
    renderer = glphong_make_renderer(128, 128, glphong_backend)
    gbuffer = renderer.gbuffer(windowed)
    mask = gbuffer.mask
    d = np.linalg.norm(gbuffer.position[mask].astype(np.float64) - (0.0, 0.0, 1.0), axis=-1)
    window = np.clip(1 - (d / 2.0) ** 4, 0, 1)
    ratio = renderer.render(windowed).radiance[mask][:, 0] / renderer.render(plain).radiance[mask][:, 0]
    # d carries a few ulps (D = 8) of float32 error, which 1 - t^4 amplifies by 4 t^4 / (1 - t^4) near the range
    tolerance = 8 * EPS32 * (4 * (d / 2.0) ** 4 + 4) + 1e-6 * window
    assert np.all(np.abs(ratio - window) <= tolerance), np.max(np.abs(ratio - window) - tolerance)
    assert np.all(ratio[d > 2.0 * (1 + 1e-6)] == 0)
    assert glphong.verify(windowed, renderer).passed


def test_key_leaves_out_what_the_scene_lacks():
    plain = glphong.SpotLight((0, 0, 1), (0, 0, -1), 1.0)
    ranged = glphong.SpotLight((0, 0, 1), (0, 0, -1), 1.0, range=3.0)
    assert light_keys([glphong.PointLight((0, 0, 1), 1.0)])[0].name == "point"  # no spot chunk without a spot light
    assert light_keys([plain])[0].defines == ()
    assert light_keys([plain, ranged])[0].defines == (("RANGE", "1"),)
    scene = _plane_scene(plain)
    key = binding(scene).program_key(scene.objects[0])
    assert [k.chunk.split("@")[0] for k in key.lights] == ["light:spot"]
    assert "lights" in key.shading_chunks() and "SPOT_RANGE" not in dict(key.defines())
    left_out = "\n".join(key.left_out())
    assert "point-light loop" in left_out and "spot lights' range window" in left_out


def test_uber_shader_holds_spot_lights(glphong_backend, glphong_make_renderer):
    scene = _plane_scene(glphong.SpotLight((0.1, 0, 1), (0, 0, -1), 2.0, 0.2, 0.5, range=2.5))
    scene.add_light(glphong.PointLight((-1, 0, 1), 5.0))
    uber = glphong_make_renderer(96, 96, glphong_backend, specialise=False)
    special = glphong_make_renderer(96, 96, glphong_backend)
    assert glphong.verify(scene, uber).passed
    np.testing.assert_allclose(uber.render(scene).radiance, special.render(scene).radiance, rtol=1e-5, atol=1e-9)


def test_gltf_round_trip(tmp_path):
    scene = _plane_scene(glphong.SpotLight((0.1, -0.2, 1.0), (0.15, 0.1, -1.0), (3.0, 2.0, 1.0), 0.2, 0.5, range=4.0))
    scene.add_light(glphong.PointLight((1.0, 2.0, 3.0), 7.0, range=9.0))
    for suffix in (".gltf", ".glb"):
        loaded = glphong.load_scene(glphong.save_gltf(scene, tmp_path / f"spot{suffix}"))
        spot, point = sorted(loaded.lights, key=lambda light: light.kind != "spot")
        np.testing.assert_allclose(spot.position, (0.1, -0.2, 1.0), atol=1e-12)
        np.testing.assert_allclose(spot.direction, scene.lights[0].direction, atol=1e-12)
        np.testing.assert_allclose(spot.intensity, (3.0, 2.0, 1.0), rtol=1e-12)
        assert (spot.inner_cone_angle, spot.outer_cone_angle, spot.range) == (0.2, 0.5, 4.0)
        np.testing.assert_allclose(point.power, scene.lights[1].power, rtol=1e-12)
        assert point.range == 9.0


@pytest.mark.parametrize("kwargs, message", [
    ({"inner_cone_angle": 0.6, "outer_cone_angle": 0.5}, "inner_cone_angle (0.6) must be at most outer_cone_angle (0.5)"),
    ({"outer_cone_angle": 0.0}, "outer_cone_angle must be finite and in (0"),
    ({"outer_cone_angle": 1.6}, "outer_cone_angle must be finite and in (0, 1.5708]"),
    ({"inner_cone_angle": -0.1}, "inner_cone_angle must be finite and in [0, 1.5708]"),
    ({"range": 0.0}, "range must be finite and in (0"),
    ({"direction": (0.0, 0.0, 0.0)}, "direction must not be the zero vector"),
])
def test_invalid_values_are_refused(kwargs, message):
    arguments = {"position": (0, 0, 1), "direction": (0, 0, -1), "intensity": 1.0} | kwargs
    with pytest.raises(ValueError, match=message.replace("(", r"\(").replace(")", r"\)").replace("[", r"\[")
                       .replace("]", r"\]")):
        glphong.SpotLight(**arguments)
