"""The built-in model 'phong_lobe' (`glphong.materials.PhongLobe`) and the material `glphong.Phong`,
tested the way a user tests their own model.

What is specific to it (twin agreement for q = 0, 1, 50, 1e4, 1e7 with ks = 1 or a zero channel and with
Fresnel factors, its figures, the definition's mechanics, the program key, vanishing at ks = 0, the sum
`Phong` as a sum of its terms and the stability cases are in tests/test_conformance.py), with the toolkit
of `glphong.testing` on both backends (fixture ``glphong_backend``):

- the twin is non-zero exactly where the lobe is (the support the conformance figures count);
- the GLSL response (`evaluate`) against the closed form ``ks max(v.r, 0)^q``, ``r = 2 (n.l) n - l``,
  written here in float64: at the peak, at half and 1e-3 and 1e-20 of the maximum, at normal, oblique
  and grazing incidence (n.l = 1e-2, 1e-4), for the +z normal and a tilted normal, within the interval
  of `lobe_interval` (angles uncertain by 8 eps, measured at most 3 eps; exp/log error
  eps (8 + 12 lambda)); q = 0 gives exactly ks everywhere n.l > 0 (0^0 := 1); exactly 0 where n.l <= 0
  (even with the view at the mirror direction) and where v.r <= 0 (q > 0); never above ks;
- the declaration (params, needs 'view', no ambient answer, vanishes with ks, declared properties per
  docs/design.md sections 1 and 8: isotropic, not reciprocal, not energy-conserving) and ``Phong.terms``;
- one render of a sphere under one point light through ``glphong_renderer``, passing
  `assert_render_matches` (relative error 1.27e-4 where the twin is at least 2^-100; bound 1e-3).
"""
import numpy as np
import pytest

import glphong
import glphong.primitives
from glphong.materials import Lambert, Phong, PhongLobe, Properties
from glphong.testing import (assert_render_matches, cosine_power_interval, direction, direction_sets, evaluate,
                             float32_units, frame_around, rotate_toward)

EPS = 2.0 ** -24
FLT_MIN = 2.0 ** -126
KS = (0.5, 0.0, 0.2)
QS = [0.0, 1.0, 50.0, 1e4, 1e7]
#: a tilted unit normal: the reflection r is then computed with rounding
TILTED = np.array([0.3, -0.2, 0.9]) / np.linalg.norm([0.3, -0.2, 0.9])
NORMALS = [np.array([0.0, 0.0, 1.0]), TILTED]


def f32(x):
    return np.asarray(x, dtype=np.float32).astype(np.float64)


# --------------------------------------------------------------------------- twin
@pytest.mark.parametrize("q", QS, ids=[f"q={q:g}" for q in QS])
def test_the_twin_is_non_zero_exactly_where_the_lobe_is(q):
    """Non-zero where n.l > 0 and v.r > 0 (everywhere n.l > 0 for q = 0), with ks = 1 and with a zero channel."""
    wi, wo, _ = direction_sets(2000, 0)
    l, v = float32_units(wi), float32_units(wo)
    n_dot_l = l[:, 2]
    v_dot_r = np.sum(v * (2 * n_dot_l[:, None] * np.array([0.0, 0.0, 1.0]) - l), axis=1)
    for ks in (1.0, KS):
        twin = evaluate(PhongLobe(ks, q), wi, wo, twin=True)
        assert int(np.any(twin != 0, axis=1).sum()) == int(np.sum((n_dot_l > 0) & ((v_dot_r > 0) | (q == 0))))


# --------------------------------------------------------------------------- closed form
# The closed form's interval is glphong.testing.cosine_power_interval; its spread for this lobe:
# The GPU's inputs are float32 unit vectors and its reflection and chord are float32 arithmetic:
# the angle it sees is alpha +- ``spread`` (8 eps here: about eps per rounded unit vector, 2-3 eps
# for r = 2 (n.l) n - l, one for the chord; measured at most 3 eps).  ``exp`` is good to
# (3 + 2 |x|) ulp (GLSL 4.50, 4.7.1) and ``ln(1 - delta)`` to a few ulp relative: at most
# eps (8 + 12 lambda) relative, lambda = -ln(lobe), with ks's rounding to float32.  A result below
# FLT_MIN may be flushed to 0.


def closed_form_rows(n, q):
    """``(wi, wo, labels)``: the light at normal, oblique and grazing incidence, the view at the peak
    and where the lobe has fallen to 1/2, 1e-3 and 1e-20 (q > 1), or at 0.5 and 1.2 rad (q <= 1)."""
    t, _ = frame_around(n)
    if q > 1:
        offsets = {"peak": 0.0, "half maximum": np.arccos(0.5 ** (1 / q)),
                   "1e-3 of maximum": np.arccos(1e-3 ** (1 / q)), "1e-20 of maximum": np.arccos(1e-20 ** (1 / q))}
    else:
        offsets = {"peak": 0.0, "0.5 rad off": 0.5, "1.2 rad off": 1.2}
    lights = {"normal incidence": 0.0, "40 deg": np.radians(40.0), "75 deg": np.radians(75.0),
              "grazing n.l=1e-2": np.arccos(1e-2), "grazing n.l=1e-4": np.arccos(1e-4)}
    wi, wo, labels = [], [], []
    for light, theta in lights.items():
        l = direction(n, theta, 0.3)
        r = 2 * np.dot(n, l) * n - l
        for where, alpha in offsets.items():
            wi.append(l)
            wo.append(rotate_toward(r, n if theta > 0 else t, alpha))
            labels.append(f"{light}, {where}")
    return np.array(wi), np.array(wo), labels


@pytest.mark.parametrize("normal", NORMALS, ids=["normal+z", "normal-tilted"])
@pytest.mark.parametrize("q", QS, ids=[f"q={q:g}" for q in QS])
def test_closed_form(glphong_backend, q, normal):
    wi, wo, labels = closed_form_rows(normal, q)
    gpu = evaluate(PhongLobe(KS, q), wi, wo, normal=normal, backend=glphong_backend).astype(np.float64)
    ks = np.array(KS)
    assert np.all(gpu[:, 1] == 0.0)  # the zero channel
    if q == 0:  # max(v.r, 0)^0 = 1 (0^0 := 1): exactly ks, as float32
        np.testing.assert_array_equal(gpu, np.tile(f32(ks), (len(wi), 1)))
        return
    r = 2 * (wi @ normal)[:, None] * normal - wi
    cos_alpha = np.sum(wo * r, axis=1)
    expected = ks * np.maximum(cos_alpha, 0.0)[:, None] ** q
    low, high = cosine_power_interval(cos_alpha, q, 8 * EPS)
    low, high = ks * low[:, None], ks * high[:, None]
    low = np.where(low < FLT_MIN, 0.0, low)
    high = np.where(high < FLT_MIN, FLT_MIN, high)
    bad = ~((gpu >= low) & (gpu <= high))
    assert not bad.any(), "\n".join(
        f"{labels[i]}: gpu {gpu[i]}, closed form {expected[i]}, interval ({low[i]}, {high[i]})"
        for i in np.nonzero(bad.any(axis=1))[0])
    peak = [i for i, s in enumerate(labels) if s.endswith("peak")]
    if normal[2] == 1.0:  # r and the chord are exact for the +z normal: the peak is exactly ks
        np.testing.assert_array_equal(gpu[peak], np.tile(f32(ks), (len(peak), 1)))


@pytest.mark.parametrize("q", [0.0, 10.0])
def test_light_below_the_surface_gives_exactly_zero(glphong_backend, q):
    # the view at the mirror direction r: the lobe would be at its peak, but n.l <= 0 gates it
    n = np.array([0.0, 0.0, 1.0])
    wi = np.array([[1.0, 0.0, 0.0], [0.6, 0.8, 0.0], [1.0, 0.0, -1e-7], [0.3, 0.1, -0.5], [0.0, 0.0, -1.0]])
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    wo = 2 * (wi @ n)[:, None] * n - wi
    wo[0:2] = [0.0, 0.6, 0.8]  # r = -l is below the horizon there: any view
    gpu = evaluate(PhongLobe(KS, q), wi, wo, normal=n, backend=glphong_backend)
    assert np.array_equal(gpu, np.zeros_like(gpu))
    wi = np.array([direction(TILTED, theta, 1.0) for theta in (np.pi / 2 + 1e-3, 2.0, np.pi)])
    wo = 2 * (wi @ TILTED)[:, None] * TILTED - wi
    gpu = evaluate(PhongLobe(KS, q), wi, wo, normal=TILTED, backend=glphong_backend)
    assert np.array_equal(gpu, np.zeros_like(gpu))


def test_view_past_ninety_degrees_from_r_gives_exactly_zero(glphong_backend):
    n = np.array([0.0, 0.0, 1.0])
    wi = np.tile(direction(n, np.radians(40.0), 0.3), (4, 1))
    r = 2 * (wi[0] @ n) * n - wi[0]
    wo = np.array([rotate_toward(r, n, alpha) for alpha in (np.pi / 2 + 1e-3, 2.0, 2.5, np.radians(140.0))])
    for q in (1.0, 50.0, 1e7):
        gpu = evaluate(PhongLobe(KS, q), wi, wo, normal=n, backend=glphong_backend)
        assert np.array_equal(gpu, np.zeros_like(gpu)), q


@pytest.mark.parametrize("q", [1.0, 50.0, 1e4, 1e7])
def test_never_above_the_peak(glphong_backend, q):
    """max(v.r, 0)^q <= 1: the response never exceeds ks (the textbook pow overshoots at high q)."""
    wi, wo, _ = direction_sets(2000, 1)
    gpu = evaluate(PhongLobe(KS, q), wi, wo, backend=glphong_backend).astype(np.float64)
    assert np.all(np.isfinite(gpu)) and np.all(gpu >= 0.0)
    assert np.all(gpu <= f32(KS))


# --------------------------------------------------------------------------- the declaration
def test_declaration():
    assert PhongLobe.name == "phong_lobe"
    ks, q = PhongLobe.params
    assert (ks.name, ks.kind, ks.glsl_type, ks.interval, ks.unit, ks.default) == ("ks", "rgb", "vec3", "[0, inf]",
                                                                                  "1/sr", None)
    assert (q.name, q.kind, q.glsl_type, q.interval, q.unit, q.default) == ("q", "scalar", "float", "[0, inf]", "",
                                                                            None)
    assert PhongLobe.needs == ("view",) and PhongLobe.uses == ("lobe",)
    assert PhongLobe.ambient is None
    assert PhongLobe.vanishes_with == ("ks",)
    assert PhongLobe.fresnel_slot.cosine == "n.l" and PhongLobe.fresnel_slot.default is None
    p = PhongLobe.properties
    assert (p.reciprocal, p.isotropic, p.energy_conserving, p.non_negative) == (False, True, False, True)


def test_phong_is_lambert_plus_phong_lobe():
    assert Phong.terms == (Lambert, PhongLobe) and Phong.name == "phong"
    assert [p.name for p in Phong.all_params()] == ["kd", "ks", "q"]
    # derived from the terms: not reciprocal (the lobe is not), isotropic (both are); docs/design.md section 1:
    # the lecture's models do not conserve energy, so it must not be declared to
    assert Phong.properties == Properties(reciprocal=False, isotropic=True, non_negative=True)
    assert Phong.properties.energy_conserving is not True


# --------------------------------------------------------------------------- a render
def test_render_matches(glphong_renderer):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene = glphong.Scene(camera, lights=[glphong.PointLight((1.5, 1.0, 3.0), (80.0, 60.0, 40.0))])
    scene.add(glphong.primitives.sphere(3), PhongLobe(KS, 20.0))
    report = assert_render_matches(scene, glphong_renderer)
    assert report.covered_pixels > 1000 and report.nonfinite_count == 0
    assert report.gpu[..., 0].max() > 0.1  # the highlight is in the picture
    # max_relative_error is 1 (the lobe's far tail underflows float32 and is flushed); where the twin is
    # at least 2^-100 it measured 1.27e-4 on llvmpipe (per-fragment normal and view in float32)
    covered = report.mask[..., None] & (report.reference >= 2.0 ** -100)
    assert report.relative_error[covered].max() < 1e-3
