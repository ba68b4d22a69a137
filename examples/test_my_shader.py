"""Unit tests of a GLSL file of your own, with glphong: copy this file and my_shader.glsl anywhere and run
``pytest test_my_shader.py`` (glphong installed with its [test] extra: pytest, hypothesis).

Three tests, each on every OpenGL backend the machine has (EGL, OSMesa; a missing one skips with the reason):
values against a numpy twin in units in the last place, a hypothesis property, an edge-case sweep.  A wrong
operator in the GLSL or in the twin fails with a report that names the worst rows (inputs, GPU value, twin value,
allowed band) and prints a reproduction.

Run as a script (``python test_my_shader.py [out.png]``, matplotlib installed), it plots what the tests compare:
each function's GPU values against its twin, on the inputs of tests 1 and 3, within the bands they allow.
"""
import sys
from pathlib import Path

import numpy as np
from hypothesis import given, settings

from glphong.testing import assert_glsl_matches, edge_inputs, glsl, glsl_function, glsl_inputs, ulps_between

pytest_plugins = ["glphong.testing"]  # the fixtures: glphong_glsl (and glphong_backend, ...)

SHADER = Path(__file__).with_name("my_shader.glsl")
TONE_ULPS = 8                    # test 1's band
WRAP_ULPS, WRAP_ATOL = 4, 5e-7   # test 3's band


# ---- the twins: the same formulas in numpy (float64), GLSL's built-ins from glphong.testing.glsl
def tone_reinhard(radiance, white):
    return radiance * (1.0 + radiance / (white * white)[..., None]) / (1.0 + radiance)


def wrap_diffuse(n, l, w):  # noqa: E741 - the light direction
    return np.maximum((glsl.dot(n, l) + w) / (1.0 + w), 0.0)


def unit_rows(rng, count):
    v = rng.normal(size=(count, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def tone_inputs(rows=4000):
    """Seeded radiance from 1e-6 to 1e4 and white points from 0.1 to 1000, log-uniform."""
    rng = np.random.default_rng(1)
    return {"radiance": 10.0 ** rng.uniform(-6, 4, (rows, 3)), "white": 10.0 ** rng.uniform(-1, 3, rows)}


def wrap_edge_inputs(fn):
    """``edge_inputs`` of wrap_diffuse (unit n and l) within the function's domain, w in [0, 1]."""
    inputs = edge_inputs(fn, unit={"n", "l"})
    inside = (inputs["w"] >= 0.0) & (inputs["w"] <= 1.0)
    return {name: value[inside] for name, value in inputs.items()}


# ---- 1. values, in float32 units in the last place
def test_tone_curve_within_8_ulps(glphong_glsl):
    fn = glphong_glsl(SHADER, "tone_reinhard")
    figures = assert_glsl_matches(fn, tone_reinhard, tone_inputs(), ulps=TONE_ULPS)
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
    inputs = wrap_edge_inputs(fn)
    # the dot product of unit float32 vectors is good to a few float32 steps, absolutely: n.l + w may cancel
    figures = assert_glsl_matches(fn, wrap_diffuse, inputs, ulps=WRAP_ULPS, atol=WRAP_ATOL)
    assert figures["compared"] > 500


# ---- run as a script: a figure of what tests 1 and 3 compare
def gpu_and_twin(fn, twin, inputs):
    """``(inputs rounded to float32, GPU values, twin values)``: the twin reads the rounded inputs, as
    ``assert_glsl_matches`` does."""
    rounded = {name: np.float32(value).astype(np.float64) for name, value in inputs.items()}
    return rounded, fn(**inputs), twin(**rounded)


def plot(out="test_my_shader.png"):
    """Both functions, on the first backend that works, against their twins, drawn into ``out``."""
    from matplotlib.figure import Figure  # only the figure needs matplotlib

    figure = Figure(figsize=(10, 3.6), layout="constrained")
    left, right = figure.subplots(1, 2)
    tone, wrap = glsl_function(SHADER, "tone_reinhard"), glsl_function(SHADER, "wrap_diffuse")
    try:
        rounded, gpu, twin = gpu_and_twin(tone, tone_reinhard, tone_inputs())
        ulps = ulps_between(gpu, twin)
        left.semilogx(rounded["radiance"].ravel(), ulps.ravel(), ".", markersize=2)
        left.axhline(TONE_ULPS, color="red", linestyle="--", label=f"test 1 allows {TONE_ULPS} ulps")
        left.set(xlabel="radiance [W/(m^2 sr)]", ylabel="|GPU - twin| [float32 ulps]",
                 title=f"tone_reinhard, {ulps.size} values: at most {ulps.max():.2g} ulps")
        rounded, gpu, twin = gpu_and_twin(wrap, wrap_diffuse, wrap_edge_inputs(wrap))
        error = np.abs(gpu - twin)
        right.plot(glsl.dot(rounded["n"], rounded["l"]), error, ".", markersize=3)
        right.axhline(WRAP_ATOL, color="red", linestyle="--", label=f"test 3 allows {WRAP_ATOL:g} (or {WRAP_ULPS} ulps)")
        right.set(xlabel="n . l", ylabel="|GPU - twin|", title=f"wrap_diffuse, {error.size} edge cases: at most "
                                                                f"{error.max():.2g}")
        for axes in (left, right):
            axes.legend(loc="center right")
    finally:
        tone.release()
        wrap.release()
    figure.savefig(out, dpi=100)
    print("wrote", out)


if __name__ == "__main__":
    plot(*sys.argv[1:2])
