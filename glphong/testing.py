"""glphong.testing: the shader unit-testing toolkit (docs/design.md sections 7 and 8).

- `evaluate`: run a material's GLSL response on the GPU for arrays of direction pairs, with no
  scene (a vertex program captured by transform feedback), or its numpy twin on the same inputs;
- `assert_twin_matches`: seeded random and edge direction sets, GPU against the twin under the
  tolerance band, with a failure message ready to paste into a regression test;
- `assert_render_matches`: the image-level cross-check (`glphong.verify`) as an assertion;
- a pytest plugin: ``pytest_plugins = ["glphong.testing"]`` in a ``conftest.py`` gives the fixtures
  `glphong_backend` (each backend; a missing one skips with its reason unless
  ``GLPHONG_REQUIRE_BACKENDS=egl,osmesa`` asks for it, then it fails), `glphong_context`,
  `glphong_renderer` (64 x 64) and `glphong_make_renderer` (a factory), all released at teardown.

Example
-------
::

    from glphong.testing import assert_twin_matches, evaluate

    def test_minnaert_twin(glphong_backend):
        assert_twin_matches(Minnaert(k=0.3, m=0.7), backend=glphong_backend)
"""
import atexit
import os
import threading

import numpy as np

from glphong.gpu.contexts import BACKENDS, BackendUnavailableError, create_context
from glphong.shaders.key import response_key
from glphong.materials.model import Material
from glphong.materials.table import uniform_as
from glphong.gpu.programs import ProgramCache
from glphong.checks.tolerances import BAND, EPS, response_band
from glphong.checks import reference as ref
from glphong.checks.verify import verify
from glphong.gpu.contexts import EGLDisplayTerminatedError
from glphong.gpu.renderer import Renderer

__all__ = ["evaluate", "direction_sets", "assert_twin_matches", "assert_render_matches", "TwinMismatch",
           "frame_around", "direction", "rotate_toward", "float32_units", "cosine_power_interval",
           "require_backend", "renderer_factory"]

_POOL = {}
_POOL_LOCK = threading.Lock()


def _pooled(backend):
    """A context and its program cache per backend, created on first use and kept until exit."""

    with _POOL_LOCK:
        entry = _POOL.get(backend)
        if entry is not None:
            try:
                with entry[2], entry[0]:
                    pass
            except EGLDisplayTerminatedError:  # its display was terminated (pyrender on EGL): start anew
                entry[0]._released = True
                entry = None
        if entry is None or entry[0].mgl is None:
            gl = create_context(backend)
            gl.detach()  # entered per call, from any thread
            entry = _POOL[backend] = (gl, ProgramCache(gl.mgl), threading.RLock())
        return entry


@atexit.register
def _release_pool():
    for gl, programs, _ in _POOL.values():
        try:
            with gl:
                programs.release()
            gl.release()
        except Exception:  # noqa: BLE001 - interpreter shutdown
            pass
    _POOL.clear()


def _rows(name, value, count, width):
    a = np.asarray(value, dtype=np.float64)
    if a.ndim == 1:
        a = np.broadcast_to(a, (count, a.shape[0]))
    if a.ndim != 2 or a.shape != (count, width):
        raise ValueError(f"{name} must have shape ({width},) or ({count}, {width}) (got {np.shape(value)})")
    return a


def _unit_rows(name, value, count):
    a = _rows(name, value, count, 3)
    length = np.linalg.norm(a, axis=1, keepdims=True)
    if not np.all(np.isfinite(a)) or np.any(length == 0):
        raise ValueError(f"{name} must be finite, non-zero 3-vectors")
    return a / length


def _inputs(material, wi, wo, normal, tangent, uv):
    """The float32 inputs both sides evaluate: unit directions (normalised in float64, rounded)."""
    if not isinstance(material, Material):
        raise TypeError(f"material must be a glphong material (got {type(material).__name__})")
    wi = np.asarray(wi, dtype=np.float64)
    if wi.ndim != 2 or wi.shape[1] != 3:
        raise ValueError(f"wi must have shape (N, 3) (got {wi.shape})")
    count = len(wi)
    f32 = lambda a: np.ascontiguousarray(a, dtype=np.float32)  # noqa: E731
    tangent = _rows("tangent", tangent, count, np.shape(tangent)[-1] if np.ndim(tangent) else 3)
    if tangent.shape[1] == 3:
        tangent = np.concatenate([tangent, np.ones((count, 1))], axis=1)
    elif tangent.shape[1] != 4:
        raise ValueError(f"tangent must have 3 or 4 components (got {tangent.shape[1]})")
    return (f32(_unit_rows("wi", wi, count)), f32(_unit_rows("wo", wo, count)), f32(_unit_rows("normal", normal, count)),
            f32(tangent), f32(_rows("uv", (0.0, 0.0) if uv is None else uv, count, 2)))


def _twin(material, key, uniforms, wi, wo, normal, tangent, uv):
    u = {k: uniform_as(v, np.float64) for k, v in uniforms.items()}
    f = ref.shading_frame(normal.astype(np.float64), tangent.astype(np.float64), uv.astype(np.float64), key)
    wi64, wo64 = wi.astype(np.float64), wo.astype(np.float64)
    n_dot_l = np.sum(f.n * wi64, axis=-1)
    out = np.zeros(wi.shape)
    gate = n_dot_l > 0
    if gate.any():
        with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
            out[gate] = ref.material_response(f.select(gate), wi64[gate], wo64[gate], n_dot_l[gate], key, u, material)
    return out, f, wi64, wo64, n_dot_l, u


def evaluate(material, wi, wo, normal=(0.0, 0.0, 1.0), tangent=(1.0, 0.0, 0.0), backend="auto", twin=False,
             uv=None, context=None):
    """A material's response ``f_r(wi, wo) (n.wi)`` [1/sr] at direction pairs, on the GPU or by its twin.

    The GLSL ``material_response()`` (the sum of the material's non-vanishing terms) runs once per
    row in a vertex program captured by transform feedback: no scene, no light, no rasterisation.
    Rows where ``n.wi <= 0`` give 0 (the light loop never evaluates them).

    Parameters
    ----------
    material : glphong.materials.Material
    wi, wo : (N, 3) array_like
        Directions toward the light and the viewer (normalised here in float64, then rounded to
        float32: both sides see the same float32 unit vectors).
    normal : (3,) or (N, 3) array_like
        Surface normal (normalised likewise).
    tangent : (3,), (4,), (N, 3) or (N, 4) array_like
        Raw tangent, handedness in the fourth component (default +1); orthonormalised against the
        normal as the shader does (only read by terms that need ``'tangent'``).
    backend : {'auto', 'egl', 'osmesa'}
        A context per backend is created on first use and kept for the process.
    twin : bool
        Return the numpy twin in float64 on the same float32 inputs instead of the GPU.
    uv : (2,) or (N, 2) array_like, optional
        Texture coordinates (for terms that need ``'uv'``).
    context : glphong.contexts.GLContext, optional
        Use this context instead of the pooled one.

    Returns
    -------
    (N, 3) ndarray
        float32 from the GPU, float64 from the twin.
    """
    wi, wo, normal, tangent, uv = _inputs(material, wi, wo, normal, tangent, uv)
    key = response_key(material)
    uniforms = material.uniform_values(key)
    if twin:
        return _twin(material, key, uniforms, wi, wo, normal, tangent, uv)[0]
    return _gpu(material, key, uniforms, wi, wo, normal, tangent, uv, backend, context)


def _gpu(material, key, uniforms, wi, wo, normal, tangent, uv, backend, context):
    import moderngl

    count = len(wi)
    if count == 0 or not key.terms:
        return np.zeros((count, 3), np.float32)
    if context is None:
        gl, programs, lock = _pooled(backend)
    else:
        gl, programs, lock = context, ProgramCache(context.mgl), threading.RLock()
    columns = {"in_wi": (wi, "3f"), "in_wo": (wo, "3f"), "in_normal": (normal, "3f")}
    if key.has_tangent:
        columns["in_tangent"] = (tangent, "4f")
    if key.has_uv:
        columns["in_uv"] = (uv, "2f")
    mgl = gl.mgl
    with lock, gl:  # one evaluation at a time on a pooled context, from any thread
        program = programs.get(key)
        program.bind(uniforms)
        buffers = {name: mgl.buffer(data.tobytes()) for name, (data, _) in columns.items()}
        result = mgl.buffer(reserve=count * 12)
        content = [(buffers[name], fmt, name) for name, (_, fmt) in columns.items() if name in program.gl_program]
        vao = mgl.vertex_array(program.gl_program, content)
        try:
            gl.bind_idle_framebuffer()
            vao.transform(result, mode=moderngl.POINTS, vertices=count)
            data = np.frombuffer(result.read(), dtype=np.float32).reshape(count, 3).copy()
            gl.check_error(f"evaluate of {material!r}")
        finally:
            for obj in (vao, result, *buffers.values()):
                obj.release()
            if context is not None:
                programs.release()
    return data


def _rotate_toward(v, axis, angle):
    """Rotate unit rows ``v`` by ``angle`` [rad] toward the unit rows ``axis`` (perpendicular to v)."""
    return np.cos(angle)[..., None] * v + np.sin(angle)[..., None] * axis


def direction_sets(n=2000, seed=0):
    """Direction pairs that exercise a BRDF: seeded random, and the edges where shaders break.

    With the normal +z: random ``wi``, ``wo`` over the upper hemisphere (and some ``wo`` below it),
    and the edge sets: grazing light (``n.l`` from 1e-2 down to 1e-7, and 0), grazing view, the mirror
    direction (the peak of Phong and Blinn lobes) and small offsets from it, ``l = v`` (the
    retro-reflection peak), ``l = -v`` mirrored at grazing, ``n.l`` just above 0, and light and view
    both so grazing (cosines 1e-30 to 1e-19) that ``(n.l)(n.v)`` is below FLT_MIN.

    Parameters
    ----------
    n : int
        Number of random pairs (the edge sets come on top, about 40 % more).
    seed : int

    Returns
    -------
    wi, wo : (M, 3) float64 ndarray
        Unit vectors.
    labels : (M,) ndarray of str
        Which set each pair belongs to.
    """
    rng = np.random.default_rng(seed)

    def hemisphere(count, lower=False):
        v = rng.normal(size=(count, 3))
        v[:, 2] = np.abs(v[:, 2]) * (-1.0 if lower else 1.0)
        return v / np.linalg.norm(v, axis=1, keepdims=True)

    def at(cos_theta, count):
        phi = rng.uniform(0, 2 * np.pi, count)
        s = np.sqrt(np.maximum(1.0 - cos_theta ** 2, 0.0))
        return np.stack([s * np.cos(phi), s * np.sin(phi), np.broadcast_to(cos_theta, (count,))], axis=1)

    def mirror(wi):
        return wi * np.array([-1.0, -1.0, 1.0])

    sets = []
    k = max(n // 20, 8)
    sets.append(("random", hemisphere(n), hemisphere(n)))
    sets.append(("view below the surface", hemisphere(k), hemisphere(k, lower=True)))
    for cosine in (1e-2, 1e-4, 1e-6, 1e-7, 0.0):
        sets.append((f"grazing light n.l={cosine:g}", at(np.full(k, cosine), k), hemisphere(k)))
    for cosine in (1e-2, 1e-4, 1e-6):
        sets.append((f"grazing view n.v={cosine:g}", hemisphere(k), at(np.full(k, cosine), k)))
    wi = hemisphere(4 * k)
    sets.append(("mirror direction (lobe peak)", wi, mirror(wi)))
    for offset in (1e-6, 1e-4, 1e-3, 1e-2, 1e-1):
        wi = hemisphere(k)
        peak = mirror(wi)
        axis = np.cross(peak, rng.normal(size=(k, 3)))
        axis /= np.linalg.norm(axis, axis=1, keepdims=True)
        sets.append((f"near the mirror direction, {offset:g} rad", wi, _rotate_toward(peak, axis, np.full(k, offset))))
    wi = hemisphere(2 * k)
    sets.append(("l = v (retro-reflection)", wi, wi.copy()))
    wi = at(np.full(k, 3e-6), k)
    sets.append(("l, v grazing and mirrored", wi, -wi * np.array([1.0, 1.0, -1.0])))
    wi = at(10.0 ** rng.uniform(-7, -3, k), k)
    sets.append(("n.l just above 0", wi, mirror(wi)))
    wi, wo = at(10.0 ** rng.uniform(-30, -19, k), k), at(10.0 ** rng.uniform(-30, -19, k), k)
    sets.append(("l and v grazing, (n.l)(n.v) below FLT_MIN", wi, wo))
    labels = np.concatenate([[label] * len(a) for label, a, _ in sets])
    return np.concatenate([a for _, a, _ in sets]), np.concatenate([b for _, _, b in sets]), labels


# --------------------------------------------------------------------------- closed-form helpers
def frame_around(n):
    """An orthonormal ``(t, b)`` completing the unit normal ``n`` (3,): ``(t, b, n)`` right-handed."""
    n = np.asarray(n, dtype=np.float64)
    helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    t = np.cross(n, helper)
    t /= np.linalg.norm(t)
    return t, np.cross(n, t)


def direction(n, theta, phi):
    """The unit vector at polar angle ``theta`` [rad] from the unit ``n`` and azimuth ``phi`` [rad] about it
    (measured from `frame_around`'s ``t``)."""
    t, b = frame_around(n)
    return np.sin(theta) * (np.cos(phi) * t + np.sin(phi) * b) + np.cos(theta) * np.asarray(n, dtype=np.float64)


def rotate_toward(a, target, angle):
    """Unit ``a`` (3,) rotated by ``angle`` [rad] toward ``target``, in their plane."""
    axis = target - np.dot(target, a) * a
    axis /= np.linalg.norm(axis)
    return np.cos(angle) * a + np.sin(angle) * axis


def float32_units(v):
    """Rows of ``v`` normalised in float64 and rounded to float32 (returned as float64): exactly the unit
    vectors `evaluate` hands to the GPU and to the twin."""
    v = np.asarray(v, dtype=np.float64)
    return np.asarray(v / np.linalg.norm(v, axis=-1, keepdims=True), dtype=np.float32).astype(np.float64)


def cosine_power_interval(cos_alpha, q, spread):
    """The interval of float32 values consistent with ``cos(alpha)^q``, for closed-form tests of lobes.

    ``alpha`` is the angle from the lobe's peak; float32 inputs and arithmetic leave it uncertain by
    ``+- spread`` [rad] (a few eps: the caller states it for its lobe); ``exp`` is good to
    ``(3 + 2|x|)`` ulp (GLSL 4.50, 4.7.1) and ``ln(1 - delta)`` to a few ulp relative, so the value is
    widened by ``eps (8 + 12 lambda)`` relative, ``lambda = -ln(value)``.  The caller accepts 0 below
    FLT_MIN (flush to zero).

    Returns
    -------
    low, high : ndarray
    """
    alpha = np.arccos(np.clip(cos_alpha, -1.0, 1.0))
    low = np.cos(np.minimum(alpha + spread, np.pi / 2)) ** q
    high = np.cos(np.maximum(alpha - spread, 0.0)) ** q
    lam = -np.log(np.maximum(low, 1e-300))
    return low * (1 - EPS * (8 + 12 * lam)), high * (1 + EPS * (8 + 12 * lam))


class TwinMismatch(AssertionError):
    """The GPU's response left the tolerance band around the twin (`assert_twin_matches`)."""


def _literal(a):
    return "[" + ", ".join(repr(float(x)) for x in np.asarray(a, dtype=np.float64).ravel()) + "]"


def assert_twin_matches(material, n=2000, seed=0, backend="auto", band=BAND, normal=(0.0, 0.0, 1.0),
                        tangent=(1.0, 0.0, 0.0), uv=None, context=None, worst=5):
    """Assert that a material's GLSL response lies in the tolerance band around its twin.

    Evaluates `evaluate` on the GPU and on the twin for `direction_sets` (seeded random pairs and
    the edge sets), and the band from each term's ``band`` method (`glphong.tolerances.response_band`).
    Where ``|n.l| <= D eps`` either outcome of the light gate is accepted; where ``n.l < -D eps``
    the GPU must return exactly 0.  NaN never passes; Inf only where the band's top is infinite.

    Parameters
    ----------
    material : glphong.materials.Material
    n : int
        Random pairs (edge sets come on top).
    seed : int
    backend : {'auto', 'egl', 'osmesa'}
    band : glphong.tolerances.BandConstants
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
    ok = (gpu >= low) & (gpu <= high) & ~np.isnan(gpu)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        rel = np.where(twin != 0, np.abs(gpu - twin) / np.abs(twin), np.where(gpu == twin, 0.0, np.inf))
        width = np.where(twin != 0, (high - low) / np.abs(twin), 0.0)
    # figures where the value is decided: the light gate certain and the band clear of 0 (a gate of
    # the model itself, such as Blinn's n.v > 0, uncertain there)
    decided = certain & (low > 0) & np.isfinite(rel) & np.isfinite(width)
    figures = {"pairs": len(wi), "nonzero": int(np.any(twin != 0, axis=1).sum()),
               "max_relative_error": float(np.max(rel[decided], initial=0.0)),
               "max_band_width": float(np.max(width[decided], initial=0.0))}
    bad = ~np.all(ok, axis=1)
    if not bad.any():
        return figures
    span = np.maximum(high - low, np.abs(twin) * EPS + np.finfo(np.float64).tiny)
    distance = np.where(ok, 0.0, np.nan_to_num(np.maximum(low - gpu, gpu - high) / span, nan=np.inf))
    order = np.argsort(-np.max(distance, axis=1))[:min(worst, int(bad.sum()))]
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
        """A `glphong.contexts.GLContext` on each backend, released at teardown."""
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
