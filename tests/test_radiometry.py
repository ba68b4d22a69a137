"""Tests for glphong.radiometry."""

import math
import re

import mpmath
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from glphong import radiometry as rad
from glphong.radiometry import (
    PLANCK,
    SPEED_OF_LIGHT,
    photon_energy,
    point_intensity,
    point_irradiance,
    power_from_intensity,
    radiant_energy,
    radiant_flux,
)

# Literal exact SI values, written out independently of the module.
H = 6.62607015e-34
C = 299792458.0


def approx(expected, rel):
    """pytest.approx with a purely relative tolerance.

    pytest.approx otherwise also accepts anything within abs=1e-12, which
    would make every comparison of ~1e-19 J photon energies vacuous.
    """
    return pytest.approx(expected, rel=rel, abs=0.0)


def _mp_irradiance(phi, d, cos_theta=1.0):
    """Reference Phi max(cos, 0) / (4 pi d^2) in 60-digit arithmetic."""
    with mpmath.workdps(60):
        phi, d, c = mpmath.mpf(float(phi)), mpmath.mpf(float(d)), mpmath.mpf(float(cos_theta))
        return phi * max(c, 0) / (4 * mpmath.pi * d * d)


def _rel_err(x, ref):
    with mpmath.workdps(60):
        return float(abs((mpmath.mpf(float(x)) - ref) / ref))


# --------------------------------------------------------------------------
# constants and photon energy
# --------------------------------------------------------------------------


def test_constants_are_exact_si_values():
    assert PLANCK == 6.62607015e-34
    assert SPEED_OF_LIGHT == 299792458.0


def test_photon_energy_green_555nm():
    e = photon_energy(555e-9)
    assert isinstance(e, np.float64)
    assert e == approx(H * C / 555e-9, rel=1e-15)
    assert e == approx(3.579e-19, rel=1e-4)
    # the lecture's rounded constants give a ~0.13 % larger value
    assert 6.63e-34 * 3e8 / 555e-9 == approx(e, rel=2e-3)
    assert 6.63e-34 * 3e8 / 555e-9 != approx(e, rel=1e-3)


def test_photon_energy_vectorised():
    lam = np.array([[400e-9, 555e-9], [700e-9, 1e-6]])
    e = photon_energy(lam)
    assert isinstance(e, np.ndarray) and e.dtype == np.float64
    assert e.shape == (2, 2)
    np.testing.assert_allclose(e, H * C / lam, rtol=1e-15)
    # shorter wavelength -> more energetic photon
    assert e[0, 0] > e[0, 1] > e[1, 0] > e[1, 1]


def test_photon_energy_list_input_and_float32():
    np.testing.assert_allclose(photon_energy([500e-9, 1e-3]), [H * C / 500e-9, H * C / 1e-3], rtol=1e-15)
    lam32 = np.float32(555e-9)
    assert photon_energy(lam32) == approx(H * C / float(lam32), rel=1e-15)


# --------------------------------------------------------------------------
# radiant energy and flux
# --------------------------------------------------------------------------


@pytest.mark.parametrize("n", [1, 2, 7, 1000, 123457])
def test_radiant_energy_of_identical_photons(n):
    q = radiant_energy(np.full(n, 555e-9))
    assert isinstance(q, np.float64)
    assert q == approx(n * (H * C / 555e-9), rel=1e-13)


def test_radiant_energy_mixed_and_edge_shapes():
    lams = [400e-9, 555e-9, 700e-9]
    assert radiant_energy(lams) == approx(sum(H * C / x for x in lams), rel=1e-15)
    assert radiant_energy(555e-9) == approx(H * C / 555e-9, rel=1e-15)  # scalar = 1 photon
    assert radiant_energy([]) == 0.0
    with pytest.raises(ValueError, match=r"wavelengths must be a scalar or a 1-D array"):
        radiant_energy(np.full((2, 3), 555e-9))


def test_radiant_flux():
    # 1 J over 2 s -> 0.5 W
    assert radiant_flux(1.0, 2.0) == 0.5
    assert isinstance(radiant_flux(1.0, 2.0), np.float64)
    # 1e18 green photons per second -> ~0.358 W
    q = radiant_energy(np.full(1000, 555e-9)) * 1e15
    assert radiant_flux(q, 1.0) == approx(1e18 * H * C / 555e-9, rel=1e-13)
    # broadcasting
    phi = radiant_flux([[3.0], [6.0]], [1.0, 2.0, 3.0])
    assert phi.shape == (2, 3)
    np.testing.assert_array_equal(phi, [[3.0, 1.5, 1.0], [6.0, 3.0, 2.0]])
    assert radiant_flux(0.0, 1.0) == 0.0


# --------------------------------------------------------------------------
# intensity <-> power
# --------------------------------------------------------------------------


def test_point_intensity_values():
    assert point_intensity(4.0 * math.pi) == approx(1.0, rel=1e-15)
    assert point_intensity(100.0) == approx(100.0 / (4.0 * math.pi), rel=1e-15)
    assert point_intensity(0.0) == 0.0
    assert power_from_intensity(1.0) == approx(4.0 * math.pi, rel=1e-15)
    assert power_from_intensity(2.5) == approx(10.0 * math.pi, rel=1e-15)


def test_intensity_power_round_trip():
    powers = np.array([0.0, 1e-12, 1.0, 60.0, 1e20])
    np.testing.assert_allclose(power_from_intensity(point_intensity(powers)), powers, rtol=1e-15)
    intens = np.array([0.0, 3e-9, 1.0, 795.77, 1e25])
    np.testing.assert_allclose(point_intensity(power_from_intensity(intens)), intens, rtol=1e-15)


def test_intensity_return_types():
    assert isinstance(point_intensity(1.0), np.float64)
    out = point_intensity([1.0, 2.0])
    assert isinstance(out, np.ndarray) and out.dtype == np.float64 and out.shape == (2,)


# --------------------------------------------------------------------------
# point irradiance
# --------------------------------------------------------------------------


@pytest.mark.parametrize(
    "phi, d",
    [(1.0, 1.0), (100.0, 2.0), (60.0, 0.5), (1e3, 3.7), (0.25, 1e3)],
)
def test_point_irradiance_matches_formula(phi, d):
    e = point_irradiance(phi, d)
    assert isinstance(e, np.float64)
    assert e == approx(phi / (4.0 * math.pi * d**2), rel=1e-14)


def test_point_irradiance_known_value():
    # 4 pi W at 1 m -> 1 W/m^2; at 2 m -> 1/4 W/m^2
    assert point_irradiance(4.0 * math.pi, 1.0) == approx(1.0, rel=1e-15)
    assert point_irradiance(4.0 * math.pi, 2.0) == approx(0.25, rel=1e-15)


def test_point_irradiance_inverse_square_is_exact():
    # Dividing by 2 twice is exact in binary floating point.
    for phi in (1.0, 7.3, 1e5):
        for d in (0.3, 1.0, 17.0):
            assert point_irradiance(phi, d) / point_irradiance(phi, 2.0 * d) == 4.0
    d = np.array([1.0, 2.0, 4.0, 8.0])
    e = point_irradiance(10.0, d)
    np.testing.assert_array_equal(e[:-1] / e[1:], [4.0, 4.0, 4.0])


def test_point_irradiance_cosine():
    e0 = point_irradiance(100.0, 2.0)
    assert point_irradiance(100.0, 2.0, 0.5) == approx(0.5 * e0, rel=1e-15)
    assert point_irradiance(100.0, 2.0, math.cos(math.radians(60))) == approx(0.5 * e0, rel=1e-14)
    assert point_irradiance(100.0, 2.0, 0.0) == 0.0
    assert point_irradiance(100.0, 2.0, 1.0) == e0


@pytest.mark.parametrize("c", [-1.0, -0.5, -1e-300, -0.0])
def test_point_irradiance_negative_cosine_clamped_to_zero(c):
    e = point_irradiance(100.0, 2.0, c)
    assert e == 0.0
    assert math.copysign(1.0, e) == 1.0  # +0.0, not -0.0


def test_point_irradiance_broadcasting():
    e = point_irradiance(np.array([[1.0], [2.0]]), np.array([1.0, 2.0, 4.0]), np.array([1.0, -1.0, 0.5]))
    assert e.shape == (2, 3) and e.dtype == np.float64
    k = 1.0 / (4.0 * math.pi)
    expected = np.array([[k, 0.0, k / 32.0], [2 * k, 0.0, k / 16.0]])
    np.testing.assert_allclose(e, expected, rtol=1e-15)


@pytest.mark.parametrize("d", [1e-30, 1e-19, 1e-10, 1.0, 1e10, 1e19, 1e30])
def test_point_irradiance_stable_over_extreme_distances(d):
    e = point_irradiance(1.0, d)
    assert np.isfinite(e) and e > 0.0
    assert _rel_err(e, _mp_irradiance(1.0, d)) <= 1e-15


def test_point_irradiance_extreme_distances_with_cosine():
    for d in (1e-19, 1e30):
        e = point_irradiance(3.0, d, 0.3)
        assert _rel_err(e, _mp_irradiance(3.0, d, 0.3)) <= 1e-15


@pytest.mark.parametrize("phi, d", [(1e300, 1e160), (1e-300, 1e-160), (1e-40, 1e-170)])
def test_point_irradiance_never_forms_d_squared(phi, d):
    # d**2 overflows (1e320) or is subnormal/zero (1e-320, 1e-340) in
    # float64, while the irradiance itself is an ordinary normal number.
    e = point_irradiance(phi, d)
    assert np.isfinite(e) and e > 1e-300
    assert _rel_err(e, _mp_irradiance(phi, d)) <= 1e-15


@pytest.mark.parametrize("d", [1e-19, 1e-30, 1e30])
def test_point_irradiance_float32_input_no_overflow(d):
    d32 = np.float32(d)
    phi32 = np.float32(1.0)
    e = point_irradiance(phi32, d32)
    assert isinstance(e, np.float64)  # computed (and returned) in float64
    assert np.isfinite(e) and e > 0.0
    # exact reference for the float32 value actually passed in
    assert _rel_err(e, _mp_irradiance(1.0, float(d32))) <= 1e-15
    # float32 array input too
    arr = point_irradiance(np.array([phi32, phi32]), np.array([d32, d32]))
    assert arr.dtype == np.float64
    assert np.all(np.isfinite(arr)) and np.all(arr == e)


def test_point_irradiance_float32_naive_would_fail():
    # Why the evaluation order matters: in float32, d**2 at d = 1e-22 is
    # deep in the subnormal range and loses most of its precision, and at
    # d = 1e-30 it underflows to 0; the module's result stays exact.
    phi32 = np.float32(1e-6)
    d32 = np.float32(1e-22)
    with np.errstate(all="ignore"):
        naive = phi32 / (np.float32(4.0 * math.pi) * d32 * d32)
        naive_zero = np.float32(1.0) / (np.float32(4.0 * math.pi) * np.float32(1e-30) ** 2)
    ref = _mp_irradiance(float(phi32), float(d32))
    assert _rel_err(naive, ref) > 1e-3
    assert np.isinf(naive_zero)
    assert _rel_err(point_irradiance(phi32, d32), ref) <= 1e-15
    assert np.isfinite(point_irradiance(np.float32(1.0), np.float32(1e-30)))


# --------------------------------------------------------------------------
# hypothesis property test
# --------------------------------------------------------------------------

_pos = dict(allow_nan=False, allow_infinity=False)


@settings(max_examples=300, deadline=None)
@given(
    phi=st.floats(min_value=1e-6, max_value=1e6, **_pos),
    d=st.floats(min_value=1e-6, max_value=1e6, **_pos),
    k=st.floats(min_value=1e-3, max_value=1e3, **_pos),
    c=st.floats(min_value=1e-3, max_value=1.0, **_pos),
)
def test_point_irradiance_linear_in_power_inverse_square_in_distance(phi, d, k, c):
    e = point_irradiance(phi, d, c)
    assert point_irradiance(k * phi, d, c) == approx(k * e, rel=1e-12)
    assert point_irradiance(phi, k * d, c) == approx(e / (k * k), rel=1e-12)


# --------------------------------------------------------------------------
# validation
# --------------------------------------------------------------------------

_BAD_CASES = [
    # (callable, args, expected message fragment)
    (photon_energy, (0.0,), "wavelength must be finite and > 0 (got 0.0)"),
    (photon_energy, (-555e-9,), "wavelength must be finite and > 0 (got -5.55e-07)"),
    (photon_energy, (float("nan"),), "wavelength must be finite and > 0 (got nan)"),
    (photon_energy, (float("inf"),), "wavelength must be finite and > 0 (got inf)"),
    (radiant_energy, ([555e-9, 0.0],), "wavelengths must be finite and > 0 (got 0.0 at index (1,))"),
    (radiant_energy, ([float("nan")],), "wavelengths must be finite and > 0 (got nan at index (0,))"),
    (radiant_flux, (-1.0, 1.0), "energy must be finite and >= 0 (got -1.0)"),
    (radiant_flux, (float("inf"), 1.0), "energy must be finite and >= 0 (got inf)"),
    (radiant_flux, (1.0, 0.0), "time must be finite and > 0 (got 0.0)"),
    (radiant_flux, (1.0, -2.0), "time must be finite and > 0 (got -2.0)"),
    (radiant_flux, (1.0, float("nan")), "time must be finite and > 0 (got nan)"),
    (point_intensity, (-1.0,), "power must be finite and >= 0 (got -1.0)"),
    (point_intensity, (float("nan"),), "power must be finite and >= 0 (got nan)"),
    (point_intensity, ([1.0, -float("inf")],), "power must be finite and >= 0 (got -inf at index (1,))"),
    (power_from_intensity, (-0.5,), "intensity must be finite and >= 0 (got -0.5)"),
    (power_from_intensity, (float("inf"),), "intensity must be finite and >= 0 (got inf)"),
    (point_irradiance, (-1.0, 1.0), "power must be finite and >= 0 (got -1.0)"),
    (point_irradiance, (float("inf"), 1.0), "power must be finite and >= 0 (got inf)"),
    (point_irradiance, (1.0, 0.0), "distance must be finite and > 0 (got 0.0)"),
    (point_irradiance, (1.0, -3.0), "distance must be finite and > 0 (got -3.0)"),
    (point_irradiance, (1.0, float("inf")), "distance must be finite and > 0 (got inf)"),
    (point_irradiance, (1.0, float("nan")), "distance must be finite and > 0 (got nan)"),
    (point_irradiance, (1.0, [[1.0, 2.0], [0.0, 1.0]]), "distance must be finite and > 0 (got 0.0 at index (1, 0))"),
    (point_irradiance, (1.0, 1.0, 1.5), "cos_theta must be finite and in [-1, 1] (got 1.5)"),
    (point_irradiance, (1.0, 1.0, -1.0000001), "cos_theta must be finite and in [-1, 1] (got -1.0000001)"),
    (point_irradiance, (1.0, 1.0, float("nan")), "cos_theta must be finite and in [-1, 1] (got nan)"),
]


@pytest.mark.parametrize(
    "func, args, message",
    _BAD_CASES,
    ids=[f"{f.__name__}-{i}" for i, (f, _, _) in enumerate(_BAD_CASES)],
)
def test_validation_errors_name_parameter_and_range(func, args, message):
    with pytest.raises(ValueError, match="^" + re.escape(message) + "$"):
        func(*args)


@pytest.mark.parametrize(
    "func, args, name",
    [
        (photon_energy, ("green",), "wavelength"),
        (photon_energy, (555e-9 + 1j,), "wavelength"),
        (point_irradiance, (1.0, "far"), "distance"),
        (point_irradiance, (1j, 1.0), "power"),
    ],
)
def test_non_real_input_raises_type_error_naming_parameter(func, args, name):
    with pytest.raises(TypeError, match=rf"^{name} must be a real number"):
        func(*args)


def test_boundary_values_are_accepted():
    assert point_irradiance(0.0, 1.0) == 0.0
    assert point_irradiance(1.0, 1.0, -1.0) == 0.0
    assert point_irradiance(1.0, 1.0, 1.0) == approx(1.0 / (4.0 * math.pi), rel=1e-15)
    # smallest subnormal distance is valid input; unlit -> exactly +0.0, not nan
    for c in (0.0, -0.0, -1.0):
        e = point_irradiance(1.0, 5e-324, c)
        assert e == 0.0 and math.copysign(1.0, e) == 1.0
    assert point_irradiance(0.0, 5e-324) == 0.0


def test_true_overflow_gives_inf_with_warning():
    # Documented: only when E itself exceeds the float64 range is it inf.
    assert np.isfinite(point_irradiance(1.0, 2.2e-155))
    with pytest.warns(RuntimeWarning, match="point_irradiance overflowed to inf"):
        assert np.isinf(point_irradiance(1.0, 1e-200))
    with pytest.warns(RuntimeWarning, match="point_irradiance overflowed to inf"):
        e = point_irradiance(1.0, [1e-200, 1.0], [1.0, 1.0])
    assert np.isinf(e[0]) and e[1] == approx(1.0 / (4.0 * math.pi), rel=1e-15)


def test_public_api():
    assert set(rad.__all__) == {
        "LUMENS_PER_WATT",
        "PLANCK",
        "SPEED_OF_LIGHT",
        "photon_energy",
        "radiant_energy",
        "radiant_flux",
        "point_intensity",
        "power_from_intensity",
        "point_irradiance",
    }
