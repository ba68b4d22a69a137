"""The built-in model 'lambert' (`glphong.Lambert`), tested the way a user tests their own model.

What is tested, with the toolkit of `glphong.testing` on both backends (fixture ``glphong_backend``):

- the GLSL response against the model's numpy twin (`assert_twin_matches`) for kd = 0.3, a kd with a
  zero channel, a tiny kd and kd = 0, with assertions on the returned figures: the maximum relative
  error (measured 5.85e-8, just under eps = 2^-24 on Mesa llvmpipe through EGL and OSMesa: the
  normal is +z, so n.l is exact and the only rounding is the product kd (n.l)) must stay below 2 eps;
- the GLSL response (`evaluate`) against the closed form ``kd (n.l)`` written here in float64, at
  normal, oblique and grazing incidence (n.l down to 1e-6), for the +z normal and a tilted normal
  (tolerance derived in `TOLERANCE`), and exactly 0 where ``n.l <= 0``;
- the definition: name, parameter (kind, range, no default, unit), needs, ambient answer, what
  makes it vanish, declared properties (DESIGN sections 1 and 8: f_r = kd is reciprocal and
  isotropic; its albedo is pi kd, so it conserves energy when pi kd <= 1), ``components``;
- the program key: the term leaves the key when kd = 0, answers the ambient light with kd L_a,
  and its uniform is ``u_lambert_kd`` (`evaluate` binds uniforms strictly: a missing or unknown one
  is an error);
- one render of a sphere under a point light and an ambient light through ``glphong_renderer``,
  passing `assert_render_matches` (max relative error 4.45e-7 measured; bound 1e-5).
"""
import numpy as np
import pytest

import glphong
import glphong.primitives
from glphong.key import program_key, response_key
from glphong.materials import Lambert, Properties
from glphong.programs import assemble
from glphong.testing import assert_render_matches, assert_twin_matches, direction, direction_sets, evaluate

EPS = 2.0 ** -24
KD = (0.1, 0.0, 0.25)
#: a tilted unit normal: n.l is then a rounded float32 dot product, not an exact coordinate
TILTED = np.array([0.3, -0.2, 0.9]) / np.linalg.norm([0.3, -0.2, 0.9])


# --------------------------------------------------------------------------- twin
@pytest.mark.parametrize("kd", [0.3, KD, 1e-3], ids=["kd=0.3", "kd-zero-channel", "kd=1e-3"])
def test_twin_matches(glphong_backend, kd):
    figures = assert_twin_matches(Lambert(kd), n=2000, seed=0, backend=glphong_backend)
    wi, _, _ = direction_sets(2000, 0)
    wi32 = (wi / np.linalg.norm(wi, axis=1, keepdims=True)).astype(np.float32)
    assert figures["pairs"] == len(wi)
    # non-zero exactly where the light is above the surface (normal +z)
    assert figures["nonzero"] == int(np.sum(wi32[:, 2] > 0))
    # measured 5.85e-8 (< eps): with normal +z, n.l is exact; kd (n.l) is one correctly rounded product
    assert figures["max_relative_error"] <= 2 * EPS


def test_twin_matches_kd_zero(glphong_backend):
    figures = assert_twin_matches(Lambert(0.0), backend=glphong_backend)
    assert figures["nonzero"] == 0 and figures["max_relative_error"] == 0.0


# --------------------------------------------------------------------------- closed form
#: polar angles of the light: normal, oblique, and grazing (n.l = 1e-2, 1e-4, 1e-6)
THETAS = [0.0, np.radians(30.0), np.radians(60.0), np.arccos(1e-2), np.arccos(1e-4), np.arccos(1e-6)]
#: |GPU - kd (n.l)| <= kd (3 eps (n.l) + 8 eps): kd and the directions are rounded to float32 (eps
#: relative each), the product once more (eps); a tilted normal's float32 dot product n.l adds at
#: most about 8 eps absolute (three rounded products, two sums, rounded unit inputs)
TOLERANCE_REL, TOLERANCE_ABS = 3 * EPS, 8 * EPS


@pytest.mark.parametrize("normal", [np.array([0.0, 0.0, 1.0]), TILTED], ids=["normal+z", "normal-tilted"])
def test_closed_form(glphong_backend, normal):
    wi = np.array([direction(normal, theta, 0.7 + k) for k, theta in enumerate(THETAS)])
    wo = np.array([direction(normal, 0.4, 2.0)] * len(wi))
    gpu = evaluate(Lambert(KD), wi, wo, normal=normal, backend=glphong_backend).astype(np.float64)
    kd = np.array(KD)
    n_dot_l = wi @ normal
    expected = kd * n_dot_l[:, None]
    tolerance = kd * (TOLERANCE_REL * n_dot_l[:, None] + TOLERANCE_ABS)
    np.testing.assert_array_less(np.abs(gpu - expected), tolerance + 1e-300)
    assert np.all(gpu[:, 1] == 0.0)  # the zero channel stays exactly zero
    if normal[2] == 1.0:  # n.l is an exact coordinate: relative 3 eps holds even at n.l = 1e-6
        np.testing.assert_array_less(np.abs(gpu - expected), 3 * EPS * expected + 1e-300)


def test_light_below_the_surface_gives_exactly_zero(glphong_backend):
    n = np.array([0.0, 0.0, 1.0])
    wi = np.array([[1.0, 0.0, 0.0], [0.6, 0.8, 0.0], [1.0, 0.0, -1e-7], [0.3, 0.1, -0.5], [0.0, 0.0, -1.0]])
    wo = np.tile([0.0, 0.6, 0.8], (len(wi), 1))
    gpu = evaluate(Lambert(0.7), wi, wo, normal=n, backend=glphong_backend)
    assert np.array_equal(gpu, np.zeros_like(gpu))
    tilted = np.array([direction(TILTED, theta, 1.0) for theta in (np.pi / 2 + 1e-3, 2.0, np.pi)])
    gpu = evaluate(Lambert(0.7), tilted, wo[:3], normal=TILTED, backend=glphong_backend)
    assert np.array_equal(gpu, np.zeros_like(gpu))


# --------------------------------------------------------------------------- the definition
def test_definition():
    assert Lambert.name == "lambert"
    assert glphong.materials.model_named("lambert") is Lambert and glphong.Lambert is Lambert
    (kd,) = Lambert.params
    assert (kd.name, kd.kind, kd.glsl_type, kd.interval, kd.unit, kd.default) == ("kd", "rgb", "vec3", "[0, inf]",
                                                                                  "1/sr", None)
    assert Lambert.needs == () and Lambert.uses == ()
    assert Lambert.ambient == "kd"
    assert Lambert.vanishes_with == ("kd",)
    assert Lambert.properties == Properties(reciprocal=True, isotropic=True, energy_conserving=True,
                                            condition="pi kd <= 1", non_negative=True)
    m = Lambert(KD)
    assert m.components == (m,)
    assert m.kd == KD and Lambert(0.2).kd == (0.2, 0.2, 0.2)  # a scalar broadcasts
    assert m.ka == (0.0, 0.0, 0.0) and m.two_sided is True
    with pytest.raises(TypeError, match="kd"):
        Lambert()  # kd has no default
    with pytest.raises(ValueError, match="kd"):
        Lambert(-0.1)
    with pytest.raises(ValueError, match="kd"):
        Lambert((0.1, np.nan, 0.1))
    assert Lambert(0.0).vanishes() and not Lambert(KD).vanishes()
    assert Lambert(KD).answers_ambient() and not Lambert(0.0).answers_ambient()


def test_program_key_and_uniform_names():
    key = program_key(Lambert(KD), {"point": 1}, None)
    assert [t.name for t in key.terms] == ["lambert"] and key.terms[0].lit and not key.terms[0].ambient
    assert not key.needs_view and not key.has_tangent and not key.has_uv
    assert Lambert(KD).uniform_values(key).keys() == {"u_lambert_kd"}
    assert Lambert.uniform_name("kd") == "u_lambert_kd"
    source = assemble(key.fragment_chunks(), key.defines(), key.generated_chunks())
    assert "uniform vec3 u_lambert_kd;" in source and "lambert_response(f, wi, wo, n_dot_l)" in source
    # the ambient answer k_d L_a: the term is kept for L_a alone, reading only u_lambert_kd
    ambient = program_key(Lambert(KD), {}, (0.1, 0.1, 0.1))
    assert [(t.name, t.lit, t.ambient, t.ambient_param) for t in ambient.terms] == [("lambert", False, True, "kd")]
    assert Lambert(KD).uniform_values(ambient).keys() == {"u_lambert_kd"}
    # kd = 0: the term vanishes from every key
    for k in (program_key(Lambert(0.0), {"point": 1}, (0.1, 0.1, 0.1)), response_key(Lambert(0.0))):
        assert k.terms == () and Lambert(0.0).uniform_values(k) == {}
    assert program_key(Lambert(0.0), {"point": 1}, None).num_lights == 0


# --------------------------------------------------------------------------- a render
def test_render_matches(glphong_renderer):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene = glphong.Scene(camera, lights=[glphong.PointLight((2.0, 2.5, 3.0), (80.0, 60.0, 40.0))],
                          ambient=glphong.AmbientLight(0.05))
    scene.add(glphong.primitives.sphere(3), Lambert(KD))
    report = assert_render_matches(scene, glphong_renderer)
    assert report.covered_pixels > 1000 and report.nonfinite_count == 0
    # measured 4.45e-7 on llvmpipe (both backends); the band itself allows more (DESIGN section 4)
    assert report.max_relative_error < 1e-5
