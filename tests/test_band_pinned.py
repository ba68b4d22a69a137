"""The tolerance band's width, pinned in closed form (docs/design.md section 4).

Every GPU-against-twin check is only as strict as the band.  These tests write the band's
formulas out with literal numbers, (A, B, C, D) = (16, 4, 6, 8) and eps = 2^-24, and compare
`glphong.checks.tolerances` with them at a few known inputs, so a band made wider (or narrower) by any
factor fails here even if every image still passes.  The expected values use only ``math``.
"""
import math
from dataclasses import replace

import numpy as np
import pytest

import glphong
from glphong.checks import tolerances
from glphong.shaders.key import program_key

EPS = 2.0 ** -24
A, B, C, D = 16.0, 4.0, 6.0, 8.0


def cos_power(delta, q):
    """(1 - delta)^q in float64 from math.log1p (independent of glphong.reference)."""
    return 1.0 if q == 0 else math.exp(q * math.log1p(-delta))


def test_constants_are_the_design_values():
    band = tolerances.BAND
    assert (band.A, band.B, band.C, band.D) == (A, B, C, D)
    assert tolerances.EPS == EPS


@pytest.mark.parametrize("delta, q", [(1e-4, 1e4), (1e-6, 1e6), (0.02, 50.0), (0.3, 2.0), (1e-9, 1e7)])
def test_lobe_band_closed_form(delta, q):
    """high = (1 - (c - C eps (1 + c))^2/2)^q (1 + eps (A + B lambda_hi)), low likewise with c + C eps (1 + c),
    c = sqrt(2 delta), lambda = -ln(value)."""
    c = math.sqrt(2.0 * delta)
    hi_core = cos_power(0.5 * (c - C * EPS * (1.0 + c)) ** 2, q)
    lo_core = cos_power(0.5 * (c + C * EPS * (1.0 + c)) ** 2, q)
    high = hi_core * (1.0 + EPS * (A + B * -math.log(hi_core)))
    low = lo_core * (1.0 - EPS * (A + B * -math.log(lo_core)))
    got_low, got_high = tolerances.lobe_band(np.array([delta]), q)
    assert got_high[0] == pytest.approx(high, rel=1e-9)
    assert got_low[0] == pytest.approx(low, rel=1e-9)
    # and its first-order width near the peak (delta << 1), eps (A + B lambda + C sqrt(2 q lambda)) per side
    if delta > 1e-3:
        return
    lam = q * delta
    first_order = EPS * (A + B * lam + C * math.sqrt(2.0 * q * lam))
    value = cos_power(delta, q)
    assert (got_high[0] - value) / value == pytest.approx(first_order, rel=0.05)


def test_lobe_band_is_narrow_where_it_must_be():
    """At q = 1e7 and lambda = 0.5 (the lobe at 0.61 of its peak) the band is 1.13e-3 relative per side:
    the chord's C eps, amplified by sqrt(2 q lambda), dominates."""
    q, delta = 1e7, 0.5e-7  # lambda = 0.5
    low, high = tolerances.lobe_band(np.array([delta]), q)
    value = cos_power(delta, q)
    width = (high[0] - low[0]) / value
    expected = 2 * EPS * (A + B * 0.5 + C * math.sqrt(2.0 * q * 0.5))
    assert width == pytest.approx(expected, rel=0.05)
    assert 2.4e-3 > width > 2.1e-3


LAMBERT = glphong.Lambert(0.25)


def lambert_key(material=LAMBERT, ambient=None, **extra):
    key = program_key(material, {"directional": 1}, ambient, output="points")
    return replace(key, two_sided=False, **extra)


@pytest.mark.parametrize("n_dot_l", [1.0, 0.5, 1e-3])
def test_lambert_point_band_closed_form(n_dot_l):
    """One directional light on a Lambert surface: kd E [n.l - D eps, n.l + D eps] (1 -+ A eps) (1 -+ eps)
    (the last factor: one term in the sum)."""
    kd, e = 0.25, 3.0
    s = math.sqrt(1.0 - n_dot_l * n_dot_l)
    u = {"u_lambert_kd": np.full(3, kd), "u_directional_towards": np.array([[s, 0.0, n_dot_l]]),
         "u_directional_irradiance": np.full((1, 3), e)}
    low, high = tolerances.point_band(lambert_key(), u, np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]),
                                      np.array([True]), LAMBERT)
    exp_low = kd * (n_dot_l - D * EPS) * e * (1 - A * EPS) * (1 - EPS)
    exp_high = kd * (n_dot_l + D * EPS) * e * (1 + A * EPS) * (1 + EPS)
    np.testing.assert_allclose(low[0], exp_low, rtol=1e-12)
    np.testing.assert_allclose(high[0], exp_high, rtol=1e-12)


def test_ambient_band_closed_form():
    """k_a + k_d L_a alone: each term (1 -+ A eps), the sum of two terms (1 -+ 2 eps)."""
    ka, kd, la = 0.01, 0.3, 0.5
    material = glphong.Lambert(kd, ka=ka)
    key = program_key(material, {}, (la, la, la), output="points")
    assert [t.name for t in key.terms if t.ambient] == ["lambert"] and key.has_ka and not key.num_lights
    u = {"u_ka": np.full(3, ka), "u_lambert_kd": np.full(3, kd), "u_ambient": np.full(3, la)}
    low, high = tolerances.point_band(key, u, np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), np.array([True]),
                                      material)
    total = ka + kd * la
    np.testing.assert_allclose(low[0], total * (1 - A * EPS) * (1 - 2 * EPS), rtol=1e-12)
    np.testing.assert_allclose(high[0], total * (1 + A * EPS) * (1 + 2 * EPS), rtol=1e-12)


def test_gate_accepts_either_side_only_within_d_eps():
    """Where |n.l| <= D eps either side of the gate is accepted (low 0); just outside, it is not."""
    kd, e = 0.25, 1.0
    for n_dot_l, low_is_zero in ((0.5 * D * EPS, True), (-0.5 * D * EPS, True), (4 * D * EPS, False)):
        s = math.sqrt(1.0 - n_dot_l * n_dot_l)
        u = {"u_lambert_kd": np.full(3, kd), "u_directional_towards": np.array([[s, 0.0, n_dot_l]]),
             "u_directional_irradiance": np.full((1, 3), e)}
        low, high = tolerances.point_band(lambert_key(), u, np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]),
                                          np.array([True]), LAMBERT)
        assert (low[0] == 0).all() == low_is_zero, n_dot_l
        np.testing.assert_allclose(high[0], kd * (n_dot_l + D * EPS) * e * (1 + A * EPS) * (1 + EPS), rtol=1e-12)
    # a light clearly behind the surface: nothing is accepted
    u = {"u_lambert_kd": np.full(3, kd), "u_directional_towards": np.array([[0.6, 0.0, -0.8]]),
         "u_directional_irradiance": np.full((1, 3), e)}
    low, high = tolerances.point_band(lambert_key(), u, np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]), np.array([True]),
                                      LAMBERT)
    assert (low == 0).all() and (high == 0).all()
