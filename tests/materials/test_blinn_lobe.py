"""The built-in model 'blinn_lobe' (`glphong.materials.BlinnLobe`) and the material `glphong.BlinnPhong`,
tested the way a user tests their own model.

What is specific to it (twin agreement for q = 0, 1, 50, 1e4, 1e7 with ks = 1 or a zero channel and with
Fresnel factors, its figures, the definition's mechanics, the program key, vanishing at ks = 0, the sum
`BlinnPhong` as a sum of its terms and the stability cases are in tests/test_conformance.py), with the toolkit
of `glphong.testing` on both backends (fixture ``glphong_backend``):

- the twin is non-zero exactly where the lobe is (the support the conformance figures count);
- the GLSL response (`evaluate`) against the closed form ``ks max(n.h, 0)^q``, ``h = (l + v)/|l + v|``,
  0 where ``n.v <= 0``, written here in float64: at the peak (h = n), at half and 1e-3 and 1e-20 of the
  maximum, at normal, oblique and grazing incidence (n.l = 1e-2, 1e-4) and grazing view, for the +z
  normal and a tilted normal, within the interval of `lobe_interval` (the angle of h uncertain by
  8 eps max(1, 2/|l + v|), measured at most 0.5 eps times that factor; exp/log error eps (8 + 12 lambda));
  q = 0 gives exactly ks where n.l > 0 and n.v > 0; exactly 0 where n.l <= 0 (even with h = n) and
  where n.v <= 0 (even with n.l > 0 and n.h > 0); never above ks;
- the declaration (params, needs 'view', no ambient answer, vanishes with ks, declared properties per
  docs/design.md sections 1 and 8: isotropic, not reciprocal, not energy-conserving) and ``BlinnPhong.terms``;
- one render of a sphere under one point light through ``glphong_renderer``, passing
  `assert_render_matches` (relative error where the twin is at least 2^-100 below 1e-3).
"""
import numpy as np
import pytest

import glphong
import glphong.primitives
from glphong.materials import BlinnLobe, BlinnPhong, Lambert, Properties
from glphong.materials.blinn import blinn_delta
from glphong.testing import (assert_render_matches, cosine_power_interval, direction, direction_sets, evaluate,
                             float32_units, frame_around, rotate_toward)

EPS = 2.0 ** -24
FLT_MIN = 2.0 ** -126
KS = (0.5, 0.0, 0.2)
QS = [0.0, 1.0, 50.0, 1e4, 1e7]
#: a tilted unit normal: h and n.h are then computed with rounding
TILTED = np.array([0.3, -0.2, 0.9]) / np.linalg.norm([0.3, -0.2, 0.9])
NORMALS = [np.array([0.0, 0.0, 1.0]), TILTED]


def f32(x):
    return np.asarray(x, dtype=np.float32).astype(np.float64)


# --------------------------------------------------------------------------- twin
@pytest.mark.parametrize("q", QS, ids=[f"q={q:g}" for q in QS])
def test_the_twin_is_non_zero_exactly_where_the_lobe_is(q):
    """n.h > 0 wherever n.l > 0 and n.v > 0, so the lobe is non-zero there, except where both directions
    graze to 1e-19 or less: there the twin's delta = |h - n|^2 / 2 may round to 1 (lobe 0 for q > 0)."""
    wi, wo, _ = direction_sets(2000, 0)
    l, v = float32_units(wi), float32_units(wo)
    defined = (l[:, 2] > 0) & (v[:, 2] > 0) & (np.linalg.norm(l + v, axis=1) > 2.0 ** -20)
    _, delta = blinn_delta(np.array([0.0, 0.0, 1.0]), l, v)
    for ks in (1.0, KS):
        twin = evaluate(BlinnLobe(ks, q), wi, wo, twin=True)
        assert int(np.any(twin != 0, axis=1).sum()) == int(np.sum(defined & ((delta < 1) | (q == 0))))


# --------------------------------------------------------------------------- closed form
# The closed form's interval is glphong.testing.cosine_power_interval; its spread for this lobe:
# The GPU's inputs are float32 unit vectors and h = (l + v)/|l + v| is float32 arithmetic: rounding
# l, v and their sum moves l + v by a few eps, which turns h by that over |l + v|; normalisation
# and the chord |h - n| add a few eps: the angle it sees is alpha +- ``spread``
# (8 eps max(1, 2/|l + v|) here; measured at most 0.5 eps times that factor).  ``exp`` is good to
# (3 + 2 |x|) ulp (GLSL 4.50, 4.7.1) and ``ln(1 - delta)`` to a few ulp relative: at most
# eps (8 + 12 lambda) relative, lambda = -ln(lobe), with ks's rounding to float32.  A result below
# FLT_MIN may be flushed to 0.


def closed_form_rows(n, q):
    """``(wi, wo, labels)``: the light at normal, oblique and grazing incidence, h at n (the peak) and
    tilted toward l until the lobe has fallen to 1/2, 1e-3 and 1e-20 (q > 1), or by 0.3 and 0.7 rad
    (q <= 1); v = the reflection of l about h.  Plus views at grazing (n.v = 1e-3) and rows whose v
    falls below the surface (the closed form is 0 there)."""
    t, _ = frame_around(n)
    if q > 1:
        offsets = {"peak": 0.0, "half maximum": np.arccos(0.5 ** (1 / q)),
                   "1e-3 of maximum": np.arccos(1e-3 ** (1 / q)), "1e-20 of maximum": np.arccos(1e-20 ** (1 / q))}
    else:
        offsets = {"peak": 0.0, "0.3 rad off": 0.3, "0.7 rad off": 0.7}
    lights = {"normal incidence": 0.0, "40 deg": np.radians(40.0), "75 deg": np.radians(75.0),
              "grazing n.l=1e-2": np.arccos(1e-2), "grazing n.l=1e-4": np.arccos(1e-4)}
    wi, wo, labels = [], [], []
    for light, theta in lights.items():
        l = direction(n, theta, 0.3)
        for where, alpha in offsets.items():
            h = rotate_toward(n, l if theta > 0 else t, alpha)
            wi.append(l)
            wo.append(2 * np.dot(h, l) * h - l)
            labels.append(f"{light}, {where}")
    for phi in (0.3, 0.3 + np.pi, 2.0):  # grazing view, the light at 40 degrees
        wi.append(direction(n, np.radians(40.0), 0.3))
        wo.append(direction(n, np.arccos(1e-3), phi))
        labels.append(f"grazing view n.v=1e-3, azimuth {phi:.2f}")
    wi, wo = np.array(wi), np.array(wo)
    assert np.all(np.abs(wo @ n) > 1e-5), "keep clear of the n.v gate (8 eps)"
    return wi, wo, labels


def closed_form(ks, n, wi, wo, q):
    """``ks max(n.h, 0)^q`` with h = (l + v)/|l + v|, 0 where n.v <= 0 (and where n.l <= 0)."""
    h = wi + wo
    h_len = np.linalg.norm(h, axis=1)
    cos_alpha = (h @ n) / h_len
    gate = (wi @ n > 0) & (wo @ n > 0)
    lobe = np.where(gate, np.maximum(cos_alpha, 0.0) ** q, 0.0)
    return np.asarray(ks) * lobe[:, None], cos_alpha, h_len, gate


@pytest.mark.parametrize("normal", NORMALS, ids=["normal+z", "normal-tilted"])
@pytest.mark.parametrize("q", QS, ids=[f"q={q:g}" for q in QS])
def test_closed_form(glphong_backend, q, normal):
    wi, wo, labels = closed_form_rows(normal, q)
    gpu = evaluate(BlinnLobe(KS, q), wi, wo, normal=normal, backend=glphong_backend).astype(np.float64)
    ks = np.array(KS)
    expected, cos_alpha, h_len, gate = closed_form(ks, normal, wi, wo, q)
    assert gate.sum() >= len(wi) // 2  # most rows are above the surface
    assert np.all(gpu[:, 1] == 0.0)  # the zero channel
    assert np.array_equal(gpu[~gate], np.zeros_like(gpu[~gate]))  # v below the surface
    gpu, expected, cos_alpha, h_len = gpu[gate], expected[gate], cos_alpha[gate], h_len[gate]
    labels = [s for s, g in zip(labels, gate) if g]
    if q == 0:  # max(n.h, 0)^0 = 1 where h is defined: exactly ks, as float32
        np.testing.assert_array_equal(gpu, np.tile(f32(ks), (len(gpu), 1)))
        return
    low, high = cosine_power_interval(cos_alpha, q, 8 * EPS * np.maximum(1.0, 2.0 / h_len))
    low, high = ks * low[:, None], ks * high[:, None]
    low = np.where(low < FLT_MIN, 0.0, low)
    high = np.where(high < FLT_MIN, FLT_MIN, high)
    bad = ~((gpu >= low) & (gpu <= high))
    assert not bad.any(), "\n".join(
        f"{labels[i]}: gpu {gpu[i]}, closed form {expected[i]}, interval ({low[i]}, {high[i]})"
        for i in np.nonzero(bad.any(axis=1))[0])
    peak = [i for i, s in enumerate(labels) if s.endswith("peak") and "grazing" not in s]
    if normal[2] == 1.0:  # h = n is exact for the +z normal away from grazing: the peak is ks to an ulp
        np.testing.assert_allclose(gpu[peak], np.tile(f32(ks), (len(peak), 1)), rtol=2 * EPS, atol=0)


@pytest.mark.parametrize("q", [0.0, 10.0])
def test_gates_give_exactly_zero(glphong_backend, q):
    n = np.array([0.0, 0.0, 1.0])
    # n.l <= 0 with the view mirrored: h is (close to) n, the lobe would be at its peak
    wi = np.array([[1.0, 0.0, 0.0], [0.6, 0.8, 0.0], [1.0, 0.0, -1e-7], [0.3, 0.1, -0.5], [0.0, 0.3, -1.0]])
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    wo = wi * np.array([-1.0, -1.0, 1.0])
    wo[:, 2] = np.abs(wo[:, 2]) + 0.05
    gpu = evaluate(BlinnLobe(KS, q), wi, wo, normal=n, backend=glphong_backend)
    assert np.array_equal(gpu, np.zeros_like(gpu))
    # n.v <= 0 with n.l > 0: h is above the surface (n.h > 0), but the lobe is 0
    wo = np.array([[0.6, 0.8, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, -1e-7], [-0.3, 0.1, -0.2], [0.0, 0.8, -0.6]])
    wi = np.array([direction(n, np.radians(20.0), phi) for phi in (0.0, 1.0, 2.0, 3.0, 4.0)])
    assert np.all((wi + wo / np.linalg.norm(wo, axis=1, keepdims=True)) @ n > 0)
    gpu = evaluate(BlinnLobe(KS, q), wi, wo, normal=n, backend=glphong_backend)
    assert np.array_equal(gpu, np.zeros_like(gpu))
    # the same with the tilted normal, clear of the gate's rounding
    wi = np.array([direction(TILTED, theta, 1.0) for theta in (0.3, 0.3, np.pi / 2 + 1e-3, 2.0)])
    wo = np.array([direction(TILTED, theta, 4.0) for theta in (np.pi / 2 + 1e-3, 2.0, 0.3, 0.3)])
    gpu = evaluate(BlinnLobe(KS, q), wi, wo, normal=TILTED, backend=glphong_backend)
    assert np.array_equal(gpu, np.zeros_like(gpu))


@pytest.mark.parametrize("q", [1.0, 50.0, 1e4, 1e7])
def test_never_above_the_peak(glphong_backend, q):
    """max(n.h, 0)^q <= 1: the response never exceeds ks (the textbook pow overshoots at high q)."""
    wi, wo, _ = direction_sets(2000, 1)
    gpu = evaluate(BlinnLobe(KS, q), wi, wo, backend=glphong_backend).astype(np.float64)
    assert np.all(np.isfinite(gpu)) and np.all(gpu >= 0.0)
    assert np.all(gpu <= f32(KS))


# --------------------------------------------------------------------------- the declaration
def test_declaration():
    assert BlinnLobe.name == "blinn_lobe"
    ks, q = BlinnLobe.params
    assert (ks.name, ks.kind, ks.glsl_type, ks.interval, ks.unit, ks.default) == ("ks", "rgb", "vec3", "[0, inf]",
                                                                                  "1/sr", None)
    assert (q.name, q.kind, q.glsl_type, q.interval, q.unit, q.default) == ("q", "scalar", "float", "[0, inf]", "",
                                                                            None)
    assert BlinnLobe.needs == ("view",) and BlinnLobe.uses == ("lobe",)
    assert BlinnLobe.ambient is None
    assert BlinnLobe.vanishes_with == ("ks",)
    assert BlinnLobe.fresnel_slot.cosine == "h.l" and BlinnLobe.fresnel_slot.default is None
    p = BlinnLobe.properties
    assert (p.reciprocal, p.isotropic, p.energy_conserving, p.non_negative) == (False, True, False, True)


def test_blinn_phong_is_lambert_plus_blinn_lobe():
    assert BlinnPhong.terms == (Lambert, BlinnLobe) and BlinnPhong.name == "blinn_phong"
    assert [p.name for p in BlinnPhong.all_params()] == ["kd", "ks", "q"]
    # derived from the terms: not reciprocal (the lobe is not), isotropic (both are); docs/design.md section 1:
    # the lecture's models do not conserve energy, so it must not be declared to
    assert BlinnPhong.properties == Properties(reciprocal=False, isotropic=True, non_negative=True)
    assert BlinnPhong.properties.energy_conserving is not True


# --------------------------------------------------------------------------- a render
def test_render_matches(glphong_renderer):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene = glphong.Scene(camera, lights=[glphong.PointLight((1.5, 1.0, 3.0), (80.0, 60.0, 40.0))])
    scene.add(glphong.primitives.sphere(3), BlinnLobe(KS, 80.0))
    report = assert_render_matches(scene, glphong_renderer)
    assert report.covered_pixels > 1000 and report.nonfinite_count == 0
    assert report.gpu[..., 0].max() > 0.1  # the highlight is in the picture
    covered = report.mask[..., None] & (report.reference >= 2.0 ** -100)
    assert report.relative_error[covered].max() < 1e-3
