"""A GLSL function against its numpy twin, with tolerances a numerical person trusts (docs/design.md section 14).

`assert_glsl_matches` runs a `glphong.testing.GlslFunction` and its twin on the same inputs (the
float32 values the GPU receives, given to the twin exactly, as float64) and compares every result:

- floats within ``ulps`` units in the last place of float32 at the twin's value, ``atol``, ``rtol``, or the band
  a function gives (the largest of those given); an equal value always passes (``inf == inf``), NaN passes only
  against NaN;
- integers and booleans exactly (integers within ``atol`` where given);
- GLSL lets an implementation flush subnormals to zero, in its inputs and results: a result that matches the twin
  evaluated on the inputs with their subnormals flushed, or is zero where the twin's value is subnormal, passes
  and is counted as ``flushed``;
- rows where the twin met a built-in's undefined domain (`glphong.testing.glsl_builtins.record_undefined`) are
  left out and reported by built-in (``undefined='fail'`` makes them a failure).

A failure raises `GlslMismatch`, naming the worst rows with their inputs, the GPU's value, the twin's and the
allowed band, and a paste-ready reproduction.
"""
import warnings

import numpy as np

from glphong.testing.glsl_builtins import UNDEFINED, record_undefined
from glphong.testing.glsl_types import decode, glsl_type

__all__ = ["GlslMismatch", "GlslUndefinedWarning", "assert_glsl_matches", "ulp32", "ulps_between", "FLT_MIN"]

FLT_MIN = float(np.finfo(np.float32).tiny)
_FLT_MAX = float(np.finfo(np.float32).max)
_FLT_TRUE_MIN = 2.0 ** -149


class GlslMismatch(AssertionError):
    """A GLSL function's results left the allowed band around its twin's (`assert_glsl_matches`)."""


class GlslUndefinedWarning(UserWarning):
    """Rows left out of a comparison because GLSL leaves the twin's built-ins undefined there."""


def ulp32(x):
    """The spacing of float32 at ``|x|`` (float64 array): ``2^(e - 23)`` for a normal ``x`` in ``[2^e, 2^(e+1))``,
    ``2^-149`` below ``FLT_MIN``, inf beyond FLT_MAX."""
    a = np.abs(np.asarray(x, dtype=np.float64))
    with np.errstate(over="ignore", invalid="ignore"):
        spacing = np.spacing(a.astype(np.float32)).astype(np.float64)
    return np.where(a > _FLT_MAX, np.inf, np.where(a < FLT_MIN, _FLT_TRUE_MIN, spacing))


def ulps_between(gpu, twin):
    """``|gpu - twin|`` in float32 units in the last place at the twin's value (0 where equal, inf where one is
    not finite and they differ)."""
    g, t = np.asarray(gpu, dtype=np.float64), np.asarray(twin, dtype=np.float64)
    with np.errstate(invalid="ignore", over="ignore"):
        out = np.abs(g - t) / ulp32(t)
    return np.where((g == t) | (np.isnan(g) & np.isnan(t)), 0.0, np.nan_to_num(out, nan=np.inf))


def _twin_inputs(fn, inputs):
    """``(exact, flushed, count)``: the values the GPU receives, as float64 (floats), int64 or bool, one row per
    invocation; and the same with subnormal floats flushed to (signed) zero."""
    params = fn.signature.inputs
    names = [p.name for p in params]
    if sorted(inputs) != sorted(names):
        raise TypeError(f"{fn.signature} takes inputs {names} (got {sorted(inputs)})")
    encoded, count = fn._rows((), dict(inputs))
    exact, flushed = {}, {}
    for p in params:
        t = glsl_type(p.type)
        value = decode(t, encoded[p.name])
        if t.base == "float":
            exact[p.name] = value.astype(np.float64)
            flushed[p.name] = np.where(np.abs(exact[p.name]) < FLT_MIN, np.copysign(0.0, exact[p.name]), exact[p.name])
        else:
            exact[p.name] = flushed[p.name] = value.astype(np.int64) if t.base != "bool" else value
    return exact, flushed, count


def _outputs(fn, value, where):
    """The twin's results as ``{name: array}`` in the order of ``fn.signature.outputs``."""
    names = [name for name, _ in fn.signature.outputs]
    if isinstance(value, dict):
        if sorted(value) != sorted(names):
            raise TypeError(f"{where} must return {names} (got {sorted(value)})")
        return {n: value[n] for n in names}
    if len(names) == 1:
        return {names[0]: value}
    if isinstance(value, (tuple, list)) and len(value) == len(names):
        return dict(zip(names, value))
    raise TypeError(f"{where} must return a dict of {names} or a tuple in that order")


def _literal(value):
    array = np.asarray(value)
    if array.dtype.kind == "f":
        return np.array2string(array.astype(np.float64), separator=", ", floatmode="unique", threshold=1 << 30,
                               max_line_width=110)
    return np.array2string(array, separator=", ", threshold=1 << 30, max_line_width=110)


def assert_glsl_matches(fn, twin, inputs, ulps=None, atol=None, rtol=None, band=None, uniforms=None, worst=5,
                        undefined="skip", flush_subnormals=True):
    """Assert that GLSL function ``fn`` agrees with its numpy ``twin`` on ``inputs``.

    Parameters
    ----------
    fn : glphong.testing.GlslFunction
    twin : callable
        ``twin(**inputs)`` on float64 (floats), int64 or bool arrays, one row per invocation: the result as an
        array, or, where ``fn`` has ``out``/``inout`` parameters, a dict by name (``'return'`` for the result) or a
        tuple in that order.  Write it with `glphong.testing.glsl`'s built-ins to have GLSL's undefined domains
        marked.
    inputs : dict of str to array_like
        One array per ``in``/``inout`` parameter (scalars and one-row values broadcast).
    ulps, atol, rtol : float, optional
        Allowed float error: units in the last place of float32 at the twin's value, absolute, relative to the
        twin's value; the largest applies.  At least one of these or ``band`` must be given.
    band : callable, optional
        ``band(name, twin_value, inputs) -> (low, high)``: the allowed interval of output ``name`` (arrays that
        broadcast against it), for a model that has its own error bound (glphong's materials have theirs).
    uniforms : dict, optional
        Uniform values, set before the call.
    worst : int
        Rows listed on failure.
    undefined : {'skip', 'fail', 'compare'}
        Rows where the twin met a GLSL built-in's undefined domain: left out (a `GlslUndefinedWarning` names them),
        a failure, or compared as any other row.
    flush_subnormals : bool
        Accept the subnormal flushing GLSL allows (counted in the result).

    Returns
    -------
    dict
        ``rows``, ``compared`` (rows compared), ``undefined`` (``{built-in: rows}``), ``flushed`` (values accepted
        as flushed subnormals), and per float output ``max_ulps`` and ``max_abs`` (dicts by output name).

    Raises
    ------
    GlslMismatch
        With the worst rows and a reproduction.
    """
    if ulps is None and atol is None and rtol is None and band is None:
        raise TypeError("assert_glsl_matches needs a tolerance: ulps=, atol=, rtol= or band=")
    if undefined not in ("skip", "fail", "compare"):
        raise ValueError(f"undefined must be 'skip', 'fail' or 'compare' (got {undefined!r})")
    exact, flushed_inputs, count = _twin_inputs(fn, inputs)
    gpu = _outputs(fn, fn(**inputs, uniforms=uniforms), "the GLSL function")
    twin_name = getattr(twin, "__qualname__", repr(twin))
    with record_undefined(count) as record:
        expected = _outputs(fn, twin(**exact), f"the twin {twin_name}")
    alternative = None
    if flush_subnormals and any(np.any(flushed_inputs[k] != exact[k]) for k in exact if exact[k].dtype.kind == "f"):
        with record_undefined(count):
            alternative = _outputs(fn, twin(**flushed_inputs), f"the twin {twin_name}")
    skip = record.rows if undefined != "compare" else np.zeros(count, bool)
    counts = record.counts()
    if counts and undefined == "fail":
        raise GlslMismatch(f"{fn.signature}: the twin met GLSL's undefined domains on {int(record.rows.sum())} of "
                           f"{count} rows ({_undefined_words(counts)}); choose inputs inside the domains")
    if counts and undefined == "skip":
        warnings.warn(f"{fn.signature}: {int(record.rows.sum())} of {count} rows left out: GLSL leaves "
                      f"{_undefined_words(counts)} undefined", GlslUndefinedWarning, stacklevel=2)
    summary = {"rows": count, "compared": int(count - skip.sum()), "undefined": counts, "flushed": 0,
               "max_ulps": {}, "max_abs": {}}
    failures = []
    for name, type_name in fn.signature.outputs:
        t = glsl_type(type_name)
        g = np.asarray(gpu[name])
        w = np.broadcast_to(np.asarray(expected[name], dtype=np.float64 if t.base == "float" else None), g.shape)
        if t.base == "float":
            ok, low, high, flushed = _float_ok(g, w, name, exact, ulps, atol, rtol, band, alternative,
                                               flush_subnormals)
            summary["flushed"] += int((flushed & ~skip.reshape((-1,) + (1,) * (g.ndim - 1))).sum())
            rows_ok = ok.reshape(count, -1).all(axis=1) | skip
            compared = ~skip
            error = ulps_between(g, w).reshape(count, -1)
            finite = np.isfinite(error) & compared[:, None]
            summary["max_ulps"][name] = float(error[finite].max(initial=0.0))
            summary["max_abs"][name] = float(np.abs(g.astype(np.float64) - w).reshape(count, -1)[finite].max(initial=0.0))
        else:
            tolerance = atol if (atol is not None and t.base != "bool") else 0
            diff = np.abs(g.astype(np.int64) - w.astype(np.int64)) if t.base != "bool" else (g != w).astype(int)
            rows_ok = (diff <= tolerance).reshape(count, -1).all(axis=1) | skip
            low = high = w
        if not rows_ok.all():
            failures.append((name, t, g, w, low, high, ~rows_ok))
    if failures:
        raise GlslMismatch(_report(fn, twin_name, failures, exact, inputs, count, skip, worst))
    return summary


def _float_ok(g, w, name, exact, ulps, atol, rtol, band, alternative, flush_subnormals):
    g64 = g.astype(np.float64)
    if band is not None:
        low, high = band(name, w, exact)
        low, high = np.broadcast_to(np.asarray(low, np.float64), w.shape), np.broadcast_to(np.asarray(high, np.float64), w.shape)
    else:
        allowed = np.zeros_like(w)
        with np.errstate(invalid="ignore", over="ignore"):
            if ulps is not None:
                allowed = np.maximum(allowed, ulps * ulp32(w))
            if atol is not None:
                allowed = np.maximum(allowed, atol)
            if rtol is not None:
                allowed = np.maximum(allowed, rtol * np.abs(w))
            low = np.where(np.isinf(w), w, w - allowed)
            high = np.where(np.isinf(w), w, w + allowed)
    both_nan = np.isnan(g64) & np.isnan(w)
    with np.errstate(invalid="ignore"):
        ok = ((g64 >= low) & (g64 <= high)) | (g64 == w) | both_nan
    flushed = np.zeros_like(ok)
    if flush_subnormals:
        flushed |= ~ok & (g64 == 0) & (np.abs(w) < FLT_MIN)
        if alternative is not None:
            a = np.broadcast_to(np.asarray(alternative[name], np.float64), w.shape)
            with np.errstate(invalid="ignore"):
                width = (high - low) / 2
                flushed |= ~ok & ((np.abs(g64 - a) <= width) | (g64 == a) | (np.isnan(g64) & np.isnan(a)))
    return ok | flushed, low, high, flushed


def _undefined_words(counts):
    return ", ".join(f"{name} where {UNDEFINED.get(name, '?')} ({rows} rows)" for name, rows in counts.items())


def _report(fn, twin_name, failures, exact, inputs, count, skip, worst):
    lines = [f"{fn.signature} disagrees with its twin {twin_name} on "
             + "; ".join(f"{name}: {int(bad.sum())} of {int(count - skip.sum())} rows" for name, _, _, _, _, _, bad in failures)]
    rows = set()
    for name, t, g, w, low, high, bad in failures:
        g64 = np.asarray(g, dtype=np.float64).reshape(count, -1)
        w64 = np.asarray(w, dtype=np.float64).reshape(count, -1)
        lo, hi = np.asarray(low, np.float64).reshape(count, -1), np.asarray(high, np.float64).reshape(count, -1)
        with np.errstate(invalid="ignore", over="ignore"):
            span = np.maximum(hi - lo, np.abs(w64) * 2.0 ** -23 + _FLT_TRUE_MIN)
            excess = np.nan_to_num(np.maximum(lo - g64, g64 - hi) / span, nan=np.inf).max(axis=1)
        order = [i for i in np.argsort(-np.where(bad, excess, -1.0)) if bad[i]][:worst]
        lines.append(f"worst rows of {name} ({t.name}):")
        for i in order:
            rows.add(int(i))
            args = ", ".join(f"{k}={_literal(v[i])}" for k, v in exact.items())
            one = (lambda a: a[0]) if t.components == 1 else (lambda a: a)
            band = "" if t.base != "float" else f"; allowed [{_literal(one(lo[i]))}, {_literal(one(hi[i]))}]; " \
                f"{_literal(one(ulps_between(g64[i], w64[i])))} ulps"
            lines.append(f"  row {i}: {args}\n    GPU {_literal(np.asarray(g)[i])}, twin {_literal(np.asarray(w)[i])}{band}")
    chosen = sorted(rows)
    source = repr(fn._origin) if fn._origin else "SOURCE"
    lines += ["reproduce (these rows):", "    import numpy as np", "    from glphong.testing import glsl_function",
              f"    fn = glsl_function({source}, {fn.signature.name!r}"
              + (f", stage={fn.stage!r}" if fn.stage != "vertex" else "") + ")"]
    for p in fn.signature.inputs:
        t = glsl_type(p.type)
        value = exact[p.name][chosen]
        dtype = {"float": "np.float32", "int": "np.int32", "uint": "np.uint32", "bool": "bool"}[t.base]
        lines.append(f"    {p.name} = np.array({_literal(value)}, {dtype})")
    call = ", ".join(f"{p.name}={p.name}" for p in fn.signature.inputs)
    lines += [f"    print(fn({call}))", f"    print({twin_name}({call}))"]
    return "\n".join(lines)
