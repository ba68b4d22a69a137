"""Validation of user parameters at the API boundary.

Every public constructor funnels its arguments through these helpers, so a bad
value fails early with a message that names the parameter and the valid range,
and nothing reaches the GPU that the shaders are not specified for.
"""
import numpy as np

FLT_MAX = float(np.finfo(np.float32).max)


def _fmt(value):
    return np.array2string(np.asarray(value), precision=6, threshold=12) if np.ndim(value) else repr(value)


def scalar(name, value, low=0.0, high=FLT_MAX, low_inclusive=True):
    """A finite real scalar in ``[low, high]`` (``(low, high]`` if not ``low_inclusive``), as float."""
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a real number (got {value!r})") from None
    if np.ndim(value) != 0:
        raise ValueError(f"{name} must be a scalar (got shape {np.shape(value)})")
    ok = np.isfinite(x) and (x >= low if low_inclusive else x > low) and x <= high
    if not ok:
        bracket = "[" if low_inclusive else "("
        raise ValueError(f"{name} must be finite and in {bracket}{low:g}, {high:g}] (got {_fmt(value)})")
    return x


def rgb(name, value, low=0.0, high=FLT_MAX):
    """An RGB triple from a scalar or a length-3 sequence, each finite and in ``[low, high]``.

    Returns
    -------
    tuple of 3 float
    """
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a real scalar or an RGB triple (got {value!r})") from None
    if a.ndim == 0:
        a = np.repeat(a, 3)
    if a.shape != (3,):
        raise ValueError(f"{name} must be a scalar or have shape (3,) (got shape {a.shape})")
    if not (np.all(np.isfinite(a)) and np.all(a >= low) and np.all(a <= high)):
        raise ValueError(f"{name} must be finite and in [{low:g}, {high:g}] per channel (got {_fmt(a)})")
    return tuple(float(c) for c in a)


def vec3(name, value, nonzero=False):
    """A finite 3-vector with every component's magnitude at most FLT_MAX, as a tuple of float."""
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise TypeError(f"{name} must be a sequence of 3 real numbers (got {value!r})") from None
    if a.shape != (3,):
        raise ValueError(f"{name} must have shape (3,) (got shape {a.shape})")
    if not (np.all(np.isfinite(a)) and np.all(np.abs(a) <= FLT_MAX)):
        raise ValueError(f"{name} must be finite with |components| <= {FLT_MAX:g} (got {_fmt(a)})")
    if nonzero and not np.any(a):
        raise ValueError(f"{name} must not be the zero vector")
    return tuple(float(c) for c in a)


def rigid_pose(name, value, tol=1e-6):
    """A 4x4 rigid transform (orthonormal rotation with det +1, finite translation), as float64 array."""
    a = np.array(value, dtype=np.float64)
    if a.shape != (4, 4):
        raise ValueError(f"{name} must have shape (4, 4) (got shape {a.shape})")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"{name} must be finite")
    if not np.allclose(a[3], (0.0, 0.0, 0.0, 1.0), atol=0.0):
        raise ValueError(f"{name} must have last row (0, 0, 0, 1) (got {_fmt(a[3])})")
    r = a[:3, :3]
    if not (np.allclose(r.T @ r, np.eye(3), atol=tol) and np.linalg.det(r) > 0):
        raise ValueError(f"{name} must have an orthonormal rotation block with determinant +1 (tolerance {tol:g})")
    a.setflags(write=False)
    return a


def affine_transform(name, value):
    """A 4x4 invertible affine transform (last row (0, 0, 0, 1)), as float64 array."""
    a = np.array(value, dtype=np.float64)
    if a.shape != (4, 4):
        raise ValueError(f"{name} must have shape (4, 4) (got shape {a.shape})")
    if not np.all(np.isfinite(a)) or np.any(np.abs(a) > FLT_MAX):
        raise ValueError(f"{name} must be finite and representable in float32")
    if not np.array_equal(a[3], (0.0, 0.0, 0.0, 1.0)):
        raise ValueError(f"{name} must have last row (0, 0, 0, 1) (got {_fmt(a[3])})")
    if not abs(np.linalg.det(a[:3, :3])) > 0:
        raise ValueError(f"{name} must be invertible (its 3x3 block is singular)")
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
        raise TypeError(f"{name} must be an integer (got {value!r})")
    if not low <= int(value) <= high:
        raise ValueError(f"{name} must be in [{low}, {high}] (got {value})")
    return int(value)
