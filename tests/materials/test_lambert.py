"""The built-in model 'lambert' (`glphong.Lambert`), tested the way a user tests their own model.

What is specific to it (the checks every model passes, twin agreement at kd = 0.3, a zero channel and
1e-3 to 2 eps with the +z normal, the definition's mechanics, the program key, vanishing at kd = 0,
the stability cases, are in tests/test_conformance.py), on both backends (fixture ``glphong_backend``):

- the twin is non-zero exactly where the light is above the surface (normal +z);
- the GLSL response (`evaluate`) against the closed form ``kd (n.l)`` written here in float64, at
  normal, oblique and grazing incidence (n.l down to 1e-6), for the +z normal and a tilted normal
  (tolerance derived in `TOLERANCE`), and exactly 0 where ``n.l <= 0``;
- the declaration: name, parameter (kind, range, no default, unit), needs, ambient answer, what
  makes it vanish, declared properties (docs/design.md sections 1 and 8: f_r = kd is reciprocal and
  isotropic; its albedo is pi kd, so it conserves energy when pi kd <= 1);
- one render of a sphere under a point light and an ambient light through ``glphong_renderer``,
  passing `assert_render_matches` (max relative error 4.45e-7 measured; bound 1e-5).
"""
import numpy as np
import pytest

import glphong
import glphong.primitives
from glphong.materials import Lambert, Properties
from glphong.testing import assert_render_matches, direction, direction_sets, evaluate

EPS = 2.0 ** -24
KD = (0.1, 0.0, 0.25)
#: a tilted unit normal: n.l is then a rounded float32 dot product, not an exact coordinate
TILTED = np.array([0.3, -0.2, 0.9]) / np.linalg.norm([0.3, -0.2, 0.9])


# --------------------------------------------------------------------------- twin
def test_the_twin_is_non_zero_exactly_where_the_light_is_above():
    wi, wo, _ = direction_sets(2000, 0)
    wi32 = (wi / np.linalg.norm(wi, axis=1, keepdims=True)).astype(np.float32)
    twin = evaluate(Lambert(KD), wi, wo, twin=True)
    assert int(np.any(twin != 0, axis=1).sum()) == int(np.sum(wi32[:, 2] > 0))


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


# --------------------------------------------------------------------------- the declaration
def test_declaration():
    assert Lambert.name == "lambert" and glphong.Lambert is Lambert
    (kd,) = Lambert.params
    assert (kd.name, kd.kind, kd.glsl_type, kd.interval, kd.unit, kd.default) == ("kd", "rgb", "vec3", "[0, inf]",
                                                                                  "1/sr", None)
    assert Lambert.needs == () and Lambert.uses == ()
    assert Lambert.ambient == "kd" and Lambert.ambient_scale == 1.0
    assert Lambert.vanishes_with == ("kd",)
    assert Lambert.properties == Properties(reciprocal=True, isotropic=True, energy_conserving=True,
                                            condition="pi kd <= 1", non_negative=True)


# --------------------------------------------------------------------------- a render
def test_render_matches(glphong_renderer):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene = glphong.Scene(camera, lights=[glphong.PointLight((2.0, 2.5, 3.0), (80.0, 60.0, 40.0))],
                          ambient=glphong.AmbientLight(0.05))
    scene.add(glphong.primitives.sphere(3), Lambert(KD))
    report = assert_render_matches(scene, glphong_renderer)
    assert report.covered_pixels > 1000 and report.nonfinite_count == 0
    # measured 4.45e-7 on llvmpipe (both backends); the band itself allows more (docs/design.md section 4)
    assert report.max_relative_error < 1e-5
