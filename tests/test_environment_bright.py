"""The bright blocks of an environment map (glphong.twin.environment_bright), against independent references: the
split reassembles the map, the blocks' moments and powers are the excess map's sums of the exact per-texel integrals
(themselves checked against a midpoint quadrature in tests/test_environment_twin.py), the disc's part above a chord
against a fine polar grid, Lambert against the excess map's exact irradiance, and the Phong lobe against the
independent quadrature (`glphong.twin.environment_quadrature`)."""
import numpy as np
import pytest

from glphong.twin import environment as env
from glphong.twin.environment_bright import (BRIGHT_SOLID_ANGLE, bright_blocks, bright_threshold,
                                             environment_bright_irradiance, environment_bright_lobe,
                                             environment_segment)
from glphong.twin.environment_quadrature import environment_integral

SUN = np.array([np.cos(np.radians(40.0)) * np.cos(0.5), np.cos(np.radians(40.0)) * np.sin(0.5), np.sin(np.radians(40.0))])


def _sky(H=64, W=128, diameter=6.0, sun=2000.0):
    """A sky 0.3 to 0.8 with a disc of ``diameter`` degrees at ``sun`` (RGB, the sun a little yellow)."""
    d = env.texel_directions(H, W)
    sky = (0.3 + 0.5 * np.maximum(d[..., 2], 0.0))[..., None] * np.array([0.8, 0.9, 1.0])
    disc = d @ SUN > np.cos(np.radians(diameter / 2))
    sky[disc] = sun * np.array([1.0, 0.9, 0.8])
    return sky, disc


@pytest.mark.parametrize("count", [1, 5, 16, 64, 200])
def test_the_split_is_exact_and_the_blocks_hold_the_excess(count):
    sky, disc = _sky()
    T = bright_threshold(sky)
    assert 0.8 < T < 2000.0 * 0.8                               # between the sky and the sun
    residual, blocks = bright_blocks(sky, T, count)
    excess = np.maximum(sky - T, 0.0)
    assert np.array_equal(residual + excess, sky) or np.allclose(residual + excess, sky, rtol=1e-15, atol=0)
    assert 0 < blocks["count"] <= count and len(blocks["radius"]) == blocks["count"]
    moments, omega = env.texel_moments(*sky.shape[:2]), env.texel_solid_angles(*sky.shape[:2])
    np.testing.assert_allclose(blocks["moment"].sum(axis=0), np.einsum("hwc,hwd->cd", excess, moments), rtol=1e-12)
    np.testing.assert_allclose(blocks["power"].sum(axis=0), np.einsum("hwc,hw->c", excess, omega), rtol=1e-12)
    assert abs(np.sum(np.pi * blocks["radius"] ** 2) - omega[disc].sum()) < 1e-12 * omega[disc].sum()
    np.testing.assert_allclose(blocks["length"], np.linalg.norm(blocks["moment"], axis=-1), rtol=1e-14)
    # every block's disc inside the cap
    reach = np.arccos(np.clip(blocks["direction"] @ blocks["center"], -1, 1)) + np.arcsin(blocks["radius"])
    assert np.all(reach <= blocks["cap"][2]) and abs(blocks["cap"][0] - np.cos(blocks["cap"][2])) < 1e-15


def test_the_automatic_threshold():
    """A smooth sky extracts nothing; a large bright region is extracted up to BRIGHT_SOLID_ANGLE (its brightest
    part); a map zero but for one texel extracts that texel."""
    d = env.texel_directions(32, 64)
    smooth = np.repeat((0.2 + np.maximum(d[..., 2], 0.0) ** 2)[..., None], 3, axis=-1)   # 0.2 to 1.2
    assert bright_blocks(smooth, bright_threshold(smooth), 32)[1]["count"] == 0
    big = smooth.copy()
    big[d @ SUN > np.cos(np.radians(30.0))] = 50.0 * (1.0 + d[d @ SUN > np.cos(np.radians(30.0))] @ SUN)[:, None]
    T = bright_threshold(big)
    above = np.any(big > T, axis=-1)
    assert 0 < env.texel_solid_angles(32, 64)[above].sum() <= BRIGHT_SOLID_ANGLE
    single = np.zeros((8, 16, 3))
    single[2, 5] = (3.0, 2.0, 1.0)
    residual, blocks = bright_blocks(single, bright_threshold(single), 32)
    assert not residual.any() and blocks["count"] >= 1


def test_the_segment_against_a_polar_grid():
    """f: the part of a disc above a chord at signed distance c from its centre; e: the mean of max(c + y, 0) over
    the disc times [c + y > 0] (the cosine-weighted part), on a 2000 x 2000 polar midpoint grid of a disc of radius
    a."""
    a = 0.05
    radius = a * np.sqrt((np.arange(2000) + 0.5) / 2000)          # equal-area rings
    angle = 2 * np.pi * (np.arange(2000) + 0.5) / 2000
    y = (radius[:, None] * np.sin(angle)[None, :]).reshape(-1)
    for c in (-0.06, -0.05, -0.03, -0.001, 0.0, 0.02, 0.0499, 0.05, 0.2):
        f, e = environment_segment(np.array([c]), a)
        assert abs(f[0] - np.mean(c + y > 0)) < 2e-3, (c, f[0])
        assert abs(e[0] - np.mean(np.maximum(c + y, 0.0))) < 2e-3 * a, (c, e[0])
    f, e = environment_segment(np.array([0.07, -0.07]), a)
    assert np.array_equal(f, [1.0, 0.0]) and e[0] == 0.07 and e[1] == 0.0


def _normals_about(axis, elevations):
    """Normals whose horizon passes at ``elevations`` [deg] from ``axis`` (n.axis = sin(elevation))."""
    side = np.cross(axis, [0.0, 0.0, 1.0])
    side /= np.linalg.norm(side)
    e = np.radians(np.asarray(elevations, dtype=np.float64))
    return np.cos(e)[:, None] * side[None, :] + np.sin(e)[:, None] * axis[None, :]


def test_lambert_is_exact_where_the_blocks_are_above_and_close_across_the_terminator():
    sky, disc = _sky()
    T = bright_threshold(sky)
    excess = np.maximum(sky - T, 0.0)
    peak = np.linalg.norm(np.einsum("hwc,hwd->cd", excess, env.texel_moments(64, 128)), axis=-1)   # (C,) [W/m^2]
    for count in (4, 32, 128):
        blocks = bright_blocks(sky, T, count)[1]
        above = _normals_about(SUN, [10.0, 30.0, 89.0])
        exact = env.irradiance(excess, above, crossed="closed")[0]
        got, _ = environment_bright_irradiance(above, blocks)
        np.testing.assert_allclose(got, exact, rtol=1e-12)
        across = _normals_about(SUN, np.linspace(-6.0, 6.0, 25))   # the sun's terminator: its disc crosses the horizon
        exact = env.irradiance(excess, across, crossed="closed")[0]
        got, _ = environment_bright_irradiance(across, blocks)
        assert np.max(np.abs(got - exact) / peak) < 0.01, (count, np.max(np.abs(got - exact) / peak))
    far = _normals_about(SUN, [-10.0, -60.0])
    assert not environment_bright_irradiance(far, blocks)[0].any()


@pytest.mark.parametrize("q", [10.0, 100.0])
def test_the_lobe_by_the_midpoint_rule_against_the_quadrature(q):
    """r at the sun and 2 and 5 degrees off it, the surface's horizon far below: within ``q h^2 / 12`` (h the texel's
    height, 2.8 degrees: 2.4e-2 at q = 100) of the peak plus 1e-6; at 60 degrees off the lobe is left out (0), by less
    than 1e-8 of the power."""
    sky, _ = _sky()
    excess = np.maximum(sky - bright_threshold(sky), 0.0)
    blocks = bright_blocks(sky, bright_threshold(sky), 64)[1]
    up = SUN[None, :]
    side = np.cross(SUN, [0.0, 0.0, 1.0])
    side /= np.linalg.norm(side)
    h = np.pi / 64
    for off in (0.0, 2.0, 5.0):
        r = np.cos(np.radians(off)) * SUN + np.sin(np.radians(off)) * side
        got, _ = environment_bright_lobe(up, r[None], q, blocks)
        value, error, converged = environment_integral(up, excess, lambda i, w: np.maximum(w @ r, 0.0) ** q)
        peak = blocks["power"].sum(axis=0)
        assert converged[0] and np.all(np.abs(got[0] - value[0]) <= q * h * h / 12 * peak + 1e-6 * peak), (
            off, got[0], value[0])
    r = np.cos(np.radians(60.0)) * SUN + np.sin(np.radians(60.0)) * side
    got, _ = environment_bright_lobe(up, r[None], q, blocks)
    skipped = np.sum(blocks["power"] * np.maximum(blocks["direction"] @ r, 0.0)[:, None] ** q, axis=0)
    assert (q < 20 and got.any()) or (not got.any() and np.all(skipped < 1e-8 * blocks["power"].sum(axis=0)))


def test_blocks_on_opposite_sides():
    """Two suns 180 degrees apart: their cap is wider than a hemisphere, which no horizon leaves on one side (its
    sine stored as 2), so every normal sums the blocks one by one: within 1 % of the brighter sun's irradiance of the
    excess map's exact one at 200 random normals."""
    d = env.texel_directions(32, 64)
    sky = np.full((32, 64, 3), 0.5)
    for axis in (SUN, -SUN):
        sky[d @ axis > np.cos(np.radians(6.0))] = 500.0
    T = bright_threshold(sky)
    blocks = bright_blocks(sky, T, 64)[1]
    assert blocks["cap"][2] > np.pi / 2 and blocks["cap"][1] == 2.0
    normals = np.random.default_rng(7).normal(size=(200, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    excess = np.maximum(sky - T, 0.0)
    exact = env.irradiance(excess, normals, crossed="closed")[0]
    got = environment_bright_irradiance(normals, blocks)[0]
    assert np.max(np.abs(got - exact)) < 0.01 * np.max(exact), np.max(np.abs(got - exact)) / np.max(exact)
