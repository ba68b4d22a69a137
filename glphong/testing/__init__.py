"""glphong.testing: the shader unit-testing toolkit (docs/design.md sections 7 and 8).

- `evaluate`: run a material's GLSL response on the GPU for arrays of direction pairs, with no
  scene (a vertex program captured by transform feedback), or its numpy twin on the same inputs;
- `assert_twin_matches`: seeded random and edge direction sets, GPU against the twin under the
  tolerance band, with a failure message ready to paste into a regression test;
- `assert_light_matches`: a light kind's GLSL against its twin at seeded points (`light_points`), through the
  real shader, under the tolerance band;
- `assert_render_matches`: the image-level cross-check (`glphong.verify`) as an assertion;
- any GLSL function, not only materials (docs/shader_tests.md): `glsl_function` compiles a user's GLSL (a string
  or a ``.glsl`` file with ``#include`` s) and runs one function on numpy arrays, bit-exactly, in the vertex or the
  fragment stage; `assert_glsl_matches` compares it with a numpy twin in ULPs, absolute, relative or a band, leaving
  out the rows where GLSL is undefined (the twin written with `glsl`, GLSL's built-ins in numpy); `edge_inputs`
  and the ``hypothesis`` strategies `glsl_values` / `glsl_inputs` make the inputs;
- a pytest plugin: ``pytest_plugins = ["glphong.testing"]`` in a ``conftest.py`` gives the fixtures
  `glphong_backend` (each backend; a missing one skips with its reason unless
  ``GLPHONG_REQUIRE_BACKENDS=egl,osmesa`` asks for it, then it fails), `glphong_context`,
  `glphong_renderer` (64 x 64), `glphong_make_renderer` (a factory) and `glphong_glsl` (a factory of
  `glsl_function` on each backend's pooled context), all released at teardown.

Example
-------
::

    from glphong.testing import assert_twin_matches, evaluate

    def test_minnaert_twin(glphong_backend):
        assert_twin_matches(Minnaert(k=0.3, m=0.7), backend=glphong_backend)
"""
import os

import numpy as np

from glphong.checks.evaluate import (_gpu, _inputs, _twin, cosine_power_interval, direction,  # noqa: F401
                                     direction_sets, evaluate, float32_units, frame_around, rotate_toward)
from glphong.checks import reference as ref
from glphong.checks import glsl_builtins as glsl
from glphong.checks.glsl_compare import GlslMismatch, GlslUndefinedWarning, assert_glsl_matches, ulp32, ulps_between
from glphong.checks.glsl_function import GlslFunction, glsl_function, subnormal_flushing
from glphong.checks.glsl_inputs import edge_inputs, edge_values, glsl_inputs, glsl_values, unit_float32
from glphong.checks.glsl_source import GlslSourceError
from glphong.checks.probe import shade_points
from glphong.checks.stability import case_inputs
from glphong.checks.tolerances import BAND, EPS, point_band, response_band
from glphong.checks.verify import verify
from glphong.gpu.contexts import BACKENDS, BackendUnavailableError, create_context
from glphong.gpu.programs import ProgramCache
from glphong.gpu.renderer import Renderer
from glphong.materials.cases import Case
from glphong.materials.lambert import Lambert
from glphong.shaders.builders import response_key

__all__ = ["evaluate", "direction_sets", "assert_twin_matches", "assert_render_matches", "assert_light_matches",
           "light_points", "TwinMismatch",
           "frame_around", "direction", "rotate_toward", "float32_units", "cosine_power_interval",
           "require_backend", "renderer_factory",
           "glsl_function", "GlslFunction", "assert_glsl_matches", "GlslMismatch", "GlslUndefinedWarning",
           "GlslSourceError", "glsl", "edge_values", "edge_inputs", "glsl_values", "glsl_inputs", "unit_float32",
           "ulp32", "ulps_between", "subnormal_flushing"]

class TwinMismatch(AssertionError):
    """The GPU's response left the tolerance band around the twin (`assert_twin_matches`)."""


def _literal(a):
    return "[" + ", ".join(repr(float(x)) for x in np.asarray(a, dtype=np.float64).ravel()) + "]"


def _judge(gpu, twin, low, high, certain, worst):
    """``(figures, bad, order)`` of GPU values against the twin and its band, each (N, 3): the largest relative
    error and band width where the value is decided (``certain`` and the band clear of 0), which rows leave the
    band (NaN never passes), and the ``worst`` of them, farthest outside first."""
    ok = (gpu >= low) & (gpu <= high) & ~np.isnan(gpu)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        rel = np.where(twin != 0, np.abs(gpu - twin) / np.abs(twin), np.where(gpu == twin, 0.0, np.inf))
        width = np.where(twin != 0, (high - low) / np.abs(twin), 0.0)
    decided = certain & (low > 0) & np.isfinite(rel) & np.isfinite(width)
    figures = {"max_relative_error": float(np.max(rel[decided], initial=0.0)),
               "max_band_width": float(np.max(width[decided], initial=0.0))}
    bad = ~np.all(ok, axis=1)
    span = np.maximum(high - low, np.abs(twin) * EPS + np.finfo(np.float64).tiny)
    with np.errstate(invalid="ignore"):
        distance = np.where(ok, 0.0, np.nan_to_num(np.maximum(low - gpu, gpu - high) / span, nan=np.inf))
    order = np.argsort(-np.max(distance, axis=1))[:min(worst, int(bad.sum()))]
    return figures, bad, order


def assert_twin_matches(material, n=2000, seed=0, backend="auto", band=BAND, normal=(0.0, 0.0, 1.0),
                        tangent=(1.0, 0.0, 0.0), uv=None, context=None, worst=5):
    """Assert that a material's GLSL response lies in the tolerance band around its twin.

    Evaluates `evaluate` on the GPU and on the twin for `direction_sets` (seeded random pairs and
    the edge sets), and the band from each term's ``band`` method (`glphong.checks.tolerances.response_band`).
    Where ``|n.l| <= D eps`` either outcome of the light gate is accepted; where ``n.l < -D eps``
    the GPU must return exactly 0.  NaN never passes; Inf only where the band's top is infinite.

    Parameters
    ----------
    material : glphong.materials.Material
    n : int
        Random pairs (edge sets come on top).
    seed : int
    backend : {'auto', 'egl', 'osmesa'}
    band : glphong.checks.tolerances.BandConstants
    normal, tangent, uv, context
        As in `evaluate`.
    worst : int
        Number of worst inputs listed on failure.

    Returns
    -------
    dict
        Figures of the check: ``pairs``, ``nonzero`` (pairs with a non-zero twin), and over the
        channels whose value is decided (``n.l > D eps`` and a band clear of 0):
        ``max_relative_error`` against the twin and ``max_band_width`` (relative).

    Raises
    ------
    TwinMismatch
        Listing the worst inputs with both values and the band, as a paste-ready regression test.
    """
    wi_all, wo_all, labels = direction_sets(n, seed)
    wi, wo, normal, tangent, uv = _inputs(material, wi_all, wo_all, normal, tangent, uv)
    key = response_key(material)
    uniforms = material.uniform_values(key)
    gpu = _gpu(material, key, uniforms, wi, wo, normal, tangent, uv, backend, context).astype(np.float64)
    twin, f, wi64, wo64, n_dot_l, u = _twin(material, key, uniforms, wi, wo, normal, tangent, uv)
    tol = band.D * EPS
    possible = n_dot_l > -tol
    certain = (n_dot_l > tol)[:, None]
    low = np.zeros_like(twin)
    high = np.zeros_like(twin)
    if possible.any():
        low[possible], high[possible] = response_band(key, u, f.select(possible), wi64[possible], wo64[possible],
                                                      n_dot_l[possible], material, band)
    low = np.where(certain, low, np.fmin(low, 0.0))
    high = np.where(np.isnan(high) & ~certain, np.inf, high)
    # figures where the value is decided: the light gate certain and the band clear of 0 (a gate of
    # the model itself, such as Blinn's n.v > 0, uncertain there)
    figures, bad, order = _judge(gpu, twin, low, high, certain, worst)
    figures = {"pairs": len(wi), "nonzero": int(np.any(twin != 0, axis=1).sum())} | figures
    if not bad.any():
        return figures
    lines = [f"{type(material).__name__}: the GPU response left the tolerance band at {int(bad.sum())} of "
             f"{len(wi)} direction pairs (normal {_literal(normal[0])}); worst first, paste-ready:"]
    for i in order:
        lines.append(f"  # {labels[i]}: n.l = {n_dot_l[i]:.6g}")
        lines.append(f"  wi = {_literal(wi[i])}; wo = {_literal(wo[i])}")
        lines.append(f"  gpu = {_literal(gpu[i])}; twin = {_literal(twin[i])}")
        lines.append(f"  band = ({_literal(low[i])}, {_literal(high[i])})")
    lines.append(f"  material = {material!r}")
    lines.append("  # reproduce: glphong.testing.evaluate(material, [wi], [wo]) against evaluate(..., twin=True)")
    raise TwinMismatch("\n".join(lines))


def assert_render_matches(scene, renderer, band=BAND, worst=5):
    """Assert that a render agrees with the float64 twin pixel by pixel (`glphong.verify`).

    Returns
    -------
    glphong.VerifyReport
        On success.

    Raises
    ------
    AssertionError
        With the report's summary and the worst pixels (row, column, GPU, twin, band).
    """

    report = verify(scene, renderer, band)
    if report.passed:
        return report
    lines = [str(report)]
    if report.mask_mismatch:
        lines.append(f"  coverage differs between the radiance render and the G-buffer at {report.mask_mismatch} pixels")
    rows, cols = np.nonzero(report.outside)
    if len(rows):
        err = np.nan_to_num(np.max(report.relative_error[rows, cols], axis=-1), nan=np.inf)
        for k in np.argsort(-err)[:worst]:
            j, i = rows[k], cols[k]
            lines.append(f"  pixel (row {j}, col {i}): gpu {_literal(report.gpu[j, i])}, twin {_literal(report.reference[j, i])}, "
                         f"band ({_literal(report.low[j, i])}, {_literal(report.high[j, i])})")
    raise AssertionError("\n".join(lines))


def light_points(light, n=2000, seed=0):
    """Seeded test points for a light (N, 3) float32: for a kind with a ``position``, directions uniform on the
    sphere about it at distances ``10^U(-3, 3)`` m (its whole cone included, whatever its axis); otherwise
    uniform in ``[-10, 10]^3`` m."""
    rng = np.random.default_rng(seed)
    if hasattr(light, "position") and light.position is not None:
        directions = rng.normal(size=(n, 3))
        directions /= np.linalg.norm(directions, axis=1, keepdims=True)
        distances = 10.0 ** rng.uniform(-3.0, 3.0, n)
        return (np.asarray(light.position) + directions * distances[:, None]).astype(np.float32)
    return rng.uniform(-10.0, 10.0, (n, 3)).astype(np.float32)


def assert_light_matches(light, points=None, n=2000, seed=0, backend="auto", band=BAND, context=None, worst=5):
    """Assert that a light's GLSL ``<kind>_incident`` agrees with its twin's ``incident`` at given points.

    The light shines on a point of the lecture's Lambert term with ``k_d = 1`` whose normal is the twin's ``wi``,
    so the GPU's ``shade_point`` returns ``E (n.wi)``, about ``E``: through the real shader (a 'points' program,
    `glphong.checks.probe.shade_points`), judged in the tolerance band (the kind's ``band``).  Points the twin
    says the light does not reach must give 0 (or a value in the band where the gate is uncertain).

    Parameters
    ----------
    light : glphong.lights.LightModel
        Any light, built-in or user-defined.
    points : (N, 3) array_like, optional
        World-space points [m] (default `light_points`).
    n, seed : int
        For the default points.
    backend, band, context, worst
        As in `assert_twin_matches`.

    Returns
    -------
    dict
        ``points``, ``lit`` (points with a non-zero twin), ``max_relative_error`` and ``max_band_width`` over the
        lit points whose band is clear of 0.

    Raises
    ------
    TwinMismatch
        Listing the worst points with both values and the band, paste-ready.
    """
    points = light_points(light, n, seed) if points is None else np.ascontiguousarray(points, dtype=np.float32)
    material = Lambert(1.0, two_sided=False)
    key, uniforms = case_inputs(Case("light", "light", material, lights=(light,)))
    kind = type(light)
    p = kind.values_from_uniforms(uniforms, 0, np.float64, key.lights[0].defines)
    valid, wi, _ = kind.twin().incident(points.astype(np.float64), p)
    normals = np.where(np.asarray(valid)[:, None], np.nan_to_num(wi), (0.0, 0.0, 1.0)).astype(np.float32)
    gl = context or create_context(backend)
    programs = ProgramCache(gl.mgl)
    try:
        gpu = shade_points(gl, programs, key, uniforms, points, normals).astype(np.float64)
    finally:
        with gl:
            programs.release()
        if context is None:
            gl.release()
    u64 = {k: np.asarray(v, dtype=np.float64) for k, v in uniforms.items()}
    n_valid, n64, _ = ref.safe_normalize(normals.astype(np.float64))
    position = points.astype(np.float64)
    twin = ref.shade_point(position, n64, n_valid, u64.get("u_eye"), key, u64, material)
    low, high = point_band(key, u64, position, n64, n_valid, material, band)
    figures, bad, order = _judge(gpu, twin, low, high, True, worst)
    figures = {"points": len(points), "lit": int(np.any(twin != 0, axis=1).sum())} | figures
    if not bad.any():
        return figures
    lines = [f"{type(light).__name__}: the GPU's irradiance left the tolerance band at {int(bad.sum())} of {len(points)} "
             "points (Lambert k_d = 1, normal toward the light); worst first, paste-ready:"]
    for i in order:
        lines.append(f"  x = {_literal(points[i])}; gpu = {_literal(gpu[i])}; twin = {_literal(twin[i])}")
        lines.append(f"  band = ({_literal(low[i])}, {_literal(high[i])})")
    lines.append(f"  light = {light!r}")
    lines.append("  # reproduce: glphong.testing.assert_light_matches(light, points=[x])")
    raise TwinMismatch("\n".join(lines))


# --------------------------------------------------------------------------- pytest plugin
def _required_backends():
    names = os.environ.get("GLPHONG_REQUIRE_BACKENDS", "")
    return {name.strip() for name in names.split(",") if name.strip()}


def require_backend(name):
    """A new `GLContext` on backend ``name``; the test skips with the reason where it is unavailable,
    or fails when the comma-separated ``GLPHONG_REQUIRE_BACKENDS`` names it."""
    import pytest

    try:
        return create_context(name)
    except BackendUnavailableError as exc:
        if name in _required_backends():
            pytest.fail(f"GLPHONG_REQUIRE_BACKENDS names {name!r}, but: {exc}")
        pytest.skip(str(exc))


def renderer_factory():
    """``(make, made)``: ``make(width, height, backend, **options)`` opens a `glphong.Renderer` with the
    skip-or-fail semantics of `require_backend`; ``made`` lists what it opened (release them)."""

    made = []

    def make(width, height, backend, **options):
        try:
            renderer = Renderer(width, height, backend=backend, **options)
        except BackendUnavailableError:
            require_backend(backend).release()  # skips or fails; if it now works, report the original error
            raise
        made.append(renderer)
        return renderer

    return make, made


try:
    import pytest as _pytest
except ImportError:  # the toolkit works without pytest; the fixtures need it
    _pytest = None

if _pytest is not None:
    @_pytest.fixture(params=BACKENDS)
    def glphong_backend(request):
        """Each OpenGL backend name ('egl', 'osmesa') that works here (else skip, or fail if required)."""
        require_backend(request.param).release()
        return request.param

    @_pytest.fixture
    def glphong_context(glphong_backend):
        """A `glphong.gpu.contexts.GLContext` on each backend, released at teardown."""
        gl = create_context(glphong_backend)
        yield gl
        gl.release()

    @_pytest.fixture
    def glphong_make_renderer():
        """Factory ``make(width, height, backend, **options)`` of `glphong.Renderer` s, released at teardown;
        an unavailable backend skips (or fails where required)."""
        make, made = renderer_factory()
        yield make
        for renderer in made:
            renderer.release()

    @_pytest.fixture
    def glphong_renderer(glphong_backend, glphong_make_renderer):
        """A 64 x 64 `glphong.Renderer` on each backend (resize it as needed), released at teardown."""
        return glphong_make_renderer(64, 64, glphong_backend)

    @_pytest.fixture
    def glphong_glsl(glphong_backend):
        """Factory ``glphong_glsl(source, name, **options)`` of `glsl_function` s on each backend (that backend's
        pooled context: compiled per test, the context made once per process), released at teardown; a missing
        backend skips with its reason (or fails where required)."""
        made = []

        def make(source, name, **options):
            fn = glsl_function(source, name, backend=glphong_backend, **options)
            made.append(fn)
            return fn

        yield make
        for fn in made:
            fn.release()
