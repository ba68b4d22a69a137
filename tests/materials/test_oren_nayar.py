"""The built-in model 'oren_nayar' (`glphong.materials.OrenNayar`, Oren and Nayar 1994), both forms,
tested the way a user tests their own model.

What is specific to it (twin agreement for sigma = 0 to pi/2, both forms, and with a tilted normal, the
definition's mechanics, the program key, vanishing at rho = 0, the declared properties and the 60
stability cases are in tests/test_conformance.py), with the toolkit of `glphong.testing` on both
backends (fixture ``glphong_backend``); figures measured on Mesa llvmpipe (LLVM 15), identical through
EGL and OSMesa:

- closed form: an independent float64 implementation written here straight from the paper
  (``theta = atan2(|n x w|, n.w)``, the azimuths by ``atan2`` in a tangent frame, ``tan`` and
  ``sin`` of the angles, no stabilisation) at 210 direction pairs per case (the light at 0, 1e-4
  rad, 30, 60 and 85 deg and n.l = 1e-2, 1e-4; the view at 0, 20, 45, 70 deg and n.v = 1e-2, 1e-4;
  azimuth differences 0 (retro), 0.7, pi/2, 2.4 and pi (forward)), sigma = 0.3, 1 and pi/2, +z
  and a tilted normal.  The error is measured relative to ``|value| + rho/pi (n.l)`` (the value
  plus Lambert's: the full form's summands cancel where it crosses 0 at large sigma).  The twin,
  called on exact float64 unit vectors, agrees to 5.1e-13 (bound 1e-12); through
  ``evaluate(..., twin=True)`` (float32 inputs, not exactly unit) to 4.6e-8 (bound 2e-7); the GPU
  to 3.2e-7 with the +z normal (bound 1e-6), and with the tilted normal within the closed form's
  interval over polar angles +-8 eps (its float32 n.l and n.v err by a few eps absolute, which at
  n.l = n.v = 1e-4 moves the value by 9.4e-5 relative) widened by 1e-7 measured (bound 1e-6);
- sigma = 0 is Lambert: bit-identical to `Diffuse` (GPU and twin) wherever n.v > 0;
- the limits: l = n and v = n (azimuth undefined; the value is the limit rho/pi C1 + 0.17 rho^2/pi
  s2/(s2 + 0.13), continuous as l -> n to 1e-7 rad), exactly 0 where n.v <= 0, finite and bounded
  by 2 rho/pi where both directions graze to 1e-30 (f_r diverges there, f_r (n.l) does not);
- reciprocity: twin f_r(l, v) = f_r(v, l) to 5.6e-16 of |f_r| + rho/pi (bound 1e-13) on 4000 random
  pairs at sigma = 0.3, 1, pi/2, checked separately where c < 0 and c >= 0 (the full form's two C2
  cases), both forms; the GPU's to 2.6e-7 (bound 1e-5, n.l and n.v above 1e-2);
- retro-reflection (the Moon's flat look): with l = v at 60, 75 and 85 deg the radiance toward
  the light exceeds Lambert's for sigma = 0.3, 0.6, 1 (both forms; at sigma = 1: 1.31x / 2.15x /
  5.34x at 60 / 75 / 85 deg (full), 1.24x / 2.11x / 5.33x (qualitative)); at normal incidence it is
  below Lambert's (C1 = A < 1: 0.74x (full), 0.62x (qualitative) at sigma = 1);
- directional albedo by Gauss-Legendre quadrature (float64 twin, rho = 1, split at the kinks
  theta_o = theta_i and c = 0) at theta_i = 0, 30, 60, 80 and 89.99 deg.  Measured (full /
  qualitative): sigma = 0: 1 to 1e-12 at every angle; sigma = 0.3: 0.962 / 0.893 at normal
  incidence, 1.051 / 1.005 at 89.99 deg; sigma = pi/2: 0.720 / 0.559 and 0.891 / 0.776.  The
  largest, over sigma in [0, pi/2]: 1.051 (full, sigma ~ 0.3) and 1.015 (qualitative, sigma
  ~ 0.2), both toward grazing incidence: not energy-conserving, as declared;
- the twin is non-zero exactly where both the light and the view are above the surface;
- one render of a sphere under a point light and an ambient light through ``glphong_renderer``,
  passing `assert_render_matches` (max relative error 1.17e-6 measured, bound 1e-5; where the light
  does not reach (181 pixels) the ambient answer is Lambert's rho/pi L_a);
- the declaration: params and ranges, needs, the form choice, the ambient answer (Lambert's rho/pi L_a),
  vanishes with rho (not with sigma), declared properties.
"""
import numpy as np
import pytest

import glphong
import glphong.primitives
from glphong.materials import Diffuse, OrenNayar, Properties, ShadingFrame
from glphong.checks.stability import cases_for
from glphong.testing import (assert_render_matches, direction, direction_sets, evaluate, float32_units, frame_around,
                             rotate_toward)

EPS = 2.0 ** -24
RHO = (0.8, 0.0, 0.3)
FORMS = ("full", "qualitative")
#: a tilted unit normal: n.l and n.v are then rounded float32 dot products
TILTED = np.array([0.3, -0.2, 0.9]) / np.linalg.norm([0.3, -0.2, 0.9])
Z = np.array([0.0, 0.0, 1.0])


def f32(x):
    return np.asarray(x, dtype=np.float32).astype(np.float64)


def twin(material, wi, wo, normal=Z):
    """The twin called directly on float64 unit vectors (no float32 rounding of the directions)."""
    n = np.tile(normal, (len(wi), 1))
    return material.response(ShadingFrame(n), wi, wo, wi @ normal, material.values())


# --------------------------------------------------------------------------- closed form
def closed_form(rho, sigma, form, n, wi, wo):
    """``f_r (n.l)`` straight from the paper, in float64 (0 where n.v <= 0): the angles by atan2, the
    azimuth difference from atan2 in a tangent frame, tan and sin of the angles."""
    n = n / np.linalg.norm(n)
    wi = wi / np.linalg.norm(wi, axis=1, keepdims=True)
    wo = wo / np.linalg.norm(wo, axis=1, keepdims=True)
    cos_i, cos_o = wi @ n, wo @ n
    theta_i = np.arctan2(np.linalg.norm(np.cross(n, wi), axis=1), cos_i)
    theta_o = np.arctan2(np.linalg.norm(np.cross(n, wo), axis=1), cos_o)
    t, b = frame_around(n)
    c = np.cos(np.arctan2(wo @ b, wo @ t) - np.arctan2(wi @ b, wi @ t))  # beta = 0 makes it irrelevant at theta = 0
    alpha, beta = np.maximum(theta_i, theta_o), np.minimum(theta_i, theta_o)
    s2 = sigma * sigma
    rho = np.asarray(rho, dtype=np.float64)[None]
    if form == "qualitative":
        a, b_ = 1 - 0.5 * s2 / (s2 + 0.33), 0.45 * s2 / (s2 + 0.09)
        f = rho / np.pi * (a + b_ * np.maximum(0.0, c) * np.sin(alpha) * np.tan(beta))[:, None]
    else:
        c1 = 1 - 0.5 * s2 / (s2 + 0.33)
        c2 = np.where(c >= 0, 0.45 * s2 / (s2 + 0.09) * np.sin(alpha),
                      0.45 * s2 / (s2 + 0.09) * (np.sin(alpha) - (2 * beta / np.pi) ** 3))
        c3 = 0.125 * s2 / (s2 + 0.09) * (4 * alpha * beta / np.pi ** 2) ** 2
        f = (rho / np.pi * (c1 + c * c2 * np.tan(beta) + (1 - np.abs(c)) * c3 * np.tan((alpha + beta) / 2))[:, None]
             + 0.17 * rho ** 2 / np.pi * s2 / (s2 + 0.13) * (1 - c * (2 * beta / np.pi) ** 2)[:, None])
    return np.where((cos_o > 0)[:, None], f * cos_i[:, None], 0.0)


LIGHTS = (0.0, 1e-4, np.radians(30.0), np.radians(60.0), np.radians(85.0), np.arccos(1e-2), np.arccos(1e-4))
VIEWS = (0.0, np.radians(20.0), np.radians(45.0), np.radians(70.0), np.arccos(1e-2), np.arccos(1e-4))
AZIMUTHS = (0.0, 0.7, np.pi / 2, 2.4, np.pi)


def closed_form_rows(n):
    """210 pairs: every light polar angle with every view polar angle and azimuth difference."""
    wi = [direction(n, ti, 0.4) for ti in LIGHTS for _ in VIEWS for _ in AZIMUTHS]
    wo = [direction(n, to, 0.4 + dphi) for _ in LIGHTS for to in VIEWS for dphi in AZIMUTHS]
    return np.array(wi), np.array(wo)


def _tilt(w, n, angle):
    """Rows of unit ``w`` turned toward ``n`` by ``angle`` (away for negative); rows along n unchanged."""
    return np.array([x if abs(np.dot(x, n)) > 1 - 1e-15 else rotate_toward(x, n, angle) for x in w])


def _scale(value, rho, n_dot_l):
    """``|value| + rho/pi (n.l)``: what the errors are measured against."""
    return np.abs(value) + np.asarray(rho)[None] / np.pi * n_dot_l[:, None]


@pytest.mark.parametrize("form", FORMS)
@pytest.mark.parametrize("sigma", [0.3, 1.0, np.pi / 2], ids=["sigma=0.3", "sigma=1", "sigma=pi/2"])
def test_twin_closed_form(form, sigma):
    """The float64 twin on exact unit vectors against the paper's formula: 1e-12 (measured 5.1e-13)."""
    m = OrenNayar(RHO, sigma, form=form)
    for normal in (Z, TILTED):
        wi, wo = closed_form_rows(normal)
        expected = closed_form(f32(RHO), f32(sigma), form, normal, wi, wo)
        got = twin(m, wi, wo, normal)
        scale = _scale(expected, f32(RHO), wi @ normal)
        error = np.abs(got - expected) / np.where(scale > 0, scale, 1.0)
        assert error.max() < 1e-12, (normal, error.max())
        assert np.all(got[(wo @ normal) <= 0] == 0.0)


@pytest.mark.parametrize("form", FORMS)
@pytest.mark.parametrize("normal", [Z, TILTED], ids=["normal+z", "normal-tilted"])
@pytest.mark.parametrize("sigma", [0.3, 1.0, np.pi / 2], ids=["sigma=0.3", "sigma=1", "sigma=pi/2"])
def test_gpu_closed_form(glphong_backend, form, normal, sigma):
    m = OrenNayar(RHO, sigma, form=form)
    wi, wo = closed_form_rows(normal)
    l, v, n = float32_units(wi), float32_units(wo), float32_units(normal[None])[0]
    gpu = evaluate(m, wi, wo, normal=normal, backend=glphong_backend).astype(np.float64)
    expected = closed_form(f32(RHO), f32(sigma), form, n, l, v)
    scale = _scale(expected, f32(RHO), l @ n)
    scale = np.where(scale > 0, scale, 1.0)
    assert np.all(np.isfinite(gpu)) and np.all(gpu[:, 1] == 0.0)  # the zero channel
    # through evaluate(twin=True): the same float32 inputs, which are unit only to about eps
    through = evaluate(m, wi, wo, normal=normal, twin=True)
    assert (np.abs(through - expected) / scale).max() < 2e-7  # measured 4.6e-8
    if normal[2] == 1.0:  # the cosines are exact coordinates
        assert (np.abs(gpu - expected) / scale).max() < 1e-6  # measured 3.2e-7
    else:  # the float32 n.l and n.v err by a few eps: the closed form over polar angles +-8 eps
        unit = n / np.linalg.norm(n)
        lu, vu = l / np.linalg.norm(l, axis=1, keepdims=True), v / np.linalg.norm(v, axis=1, keepdims=True)
        spread = 8 * EPS
        values = [closed_form(f32(RHO), f32(sigma), form, unit, _tilt(lu, unit, a), _tilt(vu, unit, b))
                  for a in (-spread, 0.0, spread) for b in (-spread, 0.0, spread)]
        low, high = np.min(values, axis=0), np.max(values, axis=0)
        outside = np.maximum(low - gpu, gpu - high) / scale
        assert outside.max() < 1e-6, outside.max()  # measured 1e-7
    gate = (v @ n) <= 0
    assert np.array_equal(gpu[gate], np.zeros_like(gpu[gate]))


def test_sigma_zero_is_lambert(glphong_backend):
    """sigma = 0: C1 = A = 1 and every other factor exactly 0, the same float32 operations as Diffuse."""
    wi, wo, _ = direction_sets(1000, 3)
    front = float32_units(wo)[:, 2] > 0
    lambert = evaluate(Diffuse(RHO), wi, wo, backend=glphong_backend)
    lambert_twin = evaluate(Diffuse(RHO), wi, wo, twin=True)
    for form in FORMS:
        gpu = evaluate(OrenNayar(RHO, 0.0, form=form), wi, wo, backend=glphong_backend)
        np.testing.assert_array_equal(gpu[front], lambert[front])
        assert np.all(gpu[~front] == 0.0)  # Oren-Nayar reflects nothing toward a viewer below the surface
        through = evaluate(OrenNayar(RHO, 0.0, form=form), wi, wo, twin=True)
        np.testing.assert_array_equal(through[front], lambert_twin[front])


# --------------------------------------------------------------------------- limits
@pytest.mark.parametrize("form", FORMS)
def test_limits_at_the_normal(glphong_backend, form):
    """l = n or v = n: the azimuth is undefined and the value is the limit beta -> 0, reached
    continuously; both directions grazing: bounded; n.v <= 0: exactly 0."""
    sigma = 0.5
    m = OrenNayar(RHO, sigma, form=form)
    rho, s2 = f32(RHO), f32(sigma) ** 2
    limit = rho / np.pi * (1 - 0.5 * s2 / (s2 + 0.33))  # f_r at beta = 0
    if form == "full":
        limit = limit + 0.17 * rho ** 2 / np.pi * s2 / (s2 + 0.13)
    thetas = np.array([0.0, 1e-7, 1e-5, 1e-3])
    views = [direction(Z, np.radians(50.0), phi) for phi in (0.0, 1.0, np.pi)]
    for swap in (False, True):  # l near n, then v near n
        near = np.array([direction(Z, t, 2.0) for t in thetas for _ in views])
        far = np.array(views * len(thetas))
        wi, wo = (far, near) if swap else (near, far)
        gpu = evaluate(m, wi, wo, backend=glphong_backend).astype(np.float64)
        f_r = gpu / float32_units(wi)[:, 2:3]
        beta = np.repeat(thetas, len(views))[:, None]
        assert np.all(np.abs(f_r - limit) <= rho / np.pi * beta + 1e-6 * limit), (swap, f_r, limit)
        np.testing.assert_allclose(f_r[:len(views)], np.tile(limit, (len(views), 1)), rtol=1e-6)
    # both directions grazing to 1e-30 (cosines), retro, crossed and forward: f_r diverges, f_r (n.l) not
    cosines = 10.0 ** -np.arange(2.0, 31.0, 4.0)
    wi = np.array([[np.sqrt(1 - c * c), 0.0, c] for c in cosines for _ in AZIMUTHS])
    wo = np.array([[np.sqrt(1 - c * c) * np.cos(p), np.sqrt(1 - c * c) * np.sin(p), c]
                   for c in cosines for p in AZIMUTHS])
    for sigma in (0.3, np.pi / 2):
        gpu = evaluate(OrenNayar(RHO, sigma, form=form), wi, wo, backend=glphong_backend).astype(np.float64)
        assert np.all(np.isfinite(gpu)) and np.all(np.abs(gpu) <= 2 * rho / np.pi)
        retro = gpu[::len(AZIMUTHS)]  # c = 1: 0.45 s2/(s2 + 0.09) rho/pi in the limit
        k = 0.45 * f32(sigma) ** 2 / (f32(sigma) ** 2 + 0.09)
        np.testing.assert_allclose(retro[-3:], np.tile(k * rho / np.pi, (3, 1)), rtol=1e-5, atol=1e-30)
    # the view below the surface, the light anywhere above: exactly 0
    wi, wo, labels = direction_sets(200, 4)
    below = labels == "view below the surface"
    gpu = evaluate(m, wi[below], wo[below], backend=glphong_backend)
    assert np.array_equal(gpu, np.zeros_like(gpu))


# --------------------------------------------------------------------------- physics
def _random_pairs(count, seed):
    rng = np.random.default_rng(seed)
    v = rng.normal(size=(2, count, 3))
    v[..., 2] = np.abs(v[..., 2])
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    return v[0], v[1]


@pytest.mark.parametrize("form", FORMS)
def test_reciprocity(glphong_backend, form):
    """f_r(l, v) = f_r(v, l): alpha, beta, |c| and the sign of c are symmetric (the full form's two C2
    cases separately)."""
    wi, wo = _random_pairs(4000, 5)
    c = np.cos(np.arctan2(wo[:, 1], wo[:, 0]) - np.arctan2(wi[:, 1], wi[:, 0]))
    for sigma in (0.3, 1.0, np.pi / 2):
        m = OrenNayar(RHO, sigma, form=form)
        forward = (twin(m, wi, wo) / wi[:, 2:3])[:, [0, 2]]  # channel 1 has rho = 0
        backward = (twin(m, wo, wi) / wo[:, 2:3])[:, [0, 2]]
        scale = np.abs(forward) + f32(RHO)[[0, 2]] / np.pi
        for cases in (c < 0, c >= 0):
            assert cases.sum() > 1500
            assert (np.abs(forward - backward)[cases] / scale[cases]).max() < 1e-13  # measured 5.6e-16
        away = (wi[:, 2] > 1e-2) & (wo[:, 2] > 1e-2)
        gpu_f = (evaluate(m, wi[away], wo[away], backend=glphong_backend) / float32_units(wi[away])[:, 2:3])[:, [0, 2]]
        gpu_b = (evaluate(m, wo[away], wi[away], backend=glphong_backend) / float32_units(wo[away])[:, 2:3])[:, [0, 2]]
        assert (np.abs(gpu_f - gpu_b) / scale[away]).max() < 1e-5  # measured 2.6e-7


@pytest.mark.parametrize("form", FORMS)
def test_retro_reflection_flattens_the_disc(glphong_backend, form):
    """l = v (light behind the viewer): for sigma > 0 the radiance toward the light at oblique incidence
    exceeds Lambert's, and falls less from normal to oblique incidence (the full Moon's flat look)."""
    thetas = np.radians([0.0, 60.0, 75.0, 85.0])
    wi = np.array([direction(Z, t, 1.1) for t in thetas])
    for sigma in (0.3, 0.6, 1.0):
        m = OrenNayar(RHO, sigma, form=form)
        gpu = evaluate(m, wi, wi, backend=glphong_backend).astype(np.float64)[:, 0]
        lam = evaluate(Diffuse(RHO), wi, wi, backend=glphong_backend).astype(np.float64)[:, 0]
        assert gpu[0] < lam[0]  # C1 = A < 1 at normal incidence
        assert np.all(gpu[1:] > lam[1:]), (sigma, gpu, lam)
        assert np.all(gpu[1:] / gpu[0] > lam[1:] / lam[0])  # flatter than cos(theta)
        np.testing.assert_allclose(gpu, twin(m, wi, wi)[:, 0], rtol=1e-6)
    ratio = gpu[2] / lam[2]  # sigma = 1, 75 deg
    assert ratio > 2.0  # measured 2.15 (full) / 2.11 (qualitative)


def _directional_albedo(m, theta_i, order=64):
    """Albedo ``int f_r cos(theta_o) dw_o`` of channel 0 by Gauss-Legendre quadrature of the float64
    twin, split where the integrand has kinks: cos(theta_o) = cos(theta_i) and c = 0."""
    def legendre(a, b, count):
        x, w = np.polynomial.legendre.leggauss(count)
        return 0.5 * (b - a) * x + 0.5 * (b + a), 0.5 * (b - a) * w

    mu_i = np.cos(theta_i)
    if 0 < mu_i < 1:
        parts = [legendre(0.0, mu_i, order), legendre(mu_i, 1.0, order)]
    else:
        parts = [legendre(0.0, 1.0, 2 * order)]
    mu, w_mu = (np.concatenate(p) for p in zip(*parts))
    parts = [legendre(0.0, np.pi / 2, order), legendre(np.pi / 2, 3 * np.pi / 2, 2 * order),
             legendre(3 * np.pi / 2, 2 * np.pi, order)]
    phi, w_phi = (np.concatenate(p) for p in zip(*parts))
    mu_grid, phi_grid = np.meshgrid(mu, phi, indexing="ij")
    s = np.sqrt(1 - mu_grid ** 2)
    wo = np.stack([s * np.cos(phi_grid), s * np.sin(phi_grid), mu_grid], axis=-1).reshape(-1, 3)
    wi = np.tile([np.sin(theta_i), 0.0, mu_i], (len(wo), 1))
    response = twin(m, wi, wo)[:, 0].reshape(mu_grid.shape)
    return float(np.sum(response / mu_i * mu_grid * np.outer(w_mu, w_phi)))


def test_directional_albedo():
    """rho = 1: sigma = 0 conserves energy exactly; sigma > 0 falls below 1 at normal incidence and
    rises above it toward grazing incidence (not energy-conserving, as declared)."""
    angles = np.radians([0.0, 30.0, 60.0, 80.0, 89.99])
    table = {(form, sigma): [_directional_albedo(OrenNayar(1.0, sigma, form=form), t) for t in angles]
             for form in FORMS for sigma in (0.0, 0.3, np.pi / 2)}
    for form in FORMS:
        np.testing.assert_allclose(table[form, 0.0], 1.0, rtol=1e-12)
    expected = {("full", 0.3): (0.9624, 1.0510), ("qualitative", 0.3): (0.8929, 1.0052),
                ("full", np.pi / 2): (0.7205, 0.8912), ("qualitative", np.pi / 2): (0.5590, 0.7760)}
    for key, (normal, grazing) in expected.items():
        np.testing.assert_allclose([table[key][0], table[key][-1]], [normal, grazing], atol=2e-4)
        assert np.all(np.diff(table[key]) > 0)  # rises toward grazing incidence
    # the largest measured (full form, sigma = 0.3, grazing) is what the condition declares
    assert OrenNayar.properties.energy_conserving is False
    assert "1.051" in OrenNayar.properties.condition
    assert max(max(v) for v in table.values()) < 1.052
    # the quadrature has converged
    assert abs(_directional_albedo(OrenNayar(1.0, 0.3), angles[-1], 128) - table["full", 0.3][-1]) < 1e-6


# --------------------------------------------------------------------------- the twin's support
@pytest.mark.parametrize("form", FORMS)
def test_the_twin_is_non_zero_where_light_and_view_are_above(form):
    wi, wo, _ = direction_sets(1000, 0)
    l, v = float32_units(wi), float32_units(wo)
    for sigma in (0.0, 0.3, 1.0, np.pi / 2):
        twin = evaluate(OrenNayar(RHO, sigma, form=form), wi, wo, twin=True)
        assert int(np.any(twin != 0, axis=1).sum()) == int(np.sum((l[:, 2] > 0) & (v[:, 2] > 0)))


# --------------------------------------------------------------------------- the declaration
def test_declaration():
    assert OrenNayar.name == "oren_nayar"
    rho, sigma = OrenNayar.params
    assert (rho.name, rho.kind, rho.glsl_type, rho.interval, rho.unit, rho.default) == ("rho", "rgb", "vec3", "[0, 1]",
                                                                                      "", None)
    assert (sigma.name, sigma.kind, sigma.glsl_type, sigma.interval, sigma.unit, sigma.default) == (
        "sigma", "scalar", "float", "[0, 1.5708]", "rad", None)
    assert sigma.high == np.pi / 2
    (form,) = OrenNayar.choices
    assert (form.name, form.values, form.default) == ("form", ("full", "qualitative"), "full")
    assert OrenNayar.needs == ("view",) and OrenNayar.uses == ("angle",) and OrenNayar.fresnel_slot is None
    assert OrenNayar.ambient == "rho" and OrenNayar.ambient_scale == 1.0 / np.pi
    assert OrenNayar.vanishes_with == ("rho",)
    assert OrenNayar.properties == Properties(reciprocal=True, isotropic=True, energy_conserving=False,
                                              condition=OrenNayar.properties.condition, non_negative=False)
    # the stability cases the conformance test runs: both forms, l = n, v = n, l and v near n, both grazing at
    # 1e-2 to 1e-6 in retro, forward and crossed azimuth, sigma = 0 and pi/2
    assert len(cases_for(OrenNayar)) == 60


# --------------------------------------------------------------------------- a render
def test_render_matches(glphong_renderer):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene = glphong.Scene(camera, lights=[glphong.PointLight((1.5, 1.0, 3.0), (80.0, 60.0, 40.0))],
                          ambient=glphong.AmbientLight(0.05))
    scene.add(glphong.primitives.sphere(3), OrenNayar(RHO, 0.5))
    report = assert_render_matches(scene, glphong_renderer)
    assert report.covered_pixels > 1000 and report.nonfinite_count == 0
    assert report.gpu[..., 0].max() > 0.1
    assert report.max_relative_error < 1e-5  # measured 1.17e-6
    # where the light does not reach, only the ambient answer rho/pi L_a remains (Lambert's)
    dark = report.mask & (report.reference[..., 0] < 0.05 * 0.8 / np.pi * 1.001)
    assert dark.sum() > 50  # measured 181 pixels
    np.testing.assert_allclose(report.gpu[dark][:, 0], 0.05 * 0.8 / np.pi, rtol=1e-5)
