"""The built-in model 'phong_lobe' (`glphong.materials.PhongLobe`) and the material `glphong.Phong`,
tested the way a user tests their own model.

What is tested, with the toolkit of `glphong.testing` on both backends (fixture ``glphong_backend``):

- the GLSL response against the numpy twin (`assert_twin_matches`, 4200 direction pairs: seeded
  random and the edge sets) for q = 0, 1, 50, 1e4, 1e7 and ks = 1 or (0.5, 0, 0.2) (a zero channel),
  and ks = 0.  Figures asserted (measured on Mesa llvmpipe, identical through EGL and OSMesa):
  ``max_relative_error`` is exactly 0 at q = 0 (the lobe is exactly 1), 2.07e-4 at q = 1 (bound
  1e-3: where v.r is small, 1 - delta loses digits), and at most 3.5e-5 for q >= 50
  (over the channels whose value is decided: the light gate certain and the band clear of 0, so
  responses llvmpipe may flush below FLT_MIN are not counted; bound 1e-4).  Where the twin is at
  least 2^-100, far above float32 underflow, the relative error measured 2.43e-5 at most (q >= 50; bound 1e-4, from exp's (3 + 2|x|) ulp with |x| <= 70 there);
- the GLSL response (`evaluate`) against the closed form ``ks max(v.r, 0)^q``, ``r = 2 (n.l) n - l``,
  written here in float64: at the peak, at half and 1e-3 and 1e-20 of the maximum, at normal, oblique
  and grazing incidence (n.l = 1e-2, 1e-4), for the +z normal and a tilted normal, within the interval
  of `lobe_interval` (angles uncertain by 8 eps, measured at most 3 eps; exp/log error
  eps (8 + 12 lambda)); q = 0 gives exactly ks everywhere n.l > 0 (0^0 := 1); exactly 0 where n.l <= 0
  (even with the view at the mirror direction) and where v.r <= 0 (q > 0); never above ks;
- the definition (params, needs 'view', no ambient answer, vanishes with ks, declared properties per
  DESIGN sections 1 and 8: isotropic, not reciprocal, not energy-conserving), ``Phong.terms`` and
  ``components``;
- the program key: the lobe leaves the key when ks = 0 (``Phong(0.2, 0.0, 10)`` has only the lambert
  term), its uniforms are ``u_phong_lobe_ks`` and ``u_phong_lobe_q`` (`evaluate` binds them strictly:
  a missing or unknown uniform is an error), and Phong's response is the sum of its terms';
- one render of a sphere under one point light through ``glphong_renderer``, passing
  `assert_render_matches` (relative error 1.27e-4 where the twin is at least 2^-100; bound 1e-3).
"""
import numpy as np
import pytest

import glphong
import glphong.primitives
from glphong.key import program_key, response_key
from glphong.materials import Lambert, Phong, PhongLobe, Properties
from glphong.programs import assemble
from glphong.testing import (assert_render_matches, assert_twin_matches, cosine_power_interval, direction,
                             direction_sets, evaluate, float32_units, frame_around, rotate_toward)

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
@pytest.mark.parametrize("ks", [1.0, KS], ids=["ks=1", "ks-zero-channel"])
@pytest.mark.parametrize("q", QS, ids=[f"q={q:g}" for q in QS])
def test_twin_matches(glphong_backend, q, ks):
    material = PhongLobe(ks, q)
    figures = assert_twin_matches(material, n=2000, seed=0, backend=glphong_backend)
    wi, wo, labels = direction_sets(2000, 0)
    l, v = float32_units(wi), float32_units(wo)
    n_dot_l = l[:, 2]
    v_dot_r = np.sum(v * (2 * n_dot_l[:, None] * np.array([0.0, 0.0, 1.0]) - l), axis=1)
    assert figures["pairs"] == len(wi)
    assert figures["nonzero"] == int(np.sum((n_dot_l > 0) & ((v_dot_r > 0) | (q == 0))))
    if q == 0:
        assert figures["max_relative_error"] == 0.0
    elif q == 1:
        assert figures["max_relative_error"] < 1e-3  # measured 2.07e-4
    else:
        assert figures["max_relative_error"] < 1e-4  # measured at most 3.5e-5 (q = 50), where decided
    # away from underflow the GPU follows the twin closely
    gpu = evaluate(material, wi, wo, backend=glphong_backend).astype(np.float64)
    twin = evaluate(material, wi, wo, twin=True)
    # away from underflow, and from the set where both directions graze to 1e-19 (there the lobe's
    # delta is 1 - 1e-38 and float32 resolves it to within eps: judged by the band above, not here)
    normal = (twin >= 2.0 ** -100) & (labels != "l and v grazing, (n.l)(n.v) below FLT_MIN")[:, None]
    rel = np.abs(gpu - twin)[normal] / twin[normal]
    assert rel.max() < (1e-3 if q <= 1 else 1e-4)  # measured 0 / 2.07e-4 / at most 2.43e-5


def test_twin_matches_ks_zero(glphong_backend):
    figures = assert_twin_matches(PhongLobe(0.0, 50.0), backend=glphong_backend)
    assert figures["nonzero"] == 0 and figures["max_relative_error"] == 0.0


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


# --------------------------------------------------------------------------- the definition
def test_definition():
    assert PhongLobe.name == "phong_lobe" and glphong.materials.model_named("phong_lobe") is PhongLobe
    ks, q = PhongLobe.params
    assert (ks.name, ks.kind, ks.glsl_type, ks.interval, ks.unit, ks.default) == ("ks", "rgb", "vec3", "[0, inf]",
                                                                                  "1/sr", None)
    assert (q.name, q.kind, q.glsl_type, q.interval, q.unit, q.default) == ("q", "scalar", "float", "[0, inf]", "",
                                                                            None)
    assert PhongLobe.needs == ("view",) and PhongLobe.uses == ("lobe",)
    assert PhongLobe.ambient is None
    assert PhongLobe.vanishes_with == ("ks",)
    p = PhongLobe.properties
    assert (p.reciprocal, p.isotropic, p.energy_conserving, p.non_negative) == (False, True, False, True)
    m = PhongLobe(KS, 10)
    assert m.components == (m,) and m.ks == KS and m.q == 10.0
    assert PhongLobe(0.0, 10).vanishes() and not PhongLobe(KS, 0.0).vanishes()
    assert not m.answers_ambient()
    with pytest.raises(TypeError, match="q"):
        PhongLobe(0.5)  # q has no default
    for bad in ({"q": -1.0}, {"q": np.inf}, {"q": np.nan}, {"ks": -0.1}):
        with pytest.raises(ValueError):
            PhongLobe(**({"ks": 0.5, "q": 10.0} | bad))


def test_phong_is_lambert_plus_phong_lobe():
    assert Phong.terms == (Lambert, PhongLobe) and Phong.name == "phong"
    assert [p.name for p in Phong.all_params()] == ["kd", "ks", "q"]
    m = Phong(0.2, KS, 10, two_sided=False)
    lam, lobe = m.components
    assert type(lam) is Lambert and type(lobe) is PhongLobe
    assert lam.kd == (0.2, 0.2, 0.2) and lobe.ks == KS and lobe.q == 10.0
    assert not lam.two_sided and not lobe.two_sided
    assert (m.kd, m.ks, m.q) == ((0.2, 0.2, 0.2), KS, 10.0)
    # derived from the terms: not reciprocal (the lobe is not), isotropic (both are); DESIGN section 1:
    # the lecture's Phong does not conserve energy, so it must not be declared to
    assert Phong.properties.reciprocal is False and Phong.properties.isotropic is True
    assert Phong.properties.energy_conserving is not True
    assert Phong.properties == Properties(reciprocal=False, isotropic=True, non_negative=True)


def test_phong_response_is_the_sum_of_its_terms(glphong_backend):
    wi, wo, _ = direction_sets(200, 2)
    total = evaluate(Phong(0.2, KS, 30), wi, wo, backend=glphong_backend).astype(np.float64)
    parts = sum(evaluate(m, wi, wo, backend=glphong_backend).astype(np.float64)
                for m in (Lambert(0.2), PhongLobe(KS, 30)))
    np.testing.assert_allclose(total, parts, rtol=2 * EPS, atol=0)  # one float32 addition


# --------------------------------------------------------------------------- program key
def test_program_key_and_uniform_names():
    names = lambda m, **kw: [t.name for t in program_key(m, {"point": 1}, None, **kw).terms]  # noqa: E731
    assert names(Phong(0.2, 0.0, 10)) == ["lambert"]
    assert names(Phong(0.0, 0.5, 10)) == ["phong_lobe"]
    assert names(Phong(0.2, KS, 10)) == ["lambert", "phong_lobe"]  # a zero channel does not vanish
    assert names(Phong(0.2, 0.5, 0.0)) == ["lambert", "phong_lobe"]  # q = 0 is a constant lobe, not zero
    assert names(PhongLobe(0.0, 10)) == [] and program_key(PhongLobe(0.0, 10), {"point": 1}, None).num_lights == 0
    assert response_key(PhongLobe(0.0, 10)).terms == ()

    key = program_key(Phong(0.2, KS, 10), {"point": 1}, None)
    assert key.needs_view and not key.has_tangent and not key.has_uv
    uniforms = Phong(0.2, KS, 10).uniform_values(key)
    assert uniforms.keys() == {"u_lambert_kd", "u_phong_lobe_ks", "u_phong_lobe_q"}
    np.testing.assert_array_equal(uniforms["u_phong_lobe_ks"], np.float32(KS))
    assert uniforms["u_phong_lobe_q"] == np.float32(10) and uniforms["u_phong_lobe_q"].shape == ()
    assert [PhongLobe.uniform_name(p) for p in ("ks", "q")] == ["u_phong_lobe_ks", "u_phong_lobe_q"]
    source = assemble(key.fragment_chunks(), key.defines(), key.generated_chunks())
    assert "uniform vec3 u_phong_lobe_ks;" in source and "uniform float u_phong_lobe_q;" in source
    assert "response += phong_lobe_response(f, wi, wo, n_dot_l);" in source

    lambert_only = program_key(Phong(0.2, 0.0, 10), {"point": 1}, None)
    assert not lambert_only.needs_view and "lobe" not in lambert_only.library_chunks()
    assert Phong(0.2, 0.0, 10).uniform_values(lambert_only).keys() == {"u_lambert_kd"}
    assert "phong_lobe" not in assemble(lambert_only.fragment_chunks(), lambert_only.defines(),
                                        lambert_only.generated_chunks())
    # no ambient answer: under L_a alone only Lambert's k_d L_a remains
    ambient = program_key(Phong(0.2, 0.5, 10), {}, (0.1, 0.1, 0.1))
    assert [(t.name, t.lit, t.ambient) for t in ambient.terms] == [("lambert", False, True)]
    assert program_key(PhongLobe(0.5, 10), {}, (0.1, 0.1, 0.1)).terms == ()


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
