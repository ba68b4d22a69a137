"""glphong.testing for any GLSL function (docs/shader_tests.md, docs/design.md section 14): the runner
(`glsl_function`), the comparison (`assert_glsl_matches`), the twin's GLSL built-ins and their undefined domains
(`glsl`), the inputs (`edge_inputs`, hypothesis strategies) and the plugin's `glphong_glsl` fixture, on every
backend the machine has.
"""
import os
import subprocess
import sys

import numpy as np
import pytest
from hypothesis import given, settings

from glphong.testing.glsl_runner import VERTEX_CHUNK
from glphong.testing.glsl_types import TYPE_NAMES, glsl_type
from glphong.testing import (GlslMismatch, GlslSourceError, GlslUndefinedWarning, assert_glsl_matches, edge_inputs,
                             edge_values, glsl, glsl_inputs, glsl_values, ulp32, ulps_between, unit_float32)

STAGES = ("vertex", "fragment")


def _identity_source(t):
    return f"{t} ident({t} x) {{ return x; }}\nvoid ident_out({t} x, out {t} y) {{ y = x; }}\n" \
           f"void ident_inout(inout {t} x) {{ }}\n"


def _values(t, rows=7, seed=3):
    """Values of every type, with the float edge cases whose bits must survive: -0.0, the smallest subnormal, NaN
    with a payload, inf."""
    gt = glsl_type(t)
    rng = np.random.default_rng(seed)
    shape = (rows,) + gt.row_shape()
    if gt.base == "float":
        words = rng.integers(0, 2 ** 32, shape, dtype=np.uint64).astype(np.uint32)
        flat = words.reshape(rows, -1)
        flat[0, 0], flat[1, 0], flat[2, 0], flat[3, 0] = 0x80000000, 0x00000001, 0x7FC00123, 0x7F800000
        return words.view(np.float32)
    if gt.base == "bool":
        return rng.integers(0, 2, shape).astype(bool)
    info = np.iinfo(gt.dtype)
    return rng.integers(info.min, int(info.max) + 1, shape, dtype=np.int64).astype(gt.dtype)


@pytest.mark.parametrize("stage", STAGES)
def test_every_type_crosses_bit_exactly_in_and_out(glphong_glsl, stage):
    """Every scalar, vector and matrix type, through the return value, an out and an inout parameter: the bits come
    back as they went (-0.0, a subnormal, a NaN payload, inf, random bit patterns); matrices as numpy writes them."""
    for t in TYPE_NAMES:
        x = _values(t)
        source = _identity_source(t)
        expect = x.view(np.uint32) if glsl_type(t).base == "float" else x
        for name, pick in (("ident", lambda r: r), ("ident_out", lambda r: r["y"]), ("ident_inout", lambda r: r["x"])):
            got = pick(glphong_glsl(source, name, stage=stage, grid_width=4)(x))
            assert got.shape == x.shape and got.dtype == x.dtype, (t, name)
            got = got.view(np.uint32) if glsl_type(t).base == "float" else got
            np.testing.assert_array_equal(got, expect, err_msg=f"{t} {name} {stage}")


def test_matrix_layout_is_numpys(glphong_glsl):
    """GLSL's m[c][r] is M[r, c]: a column read in GLSL is a numpy column."""
    fn = glphong_glsl("vec3 second_column(mat3 m) { return m[1]; }\nvec3 apply(mat3 m, vec3 v) { return m * v; }",
                      "second_column")
    m = np.arange(9.0).reshape(1, 3, 3)
    np.testing.assert_array_equal(fn(m)[0], m[0, :, 1])
    apply = glphong_glsl("vec3 apply(mat3 m, vec3 v) { return m * v; }", "apply")
    v = np.array([1.0, -2.0, 0.5])
    np.testing.assert_allclose(apply(m, v)[0], m[0] @ v, rtol=1e-6)


def test_broadcasting_and_bad_calls(glphong_glsl):
    fn = glphong_glsl("vec3 scale(vec3 a, float s) { return a * s; }", "scale")
    np.testing.assert_array_equal(fn(np.ones((5, 3)), 2.0), np.full((5, 3), 2.0, np.float32))  # a scalar broadcasts
    np.testing.assert_array_equal(fn([1.0, 2.0, 3.0], np.arange(4.0)), np.outer(np.arange(4.0), [1, 2, 3]))
    assert fn(np.zeros((0, 3)), np.zeros(0)).shape == (0, 3)
    with pytest.raises(ValueError, match=r"a vec3 takes an array of shape \(N, 3\)"):
        fn(np.ones((5, 2)), 1.0)
    with pytest.raises(ValueError, match="different numbers of rows"):
        fn(np.ones((5, 3)), np.ones(4))
    with pytest.raises(TypeError, match=r"missing \['s'\]"):
        fn(a=np.ones(3))
    with pytest.raises(TypeError, match=r"unknown \['t'\]"):
        fn(a=np.ones(3), s=1.0, t=2.0)
    ints = glphong_glsl("int twice(int i) { return 2 * i; }", "twice")
    with pytest.raises(ValueError, match="whole numbers"):
        ints(np.array([1.5]))
    with pytest.raises(ValueError, match=r"values in \[-2147483648, 2147483647\]"):
        ints(np.array([2 ** 40]))


def test_chunks_give_the_same_rows(glphong_glsl, monkeypatch):
    """A call with more rows than a draw holds is split; the rows come back the same and in order."""
    fn = glphong_glsl("float f(float x, uint k) { return x * 2.0 + float(k); }", "f")
    x, k = np.linspace(-1, 1, 2500), np.arange(2500, dtype=np.uint32)
    whole = fn(x, k)
    monkeypatch.setattr("glphong.testing.glsl_runner.VERTEX_CHUNK", 1000)
    np.testing.assert_array_equal(fn(x, k), whole)
    assert VERTEX_CHUNK == 1 << 20
    # the fragment stage's grid is at most 4096 pixels high: a one-pixel-wide grid of 5000 rows takes two draws
    where = glphong_glsl("float y(float x) { return gl_FragCoord.y + x; }", "y", stage="fragment", grid_width=1)
    np.testing.assert_array_equal(where(np.zeros(5000)), np.concatenate([np.arange(4096), np.arange(904)]) + 0.5)
    assert glphong_glsl("float one() { return 1.0; }", "one")().tolist() == [1.0]  # no inputs: one row


def test_sources_with_includes_and_clear_errors(glphong_glsl, tmp_path):
    """#include of glphong's chunks and of the user's files; every failure names the file and line or what to do."""
    (tmp_path / "lib").mkdir()
    (tmp_path / "lib" / "helpers.glsl").write_text("float twice(float x) { return 2.0 * x; }\n")
    (tmp_path / "main.glsl").write_text('#version 450\n#include "lib/helpers.glsl"\n#include <glphong/lobe>\n'
                                        "float f(float d, float q) { return twice(lobe_from_delta(d, q)); }\n")
    fn = glphong_glsl(tmp_path / "main.glsl", "f")
    assert fn(0.0, 10.0)[0] == 2.0  # lobe_from_delta(0, q) = 1
    # the compiler's log names the user's file and line, and the harness is printed
    (tmp_path / "broken.glsl").write_text('#include "lib/helpers.glsl"\n\nfloat g(float x) {\n    return twice(x) + y;\n}\n')
    with pytest.raises(GlslSourceError) as caught:
        glphong_glsl(str(tmp_path / "broken.glsl"), "g")
    message = str(caught.value)
    assert f"{tmp_path / 'broken.glsl'}:4" in message and "return twice(x) + y;" in message
    assert "<generated harness>" in message and "glphong_result = g(" in message
    # includes stay in the folder unless allowed
    (tmp_path / "lib" / "escape.glsl").write_text('#include "../main.glsl"\n')
    with pytest.raises(GlslSourceError, match="leaves the folder"):
        glphong_glsl('#include "escape.glsl"\nfloat h(float x) { return x; }', "h", include_dir=tmp_path / "lib")
    assert glphong_glsl('#include "escape.glsl"\nfloat h(float x) { return x; }', "h",
                        include_dir=tmp_path / "lib", allow_outside=True)(1.0)[0] == 1.0
    # what is read is a regular file within the size limit, checked before a byte is read
    os.mkfifo(tmp_path / "pipe.glsl")
    with pytest.raises(GlslSourceError, match="not a regular file"):
        glphong_glsl('#include "pipe.glsl"\nfloat h(float x) { return x; }', "h", include_dir=tmp_path)
    with pytest.raises(GlslSourceError, match="not a regular file"):
        glphong_glsl(tmp_path / "pipe.glsl", "h")
    (tmp_path / "big.glsl").write_text("//" + "x" * (1 << 20) + "\n")
    with pytest.raises(GlslSourceError, match="more than the limit of 1048576"):
        glphong_glsl('#include "big.glsl"\nfloat h(float x) { return x; }', "h", include_dir=tmp_path)
    (tmp_path / "loop.glsl").write_text('#include "loop.glsl"\n')
    with pytest.raises(GlslSourceError, match="includes itself"):
        glphong_glsl(tmp_path / "loop.glsl", "f")
    with pytest.raises(GlslSourceError, match="include_dir="):
        glphong_glsl('#include "x.glsl"\nfloat h(float x) { return x; }', "h")
    with pytest.raises(GlslSourceError, match="cannot read"):
        glphong_glsl('#include "missing.glsl"\nfloat h(float x) { return x; }', "h", include_dir=tmp_path)
    with pytest.raises(GlslSourceError, match="no library chunk 'nope'"):
        glphong_glsl("#include <glphong/nope>\nfloat h(float x) { return x; }", "h")
    # functions and types
    with pytest.raises(GlslSourceError, match=r"no function 'k' is defined \(defined: h\)"):
        glphong_glsl("float h(float x) { return x; }", "k")
    with pytest.raises(GlslSourceError, match="not double"):
        glphong_glsl("#version 400\ndouble d(double x) { return x; }", "d", version=400)
    with pytest.raises(GlslSourceError, match=r"float a\[2\]"):
        glphong_glsl("float s(float a[2]) { return a[0]; }", "s")
    with pytest.raises(GlslSourceError, match="is overloaded"):
        glphong_glsl("float o(float x) { return x; }\nfloat o(vec2 x) { return x.x; }", "o")
    picked = glphong_glsl("float o(float x) { return x; }\nfloat o(vec2 x) { return x.y; }", "o", overload=["vec2"])
    assert picked([1.0, 5.0])[0] == 5.0


def test_uniforms_by_name(glphong_glsl):
    source = ("uniform float u_gain;\nuniform vec3 u_tint;\nuniform mat2 u_m;\nuniform int u_k;\nuniform float u_unused;\n"
              "vec3 f(vec2 x) { vec2 y = u_m * x; return u_tint * u_gain * float(u_k) + vec3(y, 0.0); }")
    fn = glphong_glsl(source, "f")
    m = np.array([[1.0, 2.0], [3.0, 4.0]])
    out = fn(np.array([1.0, 1.0]), uniforms={"u_gain": 0.5, "u_tint": [1.0, 2.0, 3.0], "u_m": m, "u_k": 2,
                                            "u_unused": 1.0})
    np.testing.assert_allclose(out[0], [1.0 + 3.0, 2.0 + 7.0, 3.0])  # tint * gain * k + (M x, 0)
    with pytest.raises(KeyError, match="no uniform 'u_nope' is declared"):
        fn.set_uniform("u_nope", 1.0)


def test_fragment_stage_has_derivatives_and_textures(glphong_glsl):
    """Rows are pixels (i mod W, i div W): dFdx of x^2 along a row is the forward difference of its 2x2 quad;
    texture() samples a bound image."""
    fn = glphong_glsl("float slope(float x) { return dFdx(x * x); }", "slope", stage="fragment", grid_width=8)
    x = np.arange(16.0)
    expected = np.repeat((x[1::2] ** 2 - x[0::2] ** 2), 2)
    np.testing.assert_array_equal(fn(x), expected)
    coords = glphong_glsl("vec4 where(float unused) { return gl_FragCoord; }", "where", stage="fragment", grid_width=4)
    np.testing.assert_array_equal(coords(np.zeros(6))[:, :2], [[0.5, 0.5], [1.5, 0.5], [2.5, 0.5], [3.5, 0.5],
                                                               [0.5, 1.5], [1.5, 1.5]])
    sample = glphong_glsl("uniform sampler2D u_image;\nvec4 look(vec2 uv) { return texture(u_image, uv); }", "look",
                          stage="fragment")
    image = np.array([[[0.0, 0.25, 0.5, 1.0], [1.0, 0.0, 0.0, 1.0]], [[0.0, 1.0, 0.0, 1.0], [0.0, 0.0, 1.0, 1.0]]],
                     np.float32)
    sample.set_texture("u_image", image, filter="nearest")
    texel_centres = np.array([[0.25, 0.25], [0.75, 0.25], [0.25, 0.75], [0.75, 0.75]])
    np.testing.assert_array_equal(sample(texel_centres), image.reshape(4, 4))


def test_assert_glsl_matches_passes_and_reports(glphong_glsl):
    source = "float lerp3(float a, float b, float t) { return a + (b - a) * t; }"
    fn = glphong_glsl(source, "lerp3")
    rng = np.random.default_rng(5)
    inputs = {"a": rng.uniform(-1, 1, 3000), "b": rng.uniform(-1, 1, 3000), "t": rng.uniform(0, 1, 3000)}

    def twin(a, b, t):
        return a + (b - a) * t

    figures = assert_glsl_matches(fn, twin, inputs, atol=4e-7)
    assert figures["rows"] == figures["compared"] == 3000 and figures["max_abs"]["return"] < 4e-7

    def wrong(a, b, t):  # one operator changed
        return a - (b - a) * t

    with pytest.raises(GlslMismatch) as caught:
        assert_glsl_matches(fn, wrong, inputs, atol=4e-7, worst=3)
    report = str(caught.value)
    assert "disagrees with its twin" in report and "worst rows of return (float)" in report
    assert report.count("  row ") == 3 and "GPU" in report and "allowed [" in report and "ulps" in report
    assert "reproduce (these rows):" in report and "fn = glsl_function(SOURCE, 'lerp3')" in report
    assert "a = np.array([" in report and "print(fn(a=a, b=b, t=t))" in report
    with pytest.raises(TypeError, match="needs a tolerance"):
        assert_glsl_matches(fn, twin, inputs)


def test_ulps_and_exactness(glphong_glsl):
    """One float32 step is 1 ulp: ulps=1 accepts it, ulps=0 does not; integers and booleans compare exactly."""
    fn = glphong_glsl("float up(float x) { return uintBitsToFloat(floatBitsToUint(x) + 1u); }", "up")
    x = np.array([1.0, 3.0, 1e-3, 1e30], np.float32)
    assert assert_glsl_matches(fn, lambda x: x, {"x": x}, ulps=1)["max_ulps"]["return"] == 1.0
    with pytest.raises(GlslMismatch):
        assert_glsl_matches(fn, lambda x: x, {"x": x}, ulps=0)
    np.testing.assert_array_equal(ulps_between(np.nextafter(np.float32(2), np.float32(3)), 2.0), 1.0)
    assert ulp32(1.0) == 2.0 ** -23 and ulp32(0.0) == 2.0 ** -149
    parity = glphong_glsl("bool odd(int i) { return (i & 1) == 1; }", "odd")
    assert_glsl_matches(parity, lambda i: (i & 1) == 1, {"i": np.arange(-50, 50)}, ulps=0)
    with pytest.raises(GlslMismatch, match="odd"):
        assert_glsl_matches(parity, lambda i: (i & 1) == 0, {"i": np.arange(-50, 50)}, ulps=0)


def test_out_parameters_and_band_functions(glphong_glsl):
    """A function with out parameters is compared output by output, against a dict (or tuple) twin; a band function
    gives each output's interval."""
    fn = glphong_glsl("float polar(vec2 p, out float angle) { angle = atan(p.y, p.x); return length(p); }", "polar")
    p = np.random.default_rng(2).normal(size=(500, 2))

    def twin(p):
        return {"return": glsl.length(p), "angle": glsl.atan(p[:, 1], p[:, 0])}

    def band(name, value, inputs):
        width = 4e-6 * np.abs(value) + (1e-5 if name == "angle" else 0.0)  # atan: no precision in the spec
        return value - width, value + width

    figures = assert_glsl_matches(fn, twin, {"p": p}, band=band)
    assert set(figures["max_ulps"]) == {"return", "angle"}
    assert_glsl_matches(fn, lambda p: (glsl.length(p), glsl.atan(p[:, 1], p[:, 0])), {"p": p}, band=band)


def test_undefined_rows_are_left_out_and_named(glphong_glsl):
    """pow(x, y) with x < 0 is undefined in GLSL: the twin written with glsl.pow marks those rows; they are left out
    with a warning that names the built-in and its domain, or fail with undefined='fail'."""
    fn = glphong_glsl("float p(float x, float y) { return pow(x, y); }", "p")
    x = np.array([-2.0, 0.0, 0.0, 2.0, 4.0])
    y = np.array([2.0, 0.0, 1.0, 0.5, -1.0])
    with pytest.warns(GlslUndefinedWarning, match=r"pow where x < 0, or x == 0 and y <= 0 \(2 rows\)"):
        figures = assert_glsl_matches(fn, glsl.pow, {"x": x, "y": y}, ulps=4)
    assert figures["compared"] == 3 and figures["undefined"] == {"pow": 2}
    with pytest.raises(GlslMismatch, match="undefined domains on 2 of 5 rows"):
        assert_glsl_matches(fn, glsl.pow, {"x": x, "y": y}, ulps=4, undefined="fail")


@pytest.mark.parametrize("name, args, undefined", [
    ("pow", ([-1.0, 0.0, 0.0, 2.0], [2.0, 0.0, -1.0, 0.5]), [1, 1, 1, 0]),
    ("log", ([0.0, -1.0, 1e-30],), [1, 1, 0]), ("log2", ([0.0, 1.0],), [1, 0]),
    ("sqrt", ([-1e-30, 0.0],), [1, 0]), ("inversesqrt", ([0.0, 4.0],), [1, 0]),
    ("asin", ([1.0000001, -1.0],), [1, 0]), ("acos", ([-1.5, 0.5],), [1, 0]),
    ("atan", ([0.0, 0.0, 1.0], [0.0, -1.0, 0.0]), [1, 0, 0]), ("acosh", ([0.5, 1.0],), [1, 0]),
    ("atanh", ([1.0, 0.5],), [1, 0]), ("mod", ([1.0, 1.0], [0.0, 3.0]), [1, 0]),
    ("clamp", ([0.5, 0.5], [1.0, 0.0], [0.0, 1.0]), [1, 0]),
    ("smoothstep", ([1.0, 0.0, 0.0], [1.0, 1.0, -1.0], [0.5, 0.5, 0.5]), [1, 0, 1]),
    ("round", ([2.5, 2.4, -0.5],), [1, 0, 1]),
])
def test_each_builtin_marks_the_specifications_domain(name, args, undefined):
    with glsl.record_undefined(len(undefined)) as record:
        value = getattr(glsl, name)(*(np.asarray(a) for a in args))
    np.testing.assert_array_equal(record.rows, np.asarray(undefined, bool))
    assert np.all(np.isnan(value[np.asarray(undefined, bool)])) and np.all(np.isfinite(value[~np.asarray(undefined, bool)]))


def test_vector_builtins_mark_rows():
    with glsl.record_undefined(3) as record:
        glsl.normalize(np.array([[0.0, 0, 0], [1, 0, 0], [0, 0, 1e-30]]))
        glsl.inverse(np.array([np.eye(2), np.zeros((2, 2)), 2 * np.eye(2)]))
    assert record.counts() == {"normalize": 1, "inverse": 1} and record.rows.tolist() == [True, True, False]


def test_the_drivers_flushing_is_reported(glphong_backend):
    """subnormal_flushing says what the driver does with subnormal operands and results; passing through is exact
    whatever it says (llvmpipe flushes both, measured)."""
    from glphong.testing import subnormal_flushing

    found = subnormal_flushing(backend=glphong_backend)
    assert set(found) == {"inputs", "results"} and all(isinstance(v, bool) for v in found.values())


def test_subnormal_flushing_is_accepted_and_counted(glphong_glsl):
    """GLSL may flush subnormals: a GPU that does is accepted against the twin and counted; one that does not
    matches the twin itself."""
    fn = glphong_glsl("float half_of(float x) { return x * 0.5; }", "half_of")
    x = np.array([2.0 ** -126, 2.0 ** -140, 1.0, -(2.0 ** -130)], np.float32)
    figures = assert_glsl_matches(fn, lambda x: x * 0.5, {"x": x}, ulps=0)
    gpu = fn(x)
    assert figures["flushed"] == int(np.sum(gpu[[0, 1, 3]] == 0))
    if figures["flushed"]:
        with pytest.raises(GlslMismatch):
            assert_glsl_matches(fn, lambda x: x * 0.5, {"x": x}, ulps=0, flush_subnormals=False)


def test_edge_values_and_inputs():
    f = edge_values("float")
    assert np.any((f == 0) & np.signbit(f)) and np.any(f == np.float32(2.0 ** -149)) and np.any(f == np.finfo(np.float32).max)
    assert np.any(f == np.float32(1.0 - 2.0 ** -24))
    assert np.isnan(edge_values("float", nonfinite=True)).any()
    assert edge_values("ivec3").shape[1:] == (3,) and edge_values("mat2").shape[1:] == (2, 2)
    assert np.iinfo(np.int32).min in edge_values("int") and 2 ** 32 - 1 in edge_values("uint")

    class Fake:  # edge_inputs reads the signature only
        from glphong.testing.glsl_source import functions
        signature = functions("float f(vec3 n, vec3 l, float q) { return 0.0; }")["f"][0]

    rows = edge_inputs(Fake, unit={"n", "l"})
    n, l = rows["n"].astype(np.float64), rows["l"].astype(np.float64)
    cos = np.sum(n * l, axis=1)
    assert np.any(np.all(n == l, axis=1)) and np.any(np.all(n == -l, axis=1))  # equal and exactly opposite
    assert np.any(np.abs(cos) < 1e-6)  # grazing
    assert np.any(~np.all(n == l, axis=1) & (cos > 1 - 1e-6))  # distinct, 1e-7 rad apart
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, rtol=1e-7)
    assert len(edge_inputs(Fake, unit={"n", "l"}, limit=100)["q"]) == 100


def test_hypothesis_strategies(glphong_glsl):
    fn = glphong_glsl("float d(vec3 a, vec3 b) { return dot(a, b); }", "d")

    @settings(max_examples=15, deadline=None)
    @given(glsl_inputs(fn, rows=16, unit={"a", "b"}))
    def symmetric(values):
        np.testing.assert_array_equal(fn(**values), fn(a=values["b"], b=values["a"]))
        assert np.all(np.abs(fn(**values)) <= 1.0 + 4e-7)

    symmetric()

    @settings(max_examples=10, deadline=None)
    @given(glsl_values("mat3", rows=4), glsl_values("uvec2", rows=4), glsl_values("float", rows=4, min_value=0.1,
                                                                                  max_value=0.7))
    def shapes(m, u, x):
        assert m.shape == (4, 3, 3) and m.dtype == np.float32 and u.dtype == np.uint32
        assert np.all((x >= np.float32(0.1)) & (x <= np.float32(0.7)))

    shapes()
    assert np.allclose(np.linalg.norm(unit_float32([[3.0, 4.0, 0.0]]), axis=1), 1.0)


def test_library_chunks_through_the_public_api(glphong_glsl):
    """glphong's own chunks, tested the way a user tests theirs: srgb_encode against the exact sRGB curve in
    float64, lobe_from_delta against (1 - delta)^q, with the edge cases of each input."""
    from glphong.core.imaging import srgb_encode
    from glphong.twin.functions import lobe_from_delta

    encode = glphong_glsl("#include <glphong/srgb>", "srgb_encode")
    x = np.concatenate([np.linspace(0, 1, 4001), edge_values("float")[(edge_values("float") >= 0)
                                                                       & (edge_values("float") <= 1)]])
    linear = np.stack([x, x[::-1], np.sqrt(x)], axis=1)
    assert_glsl_matches(encode, lambda linear: srgb_encode(linear), {"linear": linear}, atol=2e-6)
    lobe = glphong_glsl("#include <glphong/lobe>", "lobe_from_delta")
    delta = np.concatenate([[0.0, 2.0 ** -149, 1e-7], np.geomspace(1e-6, 1.0, 400)])
    q = np.array([1.0, 50.0, 1e4, 1e6])
    rows = {"delta": np.repeat(delta, len(q)), "q": np.tile(q, len(delta))}
    figures = assert_glsl_matches(lobe, lambda delta, q: lobe_from_delta(delta, q), rows, rtol=1e-4, atol=1e-30)
    assert figures["compared"] == len(rows["q"])


def test_a_missing_backend_skips_with_its_reason(tmp_path):
    """The plugin's glphong_glsl fixture on a backend that is not there: the test skips and says why."""
    (tmp_path / "conftest.py").write_text(
        'pytest_plugins = ["glphong.testing"]\n'
        "import glphong.testing.backends\n"
        "from glphong.gpu.contexts import BackendUnavailableError\n"
        "def fail(name, *a, **k):\n"
        "    raise BackendUnavailableError(f'{name}: libEGL is not installed (test double)')\n"
        "glphong.testing.backends.create_context = fail\n")
    (tmp_path / "test_f.py").write_text("def test_f(glphong_glsl):\n    glphong_glsl('float f(float x) { return x; }', 'f')\n")
    env = {k: v for k, v in os.environ.items() if k not in ("PYTEST_ADDOPTS", "GLPHONG_REQUIRE_BACKENDS")}
    out = subprocess.run([sys.executable, "-m", "pytest", "-q", "-rs", "-p", "no:cacheprovider", str(tmp_path)],
                         cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
    assert out.returncode == 0 and "2 skipped" in out.stdout, out.stdout[-2000:]
    assert out.stdout.count("libEGL is not installed (test double)") >= 1
