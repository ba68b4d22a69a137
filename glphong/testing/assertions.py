"""The toolkit's assertions: a material's GLSL response (`assert_twin_matches`), a light's (`assert_light_matches`,
at `light_points`) and a whole render (`assert_render_matches`) against the float64 twin, under the tolerance band,
each failure listing the worst inputs, paste-ready (`TwinMismatch`).
"""
import numpy as np

from glphong.checks import reference as ref
from glphong.checks.points import shade_points
from glphong.checks.stability import case_inputs
from glphong.checks.tolerances import BAND, EPS, point_band, response_band
from glphong.checks.verify import verify
from glphong.definitions.cases import Case
from glphong.gpu.contexts import create_context
from glphong.gpu.programs import ProgramCache
from glphong.materials.lambert import Lambert
from glphong.shaders.builders import response_key
from glphong.evaluation.directions import direction_sets
from glphong.evaluation.response import gpu_response, response_inputs, twin_response

__all__ = ["assert_twin_matches", "assert_light_matches", "assert_render_matches", "light_points", "TwinMismatch"]


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
    wi, wo, normal, tangent, uv = response_inputs(material, wi_all, wo_all, normal, tangent, uv)
    key = response_key(material)
    uniforms = material.uniform_values(key)
    gpu = gpu_response(material, key, uniforms, wi, wo, normal, tangent, uv, backend, context).astype(np.float64)
    twin, f, wi64, wo64, n_dot_l, u = twin_response(material, key, uniforms, wi, wo, normal, tangent, uv)
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
    `glphong.checks.points.shade_points`), judged in the tolerance band (the kind's ``band``).  Points the twin
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
