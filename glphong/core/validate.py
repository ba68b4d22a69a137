"""Validation of user parameters at the API boundary.

Every public constructor funnels its arguments through these helpers, so a bad
value fails early with a message that names the parameter and the valid range,
and nothing reaches the GPU that the shaders are not specified for.
"""
import numbers

import numpy as np

FLT_MAX = float(np.finfo(np.float32).max)
FLT_MIN = float(np.finfo(np.float32).tiny)


def float32_uniform(value):
    """``value`` as the float32 a shader receives: rounded, with subnormal values flushed to 0.

    GPUs flush float32 subnormals (llvmpipe does), so a uniform of 1e-40 acts as 0; flushing here,
    where uniforms are made, gives the twin the very values the GPU computes with.  Values beyond
    FLT_MAX (a valid but extreme camera matrix entry) become +-Inf without a warning.
    """
    with np.errstate(over="ignore"):
        a = np.asarray(value, dtype=np.float32)
    return np.where(np.abs(a) < FLT_MIN, np.float32(0.0), a).astype(np.float32)


def _fmt(value):
    return np.array2string(np.asarray(value), precision=6, threshold=12) if np.ndim(value) else repr(value)


def real_array(name, value, expected):
    """``value`` as a float64 array, or TypeError if it is not made of real numbers.

    Strings, bools, complex numbers, None and ragged nestings are rejected (numpy
    would otherwise parse ``"1"`` as 1.0, take ``True`` as 1.0 and drop imaginary parts);
    the message names the parameter and what was ``expected``.
    """
    try:
        raw = np.asarray(value)
    except (TypeError, ValueError):
        raw = None
    if raw is not None and not isinstance(value, np.ndarray) and raw.dtype.kind in "iuf" and raw.size:
        # numpy turns (True, 0, 0) into integers: look at the elements themselves
        try:
            elements = np.asarray(value, dtype=object).ravel()
        except (TypeError, ValueError):
            elements = ()
        if any(isinstance(x, (bool, np.bool_)) for x in elements):
            raise TypeError(f"{name} must be {expected}, not booleans (got {value!r})")
    ok = raw is not None and (raw.dtype.kind in "iuf" or (raw.dtype.kind == "O" and all(
        isinstance(x, numbers.Real) and not isinstance(x, (bool, np.bool_)) for x in raw.flat)))
    if not ok:
        raise TypeError(f"{name} must be {expected} (got {value!r})")
    try:
        return raw.astype(np.float64)
    except OverflowError:  # Python ints beyond float64: keep their sign, fail the range check
        return np.array([x if abs(x) <= FLT_MAX else (np.inf if x > 0 else -np.inf) for x in raw.flat],
                        dtype=np.float64).reshape(raw.shape)


def scalar(name, value, low=0.0, high=FLT_MAX, low_inclusive=True, high_inclusive=True):
    """A finite real scalar in ``[low, high]`` as float; ``low_inclusive`` / ``high_inclusive``
    False make that end of the interval open."""
    interval = f"{'[' if low_inclusive else '('}{low:g}, {high:g}{']' if high_inclusive else ')'}"
    a = real_array(name, value, f"a real number in {interval}")
    if a.ndim != 0:
        raise ValueError(f"{name} must be a scalar in {interval} (got shape {a.shape})")
    x = float(a) + 0.0  # + 0.0 turns -0.0 into 0.0
    ok = (np.isfinite(x) and (x >= low if low_inclusive else x > low)
          and (x <= high if high_inclusive else x < high))
    if not ok:
        raise ValueError(f"{name} must be finite and in {interval} (got {x!r})")
    return x


def rgb(name, value, low=0.0, high=FLT_MAX, low_inclusive=True, high_inclusive=True):
    """An RGB triple from a scalar or a length-3 sequence, each finite and in ``[low, high]``
    (``low_inclusive`` / ``high_inclusive`` False make that end open).

    Returns
    -------
    tuple of 3 float
    """
    interval = f"{'[' if low_inclusive else '('}{low:g}, {high:g}{']' if high_inclusive else ')'}"
    a = real_array(name, value, f"a real number or an RGB triple of real numbers in {interval}")
    if a.ndim == 0:
        a = np.repeat(a, 3)
    if a.shape != (3,):
        raise ValueError(f"{name} must be a scalar or have shape (3,), each channel in {interval} "
                         f"(got shape {a.shape})")
    ok = np.all(np.isfinite(a)) and np.all(a >= low if low_inclusive else a > low) and \
        np.all(a <= high if high_inclusive else a < high)
    if not ok:
        raise ValueError(f"{name} must be finite and in {interval} per channel (got {_fmt(a)})")
    return tuple(float(c) + 0.0 for c in a)


def vec3(name, value, nonzero=False):
    """A finite 3-vector with every component's magnitude at most FLT_MAX, as a tuple of float."""
    a = real_array(name, value, f"a sequence of 3 real numbers with |components| <= {FLT_MAX:g}")
    if a.shape != (3,):
        raise ValueError(f"{name} must have shape (3,) (got shape {a.shape})")
    if not (np.all(np.isfinite(a)) and np.all(np.abs(a) <= FLT_MAX)):
        raise ValueError(f"{name} must be finite with |components| <= {FLT_MAX:g} (got {_fmt(a)})")
    if nonzero and not np.any(a):
        raise ValueError(f"{name} must not be the zero vector")
    return tuple(float(c) + 0.0 for c in a)


def unit_vec3(name, value):
    """A non-zero finite 3-vector (`vec3`) normalised to unit length, as a tuple of float: scaled by its
    largest component first, so that no square overflows or underflows."""
    d = np.asarray(vec3(name, value, nonzero=True))
    d = d / np.max(np.abs(d))
    return tuple(float(c) for c in d / np.linalg.norm(d))


def _matrix4(name, value):
    """A finite (4, 4) float64 array with entries representable in float32 and last row (0, 0, 0, 1)."""
    a = real_array(name, value, "a 4x4 array of real numbers")
    if a.shape != (4, 4):
        raise ValueError(f"{name} must have shape (4, 4) (got shape {a.shape})")
    if not (np.all(np.isfinite(a)) and np.all(np.abs(a) <= FLT_MAX)):
        raise ValueError(f"{name} must be finite with |entries| <= {FLT_MAX:g} (got {_fmt(a)})")
    if not np.array_equal(a[3], (0.0, 0.0, 0.0, 1.0)):
        raise ValueError(f"{name} must have last row (0, 0, 0, 1) (got {_fmt(a[3])})")
    return a


def rigid_pose(name, value, tol=1e-6):
    """A 4x4 rigid transform (orthonormal rotation with det +1, finite translation), as float64 array."""
    a = _matrix4(name, value)
    r = a[:3, :3]
    if not (np.allclose(r.T @ r, np.eye(3), atol=tol) and np.linalg.det(r) > 0):
        raise ValueError(f"{name} must have an orthonormal rotation block with determinant +1 (tolerance {tol:g})")
    a.setflags(write=False)
    return a


def affine_transform(name, value):
    """A 4x4 invertible affine transform (last row (0, 0, 0, 1)), as float64 array.

    The 3x3 block's inverse (which gives the normal matrix) must be finite in float32 too.
    """
    a = _matrix4(name, value)
    m = a[:3, :3]
    det = np.linalg.det(m)
    inverse = np.linalg.inv(m) if abs(det) > 0 and np.isfinite(det) else None
    if inverse is None or not (np.all(np.isfinite(inverse)) and np.all(np.abs(inverse) <= FLT_MAX)):
        raise ValueError(f"{name} must be invertible: its 3x3 block is singular or its inverse "
                         f"has entries above {FLT_MAX:g} (float32 overflow)")
    a.setflags(write=False)
    return a


def choice(name, value, options):
    """One of ``options``."""
    if value not in options:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, options))} (got {value!r})")
    return value


def positive_int(name, value, low=1, high=2**31 - 1):
    """An integer in ``[low, high]``."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{name} must be an integer in [{low}, {high}] (got {value!r})")
    if not low <= int(value) <= high:
        raise ValueError(f"{name} must be in [{low}, {high}] (got {value})")
    return int(value)
