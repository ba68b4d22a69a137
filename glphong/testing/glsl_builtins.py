"""GLSL's built-in functions in numpy, for the twins of shader unit tests, with the domains where GLSL leaves them
undefined (docs/design.md section 14; the GLSL 4.60 specification, chapter 8).

A twin written with these functions (``from glphong.testing import glsl``) computes in float64 what the GLSL
built-in computes, and, inside `record_undefined`, marks the rows where the specification leaves the result
undefined (or implementation-defined): `glphong.testing.assert_glsl_matches` leaves those rows out of the
comparison and reports them, by built-in, instead of comparing noise.  At such an element the function returns
NaN (the twin then cannot pass a comparison by accident outside `record_undefined`).

=================================== ==========================================================================
built-in                            undefined where (GLSL 4.60, section 8)
=================================== ==========================================================================
``pow(x, y)``                       ``x < 0``, or ``x == 0`` and ``y <= 0``
``log(x)``, ``log2(x)``             ``x <= 0``
``sqrt(x)``                         ``x < 0``
``inversesqrt(x)``                  ``x <= 0``
``asin(x)``, ``acos(x)``            ``|x| > 1``
``atan(y, x)``                      ``x == 0`` and ``y == 0``
``acosh(x)``                        ``x < 1``
``atanh(x)``                        ``|x| >= 1``
``mod(x, y)``                       ``y == 0`` (``x - y floor(x / y)`` divides by zero)
``clamp(x, lo, hi)``                ``lo > hi``
``smoothstep(e0, e1, x)``           ``e0 >= e1``
``normalize(x)``                    ``length(x) == 0`` (a division by zero)
``round(x)``                        a fraction of exactly 1/2 (the direction is the implementation's)
``inverse(m)``                      ``m`` singular (determinant 0)
=================================== ==========================================================================

The others (``abs``, ``sign``, ``floor``, ``ceil``, ``trunc``, ``fract``, ``min``, ``max``, ``mix``, ``step``,
``exp``, ``exp2``, ``sin``, ... ``dot``, ``cross``, ``length``, ``distance``, ``reflect``, ``refract``,
``faceforward``, ``roundEven``, ``transpose``, ``determinant``) are defined everywhere they are finite.
Vectors are numpy arrays whose last axis holds the components, one row per invocation.
"""
import contextlib
import contextvars
import functools

import numpy as np

__all__ = ["record_undefined", "UndefinedRecord", "pow", "log", "log2", "sqrt", "inversesqrt", "asin", "acos",
           "atan", "acosh", "atanh", "mod", "clamp", "smoothstep", "normalize", "round", "inverse", "exp", "exp2",
           "sin", "cos", "tan", "sinh", "cosh", "tanh", "asinh", "radians", "degrees", "abs", "sign", "floor",
           "ceil", "trunc", "fract", "min", "max", "mix", "step", "roundEven", "dot", "cross", "length",
           "distance", "reflect", "refract", "faceforward", "transpose", "determinant", "UNDEFINED"]

#: each built-in with an undefined domain, and the domain in words
UNDEFINED = {"pow": "x < 0, or x == 0 and y <= 0", "log": "x <= 0", "log2": "x <= 0", "sqrt": "x < 0",
             "inversesqrt": "x <= 0", "asin": "|x| > 1", "acos": "|x| > 1", "atan": "x == 0 and y == 0",
             "acosh": "x < 1", "atanh": "|x| >= 1", "mod": "y == 0", "clamp": "minVal > maxVal",
             "smoothstep": "edge0 >= edge1", "normalize": "length(x) == 0",
             "round": "a fraction of exactly 1/2 (implementation-defined direction)", "inverse": "m singular"}

_RECORD = contextvars.ContextVar("glphong_glsl_undefined", default=None)


class UndefinedRecord:
    """The rows a twin met GLSL's undefined domains on (`record_undefined`).

    Attributes
    ----------
    rows : (N,) bool ndarray
        Rows where any built-in was undefined.
    by_builtin : dict of str to (N,) bool ndarray
    """

    def __init__(self, count):
        self.rows = np.zeros(count, dtype=bool)
        self.by_builtin = {}

    def mark(self, name, mask):
        mask = np.asarray(mask, dtype=bool)
        if mask.ndim == 0:
            mask = np.full(len(self.rows), bool(mask))
        elif mask.shape[0] != len(self.rows):
            if mask.size == 1:
                mask = np.full(len(self.rows), bool(mask.ravel()[0]))
            else:  # a value that is not one row per invocation (a constant the twin computes): no rows
                return
        else:
            mask = mask.reshape(len(self.rows), -1).any(axis=1)
        self.rows |= mask
        self.by_builtin[name] = self.by_builtin.get(name, np.zeros_like(self.rows)) | mask

    def counts(self):
        """``{built-in: rows}`` of the built-ins that were undefined somewhere."""
        return {name: int(mask.sum()) for name, mask in self.by_builtin.items() if mask.any()}


@contextlib.contextmanager
def record_undefined(count):
    """Within the block, the built-ins of this module mark the rows (of ``count``) where GLSL leaves them
    undefined; yields the `UndefinedRecord`."""
    record = UndefinedRecord(count)
    token = _RECORD.set(record)
    try:
        yield record
    finally:
        _RECORD.reset(token)


def _undefined(name, mask, value):
    """``value`` with NaN where ``mask``; the rows recorded."""
    record = _RECORD.get()
    mask = np.asarray(mask, dtype=bool)
    if record is not None and mask.any():
        record.mark(name, mask)
    value = np.asarray(value, dtype=np.float64)
    if mask.any():
        value = np.where(np.broadcast_to(mask, np.broadcast_shapes(mask.shape, value.shape)), np.nan, value)
    return value


def _f(x):
    return np.asarray(x, dtype=np.float64)


def _quiet(fn):
    @functools.wraps(fn)
    def wrapped(*args, **kwargs):
        with np.errstate(all="ignore"):
            return fn(*args, **kwargs)
    return wrapped


# ---- with undefined domains
@_quiet
def pow(x, y):  # noqa: A001 - GLSL's name
    """``x^y``."""
    x, y = _f(x), _f(y)
    return _undefined("pow", (x < 0) | ((x == 0) & (y <= 0)), np.power(np.abs(x), y))


@_quiet
def log(x):
    """Natural logarithm."""
    x = _f(x)
    return _undefined("log", x <= 0, np.log(x))


@_quiet
def log2(x):
    x = _f(x)
    return _undefined("log2", x <= 0, np.log2(x))


@_quiet
def sqrt(x):
    x = _f(x)
    return _undefined("sqrt", x < 0, np.sqrt(x))


@_quiet
def inversesqrt(x):
    x = _f(x)
    return _undefined("inversesqrt", x <= 0, 1.0 / np.sqrt(x))


@_quiet
def asin(x):
    x = _f(x)
    return _undefined("asin", np.abs(x) > 1, np.arcsin(x))


@_quiet
def acos(x):
    x = _f(x)
    return _undefined("acos", np.abs(x) > 1, np.arccos(x))


@_quiet
def atan(y, x=None):
    """``atan(y_over_x)`` with one argument; ``atan(y, x)`` in ``[-pi, pi]`` with two."""
    if x is None:
        return np.arctan(_f(y))
    y, x = _f(y), _f(x)
    return _undefined("atan", (x == 0) & (y == 0), np.arctan2(y, x))


@_quiet
def acosh(x):
    x = _f(x)
    return _undefined("acosh", x < 1, np.arccosh(x))


@_quiet
def atanh(x):
    x = _f(x)
    return _undefined("atanh", np.abs(x) >= 1, np.arctanh(x))


@_quiet
def mod(x, y):
    """``x - y floor(x / y)``."""
    x, y = _f(x), _f(y)
    return _undefined("mod", y == 0, x - y * np.floor(x / y))


@_quiet
def clamp(x, min_val, max_val):
    x, lo, hi = _f(x), _f(min_val), _f(max_val)
    return _undefined("clamp", lo > hi, np.minimum(np.maximum(x, lo), hi))


@_quiet
def smoothstep(edge0, edge1, x):
    e0, e1, x = _f(edge0), _f(edge1), _f(x)
    t = np.clip((x - e0) / (e1 - e0), 0.0, 1.0)
    return _undefined("smoothstep", e0 >= e1, t * t * (3.0 - 2.0 * t))


@_quiet
def normalize(x):
    """``x / length(x)`` along the last axis."""
    x = _f(x)
    n = np.linalg.norm(x, axis=-1, keepdims=True)
    return _undefined("normalize", n == 0, x / n)


@_quiet
def round(x):  # noqa: A001 - GLSL's name
    """Nearest whole number; a half is implementation-defined (marked)."""
    x = _f(x)
    return _undefined("round", np.abs(x - np.trunc(x)) == 0.5, np.round(x))


@_quiet
def inverse(m):
    """Inverse of each (..., K, K) matrix."""
    m = _f(m)
    singular = np.linalg.det(m) == 0
    safe = np.where(singular[..., None, None], np.eye(m.shape[-1]), m)
    return _undefined("inverse", singular[..., None, None], np.linalg.inv(safe))


# ---- defined everywhere they are finite
@_quiet
def exp(x):
    return np.exp(_f(x))


@_quiet
def exp2(x):
    return np.exp2(_f(x))


@_quiet
def sin(x):
    return np.sin(_f(x))


@_quiet
def cos(x):
    return np.cos(_f(x))


@_quiet
def tan(x):
    return np.tan(_f(x))


@_quiet
def sinh(x):
    return np.sinh(_f(x))


@_quiet
def cosh(x):
    return np.cosh(_f(x))


@_quiet
def tanh(x):
    return np.tanh(_f(x))


@_quiet
def asinh(x):
    return np.arcsinh(_f(x))


def radians(degrees_):
    return _f(degrees_) * (np.pi / 180.0)


def degrees(radians_):
    return _f(radians_) * (180.0 / np.pi)


def abs(x):  # noqa: A001
    return np.abs(_f(x))


def sign(x):
    return np.sign(_f(x))


def floor(x):
    return np.floor(_f(x))


def ceil(x):
    return np.ceil(_f(x))


def trunc(x):
    return np.trunc(_f(x))


def roundEven(x):  # noqa: N802 - GLSL's name
    return np.round(_f(x))


def fract(x):
    x = _f(x)
    return x - np.floor(x)


def min(x, y):  # noqa: A001
    return np.minimum(_f(x), _f(y))


def max(x, y):  # noqa: A001
    return np.maximum(_f(x), _f(y))


def mix(x, y, a):
    x, y, a = _f(x), _f(y), _f(a)
    return x * (1.0 - a) + y * a


def step(edge, x):
    return np.where(_f(x) < _f(edge), 0.0, 1.0)


def dot(x, y):
    return np.sum(_f(x) * _f(y), axis=-1)


def cross(x, y):
    return np.cross(_f(x), _f(y))


def length(x):
    return np.linalg.norm(_f(x), axis=-1)


def distance(p0, p1):
    return length(_f(p0) - _f(p1))


def reflect(i, n):
    """``I - 2 dot(N, I) N`` (N unit, as GLSL requires for the expected result)."""
    i, n = _f(i), _f(n)
    return i - 2.0 * dot(n, i)[..., None] * n


@_quiet
def refract(i, n, eta):
    """GLSL's refract: zero where ``k = 1 - eta^2 (1 - dot(N, I)^2) < 0``."""
    i, n, eta = _f(i), _f(n), _f(eta)
    d = dot(n, i)
    k = 1.0 - eta * eta * (1.0 - d * d)
    out = (eta[..., None] if np.ndim(eta) else eta) * i - ((eta * d + np.sqrt(np.maximum(k, 0.0)))[..., None]) * n
    return np.where((k < 0)[..., None], 0.0, out)


def faceforward(n, i, nref):
    n = _f(n)
    return np.where((dot(nref, i) < 0)[..., None], n, -n)


def transpose(m):
    return np.swapaxes(_f(m), -1, -2)


def determinant(m):
    return np.linalg.det(_f(m))
