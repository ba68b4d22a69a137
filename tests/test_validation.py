"""Bad input gives a clear error (docs/design.md section 7, layer 6).

Every public constructor and entry point is fed bad values; each error must be of
the right type and its message must name the parameter *and* state the valid range
(or the expected shape / type), so a test fails if a message loses either.  Valid
edge values are accepted and stored as documented, and a failed validation leaves
a live `Renderer` and `Scene` untouched (the last tests, on each GL backend).
"""
import math
import re

import numpy as np
import pytest
import trimesh

import glphong
from glphong import imaging
from glphong.gpu.contexts import BACKENDS
from glphong.scene.geometry import MeshData
from glphong.lights.point import _MAX_POWER

FLT_MAX = float(np.finfo(np.float32).max)
NAN, INF = float("nan"), float("inf")

#: the range texts of the messages, as they print
R_FLT = "3.40282e+38]"            # upper end of [0, FLT_MAX] and (0, FLT_MAX]
R_YFOV = "(0, 3.14159)"           # (0, pi), open at both ends
R_NONNEG = "[0, 3.40282e+38]"
R_POSITIVE = "(0, 3.40282e+38]"
R_POWER = "[0, 4.27611e+39]"      # [0, 4 pi FLT_MAX]


def m(*parts):
    """A `match` pattern requiring the literal ``parts`` in order."""
    return ".*".join(re.escape(p) for p in parts)


# =========================================================================== PerspectiveCamera


@pytest.mark.parametrize("yfov", [0.0, -0.0, -1.0, math.pi, np.pi, 4.0, NAN, INF, -INF, 1e400, 10**400])
def test_camera_yfov_out_of_range(yfov):
    with pytest.raises(ValueError, match=m("yfov must be finite and in", R_YFOV)):
        glphong.PerspectiveCamera(yfov)


@pytest.mark.parametrize("yfov", ["wide", "1.0", None, True, np.bool_(True), 1 + 0j, [1.0, 2.0, "x"]])
def test_camera_yfov_not_a_real_number(yfov):
    with pytest.raises(TypeError, match=m("yfov must be a real number in", R_YFOV)):
        glphong.PerspectiveCamera(yfov)


@pytest.mark.parametrize("yfov", [[1.0], np.array([1.0, 1.2]), np.ones((1, 1))])
def test_camera_yfov_not_a_scalar(yfov):
    with pytest.raises(ValueError, match=m("yfov must be a scalar in", R_YFOV, "got shape", str(np.shape(yfov)))):
        glphong.PerspectiveCamera(yfov)


@pytest.mark.parametrize("znear", [0.0, -1e-9, -1.0, NAN, INF, 1e39])
def test_camera_znear_out_of_range(znear):
    with pytest.raises(ValueError, match=m("znear must be finite and in", R_POSITIVE)):
        glphong.PerspectiveCamera(1.0, znear=znear, zfar=1e38)


@pytest.mark.parametrize("znear, zfar", [(1.0, 1.0), (1.0, 0.5), (2.0, np.nextafter(2.0, 0.0)), (0.05, 0.01)])
def test_camera_zfar_not_beyond_znear(znear, zfar):
    with pytest.raises(ValueError, match=m("zfar must be greater than znear, in", f"({float(znear)!r}, {R_FLT}")):
        glphong.PerspectiveCamera(1.0, znear=znear, zfar=zfar)


@pytest.mark.parametrize("zfar", [0.0, -5.0, NAN, INF])
def test_camera_zfar_not_positive_finite(zfar):
    with pytest.raises(ValueError, match=m("zfar must be finite and in", R_POSITIVE)):
        glphong.PerspectiveCamera(1.0, zfar=zfar)


@pytest.mark.parametrize("pose", [np.eye(3), np.eye(4)[:3], np.arange(16.0), np.eye(4)[None], np.eye(5)])
def test_camera_pose_wrong_shape(pose):
    with pytest.raises(ValueError, match=m("pose must have shape (4, 4)", f"got shape {pose.shape}")):
        glphong.PerspectiveCamera(1.0, pose=pose)


@pytest.mark.parametrize("pose", ["identity", [[1, 0], [0]], [[1.0] * 4] * 3 + [["0", "0", "0", "1"]],
                                  np.eye(4, dtype=complex), np.eye(4, dtype=bool)])
def test_camera_pose_not_real(pose):
    with pytest.raises(TypeError, match=m("pose must be a 4x4 array of real numbers")):
        glphong.PerspectiveCamera(1.0, pose=pose)


def _pose_with(i, j, value):
    pose = np.eye(4)
    pose[i, j] = value
    return pose


@pytest.mark.parametrize("pose", [
    np.diag([2.0, 1.0, 1.0, 1.0]),      # scaled
    np.diag([-1.0, 1.0, 1.0, 1.0]),     # mirror: orthonormal but det -1
    _pose_with(0, 1, 0.1),              # shear
    np.diag([1.0 + 1e-5, 1.0, 1.0, 1.0]),  # beyond the 1e-6 tolerance
    np.zeros((4, 4)) + _pose_with(3, 3, 1.0) - np.eye(4) + np.eye(4) * [0, 0, 0, 1],  # zero rotation block
])
def test_camera_pose_not_rigid(pose):
    with pytest.raises(ValueError, match=m("pose must have an orthonormal rotation block with determinant +1",
                                           "tolerance 1e-06")):
        glphong.PerspectiveCamera(1.0, pose=pose)


@pytest.mark.parametrize("pose", [_pose_with(0, 3, NAN), _pose_with(1, 1, NAN), _pose_with(2, 3, INF),
                                  _pose_with(0, 3, -1e39), _pose_with(0, 3, 1e300)])
def test_camera_pose_not_finite_in_float32(pose):
    with pytest.raises(ValueError, match=m("pose must be finite with |entries| <= 3.40282e+38")):
        glphong.PerspectiveCamera(1.0, pose=pose)


@pytest.mark.parametrize("row", [(1.0, 0.0, 0.0, 1.0), (0.0, 0.0, 0.0, 2.0), (0.0, 0.0, 0.0, 1.0 + 1e-9)])
def test_camera_pose_last_row(row):
    pose = np.eye(4)
    pose[3] = row
    with pytest.raises(ValueError, match=m("pose must have last row (0, 0, 0, 1)")):
        glphong.PerspectiveCamera(1.0, pose=pose)


def test_camera_valid_edge_values_are_stored():
    just_under_pi = np.nextafter(np.pi, 0.0)
    cam = glphong.PerspectiveCamera(just_under_pi, znear=1.0, zfar=np.nextafter(1.0, 2.0))
    assert cam.yfov == just_under_pi and type(cam.yfov) is float
    assert cam.znear == 1.0 and cam.zfar == np.nextafter(1.0, 2.0)
    assert np.all(np.isfinite(cam.projection_matrix(1.0).astype(np.float32)))
    # numpy scalars and 0-d arrays
    cam = glphong.PerspectiveCamera(np.float32(0.5), znear=np.float64(1e-3), zfar=np.int64(7))
    assert (cam.yfov, cam.znear, cam.zfar) == (0.5, 1e-3, 7.0)
    assert all(type(v) is float for v in (cam.yfov, cam.znear, cam.zfar))
    assert glphong.PerspectiveCamera(np.array(1.25)).yfov == 1.25
    assert glphong.PerspectiveCamera(1e-30).yfov == 1e-30
    # a rigid pose within the tolerance, given as nested lists of ints, is stored as read-only float64
    pose = [[0, -1, 0, 3], [1, 0, 0, -2], [0, 0, 1, 5], [0, 0, 0, 1]]
    cam = glphong.PerspectiveCamera(1.0, pose=pose)
    assert cam.pose.dtype == np.float64 and not cam.pose.flags.writeable
    np.testing.assert_array_equal(cam.pose, pose)
    np.testing.assert_array_equal(cam.position, (3.0, -2.0, 5.0))
    assert glphong.PerspectiveCamera(1.0).pose.tolist() == np.eye(4).tolist()


# --------------------------------------------------------------------------- look_at


@pytest.mark.parametrize("eye, target", [((1.0, 2.0, 3.0), (1.0, 2.0, 3.0)), ((0, 0, 0), (0.0, -0.0, 0.0)),
                                         (np.zeros(3), [0, 0, 0])])
def test_look_at_eye_equals_target(eye, target):
    with pytest.raises(ValueError, match=m("target must differ from eye")):
        glphong.PerspectiveCamera.look_at(eye, target)


@pytest.mark.parametrize("up", [(0.0, 0.0, 1.0), (0.0, 0.0, -5.0), (0.0, 0.0, 1e-300), (1e-13, 0.0, 1.0)])
def test_look_at_up_parallel_to_view_direction(up):
    with pytest.raises(ValueError, match=m("up must not be parallel to the viewing direction target - eye")):
        glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), up=up)


@pytest.mark.parametrize("which, value", [("eye", (0.0, 0.0)), ("eye", (0, 0, 1, 1)), ("target", np.zeros((1, 3))),
                                          ("target", 0.0), ("up", (0.0, 1.0)), ("up", np.eye(3))])
def test_look_at_wrong_shapes(which, value):
    args = {"eye": (0.0, 0.0, 3.0), "target": (0.0, 0.0, 0.0), "up": (0.0, 1.0, 0.0), which: value}
    with pytest.raises(ValueError, match=m(f"{which} must have shape (3,)", f"got shape {np.shape(value)}")):
        glphong.PerspectiveCamera.look_at(**args)


@pytest.mark.parametrize("which, value", [("eye", (0.0, NAN, 3.0)), ("target", (INF, 0.0, 0.0)), ("up", (0.0, 1e39, 0.0))])
def test_look_at_non_finite(which, value):
    args = {"eye": (0.0, 0.0, 3.0), "target": (0.0, 0.0, 0.0), "up": (0.0, 1.0, 0.0), which: value}
    with pytest.raises(ValueError, match=m(f"{which} must be finite with |components| <= 3.40282e+38")):
        glphong.PerspectiveCamera.look_at(**args)


def test_look_at_zero_up_and_strings():
    with pytest.raises(ValueError, match=m("up must not be the zero vector")):
        glphong.PerspectiveCamera.look_at((0, 0, 3), (0, 0, 0), up=(0, 0, 0))
    with pytest.raises(TypeError, match=m("eye must be a sequence of 3 real numbers")):
        glphong.PerspectiveCamera.look_at("origin", (0, 0, 0))
    with pytest.raises(ValueError, match=m("yfov must be finite and in", R_YFOV)):
        glphong.PerspectiveCamera.look_at((0, 0, 3), (0, 0, 0), yfov=0.0)
    with pytest.raises(ValueError, match=m("zfar must be greater than znear")):
        glphong.PerspectiveCamera.look_at((0, 0, 3), (0, 0, 0), znear=2.0, zfar=1.0)


def test_look_at_valid_edge_values():
    # tiny offsets (squares underflow in float64) still give an orthonormal pose looking at the target
    cam = glphong.PerspectiveCamera.look_at((1e-200, 0.0, 0.0), (0.0, 0.0, 0.0))
    np.testing.assert_allclose(cam.pose[:3, 2], (1.0, 0.0, 0.0), atol=1e-15)
    np.testing.assert_allclose(cam.pose[:3, 1], (0.0, 1.0, 0.0), atol=1e-15)
    cam = glphong.PerspectiveCamera.look_at((0.0, 0.0, 2.0), (0.0, 0.0, 0.0), up=(0.0, 1e-300, 0.0))
    np.testing.assert_allclose(cam.pose, np.array([[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 2], [0, 0, 0, 1.0]]), atol=1e-15)
    # far apart (difference above FLT_MAX in float64 is fine), up nearly but not quite parallel
    cam = glphong.PerspectiveCamera.look_at((3e38, 0.0, 0.0), (-3e38, 0.0, 0.0))
    np.testing.assert_allclose(cam.pose[:3, 2], (1.0, 0.0, 0.0))
    cam = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), up=(1e-9, 0.0, 1.0))
    np.testing.assert_allclose(cam.pose[:3, :3], [[0, 1, 0], [-1, 0, 0], [0, 0, 1]], atol=1e-15)  # image up = +x
    assert np.isclose(cam.yfov, np.pi / 4) and (cam.znear, cam.zfar) == (0.05, 100.0)


# =========================================================================== lights


@pytest.mark.parametrize("position", [(NAN, 0.0, 0.0), (0.0, INF, 0.0), (0.0, 0.0, -INF), (1e39, 0.0, 0.0)])
def test_point_light_position_not_finite(position):
    with pytest.raises(ValueError, match=m("position must be finite with |components| <= 3.40282e+38")):
        glphong.PointLight(position, 1.0)


@pytest.mark.parametrize("position", [(0.0, 0.0), (0, 0, 0, 1), np.zeros((3, 1)), 1.0, []])
def test_point_light_position_wrong_shape(position):
    with pytest.raises(ValueError, match=m("position must have shape (3,)", f"got shape {np.shape(position)}")):
        glphong.PointLight(position, 1.0)


@pytest.mark.parametrize("position", ["origin", None, (0, "1", 2), (1j, 0, 0), (True, False, True)])
def test_point_light_position_not_real(position):
    with pytest.raises(TypeError, match=m("position must be a sequence of 3 real numbers")):
        glphong.PointLight(position, 1.0)


@pytest.mark.parametrize("power", [-1.0, -1e-300, (1.0, -1.0, 1.0), NAN, (1.0, 1.0, NAN), INF, -INF,
                                   np.nextafter(_MAX_POWER, INF), 1e40, (0.0, 0.0, 4.3e39)])
def test_point_light_power_out_of_range(power):
    with pytest.raises(ValueError, match=m("power must be finite and in", R_POWER, "per channel")):
        glphong.PointLight((0.0, 0.0, 0.0), power)


@pytest.mark.parametrize("power", [(1.0, 2.0), np.ones(4), [[1.0, 2.0, 3.0]], np.ones((3, 3))])
def test_point_light_power_wrong_shape(power):
    with pytest.raises(ValueError, match=m("power must be a scalar or have shape (3,)", R_POWER,
                                           f"got shape {np.shape(power)}")):
        glphong.PointLight((0.0, 0.0, 0.0), power)


@pytest.mark.parametrize("power", ["bright", "1", None, True, 1 + 1j, [1.0, None, 1.0], [1, [2, 3]]])
def test_point_light_power_not_real(power):
    with pytest.raises(TypeError, match=m("power must be a real number or an RGB triple", R_POWER)):
        glphong.PointLight((0.0, 0.0, 0.0), power)


def test_point_light_valid_edge_values_are_stored():
    light = glphong.PointLight([0, 0, 0], 0)
    assert light.power == (0.0, 0.0, 0.0) and light.position == (0.0, 0.0, 0.0)
    assert all(type(c) is float for c in light.power + light.position)
    assert glphong.PointLight((0.0, 0.0, 0.0), -0.0).power == (0.0, 0.0, 0.0)
    assert all(math.copysign(1.0, c) == 1.0 for c in glphong.PointLight((0.0, 0.0, 0.0), -0.0).power)
    assert glphong.PointLight((1, 2, 3), 100).power == (100.0, 100.0, 100.0)
    assert glphong.PointLight(np.array([1.5, 2.0, -3.0], np.float32), np.float32(2.5)).position == (1.5, 2.0, -3.0)
    assert glphong.PointLight((0, 0, 0), np.array([1, 2, 3], np.int64)).power == (1.0, 2.0, 3.0)
    assert glphong.PointLight((0, 0, 0), np.float32(2.5)).power == (2.5, 2.5, 2.5)
    assert glphong.PointLight((FLT_MAX, -FLT_MAX, 0.0), 1.0).position == (FLT_MAX, -FLT_MAX, 0.0)
    # the largest power: its intensity Phi/(4 pi) is still finite in float32
    top = glphong.PointLight((0.0, 0.0, 0.0), _MAX_POWER)
    assert top.power == (_MAX_POWER,) * 3
    assert np.all(np.isfinite(np.asarray(top.intensity, dtype=np.float32)))
    assert _MAX_POWER == 4.0 * math.pi * FLT_MAX


@pytest.mark.parametrize("radiance, error, text", [
    (-1.0, ValueError, "radiance must be finite and in [0, 3.40282e+38] per channel"),
    (NAN, ValueError, "radiance must be finite and in [0, 3.40282e+38] per channel"),
    (INF, ValueError, "radiance must be finite and in [0, 3.40282e+38] per channel"),
    (1e39, ValueError, "radiance must be finite and in [0, 3.40282e+38] per channel"),
    ((1.0, 2.0), ValueError, "radiance must be a scalar or have shape (3,), each channel in [0, 3.40282e+38]"),
    ("dim", TypeError, "radiance must be a real number or an RGB triple of real numbers in [0, 3.40282e+38]"),
])
def test_unattenuated_point_light_radiance(radiance, error, text):
    with pytest.raises(error, match=m(text)):
        glphong.UnattenuatedPointLight((0.0, 0.0, 1.0), radiance)


def test_unattenuated_point_light_position_and_valid_values():
    with pytest.raises(ValueError, match=m("position must be finite with |components| <= 3.40282e+38")):
        glphong.UnattenuatedPointLight((0.0, NAN, 0.0), 1.0)
    with pytest.raises(ValueError, match=m("position must have shape (3,)")):
        glphong.UnattenuatedPointLight((0.0, 0.0), 1.0)
    light = glphong.UnattenuatedPointLight(np.array([1, 2, 3]), 0)
    assert light.position == (1.0, 2.0, 3.0) and light.radiance == (0.0, 0.0, 0.0)
    assert glphong.UnattenuatedPointLight((0, 0, 0), (0.5, 1, FLT_MAX)).radiance == (0.5, 1.0, FLT_MAX)


@pytest.mark.parametrize("direction", [(0.0, 0.0, 0.0), np.zeros(3), (0.0, -0.0, 0.0)])
def test_directional_light_zero_direction(direction):
    with pytest.raises(ValueError, match=m("direction must not be the zero vector")):
        glphong.DirectionalLight(direction, 1.0)


@pytest.mark.parametrize("direction, error, text", [
    ((0.0, 0.0, NAN), ValueError, "direction must be finite with |components| <= 3.40282e+38"),
    ((INF, 0.0, 0.0), ValueError, "direction must be finite with |components| <= 3.40282e+38"),
    ((0.0, -1.0), ValueError, "direction must have shape (3,)"),
    ("down", TypeError, "direction must be a sequence of 3 real numbers"),
])
def test_directional_light_bad_direction(direction, error, text):
    with pytest.raises(error, match=m(text)):
        glphong.DirectionalLight(direction, 1.0)


@pytest.mark.parametrize("irradiance", [-1.0, NAN, INF, (1.0, 1.0, -0.5)])
def test_directional_light_bad_irradiance(irradiance):
    with pytest.raises(ValueError, match=m("irradiance must be finite and in [0, 3.40282e+38] per channel")):
        glphong.DirectionalLight((0.0, 0.0, -1.0), irradiance)


def test_directional_light_valid_values_are_normalised():
    light = glphong.DirectionalLight((0, 0, -5), 2)
    assert light.direction == (0.0, 0.0, -1.0) and light.irradiance == (2.0, 2.0, 2.0)
    # subnormal and huge lengths normalise without underflow or overflow
    assert glphong.DirectionalLight((0.0, 0.0, -5e-324), 1.0).direction == (0.0, 0.0, -1.0)
    d = glphong.DirectionalLight((FLT_MAX, FLT_MAX, 0.0), 1.0).direction
    np.testing.assert_allclose(d, (math.sqrt(0.5), math.sqrt(0.5), 0.0), rtol=1e-15)
    assert light.uniform_value("towards") == (0.0, 0.0, 1.0)


@pytest.mark.parametrize("radiance, error, text", [
    (-1.0, ValueError, "radiance must be finite and in [0, 3.40282e+38] per channel"),
    ((0.1, NAN, 0.1), ValueError, "radiance must be finite and in [0, 3.40282e+38] per channel"),
    (INF, ValueError, "radiance must be finite and in [0, 3.40282e+38] per channel"),
    ((1.0, 1.0), ValueError, "radiance must be a scalar or have shape (3,)"),
    ("grey", TypeError, "radiance must be a real number or an RGB triple of real numbers in [0, 3.40282e+38]"),
    (None, TypeError, "radiance must be a real number or an RGB triple of real numbers in [0, 3.40282e+38]"),
])
def test_ambient_light_bad_radiance(radiance, error, text):
    with pytest.raises(error, match=m(text)):
        glphong.AmbientLight(radiance)


def test_ambient_light_valid_values():
    assert glphong.AmbientLight(0).radiance == (0.0, 0.0, 0.0)
    assert glphong.AmbientLight(np.float32(0.25)).radiance == (0.25, 0.25, 0.25)
    assert glphong.AmbientLight([0.1, 0.2, 0.3]).radiance == (0.1, 0.2, 0.3)


# =========================================================================== materials

MATERIAL_CLASSES = [glphong.Lambert, glphong.Phong, glphong.BlinnPhong]
GLOSSY_CLASSES = [glphong.Phong, glphong.BlinnPhong]


def make_material(cls, **overrides):
    args = {"kd": 0.2} if cls is glphong.Lambert else {"kd": 0.2, "ks": 0.5, "q": 10.0}
    args.update(overrides)
    return cls(**args)


def _coefficient_params():
    for cls in MATERIAL_CLASSES:
        for name in ("kd", "ka") + (("ks",) if cls in GLOSSY_CLASSES else ()):
            yield pytest.param(cls, name, id=f"{cls.__name__}-{name}")


BAD_COEFFICIENT_VALUES = [
    pytest.param(-1.0, ValueError, "must be finite and in [0, 3.40282e+38] per channel", id="negative"),
    pytest.param((0.1, -1e-9, 0.1), ValueError, "must be finite and in [0, 3.40282e+38] per channel", id="negative-channel"),
    pytest.param(NAN, ValueError, "must be finite and in [0, 3.40282e+38] per channel", id="nan"),
    pytest.param((0.1, 0.1, NAN), ValueError, "must be finite and in [0, 3.40282e+38] per channel", id="nan-channel"),
    pytest.param(INF, ValueError, "must be finite and in [0, 3.40282e+38] per channel", id="inf"),
    pytest.param(1e39, ValueError, "must be finite and in [0, 3.40282e+38] per channel", id="above-flt-max"),
    pytest.param((0.1, 0.2), ValueError, "must be a scalar or have shape (3,), each channel in [0, 3.40282e+38]", id="shape-2"),
    pytest.param(np.ones((3, 1)), ValueError, "must be a scalar or have shape (3,), each channel in [0, 3.40282e+38]", id="shape-3x1"),
    pytest.param("red", TypeError, "must be a real number or an RGB triple of real numbers in [0, 3.40282e+38]", id="string"),
    pytest.param("0.5", TypeError, "must be a real number or an RGB triple of real numbers in [0, 3.40282e+38]", id="numeric-string"),
    pytest.param(["0.1", "0.2", "0.3"], TypeError, "must be a real number or an RGB triple of real numbers", id="strings"),
    pytest.param(None, TypeError, "must be a real number or an RGB triple of real numbers", id="none"),
    pytest.param(True, TypeError, "must be a real number or an RGB triple of real numbers", id="bool"),
    pytest.param(np.array([0.1 + 1j, 0.1, 0.1]), TypeError, "must be a real number or an RGB triple of real numbers", id="complex"),
]


@pytest.mark.parametrize("cls, name", list(_coefficient_params()))
@pytest.mark.parametrize("value, error, text", BAD_COEFFICIENT_VALUES)
def test_material_bad_coefficient(cls, name, value, error, text):
    with pytest.raises(error, match=m(f"{name} {text}")):
        make_material(cls, **{name: value})


@pytest.mark.parametrize("cls", GLOSSY_CLASSES)
@pytest.mark.parametrize("q, error, text", [
    (-1.0, ValueError, "q must be finite and in [0, 3.40282e+38]"),
    (-1e-300, ValueError, "q must be finite and in [0, 3.40282e+38]"),
    (NAN, ValueError, "q must be finite and in [0, 3.40282e+38]"),
    (INF, ValueError, "q must be finite and in [0, 3.40282e+38]"),
    (1e39, ValueError, "q must be finite and in [0, 3.40282e+38]"),
    (np.array([10.0, 20.0]), ValueError, "q must be a scalar in [0, 3.40282e+38] (got shape (2,))"),
    ([10.0], ValueError, "q must be a scalar in [0, 3.40282e+38] (got shape (1,))"),
    ((1.0, 2.0, 3.0), ValueError, "q must be a scalar in [0, 3.40282e+38] (got shape (3,))"),
    ("shiny", TypeError, "q must be a real number in [0, 3.40282e+38]"),
    ("50", TypeError, "q must be a real number in [0, 3.40282e+38]"),
    (None, TypeError, "q must be a real number in [0, 3.40282e+38]"),
    (True, TypeError, "q must be a real number in [0, 3.40282e+38]"),
    (5 + 0j, TypeError, "q must be a real number in [0, 3.40282e+38]"),
])
def test_material_bad_exponent(cls, q, error, text):
    with pytest.raises(error, match=m(text)):
        make_material(cls, q=q)


@pytest.mark.parametrize("cls", MATERIAL_CLASSES)
@pytest.mark.parametrize("two_sided", [1, 0, "yes", None, 1.0])
def test_material_two_sided_not_bool(cls, two_sided):
    with pytest.raises(TypeError, match=m("two_sided must be a bool, True or False")):
        make_material(cls, two_sided=two_sided)


@pytest.mark.parametrize("cls", GLOSSY_CLASSES)
def test_glossy_material_requires_ks_and_q(cls):
    with pytest.raises(TypeError, match="q"):
        cls(0.2, 0.5)


@pytest.mark.parametrize("cls", MATERIAL_CLASSES)
def test_material_valid_edge_values_are_stored(cls):
    mat = make_material(cls, kd=0, ka=np.float32(0.5), two_sided=np.bool_(False))
    assert mat.kd == (0.0, 0.0, 0.0) and mat.ka == (0.5, 0.5, 0.5)
    assert mat.two_sided is False
    assert all(type(c) is float for c in mat.kd + mat.ka)
    mat = make_material(cls, kd=np.array([0.1, 0.2, 0.3]), ka=[1, 2, 3], two_sided=True)
    assert mat.kd == (0.1, 0.2, 0.3) and mat.ka == (1.0, 2.0, 3.0) and mat.two_sided is True
    assert make_material(cls, kd=-0.0).kd == (0.0, 0.0, 0.0)
    assert make_material(cls, kd=FLT_MAX).kd == (FLT_MAX,) * 3
    assert make_material(cls).ka == (0.0, 0.0, 0.0) and make_material(cls).two_sided is True


@pytest.mark.parametrize("cls", GLOSSY_CLASSES)
def test_glossy_valid_edge_values_are_stored(cls):
    mat = cls(kd=0.2, ks=0.5, q=0)
    assert mat.q == 0.0 and type(mat.q) is float and mat.ks == (0.5, 0.5, 0.5)
    assert [t.vanishes() for t in mat.components] == [False, False]
    assert cls(0.2, 0.5, -0.0).q == 0.0 and math.copysign(1.0, cls(0.2, 0.5, -0.0).q) == 1.0
    assert cls(0.2, 0.5, np.float32(1e7)).q == 1e7
    assert cls(0.2, 0.5, np.int64(3)).q == 3.0
    assert cls(0.2, 0.5, np.array(64.0)).q == 64.0
    assert cls(0.2, 0.5, FLT_MAX).q == FLT_MAX
    mat = cls(0.2, (0.0, 0.0, 0.0), 5.0)
    assert mat.ks == (0.0, 0.0, 0.0) and [t.vanishes() for t in mat.components] == [False, True]


# =========================================================================== Scene


@pytest.fixture
def camera():
    return glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0))


@pytest.mark.parametrize("bad", [None, "camera", np.eye(4), glphong.PerspectiveCamera])
def test_scene_camera_wrong_type(bad):
    with pytest.raises(TypeError, match=m("camera must be a glphong camera such as PerspectiveCamera", f"got {type(bad).__name__}")):
        glphong.Scene(bad)


@pytest.mark.parametrize("bad", [0.5, (0.1, 0.1, 0.1), glphong.PointLight((0, 0, 0), 1.0), "dim"])
def test_scene_ambient_wrong_type(camera, bad):
    with pytest.raises(TypeError, match=m("ambient must be a glphong.AmbientLight or None", f"got {type(bad).__name__}")):
        glphong.Scene(camera, ambient=bad)


@pytest.mark.parametrize("bad", [glphong.AmbientLight(1.0), "light", None, (0.0, 0.0, 1.0), glphong.PointLight])
def test_scene_bad_light_in_list(camera, bad):
    good = glphong.PointLight((0.0, 0.0, 1.0), 1.0)
    with pytest.raises(TypeError, match=m("lights[1] must be one of the glphong lights (PointLight, SpotLight, DirectionalLight, "
                                          "UnattenuatedPointLight or a LightModel of yours)",
                                          f"got {type(bad).__name__}")):
        glphong.Scene(camera, lights=[good, bad])


@pytest.mark.parametrize("bad", [glphong.PointLight((0, 0, 0), 1.0), None, 5, "lights"])
def test_scene_lights_not_a_sequence(camera, bad):
    with pytest.raises(TypeError, match=m("lights must be a sequence of glphong lights (PointLight, SpotLight, "
                                          "DirectionalLight", f"got {type(bad).__name__}")):
        glphong.Scene(camera, lights=bad)


class _DuckLight:
    """Has a light's ``kind`` but is no glphong light."""
    kind = "point"


@pytest.mark.parametrize("bad", [glphong.AmbientLight(1.0), None, _DuckLight(), "point"])
def test_scene_add_light_wrong_type(camera, bad):
    scene = glphong.Scene(camera, lights=[glphong.DirectionalLight((0, 0, -1), 1.0)])
    with pytest.raises(TypeError, match=m("light must be one of the glphong lights (PointLight, SpotLight, DirectionalLight",
                                          f"got {type(bad).__name__}")):
        scene.add_light(bad)
    assert len(scene.lights) == 1 and scene.light_counts() == {"directional": 1}


def test_scene_valid_lights(camera):
    lights = [glphong.PointLight((0, 0, 1), 1.0), glphong.UnattenuatedPointLight((0, 0, 1), 2.0),
              glphong.DirectionalLight((0, 0, -1), 3.0)]
    for given in (lights, tuple(lights), iter(lights)):
        scene = glphong.Scene(camera, lights=given, ambient=glphong.AmbientLight(0.1))
        assert scene.lights == tuple(lights) and scene.ambient_radiance == (0.1, 0.1, 0.1)
    scene = glphong.Scene(camera)
    assert scene.lights == () and scene.ambient is None and scene.camera is camera
    assert scene.add_light(lights[0]) is lights[0] and scene.lights == (lights[0],)


@pytest.fixture
def box():
    return trimesh.creation.box()


def _bad_add_cases():
    lam = glphong.Lambert(0.2)
    box = trimesh.creation.box()
    yield pytest.param("mesh", lam, None, TypeError, "mesh must be a trimesh.Trimesh or a glphong.scene.geometry.MeshData (got str)", id="mesh-str")
    yield pytest.param(np.zeros((3, 3)), lam, None, TypeError, "mesh must be a trimesh.Trimesh or a glphong.scene.geometry.MeshData (got ndarray)", id="mesh-array")
    yield pytest.param(trimesh.PointCloud(np.zeros((3, 3))), lam, None, TypeError, "mesh must be a trimesh.Trimesh or a glphong.scene.geometry.MeshData (got PointCloud)", id="mesh-pointcloud")
    yield pytest.param(trimesh.Scene([box]), lam, None, TypeError, "mesh must be a trimesh.Trimesh or a glphong.scene.geometry.MeshData (got Scene)", id="mesh-scene")
    yield pytest.param(trimesh.Trimesh(), lam, None, ValueError, "mesh must have at least one face", id="mesh-empty")
    yield pytest.param(trimesh.Trimesh(vertices=np.eye(3), faces=np.zeros((0, 3), int)), lam, None, ValueError,
                       "mesh must have at least one face", id="mesh-no-faces")
    yield pytest.param(box, "phong", None, TypeError, "material must be a glphong material such as Lambert or Phong (got str)", id="material-str")
    yield pytest.param(box, glphong.Lambert, None, TypeError, "material must be a glphong material such as Lambert or Phong (got type)", id="material-class")
    yield pytest.param(box, None, None, TypeError, "material must be a glphong material such as Lambert or Phong (got NoneType)", id="material-none")
    yield pytest.param(box, lam, np.eye(3), ValueError, "pose must have shape (4, 4) (got shape (3, 3))", id="pose-3x3")
    yield pytest.param(box, lam, np.eye(4).ravel(), ValueError, "pose must have shape (4, 4) (got shape (16,))", id="pose-flat")
    yield pytest.param(box, lam, "identity", TypeError, "pose must be a 4x4 array of real numbers", id="pose-str")
    yield pytest.param(box, lam, _pose_with(0, 0, NAN), ValueError, "pose must be finite with |entries| <= 3.40282e+38", id="pose-nan")
    yield pytest.param(box, lam, _pose_with(1, 3, INF), ValueError, "pose must be finite with |entries| <= 3.40282e+38", id="pose-inf")
    yield pytest.param(box, lam, _pose_with(1, 3, 1e39), ValueError, "pose must be finite with |entries| <= 3.40282e+38", id="pose-above-flt-max")
    yield pytest.param(box, lam, np.diag([1.0, 1.0, 0.0, 1.0]), ValueError, "pose must be invertible: its 3x3 block is singular", id="pose-singular")
    yield pytest.param(box, lam, np.zeros((4, 4)) + _pose_with(3, 3, 1.0) - np.eye(4) + np.diag([0, 0, 0, 1.0]),
                       ValueError, "pose must be invertible: its 3x3 block is singular", id="pose-zero-block")
    yield pytest.param(box, lam, np.array([[1, 2, 3, 0], [2, 4, 6, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]]), ValueError,
                       "pose must be invertible: its 3x3 block is singular", id="pose-rank-2")
    yield pytest.param(box, lam, np.diag([1e-39, 1.0, 1.0, 1.0]), ValueError,
                       "its inverse has entries above 3.40282e+38 (float32 overflow)", id="pose-inverse-overflows")
    yield pytest.param(box, lam, _pose_with(3, 0, 1.0), ValueError, "pose must have last row (0, 0, 0, 1) (got [1. 0. 0. 1.])", id="pose-last-row")
    yield pytest.param(box, lam, np.diag([1.0, 1.0, 1.0, 2.0]), ValueError, "pose must have last row (0, 0, 0, 1)", id="pose-last-row-w")


@pytest.mark.parametrize("mesh, material, pose, error, text", list(_bad_add_cases()))
def test_scene_add_rejects(camera, box, mesh, material, pose, error, text):
    scene = glphong.Scene(camera)
    scene.add(box, glphong.Lambert(0.1))
    with pytest.raises(error, match=m(text)):
        scene.add(mesh, material, pose=pose)
    assert len(scene.objects) == 1 and scene.objects[0].name == "object0"


@pytest.mark.parametrize("kwargs, text", [
    ({"smooth": "no"}, "smooth must be a bool, True or False (got 'no')"),
    ({"smooth": 1}, "smooth must be a bool, True or False (got 1)"),
    ({"name": 5}, "name must be a str or None (got int)"),
])
def test_scene_add_rejects_options(camera, box, kwargs, text):
    scene = glphong.Scene(camera)
    with pytest.raises(TypeError, match=m(text)):
        scene.add(box, glphong.Lambert(0.1), **kwargs)
    assert scene.objects == ()


def test_scene_add_valid_edge_values(camera, box):
    scene = glphong.Scene(camera)
    mirror = np.diag([-1.0, 2.0, 0.5, 1.0])
    mirror[:3, 3] = (1, 2, 3)
    obj = scene.add(box, glphong.Lambert(0.1), pose=mirror.astype(np.float32), smooth=np.bool_(False), name="m")
    np.testing.assert_array_equal(obj.pose, mirror)
    assert obj.pose.dtype == np.float64 and not obj.pose.flags.writeable
    assert obj.name == "m" and obj.mesh.triangle_count == 12 and len(obj.mesh.positions) == 36  # flat: 3 per face
    np.testing.assert_allclose(obj.normal_matrix, np.diag([-1.0, 0.5, 2.0]))
    # a tiny but float32-invertible scale, and MeshData directly
    data = MeshData([[0, 0, 0], [1, 0, 0], [0, 1, 0]], [[0, 0, 1]] * 3, [[0, 1, 2]])
    obj = scene.add(data, glphong.Phong(0.1, 0.2, 0.0), pose=np.diag([1e-30, 1e-30, 1e-30, 1.0]))
    assert obj.mesh is data and obj.name == "object1" and obj.pose[0, 0] == 1e-30
    assert np.all(np.isfinite(obj.normal_matrix.astype(np.float32)))
    assert scene.add(box, glphong.Lambert(0.1)).pose.tolist() == np.eye(4).tolist()
    assert len(scene.objects) == 3


# =========================================================================== MeshData

TRI_POS = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])
TRI_NOR = np.tile([0.0, 0.0, 1.0], (3, 1))
TRI_IDX = np.array([[0, 1, 2]])


@pytest.mark.parametrize("positions, normals, indices, error, text", [
    pytest.param(TRI_POS[:, :2], TRI_NOR[:, :2], TRI_IDX, ValueError, "positions must have shape (V, 3) with V >= 1 (got shape (3, 2))", id="pos-2d"),
    pytest.param(TRI_POS.ravel(), TRI_NOR.ravel(), TRI_IDX, ValueError, "positions must have shape (V, 3) with V >= 1 (got shape (9,))", id="pos-flat"),
    pytest.param(np.zeros((0, 3)), np.zeros((0, 3)), TRI_IDX, ValueError, "positions must have shape (V, 3) with V >= 1 (got shape (0, 3))", id="pos-empty"),
    pytest.param(np.where(np.eye(3) > 0, NAN, TRI_POS), TRI_NOR, TRI_IDX, ValueError, "positions must be finite with |components| <= 3.40282e+38", id="pos-nan"),
    pytest.param(TRI_POS + [0.0, 0.0, INF], TRI_NOR, TRI_IDX, ValueError, "positions must be finite with |components| <= 3.40282e+38", id="pos-inf"),
    pytest.param(TRI_POS * 1e39, TRI_NOR, TRI_IDX, ValueError, "positions must be finite with |components| <= 3.40282e+38", id="pos-above-flt-max"),
    pytest.param("triangle", TRI_NOR, TRI_IDX, TypeError, "positions must be a (V, 3) array of real numbers", id="pos-str"),
    pytest.param(TRI_POS, "up", TRI_IDX, TypeError, "normals must be a (V, 3) array of real numbers", id="nor-str"),
    pytest.param(TRI_POS, TRI_NOR[:2], TRI_IDX, ValueError, "normals must have the shape of positions (3, 3) (got (2, 3))", id="nor-shape"),
    pytest.param(TRI_POS, TRI_NOR, [0, 1, 2], ValueError, "indices must have shape (F, 3) with F >= 1 (got shape (3,))", id="idx-flat"),
    pytest.param(TRI_POS, TRI_NOR, np.zeros((0, 3), int), ValueError, "indices must have shape (F, 3) with F >= 1 (got shape (0, 3))", id="idx-empty"),
    pytest.param(TRI_POS, TRI_NOR, [[0, 1, 2, 0]], ValueError, "indices must have shape (F, 3) with F >= 1 (got shape (1, 4))", id="idx-quad"),
    pytest.param(TRI_POS, TRI_NOR, [[0, 1, 3]], ValueError, "indices must be in [0, 2] (got values from 0 to 3)", id="idx-above"),
    pytest.param(TRI_POS, TRI_NOR, [[0, 1, -1]], ValueError, "indices must be in [0, 2] (got values from -1 to 1)", id="idx-negative"),
    pytest.param(TRI_POS, TRI_NOR, np.array([[0, 1, 2**32]]), ValueError, "indices must be in [0, 2]", id="idx-huge"),
    pytest.param(TRI_POS, TRI_NOR, [[0.0, 1.0, 2.0]], TypeError, "indices must be integers in [0, 2] (got dtype float64)", id="idx-float"),
    pytest.param(TRI_POS, TRI_NOR, np.ones((1, 3), bool), TypeError, "indices must be integers in [0, 2] (got dtype bool)", id="idx-bool"),
])
def test_meshdata_rejects(positions, normals, indices, error, text):
    with pytest.raises(error, match=m(text)):
        MeshData(positions, normals, indices)


def test_meshdata_valid_values_are_stored():
    mesh = MeshData(TRI_POS.tolist(), TRI_NOR * NAN, np.array([[2, 1, 0]], np.int8))  # non-finite normals: documented as valid
    assert mesh.positions.dtype == np.float32 and mesh.normals.dtype == np.float32 and mesh.indices.dtype == np.uint32
    assert not (mesh.positions.flags.writeable or mesh.normals.flags.writeable or mesh.indices.flags.writeable)
    np.testing.assert_array_equal(mesh.positions, TRI_POS)
    assert np.all(np.isnan(mesh.normals)) and mesh.indices.tolist() == [[2, 1, 0]] and mesh.triangle_count == 1
    mesh = MeshData(TRI_POS * FLT_MAX, TRI_NOR * 1e39, TRI_IDX)  # positions at FLT_MAX; normals overflow to inf
    assert np.all(np.isfinite(mesh.positions)) and np.all(np.isinf(mesh.normals[:, 2]))


@pytest.mark.parametrize("smooth", [True, False])
def test_meshdata_from_trimesh_rejects(smooth):
    with pytest.raises(TypeError, match=m("mesh must be a trimesh.Trimesh (got list)")):
        MeshData.from_trimesh([TRI_POS], smooth=smooth)
    with pytest.raises(ValueError, match=m("mesh must have at least one face")):
        MeshData.from_trimesh(trimesh.Trimesh(), smooth=smooth)
    bad = trimesh.Trimesh(vertices=[[0, 0, 0], [1, 0, NAN], [0, 1, 0]], faces=[[0, 1, 2]], process=False)
    with pytest.raises(ValueError, match=m("positions must be finite with |components| <= 3.40282e+38")):
        MeshData.from_trimesh(bad, smooth=smooth)


# =========================================================================== Renderer (no GL needed: fails first)


@pytest.mark.parametrize("which", ["width", "height"])
@pytest.mark.parametrize("value, error, text", [
    (0, ValueError, "must be in [1, 16384] (got 0)"),
    (-1, ValueError, "must be in [1, 16384] (got -1)"),
    (16385, ValueError, "must be in [1, 16384] (got 16385)"),
    (np.int64(2**40), ValueError, "must be in [1, 16384]"),
    (64.0, TypeError, "must be an integer in [1, 16384] (got 64.0)"),
    (np.float32(64), TypeError, "must be an integer in [1, 16384]"),
    (True, TypeError, "must be an integer in [1, 16384] (got True)"),
    ("64", TypeError, "must be an integer in [1, 16384] (got '64')"),
    (None, TypeError, "must be an integer in [1, 16384] (got None)"),
])
def test_renderer_bad_size(which, value, error, text):
    size = {"width": 8, "height": 8, which: value}
    with pytest.raises(error, match=m(f"{which} {text}")):
        glphong.Renderer(size["width"], size["height"])


@pytest.mark.parametrize("backend", ["vulkan", "EGL ", None, "", 0])
def test_renderer_bad_backend(backend):
    with pytest.raises(ValueError, match=m("backend must be one of 'auto', 'egl', 'osmesa'", f"got {backend!r}")):
        glphong.Renderer(8, 8, backend=backend)


# =========================================================================== imaging


@pytest.mark.parametrize("exposure", [0.0, -0.0, -1.0, NAN, INF, -INF, 1e39])
def test_encode_srgb8_bad_exposure(exposure):
    with pytest.raises(ValueError, match=m("exposure must be finite and in", R_POSITIVE)):
        imaging.encode_srgb8(np.zeros((2, 2, 3)), exposure)


@pytest.mark.parametrize("exposure", ["bright", None, True, [1.0]])
def test_encode_srgb8_exposure_not_a_real_scalar(exposure):
    error = ValueError if isinstance(exposure, list) else TypeError
    with pytest.raises(error, match=m("exposure must be a", R_POSITIVE)):
        imaging.encode_srgb8(np.zeros((2, 2, 3)), exposure)


def test_encode_srgb8_valid_exposure():
    radiance = np.full((1, 2, 3), 0.25)
    expected = round((1.055 * 0.5 ** (1 / 2.4) - 0.055) * 255.0)
    assert imaging.encode_srgb8(radiance, np.float32(2.0)).tolist() == [[[expected] * 3] * 2]
    assert imaging.encode_srgb8(radiance, 5e-324).tolist() == [[[0] * 3] * 2]  # smallest positive exposure
    assert imaging.encode_srgb8(radiance, 1e30).tolist() == [[[255] * 3] * 2]


# =========================================================================== a live Renderer is not disturbed

N = 33  # odd: the centre pixel's ray is the optical axis
PHI, KD, D = 100.0, 0.2, 2.0


@pytest.fixture(params=BACKENDS)
def renderer(request, make_renderer):
    """A `glphong.Renderer` on each backend (skipped where unavailable)."""
    return make_renderer(N, N, request.param)


def _head_on_scene():
    """A plane at distance D in front of the camera, lit by a point light at the camera centre."""
    camera = glphong.PerspectiveCamera(np.pi / 3, znear=0.1, zfar=10.0)
    scene = glphong.Scene(camera, lights=[glphong.PointLight((0.0, 0.0, 0.0), PHI)])
    quad = MeshData([[-5, -5, -D], [5, -5, -D], [5, 5, -D], [-5, 5, -D]], [[0, 0, 1]] * 4, [[0, 1, 2], [0, 2, 3]])
    scene.add(quad, glphong.Lambert(KD))
    return scene


def _attempt_bad_input(scene):
    """Every failure path once, aimed at a live scene; returns how many raised."""
    attempts = [
        lambda: glphong.Renderer(0, N),
        lambda: glphong.Renderer(N, 16385),
        lambda: glphong.Renderer(N, N, backend="vulkan"),
        lambda: glphong.PerspectiveCamera(np.pi),
        lambda: glphong.PerspectiveCamera.look_at((0, 0, 1), (0, 0, 1)),
        lambda: glphong.PointLight((0, 0, 0), -1.0),
        lambda: glphong.Lambert(NAN),
        lambda: glphong.Phong(0.1, 0.2, -1.0),
        lambda: glphong.Scene("camera"),
        lambda: scene.add_light(glphong.AmbientLight(1.0)),
        lambda: scene.add(trimesh.creation.box(), "lambert"),
        lambda: scene.add(trimesh.creation.box(), glphong.Lambert(0.5), pose=np.diag([1.0, 0.0, 1.0, 1.0])),
        lambda: scene.add(trimesh.Trimesh(), glphong.Lambert(0.5)),
        lambda: MeshData(TRI_POS, TRI_NOR, [[0, 1, 3]]),
        lambda: imaging.encode_srgb8(np.zeros((1, 1, 3)), 0.0),
    ]
    raised = 0
    for attempt in attempts:
        with pytest.raises((TypeError, ValueError)):
            attempt()
        raised += 1
    return raised


def test_failed_validation_leaves_renderer_and_scene_intact(renderer):
    scene = _head_on_scene()
    before = renderer.render(scene).radiance.copy()
    objects_before = renderer.gl_object_count()
    expected = KD * PHI / (4.0 * math.pi * D * D)
    assert before[N // 2, N // 2, 0] == pytest.approx(expected, rel=1e-5)

    assert _attempt_bad_input(scene) == 15
    with pytest.raises(ValueError, match=m("width must be in [1, 16384] (got 0)")):
        renderer.resize(0, N)
    with pytest.raises(TypeError, match=m("height must be an integer in [1, 16384]")):
        renderer.resize(N, float(N))
    assert (renderer.width, renderer.height) == (N, N)
    assert len(scene.objects) == 1 and len(scene.lights) == 1

    frame = renderer.render(scene)
    centre = frame.radiance[N // 2, N // 2]
    np.testing.assert_allclose(centre, [expected] * 3, rtol=1e-5)
    np.testing.assert_array_equal(frame.radiance, before)
    assert frame.mask.all()
    assert renderer.gl_object_count() == objects_before


@pytest.mark.parametrize("backend", BACKENDS)
def test_renderer_accepts_numpy_integer_size(make_renderer, backend):
    r = make_renderer(np.int64(N), np.int32(N + 2), backend)  # skips or fails per GLPHONG_REQUIRE_BACKENDS
    assert (r.width, r.height) == (N, N + 2) and type(r.width) is int and type(r.height) is int
    frame = r.render(_head_on_scene())
    assert frame.radiance.shape == (N + 2, N, 3)
    expected = KD * PHI / (4.0 * math.pi * D * D)
    np.testing.assert_allclose(frame.radiance[(N + 2) // 2, N // 2], [expected] * 3, rtol=1e-5)


def test_encode_srgb8_rejects_wrong_shape():
    from glphong.imaging import encode_srgb8

    with pytest.raises(ValueError, match=r"radiance must have shape \(H, W, 3\)"):
        encode_srgb8(np.zeros((2, 2)))


def test_render_rejects_non_scene_and_released_renderer(make_renderer):
    r = make_renderer(4, 4, "egl")
    with pytest.raises(TypeError, match="scene must be a glphong.Scene"):
        r.render("not a scene")
    r.release()
    camera = glphong.PerspectiveCamera.look_at((0, 0, 1), (0, 0, 0))
    with pytest.raises(RuntimeError, match="released"):
        r.render(glphong.Scene(camera))


def test_renderer_samples_must_be_an_integer_choice():
    with pytest.raises(TypeError, match="samples must be an integer"):
        glphong.Renderer(8, 8, samples=2.0)
    with pytest.raises(TypeError, match="samples must be an integer"):
        glphong.Renderer(8, 8, samples=True)
    with pytest.raises(ValueError, match="samples must be one of"):
        glphong.Renderer(8, 8, samples=3)


def test_resize_after_release_names_the_problem(make_renderer):
    r = make_renderer(4, 4, "egl")
    r.release()
    with pytest.raises(RuntimeError, match="released"):
        r.resize(8, 8)


def test_float32_twin_uses_the_glsl_series_length():
    from glphong.twin import functions as ref_functions

    assert ref_functions._series_terms(np.float32) == 8  # lobe.glsl sums 8 terms
    assert ref_functions._series_terms(np.float64) == 16
