"""Unit tests of a GLSL file of your own, with glphong: copy this file and my_shader.glsl anywhere and run
``pytest test_my_shader.py`` (glphong installed with its [test] extra: pytest, hypothesis).

Three tests, each on every OpenGL backend the machine has (EGL, OSMesa; a missing one skips with the reason):
values against a numpy twin in units in the last place, a hypothesis property, an edge-case sweep.  A wrong
operator in the GLSL or in the twin fails with a report that names the worst rows (inputs, GPU value, twin value,
allowed band) and prints a reproduction.
"""
from pathlib import Path

import numpy as np
from hypothesis import given, settings

from glphong.testing import assert_glsl_matches, edge_inputs, glsl, glsl_inputs

pytest_plugins = ["glphong.testing"]  # the fixtures: glphong_glsl (and glphong_backend, ...)

SHADER = Path(__file__).with_name("my_shader.glsl")


# ---- the twins: the same formulas in numpy (float64), GLSL's built-ins from glphong.testing.glsl
def tone_reinhard(radiance, white):
    return radiance * (1.0 + radiance / (white * white)[..., None]) / (1.0 + radiance)


def wrap_diffuse(n, l, w):  # noqa: E741 - the light direction
    return np.maximum((glsl.dot(n, l) + w) / (1.0 + w), 0.0)


def unit_rows(rng, count):
    v = rng.normal(size=(count, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


# ---- 1. values, in float32 units in the last place
def test_tone_curve_within_8_ulps(glphong_glsl):
    fn = glphong_glsl(SHADER, "tone_reinhard")
    rng = np.random.default_rng(1)
    inputs = {"radiance": 10.0 ** rng.uniform(-6, 4, (4000, 3)), "white": 10.0 ** rng.uniform(-1, 3, 4000)}
    figures = assert_glsl_matches(fn, tone_reinhard, inputs, ulps=8)
    assert figures["compared"] == 4000


# ---- 2. a property: the curve maps [0, white] into [0, 1], and white to 1 (within float32 rounding)
def test_tone_curve_maps_zero_to_white_into_unit_interval(glphong_glsl):
    fn = glphong_glsl(SHADER, "tone_reinhard")

    @settings(max_examples=25, deadline=None)
    @given(glsl_inputs(fn, rows=64, radiance={"min_value": 0.0, "max_value": 1e4},
                       white={"min_value": 1e-2, "max_value": 1e2}))
    def check(values):
        radiance = np.minimum(values["radiance"], values["white"][:, None])  # inside [0, white]
        out = fn(radiance=radiance, white=values["white"]).astype(np.float64)
        assert np.all(out >= 0.0) and np.all(out <= 1.0 + 4e-7), out.max()
        at_white = fn(radiance=np.repeat(values["white"][:, None], 3, axis=1), white=values["white"])
        np.testing.assert_allclose(at_white, 1.0, rtol=4e-7)

    check()


# ---- 3. an edge-case sweep: direction pairs equal, opposite, grazing, perpendicular; wraps at their edges
def test_wrap_diffuse_edge_sweep(glphong_glsl):
    fn = glphong_glsl(SHADER, "wrap_diffuse")
    inputs = edge_inputs(fn, unit={"n", "l"})
    inside = (inputs["w"] >= 0.0) & (inputs["w"] <= 1.0)  # the function's domain: w in [0, 1]
    inputs = {name: value[inside] for name, value in inputs.items()}
    # the dot product of unit float32 vectors is good to a few float32 steps, absolutely: n.l + w may cancel
    figures = assert_glsl_matches(fn, wrap_diffuse, inputs, ulps=4, atol=5e-7)
    assert figures["compared"] > 500
