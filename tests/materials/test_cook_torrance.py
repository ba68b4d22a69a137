"""The built-in model 'cook_torrance_lobe' (`glphong.materials.CookTorranceLobe`) and the material
`glphong.materials.CookTorrance` (= ``Diffuse + CookTorranceLobe``), tested the way a user tests a model.

What is specific to it (twin agreement for m = 1e-3 to 10, both forms, the Fresnel choices and with the
diffuse term, never NaN or Inf with F = 1 at both ends of the m range, the definition's mechanics, the
program key, the sum of the terms, the declared properties and the stability cases are in
tests/test_conformance.py; GPU parts on both backends, fixture ``glphong_backend``; the figures were
measured on Mesa llvmpipe and are identical through EGL and OSMesa):

- the closed form, written here in float64 from the textbook formulas (h = (l + v)/|l + v|, ``sin^2`` from
  ``|n x h|^2``, ``D = exp(-tan^2/m^2) / (pi m^2 cos^4)``, the min() masking, Schlick on ``h.l``, divided by
  ``4 (n.l)(n.v)``, or by ``pi (n.l)(n.v)`` with ``pi D``), at normal, oblique (40, 75 degrees) and grazing
  (n.l = 1e-2, 1e-4) incidence, at the peak and at theta_h = m/2, m, 2m, 2.5m (0.15 to 0.7 rad for m >= 1),
  at grazing view n.v = 1e-3 and on 60 seeded random pairs, for the +z and a tilted normal and
  m = 1e-3, 0.05, 0.3, 1, 10:
  the GPU (`evaluate`) lies in the closed form's range over the float32 uncertainty of its inputs (n, l, v
  each turned by 8 eps about two axes and scaled by 1 +- 8 eps), widened by 1e-5 relative; away from
  grazing its relative error is below 5e-4, 3e-5, 3e-5, 1e-5, 1e-5 for those m (measured 3.9e-4, 1.9e-5,
  1.3e-5, 3.1e-6, 9.6e-7);
  the twin (`CookTorranceLobe.response` on the exact float64 directions) agrees to 1e-12 (measured 1.3e-13),
  and to 1e-10 at grazing incidence, where l + v cancels to 2 (h.l) in float64 too (measured 4.7e-11);
- the smallest m: at m = 1e-3 (the lower end of the range) the GPU stays within 1e-3 relative of the closed
  form over three decades around the peak (D >= 1e-3 D(0)), 300 seeded pairs per normal (measured 5.0e-4
  for the +z normal, 3.7e-4 tilted; the float32 twin measured 1.2e-3 at m = 3e-4, 5e-3 at 1e-4: about 4e-7/m);
- the ratio of the forms: the 1982 response is exactly 4 times the microfacet one (not 4/pi), bit for bit on
  the GPU and in the twin, on `direction_sets` wherever neither is flushed or saturated;
- reciprocity (declared): ``f_r(l, v) = f_r(v, l)`` for both forms and the three Fresnel choices in the twin
  (bound 1e-13, measured 4.4e-16) and on the GPU for m = 0.3 with both cosines >= 0.05 (bound 1e-5,
  measured 2.3e-7);
- normalisation by quadrature (Gauss-Legendre in theta_h, midpoint rule in phi): ``int D (n.h) dw_h = 1``
  to 1e-12 for m = 0.05, 0.3, 1 (the twin's ``cook_torrance_beckmann / pi``; measured 6e-15); the specular
  directional albedo with ``F = 1`` (``SchlickFresnel(1.0)``) of the microfacet form is at most 1 at
  incident angles 0, 45, 75, 85 degrees (m = 0.05: 1.0000, 1.0000, 0.9991, 0.9431; m = 0.3: 0.9956,
  0.9567, 0.9273, 0.9702; m = 1: 0.4534, 0.6405, 0.9063, 0.9695; quadrature converged to 2e-4); the 1982
  form's is 4 times it (3.6 to 4.0 at 75 degrees: above 1, as documented);
- the model's 59 stability cases (run in the conformance test: generic geometry for both forms, grazing
  view down to n.v = 1e-30, mirrored grazing pairs with (n.l)(n.v) = 1e-20 and 1e-40, one beyond
  FLT_MAX that saturates, grazing half vectors with tan^2/m^2 up to 1e4 and (n.h)^2 underflowing,
  m = 1e-3 to 10 at and around the peak, v.h down to 1e-6, Schlick at h.l rounding to 1): the
  saturating one is the only case outside the valid range, and gives FLT_MAX, not Inf;
- the declaration: params and range [0.001, 10], needs 'view', the form choice, the Fresnel cosine and
  the default ``SchlickFresnel(0.04)``, an empty ``vanishes_with`` (the lobe stays in the key even with
  f0 = 0, where F is still > 0 off the normal), the declared properties and their conditions;
- a sphere under a point light rendered through ``glphong_renderer``, passing `assert_render_matches`
  (relative error below 1e-4 where the twin is at least 2^-100; measured 3.7e-5).
"""
import numpy as np
import pytest

import glphong
import glphong.primitives
from glphong.shaders.key import program_key
from glphong.materials import (CookTorrance, CookTorranceLobe, DielectricFresnel, Diffuse, SchlickFresnel,
                               ShadingFrame)
from glphong.materials.cook_torrance import COOK_TORRANCE_FORM_RATIO, cook_torrance_beckmann
from glphong.checks.stability import cases_for, run_stability
from glphong.testing import assert_render_matches, direction, direction_sets, evaluate, frame_around, rotate_toward

EPS = 2.0 ** -24
FLT_MIN = 2.0 ** -126
FLT_MAX = float(np.finfo(np.float32).max)
Z = np.array([0.0, 0.0, 1.0])
TILTED = np.array([0.3, -0.2, 0.9]) / np.linalg.norm([0.3, -0.2, 0.9])
MS = [1e-3, 0.05, 0.3, 1.0, 10.0]


def f32(x):
    return np.asarray(x, dtype=np.float32).astype(np.float64)


# --------------------------------------------------------------------------- the closed form
def closed_form(n, l, v, m, f0=0.04, form="microfacet"):
    """The response ``f_r (n.l)`` from the textbook formulas in float64 (rows of unit l, v; f0 scalar)."""
    n = np.broadcast_to(n, l.shape).astype(np.float64)
    h = l + v
    h = h / np.linalg.norm(h, axis=-1, keepdims=True)
    nl, nv, nh, vh = (np.sum(n * l, -1), np.sum(n * v, -1), np.sum(n * h, -1), np.sum(v * h, -1))
    tan2 = np.sum(np.cross(n, h) ** 2, -1) / nh ** 2
    d = np.exp(-tan2 / m ** 2) / (np.pi * m ** 2 * nh ** 4)
    g = np.minimum(1.0, np.minimum(2 * nh * nv / vh, 2 * nh * nl / vh))
    f = f0 + (1 - f0) * (1 - np.sum(h * l, -1)) ** 5
    f_r = f * d * g / (4 * nl * nv) if form == "microfacet" else f * (np.pi * d) * g / (np.pi * nl * nv)
    return np.where((nl > 0) & (nv > 0), f_r * nl, 0.0)


def _turn(a, axis, angle):
    out = np.cos(angle) * a + np.sin(angle) * axis
    return out / np.linalg.norm(out, axis=-1, keepdims=True)


def closed_form_interval(n, l, v, m, f0=0.04, form="microfacet", spread=8 * EPS, rtol=1e-5):
    """The closed form's range over the float32 uncertainty of its inputs, widened by ``rtol`` relative
    (exp's (3 + 2|x|) ulp and the products, for tan^2/m^2 <= 7).

    The GPU's n, l and v are float32 unit vectors and its arithmetic float32: each direction is turned by
    up to a few eps and its length is 1 to a few eps.  So each of n, l, v is turned by ``+- spread`` rad
    about two axes perpendicular to it and scaled by ``1 +- spread`` (one at a time); the closed form's
    range over these 18 inputs is the interval.  (At grazing incidence the length matters most: l + v is
    then nearly perpendicular to l and v, and a change of |l| turns h by spread / |l + v|.)"""
    n = np.broadcast_to(n, l.shape).astype(np.float64)
    values = [closed_form(n, l, v, m, f0, form)]
    for which in range(3):
        a = (n, l, v)[which]
        helper = np.where(np.abs(a[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]])
        p = np.cross(a, helper)
        p /= np.linalg.norm(p, axis=1, keepdims=True)
        moved = [_turn(a, axis, sign * spread) for axis in (p, np.cross(a, p)) for sign in (1.0, -1.0)]
        moved += [a * (1 + spread), a * (1 - spread)]
        for b in moved:
            args = [n, l, v]
            args[which] = b
            values.append(closed_form(*args, m, f0, form))
    values = np.array(values)
    return values.min(axis=0) * (1 - rtol), values.max(axis=0) * (1 + rtol)


def closed_form_rows(n, m, seed=0):
    """``(wi, wo, labels)``: the light at normal, oblique and grazing incidence; h at the peak and tilted
    toward l by m/2, m, 2m, 2.5m (for m >= 1: 0.15, 0.3, 0.5, 0.7 rad); v the mirror of l about h; views at
    grazing (n.v = 1e-3); 60 seeded random pairs."""
    t, _ = frame_around(n)
    offsets = {"peak": 0.0}
    for k in (0.5, 1.0, 2.0, 2.5):
        offsets[f"theta_h={k:g}m"] = k * m if m < 1 else {0.5: 0.15, 1.0: 0.3, 2.0: 0.5, 2.5: 0.7}[k]
    lights = {"normal incidence": 0.0, "40 deg": np.radians(40.0), "75 deg": np.radians(75.0),
              "grazing n.l=1e-2": np.arccos(1e-2), "grazing n.l=1e-4": np.arccos(1e-4)}
    wi, wo, labels = [], [], []
    for light, theta in lights.items():
        l = direction(n, theta, 0.3)
        for where, alpha in offsets.items():
            h = rotate_toward(n, l if theta > 0 else t, alpha)
            v = 2 * np.dot(h, l) * h - l
            if np.dot(v, n) < 1e-5:
                continue
            wi.append(l)
            wo.append(v)
            labels.append(f"{light}, {where}")
    for phi in (0.3, 0.3 + np.pi, 2.0):
        wi.append(direction(n, np.radians(40.0), 0.3))
        wo.append(direction(n, np.arccos(1e-3), phi))
        labels.append(f"grazing view n.v=1e-3, azimuth {phi:.2f}")
    rng = np.random.default_rng(seed)
    for _ in range(60):
        wi.append(direction(n, rng.uniform(0, 1.4), rng.uniform(0, 2 * np.pi)))
        wo.append(direction(n, rng.uniform(0, 1.4), rng.uniform(0, 2 * np.pi)))
        labels.append("random")
    return np.array(wi), np.array(wo), labels


def twin64(material, n, wi, wo):
    """The twin on exact float64 unit vectors (no float32 rounding of the inputs)."""
    n = np.broadcast_to(n, wi.shape).astype(np.float64)
    n_dot_l = np.sum(n * wi, -1)
    out = np.zeros(wi.shape)
    lit = n_dot_l > 0
    for term in material.components:
        out[lit] += term.response(ShadingFrame(n[lit]), wi[lit], wo[lit], n_dot_l[lit], term.values())
    return out


@pytest.mark.parametrize("normal", [Z, TILTED], ids=["normal+z", "normal-tilted"])
@pytest.mark.parametrize("m", MS, ids=[f"m={m:g}" for m in MS])
def test_closed_form(glphong_backend, m, normal):
    wi, wo, labels = closed_form_rows(normal, m)
    material = CookTorranceLobe(m)
    m32 = float(np.float32(m))
    f0 = float(np.float32(0.04))
    expected = closed_form(normal, wi, wo, m32, f0)
    lobe_rows = np.array([s != "random" and not s.startswith("grazing view") for s in labels])
    assert np.all(np.isfinite(expected)) and np.all(expected[lobe_rows] > 1e-20)  # rows in the lobe are inside D
    tiny = expected < 1e-30  # random pairs far outside a narrow lobe: the twin's D is cut at tan^2/m^2 = 104
    grazing_light = np.array(["grazing n.l" in s for s in labels])
    # the twin on the exact directions; at grazing incidence l + v cancels to 2 (h.l) and both sides lose
    # digits to it (4.7e-11 at n.l = 1e-4 and m = 1e-3)
    twin = twin64(material, normal, wi, wo)[:, 0]
    np.testing.assert_allclose(twin[~tiny & ~grazing_light], expected[~tiny & ~grazing_light], rtol=1e-12)
    np.testing.assert_allclose(twin[~tiny & grazing_light], expected[~tiny & grazing_light], rtol=1e-10)
    assert np.all(twin[tiny] < 1e-30)
    # the GPU on the float32 directions: inside the closed form's interval over the float32 uncertainty
    gpu = evaluate(material, wi, wo, normal=normal, backend=glphong_backend).astype(np.float64)
    assert np.all(gpu[:, 0] == gpu[:, 1]) and np.all(gpu[:, 1] == gpu[:, 2])  # grey f0
    low, high = closed_form_interval(normal, wi, wo, m32, f0)
    low = np.where(low < FLT_MIN, 0.0, low)  # float32 flushes below FLT_MIN
    bad = ~((gpu[:, 0] >= low) & (gpu[:, 0] <= np.maximum(high, FLT_MIN)))
    assert not bad.any(), "\n".join(f"{labels[i]}: gpu {gpu[i, 0]!r}, closed form {expected[i]!r}, interval "
                                    f"({low[i]!r}, {high[i]!r})" for i in np.nonzero(bad)[0])
    # relative error away from grazing: 1e-5 for m >= 1, more for narrow lobes (D's sensitivity 2 tan / m^2)
    away = ~tiny & ~np.array(["grazing" in s for s in labels])
    rel = np.abs(gpu[away, 0] / expected[away] - 1)
    assert rel.max() < GPU_RTOL[m], rel.max()


#: GPU against the closed form away from grazing; measured 3.9e-4, 1.9e-5, 1.3e-5, 3.1e-6, 9.6e-7
GPU_RTOL = {1e-3: 5e-4, 0.05: 3e-5, 0.3: 3e-5, 1.0: 1e-5, 10.0: 1e-5}


def _peak_rows(n, m, count, seed):
    """Pairs whose h lies within three decades of D's peak (tan^2/m^2 <= ln 1000), lights up to 75 deg."""
    rng = np.random.default_rng(seed)
    t, b = frame_around(n)
    wi, wo = [], []
    while len(wi) < count:
        l = direction(n, rng.uniform(0, np.radians(75)), rng.uniform(0, 2 * np.pi))
        phi = rng.uniform(0, 2 * np.pi)
        alpha = np.arctan(m * np.sqrt(rng.uniform(0, np.log(1000.0))))
        h = np.cos(alpha) * n + np.sin(alpha) * (np.cos(phi) * t + np.sin(phi) * b)
        v = 2 * np.dot(h, l) * h - l
        if np.dot(v, n) > 0.05:
            wi.append(l)
            wo.append(v)
    return np.array(wi), np.array(wo)


@pytest.mark.parametrize("normal", [Z, TILTED], ids=["normal+z", "normal-tilted"])
def test_smallest_m_near_the_peak(glphong_backend, normal):
    """m = 1e-3 (the lower end of the range): relative error below 1e-3 within three decades of the peak."""
    wi, wo = _peak_rows(normal, 1e-3, 300, 5)
    expected = closed_form(normal, wi, wo, float(np.float32(1e-3)), float(np.float32(0.04)))
    gpu = evaluate(CookTorranceLobe(1e-3), wi, wo, normal=normal, backend=glphong_backend)[:, 0].astype(np.float64)
    assert np.abs(gpu / expected - 1).max() < 1e-3  # measured 5.0e-4 (+z), 3.7e-4 (tilted)


# --------------------------------------------------------------------------- the two forms
def test_the_1982_form_is_exactly_4_times_the_microfacet_form(glphong_backend):
    assert COOK_TORRANCE_FORM_RATIO == 4.0
    wi, wo, _ = direction_sets(1000, 3)
    for m, fresnel in ((1e-3, SchlickFresnel(0.04)), (0.3, DielectricFresnel(1.5)), (10.0, None)):
        micro, paper = CookTorranceLobe(m, fresnel), CookTorranceLobe(m, fresnel, form="1982")
        for kw in ({"backend": glphong_backend}, {"twin": True}):
            a = evaluate(micro, wi, wo, **kw).astype(np.float64)
            b = evaluate(paper, wi, wo, **kw).astype(np.float64)
            normal = (a >= 4 * FLT_MIN) & (b < FLT_MAX)
            assert normal.sum() > 500
            np.testing.assert_array_equal(b[normal], 4.0 * a[normal])  # bit for bit
            assert np.all(a[b == 0] == 0) and np.all(b[a == 0] < 4 * FLT_MIN)  # 0 only where flushed
    # and the closed forms
    wi, wo, _ = closed_form_rows(Z, 0.3)
    np.testing.assert_allclose(closed_form(Z, wi, wo, 0.3, form="1982"), 4 * closed_form(Z, wi, wo, 0.3), rtol=1e-14)


# --------------------------------------------------------------------------- reciprocity
@pytest.mark.parametrize("form", ["microfacet", "1982"])
@pytest.mark.parametrize("fresnel", [SchlickFresnel(0.04), DielectricFresnel(1.5), None],
                         ids=["schlick", "dielectric", "F=1"])
def test_reciprocal_in_the_twin(form, fresnel):
    rng = np.random.default_rng(7)
    wi, wo = rng.normal(size=(2, 500, 3))
    wi[:, 2], wo[:, 2] = np.abs(wi[:, 2]), np.abs(wo[:, 2])
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    wo /= np.linalg.norm(wo, axis=1, keepdims=True)
    material = CookTorrance(0.2, 0.3, fresnel, form)
    forward = twin64(material, Z, wi, wo) / wi[:, 2:3]
    backward = twin64(material, Z, wo, wi) / wo[:, 2:3]
    assert np.all(forward > 0)
    np.testing.assert_allclose(forward, backward, rtol=1e-13)  # measured 4e-16
    assert CookTorranceLobe.properties.reciprocal and CookTorrance.properties.reciprocal


def test_reciprocal_on_the_gpu(glphong_backend):
    wi, wo, _ = direction_sets(1000, 8)
    keep = (wi[:, 2] >= 0.05) & (wo[:, 2] >= 0.05)
    wi, wo = wi[keep], wo[keep]
    material = CookTorranceLobe(0.3)
    forward = evaluate(material, wi, wo, backend=glphong_backend).astype(np.float64) / f32(wi[:, 2:3])
    backward = evaluate(material, wo, wi, backend=glphong_backend).astype(np.float64) / f32(wo[:, 2:3])
    seen = forward[:, 0] > 1e-30  # D is 0 beyond tan^2(theta_h) = 104 m^2 (72 degrees)
    assert seen.sum() > 1000
    np.testing.assert_allclose(forward[seen], backward[seen], rtol=RECIPROCITY_RTOL)
    assert np.array_equal(backward[~seen] > 1e-30, forward[~seen] > 1e-30)


#: GPU reciprocity for m = 0.3, both cosines >= 0.05
RECIPROCITY_RTOL = 1e-5  # measured 2.3e-7


# --------------------------------------------------------------------------- quadrature
def _gauss(a, b, count):
    x, w = np.polynomial.legendre.leggauss(count)
    return 0.5 * (b - a) * x + 0.5 * (b + a), 0.5 * (b - a) * w


@pytest.mark.parametrize("m", [0.05, 0.3, 1.0])
def test_beckmann_is_normalised(m):
    """int D (n.h) dw_h = 2 pi int D cos sin d theta = 1, with D = cook_torrance_beckmann / pi (the twin)."""
    total = 0.0
    edges = np.linspace(0.0, np.pi / 2, 9) if m >= 0.3 else np.linspace(0.0, 20 * m, 9)
    for a, b in zip(edges[:-1], edges[1:]):
        theta, w = _gauss(a, b, 200)
        d = cook_torrance_beckmann(np.tan(theta) ** 2, m) / np.pi
        total += 2 * np.pi * np.sum(d * np.cos(theta) * np.sin(theta) * w)
    assert abs(total - 1.0) < 1e-12  # measured 6e-15


def _specular_albedo(material, theta_i, n_theta=240, n_phi=96):
    """``int f_r(l, v) (n.v) dw_v`` of the twin, over the half vector: ``dw_v = 4 (h.l) dw_h``,
    ``v = 2 (h.l) h - l``; Gauss-Legendre on 4 panels of theta_h in [0, min(pi/2, 16 m)], midpoint rule in
    phi_h (periodic).  Converged to 2e-4 (against 800 x 512 points; 1e-13 where the lobe misses the horizon)."""
    m = material.m
    l = np.array([np.sin(theta_i), 0.0, np.cos(theta_i)])
    edges = np.linspace(0.0, min(np.pi / 2, 16 * m), 5)
    theta, w_theta = map(np.concatenate, zip(*[_gauss(a, b, n_theta // 4) for a, b in zip(edges[:-1], edges[1:])]))
    phi = (np.arange(n_phi) + 0.5) * 2 * np.pi / n_phi
    t, p = np.meshgrid(theta, phi, indexing="ij")
    h = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1).reshape(-1, 3)
    h_dot_l = h @ l
    v = 2 * h_dot_l[:, None] * h - l
    ok = (h_dot_l > 0) & (v[:, 2] > 0)
    f_r = np.zeros(len(h))
    f_r[ok] = twin64(material, Z, np.repeat(l[None], ok.sum(), axis=0), v[ok])[:, 0] / l[2]
    weight = (w_theta[:, None] * np.sin(t) * (2 * np.pi / n_phi)).reshape(-1)
    return float(np.sum(f_r * v[:, 2] * 4 * h_dot_l * weight))


#: the microfacet form's specular albedo with F = 1 at 0, 45, 75, 85 degrees (converged quadrature)
ALBEDO = {0.05: (1.0000, 1.0000, 0.9991, 0.9431), 0.3: (0.9956, 0.9567, 0.9273, 0.9702),
          1.0: (0.4534, 0.6405, 0.9063, 0.9695)}


@pytest.mark.parametrize("m", sorted(ALBEDO))
def test_specular_albedo(m):
    """Microfacet form with F = 1: directional albedo <= 1 at 0, 45, 75, 85 degrees; the 1982 form's is 4
    times it (above 1: the paper's normalisation does not conserve energy)."""
    albedo = {}
    for degrees, measured in zip((0.0, 45.0, 75.0, 85.0), ALBEDO[m]):
        albedo[degrees] = a = _specular_albedo(CookTorranceLobe(m, SchlickFresnel(1.0)), np.radians(degrees))
        assert a <= 1.0 + 1e-9 and abs(a - measured) < 5e-4, (m, degrees, a)
    b = _specular_albedo(CookTorranceLobe(m, SchlickFresnel(1.0), form="1982"), np.radians(75.0))
    assert abs(b - 4 * albedo[75.0]) < 1e-12 and b > 3.6  # 4 times the microfacet form's: above 1


# --------------------------------------------------------------------------- stability
def test_the_stability_cases_and_the_saturating_one(glphong_backend):
    cases = cases_for(CookTorranceLobe)
    assert len(cases) == 69
    saturated = [c for c in cases if not c.in_range]
    assert [c.name for c in saturated] == ["cook_torrance mirrored grazing n.l=n.v=1e-36 m=1e-3"]
    report = run_stability(backend=glphong_backend, cases=saturated)
    assert report.passed_count == 1 and report.rows[0].gpu == [FLT_MAX] * 3
    ggx = [c for c in cases if c.group == "cook-torrance ggx"]  # the GGX option: peak to m = 1e-3, tails, grazing
    report = run_stability(backend=glphong_backend, cases=ggx)
    assert len(ggx) == 10 and report.passed_count == 10, [(r.case, r.relative_error) for r in report.rows if not r.passed]


# --------------------------------------------------------------------------- the declaration
def test_declaration():
    assert CookTorranceLobe.name == "cook_torrance_lobe" and CookTorrance.name == "cook_torrance"
    assert CookTorrance.terms == (Diffuse, CookTorranceLobe)
    (m,) = CookTorranceLobe.params
    assert (m.name, m.kind, m.glsl_type, m.interval, m.default) == ("m", "scalar", "float", "[0.001, 10]", None)
    assert [a.name for a in CookTorrance.arguments()] == ["rho_d", "m", "fresnel", "form", "distribution"]
    assert CookTorranceLobe.needs == ("view",) and CookTorranceLobe.ambient is None
    assert CookTorranceLobe.vanishes_with == ()
    assert CookTorranceLobe.fresnel_slot.cosine == "h.l"
    assert CookTorranceLobe.fresnel_slot.default == SchlickFresnel(0.04)
    form, distribution = CookTorranceLobe.choices
    assert (form.name, form.values, form.default) == ("form", ("microfacet", "1982"), "microfacet")
    assert (distribution.name, distribution.values, distribution.default) == ("distribution", ("beckmann", "ggx"),
                                                                             "beckmann")
    p = CookTorranceLobe.properties
    assert (p.reciprocal, p.isotropic, p.energy_conserving, p.non_negative) == (True, True, True, True)
    assert "1982" in p.condition and "microfacet" in CookTorrance.properties.condition
    # F(h.l) > 0 off the normal even with f0 = 0: no value of the lobe's parameters removes it
    assert not CookTorranceLobe(0.3, SchlickFresnel(0.0)).vanishes()
    assert [t.name for t in program_key(CookTorrance(0.0, 0.3, SchlickFresnel(0.0)), {"point": 1}, None).terms] == [
        "cook_torrance_lobe"]


# --------------------------------------------------------------------------- a render
def test_render_matches(glphong_renderer):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene = glphong.Scene(camera, lights=[glphong.PointLight((1.5, 1.0, 3.0), (80.0, 60.0, 40.0))])
    scene.add(glphong.primitives.sphere(3), CookTorrance((0.3, 0.1, 0.05), 0.15, SchlickFresnel((0.9, 0.6, 0.3))))
    report = assert_render_matches(scene, glphong_renderer)
    assert report.covered_pixels > 1000 and report.nonfinite_count == 0
    assert report.gpu[..., 0].max() > 1.0  # the highlight is in the picture
    covered = report.mask[..., None] & (report.reference >= 2.0 ** -100)
    assert report.relative_error[covered].max() < 1e-4  # measured 3.7e-5


# --------------------------------------------------------------------------- the GGX option
def _ggx_closed_form(n, l, v, m, f0=0.04):
    """Cook-Torrance with Walter et al.'s GGX (alpha = m) in float64, written here: F(h.l) D G / (4 (n.l)(n.v))."""
    h = (l + v) / np.linalg.norm(l + v, axis=-1, keepdims=True)
    nl, nv, nh, hl = (np.sum(a * b, -1) for a, b in ((n, l), (n, v), (n, h), (h, l)))
    a2 = m ** 2  # alpha = m
    d = a2 / (np.pi * (nh ** 2 * (a2 - 1) + 1) ** 2)
    g = np.minimum(1.0, np.minimum(2 * nh * nv / hl, 2 * nh * nl / hl))
    f = f0 + (1 - f0) * (1 - hl) ** 5
    return (f * d * g / (4 * nl * nv) * nl)[:, None] * np.ones(3)


@pytest.mark.parametrize("m", [0.01, 0.3, 2.0])
def test_ggx_option_against_its_closed_form(m, glphong_backend):
    rng = np.random.default_rng(int(100 * m))
    count = 400
    t, p = rng.uniform(0, 1.4, (2, count)), rng.uniform(0, 2 * np.pi, (2, count))
    l, v = (np.stack([np.sin(t[i]) * np.cos(p[i]), np.sin(t[i]) * np.sin(p[i]), np.cos(t[i])], -1) for i in (0, 1))
    n = np.broadcast_to([0.0, 0.0, 1.0], l.shape)
    lobe = CookTorranceLobe(m, distribution="ggx")
    term = lobe.components[0]
    expected = _ggx_closed_form(n, l, v, float(np.float32(m)), f0=float(np.float32(0.04)))  # the float32 parameters
    twin = term.response(ShadingFrame(n), l, v, np.sum(n * l, -1), term.values())
    np.testing.assert_allclose(twin, expected, rtol=1e-11, atol=0)
    gpu = evaluate(lobe, wi=l, wo=v, backend=glphong_backend)
    big = expected[:, 0] > 1e-6 * expected[:, 0].max()
    np.testing.assert_allclose(gpu[big], expected[big], rtol=2e-4)
    # GGX is not Beckmann: the tails differ by orders of magnitude
    beckmann = CookTorranceLobe(m).components[0]
    assert not np.allclose(beckmann.response(ShadingFrame(n), l, v, np.sum(n * l, -1), beckmann.values()), twin, rtol=0.1)
