"""The built-in models 'normalized_phong_lobe' and 'normalized_blinn_lobe' (`glphong.materials.NormalizedPhongLobe`,
`glphong.materials.NormalizedBlinnLobe`) and the materials `NormalizedPhong` (Lafortune and Willems 1994) and
`NormalizedBlinnPhong` (exact normalisation), tested the way a user tests their own model.

What is specific to them (twin agreement for q = 0 to 1e7 with no Fresnel factor, Schlick and dielectric,
and for the sums, the definition's mechanics, the program key, the sums of the terms, the declared
properties and the stability cases are in tests/test_conformance.py), with the toolkit of
`glphong.testing` on both backends (fixture ``glphong_backend``); every figure below was measured on
Mesa llvmpipe and is identical through EGL and OSMesa:

- the closed forms ``f_r = rho_d/pi + rho_s (q+2)/(2 pi) max(v.r, 0)^q`` and
  ``rho_d/pi + rho_s (q+2)(q+4)/(8 pi (q + 2^(-q/2))) max(n.h, 0)^q`` (0 where n.v <= 0), written here in
  float64, at normal, oblique (40, 75 deg) and grazing (n.l = 1e-2, 1e-4) incidence, at the peak and where
  the lobe has fallen to 1/2, 1e-3 and 1e-20 (Blinn also at grazing view n.v = 1e-3), for q = 0, 1, 50,
  1e4, 1e6, the +z and a tilted normal.  The GPU (`evaluate`) lies within `cosine_power_interval` (angle
  spread 8 eps, Blinn's times max(1, 2/|l + v|); the constant to 16 eps, n.l to 4 eps), and within 1e-5
  relative at the peaks away from grazing (measured at most 3.2e-7) and, for q <= 50 and n.l >= 0.1,
  down to half the maximum (measured at most 1.2e-6).  The twin (its ``response`` on float64 unit
  vectors) matches to 1e-12 + q 1e-15 relative (measured 4.4e-10 at q = 1e6, 4.4e-12 at q = 1e4: the
  closed form's own cos^q loses q ulps), where the value is above 1e-30;
- the normalisation constants: the GLSL ``normalized_*_lobe_norm(q)`` (probed) against the closed forms
  for q from 0 to 1e7 (including q > 252, where 2^(-q/2) underflows): finite, within 12 eps (measured
  at most 1.5 eps for Phong, 3.8 eps for Blinn); the twin in float64 to 4e-15 (measured 2.2e-16), and
  in float32 within 12 eps; the approximation (q+8)/(8 pi) is 2.4 %, 7.5 %, 1.8 % and 0.2 % high at
  q = 1, 10, 100, 1000 (at most 7.52 %, near q = 8.8);
- reciprocity: f_r(wi, wo) = f_r(wo, wi) for both materials, by the twin for q = 0, 1, 50, 1e4 (bound
  1e-12 + q 1e-15 relative; measured at most 3.6e-15) and on the GPU at q = 20 (bound 1e-5; measured at
  most 2.1e-7); its violation for NormalizedPhong with a Fresnel factor F(n.l) (exactly the ratio
  F(n.l)/F(n.v), more than 50 % where a direction grazes), not for NormalizedBlinnPhong with F(h.l);
- directional albedo by Gauss-Legendre quadrature of the twin (float64): NormalizedBlinnPhong's at
  normal incidence is rho_s to 1e-4 relative for q = 1, 10, 100, 1000 (measured at most 2.8e-14), while
  the (q+8)/(8 pi) normalisation would reflect (q+8)/(8 pi c(q)) rho_s, 2e-3 to 7.5e-2 off; both lobes'
  albedo is rho_s at normal incidence (measured at most 6.8e-14 on the 2D grid) and decreases at 30,
  60, 80 deg for q = 1, 10, 100, 1000 (e.g. Phong q = 100: 1, 0.866, 0.5, 0.175; Blinn q = 100: 1,
  0.755, 0.265, 0.049), and with the diffuse term (albedo rho_d at every angle) stays at most
  rho_d + rho_s;
- the twin's support: non-zero wherever the lobe is (Phong: n.l > 0 and v.r > 0, or q = 0), the same pairs
  with and without a Fresnel factor (it never zeroes a response); never NaN or Inf on the GPU and never
  above ``rho_s c(q) n.l`` for q up to 1e7 (no Inf * 0 with c(1e7) = 4e5 or 1.6e6);
- the declaration (params and ranges, needs 'view', no choices, Fresnel cosines n.l and h.l, vanishes
  with rho_s, declared properties and their conditions) and the sums' terms and arguments;
- one render of a sphere under a point light per material through ``glphong_renderer``, passing
  `assert_render_matches` (relative error measured 3.7e-5 where the twin is at least 2^-100; bound 1e-3);
- the models' 38 stability cases each (run in the conformance test): the generic geometry, the exponent
  sweep q = 0 to 1e7 at, near and in the tail of the peak, Fresnel at grazing incidence at the peak.
"""
import numpy as np
import pytest

import glphong
import glphong.primitives
from glphong.testing import probe
from glphong.materials import (DielectricFresnel, Diffuse, NormalizedBlinnLobe, NormalizedBlinnPhong,
                               NormalizedPhong, NormalizedPhongLobe, SchlickFresnel, ShadingFrame)
from glphong.materials.normalized import normalized_blinn_lobe_norm
from glphong.checks.stability import cases_for
from glphong.testing import (assert_render_matches, cosine_power_interval, direction, direction_sets, evaluate,
                             float32_units, frame_around, rotate_toward)

EPS = 2.0 ** -24
FLT_MIN = 2.0 ** -126
RHO_S = (0.5, 0.0, 0.2)
QS = [0.0, 1.0, 50.0, 1e4, 1e6]
#: a tilted unit normal: r, h and the dot products are then computed with rounding
TILTED = np.array([0.3, -0.2, 0.9]) / np.linalg.norm([0.3, -0.2, 0.9])
NORMALS = [np.array([0.0, 0.0, 1.0]), TILTED]
LOBES = {"phong": NormalizedPhongLobe, "blinn": NormalizedBlinnLobe}
SUMS = {"phong": NormalizedPhong, "blinn": NormalizedBlinnPhong}


def f32(x):
    return np.asarray(x, dtype=np.float32).astype(np.float64)


# --------------------------------------------------------------------------- independent closed forms
def c_phong(q):
    """Lafortune and Willems' normalisation (q + 2) / (2 pi)."""
    return (q + 2.0) / (2.0 * np.pi)


def c_blinn(q):
    """The exact Blinn normalisation: the normal-incidence albedo integral
    2 pi int_0^(pi/2) cos^q(theta/2) cos(theta) sin(theta) d theta = 8 pi (q + 2^(-q/2)) / ((q + 2)(q + 4))
    (x = cos(theta/2): 8 pi int_(1/sqrt 2)^1 x^(q+1) (2 x^2 - 1) dx), inverted."""
    return (q + 2.0) * (q + 4.0) / (8.0 * np.pi * (q + 2.0 ** (-q / 2.0)))


def c_blinn_approximate(q):
    """The common approximation (q + 8) / (8 pi)."""
    return (q + 8.0) / (8.0 * np.pi)


def closed_form_f_r(kind, rho_d, rho_s, q, n, wi, wo):
    """``f_r`` (N, 3) of the textbook formulas in float64: 0^0 := 1 (numpy's 0.0 ** 0 is 1)."""
    n_dot_l, n_dot_v = wi @ n, wo @ n
    if kind == "phong":
        r = 2 * n_dot_l[:, None] * n - wi
        lobe = c_phong(q) * np.maximum(np.sum(wo * r, axis=1), 0.0) ** q
    else:
        h = (wi + wo) / np.linalg.norm(wi + wo, axis=1, keepdims=True)
        lobe = np.where(n_dot_v > 0, c_blinn(q) * np.maximum(h @ n, 0.0) ** q, 0.0)
    return np.asarray(rho_d) / np.pi + np.asarray(rho_s) * lobe[:, None]


def twin_f_r(material, n, wi, wo):
    """``f_r`` by the twin: the sum of the terms' ``response`` over ``n.l``, on the float64 unit vectors
    given (no float32 rounding of the directions; the parameters are the GPU's float32 values)."""
    n = np.broadcast_to(np.asarray(n, dtype=np.float64), wi.shape)
    n_dot_l = np.sum(n * wi, axis=1)
    frame = ShadingFrame(n)
    total = sum(term.response(frame, wi, wo, n_dot_l, term.values()) for term in material.components
                if not term.vanishes())
    return total / n_dot_l[:, None]


def hemisphere_pairs(count, seed):
    rng = np.random.default_rng(seed)
    v = rng.normal(size=(2, count, 3))
    v[..., 2] = np.abs(v[..., 2]) + 1e-3
    v /= np.linalg.norm(v, axis=2, keepdims=True)
    return v[0], v[1]


# --------------------------------------------------------------------------- closed form
def closed_form_rows(kind, n, q):
    """``(wi, wo, labels)``: the light at normal, 40 and 75 deg and grazing incidence (n.l = 1e-2, 1e-4),
    the view at the lobe's peak and where the lobe has fallen to 1/2, 1e-3 and 1e-20 (q > 1), or 0.3 and
    0.7 rad off (q <= 1).  Phong rotates v away from r; Blinn tilts h away from n and reflects l about it.
    Blinn also gets views at grazing (n.v = 1e-3)."""
    t, _ = frame_around(n)
    width = 1.0 if kind == "phong" else 0.5  # Blinn's h turns by half the angle v does
    if q > 1:
        offsets = {"peak": 0.0, "half maximum": np.arccos(0.5 ** (1 / q)),
                   "1e-3 of maximum": np.arccos(1e-3 ** (1 / q)), "1e-20 of maximum": np.arccos(1e-20 ** (1 / q))}
    else:
        offsets = {"peak": 0.0, "0.3 rad off": 0.3 * width, "0.7 rad off": 0.7 * width}
    lights = {"normal incidence": 0.0, "40 deg": np.radians(40.0), "75 deg": np.radians(75.0),
              "grazing n.l=1e-2": np.arccos(1e-2), "grazing n.l=1e-4": np.arccos(1e-4)}
    wi, wo, labels = [], [], []
    for light, theta in lights.items():
        l = direction(n, theta, 0.3)
        r = 2 * np.dot(n, l) * n - l
        for where, alpha in offsets.items():
            if kind == "phong":
                v = rotate_toward(r, n if theta > 0 else t, alpha)
            else:
                h = rotate_toward(n, l if theta > 0 else t, alpha)
                v = 2 * np.dot(h, l) * h - l
            wi.append(l)
            wo.append(v)
            labels.append(f"{light}, {where}")
    if kind == "blinn":
        for phi in (0.3, 0.3 + np.pi, 2.0):
            wi.append(direction(n, np.radians(40.0), 0.3))
            wo.append(direction(n, np.arccos(1e-3), phi))
            labels.append(f"grazing view n.v=1e-3, azimuth {phi:.2f}")
    wi, wo = np.array(wi), np.array(wo)
    assert np.all(np.abs(wo @ n) > 1e-5), "keep clear of Blinn's n.v gate (8 eps)"
    return wi, wo, labels


@pytest.mark.parametrize("normal", NORMALS, ids=["normal+z", "normal-tilted"])
@pytest.mark.parametrize("q", QS, ids=[f"q={q:g}" for q in QS])
@pytest.mark.parametrize("kind", ["phong", "blinn"])
def test_closed_form(glphong_backend, kind, q, normal):
    wi, wo, labels = closed_form_rows(kind, normal, q)
    n_dot_l, n_dot_v = wi @ normal, wo @ normal
    rho_s = f32(RHO_S)
    lobe_model = LOBES[kind](RHO_S, q)
    expected = (closed_form_f_r(kind, 0.0, rho_s, q, normal, wi, wo)) * n_dot_l[:, None]  # the lobe's response
    # the twin on the exact float64 directions: the same values, up to float64 rounding amplified by q
    twin = twin_f_r(lobe_model, normal, wi, wo) * n_dot_l[:, None]
    # (below 1e-30: lobe_from_delta's floor exp(-104) keeps the twin at 1e-45 c(q) where float64's
    # cos^q underflows to 0; the GPU flushes both)
    on = expected[:, 0] > 1e-30
    rel = np.abs(twin[on, 0] - expected[on, 0]) / expected[on, 0]
    assert rel.max() < 1e-12 + q * 1e-15  # measured 4.4e-10 (q = 1e6, the 1e-20 tail)
    assert np.all(twin[~on] < 1e-30)

    gpu = evaluate(lobe_model, wi, wo, normal=normal, backend=glphong_backend).astype(np.float64)
    assert np.all(gpu[:, 1] == 0.0)  # the zero channel
    if kind == "blinn":
        assert np.all(gpu[n_dot_v <= 0] == 0.0)
    # the lobe within cosine_power_interval: the GPU sees the angle from the peak within +- spread
    if kind == "phong":
        cos_alpha = np.sum(wo * (2 * n_dot_l[:, None] * normal - wi), axis=1)
        spread = 8 * EPS
        norm = c_phong(q)
    else:
        h_len = np.linalg.norm(wi + wo, axis=1)
        cos_alpha = ((wi + wo) @ normal) / h_len
        spread = 8 * EPS * np.maximum(1.0, 2.0 / h_len)
        norm = c_blinn(q)
    low, high = cosine_power_interval(cos_alpha, q, spread)
    if kind == "blinn":
        low, high = np.where(n_dot_v > 0, low, 0.0), np.where(n_dot_v > 0, high, 0.0)
    # the constant, n.l (the GPU's dot product of rounded unit vectors: within 4 eps) and the products
    low = rho_s * (norm * (1 - 16 * EPS) * low * np.maximum(n_dot_l - 4 * EPS, 0.0))[:, None]
    high = rho_s * (norm * (1 + 16 * EPS) * high * (n_dot_l + 4 * EPS))[:, None]
    low = np.where(low < FLT_MIN, 0.0, low)
    high = np.where(high < FLT_MIN, FLT_MIN, high)
    bad = ~((gpu >= low) & (gpu <= high))
    assert not bad.any(), "\n".join(
        f"{labels[i]}: gpu {gpu[i]}, closed form {expected[i]}, interval ({low[i]}, {high[i]})"
        for i in np.nonzero(bad.any(axis=1))[0])
    # flat relative tolerance where the lobe's q-amplified angle sensitivity does not dominate: the peak
    # (not grazing), and for q <= 50 the rows with n.l >= 0.1 down to half the maximum
    peak = np.array([s.endswith("peak") and "grazing" not in s for s in labels])
    shallow = np.array([s.endswith(("half maximum", "rad off")) for s in labels])
    flat = peak | ((n_dot_l >= 0.1) & (q <= 50) & shallow & (expected[:, 0] > 0))
    rel = np.abs(gpu[flat, 0] - expected[flat, 0]) / expected[flat, 0]
    assert rel.max() < 1e-5  # measured at most 3.2e-7 at the peaks, 1.2e-6 for q <= 50


@pytest.mark.parametrize("kind", ["phong", "blinn"])
def test_normalisation_constants_in_float32(glphong_context, kind):
    """The GLSL constants (probed) against the closed forms, q = 0 to 1e7: finite, a few eps."""
    qs = np.concatenate([[0.0, 0.5, 1.0, 2.0, 8.764, 100.0, 252.0, 253.0, 300.0], np.logspace(-3, 7, 60), [1e7]])
    qs = f32(qs)
    gpu = probe.evaluate(glphong_context, f"normalized_{kind}_lobe_norm", q=qs)["return"].astype(np.float64)
    want = c_phong(qs) if kind == "phong" else c_blinn(qs)
    assert np.all(np.isfinite(gpu))
    np.testing.assert_allclose(gpu, want, rtol=12 * EPS, atol=0)  # measured at most 1.5 eps (Phong), 3.8 eps (Blinn)
    twin = getattr(glphong.reference, f"normalized_{kind}_lobe_norm")  # found by glphong.reference
    np.testing.assert_allclose(twin(qs), want, rtol=4e-15, atol=0)
    single = twin(qs.astype(np.float32))  # dtype-generic: the same arithmetic in float32
    assert single.dtype == np.float32 and np.all(np.isfinite(single))
    np.testing.assert_allclose(single.astype(np.float64), want, rtol=12 * EPS, atol=0)
    assert want.max() < (1.6e6 if kind == "phong" else 4e5)  # finite and modest: never Inf * 0


def test_the_approximate_blinn_normalisation_differs():
    """(q + 8) / (8 pi) is only an approximation of c(q): too high by up to 7.5 % (near q = 9)."""
    q = np.array([0.0, 1.0, 10.0, 100.0, 1000.0, 1e6])
    ratio = c_blinn_approximate(q) / c_blinn(q)
    np.testing.assert_allclose(ratio, [1.0, 1.0242640687, 1.0747767857, 1.0180995475, 1.0019801035, 1.000002],
                               rtol=1e-6)
    dense = np.linspace(0.0, 200.0, 20001)
    worst = np.max(c_blinn_approximate(dense) / c_blinn(dense))
    assert 1.075 < worst < 1.0753
    assert abs(normalized_blinn_lobe_norm(10.0) / c_blinn_approximate(10.0) - 1) > 0.06


# --------------------------------------------------------------------------- reciprocity
@pytest.mark.parametrize("q", [0.0, 1.0, 50.0, 1e4])
@pytest.mark.parametrize("kind", ["phong", "blinn"])
def test_reciprocity_twin(kind, q):
    wi, wo = hemisphere_pairs(2000, 3)
    for normal in NORMALS:
        material = SUMS[kind](0.2, RHO_S, q)
        a = twin_f_r(material, normal, wi, wo)
        b = twin_f_r(material, normal, wo, wi)
        ok = (wi @ normal > 0) & (wo @ normal > 0)
        assert ok.sum() > 1000
        np.testing.assert_allclose(a[ok], b[ok], rtol=1e-12 + q * 1e-15, atol=0)  # measured at most 3.6e-15
        np.testing.assert_allclose(a[ok], closed_form_f_r(kind, f32(0.2), f32(RHO_S), q, normal, wi[ok], wo[ok]),
                                   rtol=1e-12 + q * 1e-15, atol=0)


def test_reciprocity_gpu(glphong_backend):
    wi, wo = hemisphere_pairs(1000, 4)
    for kind in ("phong", "blinn"):
        material = SUMS[kind](0.2, RHO_S, 20.0)
        a = evaluate(material, wi, wo, backend=glphong_backend).astype(np.float64) / float32_units(wi)[:, 2:3]
        b = evaluate(material, wo, wi, backend=glphong_backend).astype(np.float64) / float32_units(wo)[:, 2:3]
        assert np.all(a > 0) and np.all(b > 0)
        rel = np.abs(a - b) / a
        assert rel.max() < 1e-5, kind  # measured at most 2.1e-7 (diffuse 0.2/pi bounds f_r from below)


def test_fresnel_at_n_dot_l_breaks_phong_reciprocity_but_not_blinn():
    wi, wo = hemisphere_pairs(500, 5)
    n = NORMALS[0]
    fresnel = SchlickFresnel(0.04)
    f0 = f32(0.04)  # the GPU's (and the twin's) float32 f0
    schlick = lambda c: f0 + (1 - f0) * (1 - c) ** 5  # noqa: E731
    phong_lobe = NormalizedPhongLobe(0.5, 30.0, fresnel)
    a, b = twin_f_r(phong_lobe, n, wi, wo), twin_f_r(phong_lobe, n, wo, wi)
    on = a[:, 0] > 1e-200
    ratio = a[on, 0] / b[on, 0]
    np.testing.assert_allclose(ratio, schlick(wi[on, 2]) / schlick(wo[on, 2]), rtol=1e-12)
    assert np.max(np.abs(ratio - 1)) > 0.5  # strongly violated where one direction grazes
    blinn = NormalizedBlinnPhong(0.2, 0.5, 30.0, fresnel)
    np.testing.assert_allclose(twin_f_r(blinn, n, wi, wo), twin_f_r(blinn, n, wo, wi), rtol=1e-12, atol=0)


# --------------------------------------------------------------------------- directional albedo
def _gauss(a, b, count):
    x, w = np.polynomial.legendre.leggauss(count)
    return 0.5 * (b - a) * x + 0.5 * (b + a), 0.5 * (b - a) * w


def blinn_normal_albedo(material):
    """``2 pi int f_r cos(theta) sin(theta) d theta`` at normal incidence (azimuthally symmetric), by
    Gauss-Legendre on [0, theta_c] and [theta_c, pi/2], theta_c where cos^q(theta/2) < e^-100."""
    q = float(material.q)
    theta_c = min(np.pi / 2, 30.0 / np.sqrt(max(q, 1.0)))
    parts = [_gauss(0.0, theta_c, 400)] + ([_gauss(theta_c, np.pi / 2, 100)] if theta_c < np.pi / 2 else [])
    theta = np.concatenate([p[0] for p in parts])
    weight = np.concatenate([p[1] for p in parts])
    wo = np.stack([np.sin(theta), np.zeros_like(theta), np.cos(theta)], axis=1)
    wi = np.tile([0.0, 0.0, 1.0], (len(theta), 1))
    f = twin_f_r(material, np.array([0.0, 0.0, 1.0]), wi, wo)
    return 2 * np.pi * np.sum(f * (np.cos(theta) * np.sin(theta) * weight)[:, None], axis=0)


def directional_albedo(material, theta_i, axis, a_max, count=300):
    """``int f_r max(n.v, 0) d omega_v`` at incidence ``theta_i`` (light in the xz-plane, n = +z), by
    Gauss-Legendre in polar coordinates (alpha, phi) about the unit ``axis``, alpha in [0, a_max]:
    the caller puts the axis at the lobe's peak and a_max where the integrand has fallen below e^-100
    (or at pi/2 about n, for the whole hemisphere)."""
    n = np.array([0.0, 0.0, 1.0])
    l = np.array([np.sin(theta_i), 0.0, np.cos(theta_i)])
    alpha, wa = _gauss(0.0, a_max, count)
    phi, wp = _gauss(0.0, 2 * np.pi, count)
    t, b = frame_around(axis)
    A, P = (g.ravel() for g in np.meshgrid(alpha, phi, indexing="ij"))
    v = np.cos(A)[:, None] * axis + np.sin(A)[:, None] * (np.cos(P)[:, None] * t + np.sin(P)[:, None] * b)
    weight = np.outer(wa * np.sin(alpha), wp).ravel()
    up = v[:, 2] > 0
    f = twin_f_r(material, n, np.tile(l, (int(up.sum()), 1)), v[up])
    return np.sum(f * (v[up, 2] * weight[up])[:, None], axis=0)


def lobe_albedo(lobe, theta_i, kind):
    """The lobe's directional albedo: about its peak r (Phong: v = r; Blinn: h = n), alpha up to where
    cos^q(alpha) (Phong) or cos^q(alpha/2) (Blinn) is below e^-100, and never past the horizon at
    normal incidence (where the integrand is then smooth)."""
    q = float(lobe.q)
    l = np.array([np.sin(theta_i), 0.0, np.cos(theta_i)])
    axis = 2 * l[2] * np.array([0.0, 0.0, 1.0]) - l
    if kind == "phong":  # the lobe is 0 beyond alpha = pi/2
        a_max = min(np.pi / 2, 15.0 / np.sqrt(q))
    else:
        a_max = min(np.pi / 2 if theta_i == 0 else np.pi, 30.0 / np.sqrt(q))
    return directional_albedo(lobe, theta_i, axis, a_max)


@pytest.mark.parametrize("q", [1.0, 10.0, 100.0, 1000.0])
def test_blinn_albedo_at_normal_incidence_is_rho_s(q):
    rho_s = (0.5, 0.25, 1.0)
    albedo = blinn_normal_albedo(NormalizedBlinnLobe(rho_s, q))
    np.testing.assert_allclose(albedo, f32(rho_s), rtol=1e-4)  # measured at most 2.8e-14
    # the (q + 8) / (8 pi) normalisation reflects (q + 8)/(8 pi c(q)) of rho_s instead: 2e-3 to 7.5e-2 off
    approximate = albedo * c_blinn_approximate(q) / c_blinn(q)
    assert np.all(np.abs(approximate / f32(rho_s) - 1) > 1.9e-3)
    np.testing.assert_allclose(approximate / f32(rho_s), c_blinn_approximate(q) / c_blinn(q), rtol=1e-4)


@pytest.mark.parametrize("q", [1.0, 10.0, 100.0, 1000.0])
@pytest.mark.parametrize("kind", ["phong", "blinn"])
def test_albedo_is_rho_s_at_normal_incidence_and_decreases(kind, q):
    rho_d, rho_s = 0.3, 0.6
    lobe = LOBES[kind](rho_s, q)
    angles = np.radians([0.0, 30.0, 60.0, 80.0])
    albedo = np.array([lobe_albedo(lobe, theta, kind)[0] for theta in angles]) / f32(rho_s)
    np.testing.assert_allclose(albedo[0], 1.0, rtol=1e-4)  # measured at most 6.8e-14
    assert np.all(np.diff(albedo) < 0), albedo  # e.g. Phong q = 100: 1, 0.866, 0.5, 0.175
    diffuse = np.array([directional_albedo(Diffuse(rho_d), theta, np.array([0.0, 0.0, 1.0]), np.pi / 2, 100)[0]
                        for theta in angles])
    np.testing.assert_allclose(diffuse, f32(rho_d), rtol=1e-10)  # rho_d at every angle
    total = diffuse + albedo * f32(rho_s)
    assert np.all(total <= f32(rho_d) + f32(rho_s) * (1 + 1e-10))  # energy: at most rho_d + rho_s


# --------------------------------------------------------------------------- the twin's support
TWIN_QS = [0.0, 1.0, 50.0, 1e4, 1e6, 1e7]
FRESNELS = [None, SchlickFresnel(0.04), DielectricFresnel(1.5)]


@pytest.mark.parametrize("q", TWIN_QS, ids=[f"q={q:g}" for q in TWIN_QS])
@pytest.mark.parametrize("kind", ["phong", "blinn"])
def test_the_twin_is_non_zero_where_the_lobe_is(kind, q):
    """The pairs of the conformance test's twin check: the Fresnel factor never zeroes a response, and the
    Phong lobe is non-zero wherever n.l > 0 and v.r > 0 (or q = 0)."""
    wi, wo, _ = direction_sets(1000, 0)
    nonzero = {int(np.any(evaluate(LOBES[kind](RHO_S if fresnel is None else 1.0, q, fresnel), wi, wo, twin=True) != 0,
                          axis=1).sum()) for fresnel in FRESNELS}
    assert len(nonzero) == 1
    if kind == "phong":
        l, v = float32_units(wi), float32_units(wo)
        v_dot_r = np.sum(v * (2 * l[:, 2:3] * np.array([0.0, 0.0, 1.0]) - l), axis=1)
        assert nonzero == {int(np.sum((l[:, 2] > 0) & ((v_dot_r > 0) | (q == 0))))}


@pytest.mark.parametrize("q", [1.0, 50.0, 1e4, 1e7])
@pytest.mark.parametrize("kind", ["phong", "blinn"])
def test_finite_and_never_above_the_peak(glphong_backend, kind, q):
    """``rho_s c(q) lobe (n.l) <= rho_s c(q) (n.l)``: finite (no Inf * 0 with c(1e7) ~ 4e5 to 1.6e6)."""
    wi, wo, _ = direction_sets(1000, 1)
    gpu = evaluate(LOBES[kind](RHO_S, q), wi, wo, backend=glphong_backend).astype(np.float64)
    assert np.all(np.isfinite(gpu)) and np.all(gpu >= 0.0)
    norm = c_phong(q) if kind == "phong" else c_blinn(q)
    bound = f32(RHO_S) * (norm * np.maximum(float32_units(wi)[:, 2:3], 0.0) + 8 * EPS) * (1 + 16 * EPS)
    assert np.all(gpu <= bound)
    assert gpu.max() > 0.1 * norm * 0.5  # the peak is in the set (the mirror direction)


# --------------------------------------------------------------------------- the declaration
@pytest.mark.parametrize("kind", ["phong", "blinn"])
def test_declaration(kind):
    lobe, total = LOBES[kind], SUMS[kind]
    assert lobe.name == f"normalized_{kind}_lobe"
    assert total.name == ("normalized_phong" if kind == "phong" else "normalized_blinn_phong")
    rho_s, q = lobe.params
    assert (rho_s.name, rho_s.kind, rho_s.glsl_type, rho_s.interval, rho_s.unit, rho_s.default) == \
        ("rho_s", "rgb", "vec3", "[0, 1]", "", None)
    assert (q.name, q.kind, q.glsl_type, q.interval, q.unit, q.default) == ("q", "scalar", "float", "[0, 1e+07]", "",
                                                                            None)
    assert lobe.needs == ("view",) and lobe.uses == ("lobe",) and lobe.choices == ()
    assert lobe.fresnel_slot.cosine == ("n.l" if kind == "phong" else "h.l") and lobe.fresnel_slot.default is None
    assert lobe.ambient is None and lobe.vanishes_with == ("rho_s",)
    p = lobe.properties
    assert (p.reciprocal, p.isotropic, p.energy_conserving, p.non_negative) == (True, True, True, True)
    p = total.properties
    assert (p.reciprocal, p.isotropic, p.energy_conserving, p.non_negative) == (True, True, True, True)
    assert "rho_d + rho_s <= 1" in p.condition
    assert total.terms == (Diffuse, lobe)
    assert [a.name for a in total.arguments()] == ["rho_d", "rho_s", "q", "fresnel"]


# --------------------------------------------------------------------------- a render
@pytest.mark.parametrize("kind", ["phong", "blinn"])
def test_render_matches(glphong_renderer, kind):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene = glphong.Scene(camera, lights=[glphong.PointLight((1.5, 1.0, 3.0), (80.0, 60.0, 40.0))])
    material = (NormalizedPhong(0.2, RHO_S, 20.0) if kind == "phong"
                else NormalizedBlinnPhong((0.1, 0.2, 0.3), 0.6, 80.0, SchlickFresnel(0.5)))
    scene.add(glphong.primitives.sphere(3), material)
    report = assert_render_matches(scene, glphong_renderer)
    assert report.covered_pixels > 1000 and report.nonfinite_count == 0
    assert report.gpu[..., 0].max() > 0.1  # the highlight is in the picture
    covered = report.mask[..., None] & (report.reference >= 2.0 ** -100)
    assert report.relative_error[covered].max() < 1e-3


# --------------------------------------------------------------------------- stability
@pytest.mark.parametrize("lobe", [NormalizedPhongLobe, NormalizedBlinnLobe], ids=["phong", "blinn"])
def test_stability_case_list(lobe):
    """What the cases the conformance test runs hold."""
    cases = cases_for(lobe)
    assert len(cases) == 38
    assert {"grazing", "behind", "opposite", "lobe", "fresnel"} <= {c.group for c in cases}
    assert any("q=1e+07 peak" in c.name for c in cases) and any("q=1e+06 tail" in c.name for c in cases)
