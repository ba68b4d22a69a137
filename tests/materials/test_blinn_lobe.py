"""The built-in model 'blinn_lobe' (`glphong.materials.BlinnLobe`) and the material `glphong.BlinnPhong`,
tested the way a user tests their own model.

What is tested, with the toolkit of `glphong.testing` on both backends (fixture ``glphong_backend``):

- the GLSL response against the numpy twin (`assert_twin_matches`, 4200 direction pairs: seeded
  random and the edge sets) for q = 0, 1, 50, 1e4, 1e7 and ks = 1 or (0.5, 0, 0.2) (a zero channel),
  and ks = 0.  Figures asserted (measured on Mesa llvmpipe, identical through EGL and OSMesa):
  ``max_relative_error`` is exactly 0 at q = 0, 7.2e-5 at q = 1 (bound 1e-3), and at most 2.9e-5 for
  q >= 50 over the channels whose value is decided (the light gate certain, the band clear of 0, so
  responses llvmpipe may flush below FLT_MIN are not counted; bound 1e-4).  Where the twin is at least 2^-100 the relative error measured 2.29e-5 at most for q >= 50 (bound
  1e-4, from exp's (3 + 2|x|) ulp with |x| <= 70 there);
- the GLSL response (`evaluate`) against the closed form ``ks max(n.h, 0)^q``, ``h = (l + v)/|l + v|``,
  0 where ``n.v <= 0``, written here in float64: at the peak (h = n), at half and 1e-3 and 1e-20 of the
  maximum, at normal, oblique and grazing incidence (n.l = 1e-2, 1e-4) and grazing view, for the +z
  normal and a tilted normal, within the interval of `lobe_interval` (the angle of h uncertain by
  8 eps max(1, 2/|l + v|), measured at most 0.5 eps times that factor; exp/log error eps (8 + 12 lambda));
  q = 0 gives exactly ks where n.l > 0 and n.v > 0; exactly 0 where n.l <= 0 (even with h = n) and
  where n.v <= 0 (even with n.l > 0 and n.h > 0); never above ks;
- the definition (params, needs 'view', no ambient answer, vanishes with ks, declared properties per
  DESIGN sections 1 and 8: isotropic, not reciprocal, not energy-conserving), ``BlinnPhong.terms``
  and ``components``;
- the program key: the lobe leaves the key when ks = 0 (``BlinnPhong(0.2, 0.0, 10)`` has only the
  lambert term), its uniforms are ``u_blinn_lobe_ks`` and ``u_blinn_lobe_q`` (`evaluate` binds them
  strictly: a missing or unknown uniform is an error), and BlinnPhong's response is the sum of its terms';
- one render of a sphere under one point light through ``glphong_renderer``, passing
  `assert_render_matches` (relative error where the twin is at least 2^-100 below 1e-3).
"""
import numpy as np
import pytest

import glphong
import glphong.primitives
from glphong.key import program_key, response_key
from glphong.materials import BlinnLobe, BlinnPhong, Lambert, Properties
from glphong.materials.blinn import blinn_delta
from glphong.programs import assemble
from glphong.testing import (assert_render_matches, assert_twin_matches, cosine_power_interval, direction,
                             direction_sets, evaluate, float32_units, frame_around, rotate_toward)

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
@pytest.mark.parametrize("ks", [1.0, KS], ids=["ks=1", "ks-zero-channel"])
@pytest.mark.parametrize("q", QS, ids=[f"q={q:g}" for q in QS])
def test_twin_matches(glphong_backend, q, ks):
    material = BlinnLobe(ks, q)
    figures = assert_twin_matches(material, n=2000, seed=0, backend=glphong_backend)
    wi, wo, labels = direction_sets(2000, 0)
    l, v = float32_units(wi), float32_units(wo)
    defined = (l[:, 2] > 0) & (v[:, 2] > 0) & (np.linalg.norm(l + v, axis=1) > 2.0 ** -20)
    # n.h > 0 wherever n.l > 0 and n.v > 0, so the lobe is non-zero there, except where both directions
    # graze to 1e-19 or less: there the twin's delta = |h - n|^2 / 2 may round to 1 (lobe 0 for q > 0)
    _, delta = blinn_delta(np.array([0.0, 0.0, 1.0]), l, v)
    assert figures["pairs"] == len(wi)
    assert figures["nonzero"] == int(np.sum(defined & ((delta < 1) | (q == 0))))
    if q == 0:
        assert figures["max_relative_error"] == 0.0
    elif q == 1:
        assert figures["max_relative_error"] < 1e-3  # measured 7.2e-5
    else:
        assert figures["max_relative_error"] < 1e-4  # measured at most 2.9e-5 (q = 50), where decided
    gpu = evaluate(material, wi, wo, backend=glphong_backend).astype(np.float64)
    twin = evaluate(material, wi, wo, twin=True)
    # away from underflow, and from the set where both directions graze to 1e-19 (there the lobe's
    # delta is 1 - 1e-38 and float32 resolves it to within eps: judged by the band above, not here)
    normal = (twin >= 2.0 ** -100) & (labels != "l and v grazing, (n.l)(n.v) below FLT_MIN")[:, None]
    rel = np.abs(gpu - twin)[normal] / twin[normal]
    assert rel.max() < (1e-3 if q <= 1 else 1e-4)  # measured 0 / 7.2e-5 / at most 2.29e-5


def test_twin_matches_ks_zero(glphong_backend):
    figures = assert_twin_matches(BlinnLobe(0.0, 50.0), backend=glphong_backend)
    assert figures["nonzero"] == 0 and figures["max_relative_error"] == 0.0


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


# --------------------------------------------------------------------------- the definition
def test_definition():
    assert BlinnLobe.name == "blinn_lobe" and glphong.materials.model_named("blinn_lobe") is BlinnLobe
    ks, q = BlinnLobe.params
    assert (ks.name, ks.kind, ks.glsl_type, ks.interval, ks.unit, ks.default) == ("ks", "rgb", "vec3", "[0, inf]",
                                                                                  "1/sr", None)
    assert (q.name, q.kind, q.glsl_type, q.interval, q.unit, q.default) == ("q", "scalar", "float", "[0, inf]", "",
                                                                            None)
    assert BlinnLobe.needs == ("view",) and BlinnLobe.uses == ("lobe",)
    assert BlinnLobe.ambient is None
    assert BlinnLobe.vanishes_with == ("ks",)
    p = BlinnLobe.properties
    assert (p.reciprocal, p.isotropic, p.energy_conserving, p.non_negative) == (False, True, False, True)
    m = BlinnLobe(KS, 10)
    assert m.components == (m,) and m.ks == KS and m.q == 10.0
    assert BlinnLobe(0.0, 10).vanishes() and not BlinnLobe(KS, 0.0).vanishes()
    assert not m.answers_ambient()
    with pytest.raises(TypeError, match="q"):
        BlinnLobe(0.5)  # q has no default
    for bad in ({"q": -1.0}, {"q": np.inf}, {"q": np.nan}, {"ks": -0.1}):
        with pytest.raises(ValueError):
            BlinnLobe(**({"ks": 0.5, "q": 10.0} | bad))


def test_blinn_phong_is_lambert_plus_blinn_lobe():
    assert BlinnPhong.terms == (Lambert, BlinnLobe) and BlinnPhong.name == "blinn_phong"
    assert [p.name for p in BlinnPhong.all_params()] == ["kd", "ks", "q"]
    m = BlinnPhong(0.2, KS, 10, two_sided=False)
    lam, lobe = m.components
    assert type(lam) is Lambert and type(lobe) is BlinnLobe
    assert lam.kd == (0.2, 0.2, 0.2) and lobe.ks == KS and lobe.q == 10.0
    assert not lam.two_sided and not lobe.two_sided
    assert (m.kd, m.ks, m.q) == ((0.2, 0.2, 0.2), KS, 10.0)
    # derived from the terms: not reciprocal (the lobe is not), isotropic (both are); DESIGN section 1:
    # the lecture's models do not conserve energy, so it must not be declared to
    assert BlinnPhong.properties.reciprocal is False and BlinnPhong.properties.isotropic is True
    assert BlinnPhong.properties.energy_conserving is not True
    assert BlinnPhong.properties == Properties(reciprocal=False, isotropic=True, non_negative=True)


def test_blinn_phong_response_is_the_sum_of_its_terms(glphong_backend):
    wi, wo, _ = direction_sets(200, 2)
    total = evaluate(BlinnPhong(0.2, KS, 30), wi, wo, backend=glphong_backend).astype(np.float64)
    parts = sum(evaluate(m, wi, wo, backend=glphong_backend).astype(np.float64)
                for m in (Lambert(0.2), BlinnLobe(KS, 30)))
    np.testing.assert_allclose(total, parts, rtol=2 * EPS, atol=0)  # one float32 addition


# --------------------------------------------------------------------------- program key
def test_program_key_and_uniform_names():
    names = lambda m: [t.name for t in program_key(m, {"point": 1}, None).terms]  # noqa: E731
    assert names(BlinnPhong(0.2, 0.0, 10)) == ["lambert"]
    assert names(BlinnPhong(0.0, 0.5, 10)) == ["blinn_lobe"]
    assert names(BlinnPhong(0.2, KS, 10)) == ["lambert", "blinn_lobe"]  # a zero channel does not vanish
    assert names(BlinnPhong(0.2, 0.5, 0.0)) == ["lambert", "blinn_lobe"]  # q = 0 is a constant lobe, not zero
    assert names(BlinnLobe(0.0, 10)) == [] and program_key(BlinnLobe(0.0, 10), {"point": 1}, None).num_lights == 0
    assert response_key(BlinnLobe(0.0, 10)).terms == ()

    key = program_key(BlinnPhong(0.2, KS, 10), {"point": 1}, None)
    assert key.needs_view and not key.has_tangent and not key.has_uv
    uniforms = BlinnPhong(0.2, KS, 10).uniform_values(key)
    assert uniforms.keys() == {"u_lambert_kd", "u_blinn_lobe_ks", "u_blinn_lobe_q"}
    np.testing.assert_array_equal(uniforms["u_blinn_lobe_ks"], np.float32(KS))
    assert uniforms["u_blinn_lobe_q"] == np.float32(10) and uniforms["u_blinn_lobe_q"].shape == ()
    assert [BlinnLobe.uniform_name(p) for p in ("ks", "q")] == ["u_blinn_lobe_ks", "u_blinn_lobe_q"]
    source = assemble(key.fragment_chunks(), key.defines(), key.generated_chunks())
    assert "uniform vec3 u_blinn_lobe_ks;" in source and "uniform float u_blinn_lobe_q;" in source
    assert "response += blinn_lobe_response(f, wi, wo, n_dot_l);" in source

    lambert_only = program_key(BlinnPhong(0.2, 0.0, 10), {"point": 1}, None)
    assert not lambert_only.needs_view and "lobe" not in lambert_only.library_chunks()
    assert BlinnPhong(0.2, 0.0, 10).uniform_values(lambert_only).keys() == {"u_lambert_kd"}
    assert "blinn_lobe" not in assemble(lambert_only.fragment_chunks(), lambert_only.defines(),
                                        lambert_only.generated_chunks())
    ambient = program_key(BlinnPhong(0.2, 0.5, 10), {}, (0.1, 0.1, 0.1))
    assert [(t.name, t.lit, t.ambient) for t in ambient.terms] == [("lambert", False, True)]
    assert program_key(BlinnLobe(0.5, 10), {}, (0.1, 0.1, 0.1)).terms == ()


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
