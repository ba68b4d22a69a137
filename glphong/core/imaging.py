"""Output encoding: explicit exposure, the exact sRGB curve, PNG and .npy files (docs/design.md section 2).

Radiance stays linear float32 until here; nothing is clamped or gamma-encoded in a shader.
"""
import functools

import numpy as np

from glphong.core import validate as _validate
from glphong.core.png import THREADS, encode_png, parallel_map

__all__ = ["srgb_encode", "srgb_decode", "encode_srgb8", "encode_srgb8_reference", "save_png", "save_npy"]


def srgb_encode(linear):
    """The exact piecewise sRGB transfer function (IEC 61966-2-1).

    Parameters
    ----------
    linear : array_like
        Linear values; clipped to [0, 1] first (NaN becomes 0).

    Returns
    -------
    ndarray of float64, same shape
        ``12.92 x`` for ``x <= 0.0031308``, else ``1.055 x^(1/2.4) - 0.055``.
    """
    x = np.clip(np.nan_to_num(np.asarray(linear, dtype=np.float64), nan=0.0), 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)


def srgb_decode(encoded):
    """Inverse of `srgb_encode` on [0, 1]: ``x / 12.92`` for ``x <= 0.04045``, else ``((x + 0.055) / 1.055)^2.4``.

    Parameters
    ----------
    encoded : array_like
        sRGB-encoded values in [0, 1] (e.g. ``uint8 / 255``).

    Returns
    -------
    ndarray of float64
        Linear values.
    """
    x = np.clip(np.asarray(encoded, dtype=np.float64), 0.0, 1.0)
    return np.where(x <= 0.04045, x / 12.92, ((x + 0.055) / 1.055) ** 2.4)


def encode_srgb8(radiance, exposure=1.0):
    """Tone-map linear radiance by a linear exposure and encode it as 8-bit sRGB.

    The code of a value ``x`` is ``rint(srgb_encode(exposure * x) * 255)`` with the product in float64
    (NaN and negative values give 0).  float32 radiance (what a `Renderer` returns) is encoded through
    a table of the 255 float32 thresholds where that code steps, the same numbers about 4x faster, in row blocks on
    threads for large images (`encode_srgb8_reference` is the formula itself; they are compared in the tests).

    Parameters
    ----------
    radiance : (H, W, 3) array_like
        Linear radiance [W/(m^2 sr)].
    exposure : float
        Scale applied before encoding: display value = exposure * radiance, clipped to [0, 1].

    Returns
    -------
    (H, W, 3) uint8 ndarray
    """
    exposure = _validate.scalar("exposure", exposure, low=0.0, low_inclusive=False)
    array = np.asarray(radiance)
    if array.ndim != 3 or array.shape[2] != 3:
        raise ValueError(f"radiance must have shape (H, W, 3) (got shape {array.shape})")
    if array.dtype != np.float32:
        return encode_srgb8_reference(array, exposure)
    cells, thresholds = _float32_code_table(float(exposure))

    def rows(block):  # a contiguous copy first: a frame's radiance is a strided view of its RGBA read-back
        part = np.ascontiguousarray(array[block])
        code = np.take(cells, part.view(np.uint32) >> _CELL_SHIFT)
        code += part >= np.take(thresholds, code)  # a cell holds at most one step
        return code

    height = array.shape[0]
    blocks = THREADS if array.size >= 1 << 18 else 1  # numpy's passes release the GIL: row blocks on threads
    cuts = [height * k // blocks for k in range(blocks + 1)]
    parts = parallel_map(rows, [slice(cuts[k], cuts[k + 1]) for k in range(blocks)])
    return parts[0] if len(parts) == 1 else np.concatenate(parts)


def encode_srgb8_reference(radiance, exposure=1.0):
    """`encode_srgb8` by its formula, ``rint(srgb_encode(exposure * x) * 255)`` in float64, for any dtype."""
    radiance = np.asarray(radiance, dtype=np.float64)
    return np.rint(srgb_encode(exposure * radiance) * 255.0).astype(np.uint8)


#: float32 bit patterns per cell of the code table: 2^12, a relative width of 2^-11 (the steps are at
#: least 2^-8 apart relative), so a cell holds at most one of the 255 steps
_CELL_SHIFT = 12


def _code_steps():
    """The 255 smallest float64 values ``y`` whose code ``rint(srgb_encode(y) * 255)`` is 1, 2, ... 255,
    found by bisection over float64 bit patterns (made once)."""
    if not _STEPS:
        lo = np.zeros(255, np.int64)  # bit patterns of 0.0 ... 1.0 (ordered like the values for y >= 0)
        hi = np.full(255, np.float64(1.0).view(np.int64))
        wanted = np.arange(1, 256)
        while np.any(hi - lo > 1):
            mid = (lo + hi) // 2
            reached = np.rint(srgb_encode(mid.view(np.float64)) * 255.0) >= wanted
            hi, lo = np.where(reached, mid, hi), np.where(reached, lo, mid)
        _STEPS.append(hi.view(np.float64))
    return _STEPS[0]


_STEPS = []


@functools.lru_cache(maxsize=8)
def _float32_code_table(exposure):
    """``(cells, thresholds)`` for float32 input at ``exposure``: ``thresholds[k]`` the smallest float32 ``x``
    with code ``> k`` (float64 ``x * exposure`` against the steps; NaN past the last, so nothing passes
    it), ``cells[c]`` the code of the lowest value of cell ``c`` of the bit patterns (negative values and
    NaN: 0)."""
    steps = _code_steps()
    with np.errstate(over="ignore", divide="ignore", under="ignore", invalid="ignore"):
        x = (steps / exposure).astype(np.float32)
        for _ in range(4):  # to the exact float32: the product in float64 decides
            below = np.nextafter(x, np.float32(0))
            x = np.where((x > 0) & (below.astype(np.float64) * exposure >= steps), below, x)
            x = np.where(x.astype(np.float64) * exposure < steps, np.nextafter(x, np.float32(np.inf)), x)
    thresholds = np.append(x, np.float32(np.nan))
    lowest = (np.arange(2 ** (32 - _CELL_SHIFT), dtype=np.uint64) << _CELL_SHIFT).astype(np.uint32).view(np.float32)
    with np.errstate(invalid="ignore"):
        cells = np.searchsorted(x, lowest, side="right").astype(np.uint8)
        cells[~(lowest >= 0)] = 0  # negative and NaN cells
    return cells, thresholds


def save_png(path, radiance, exposure=1.0, compress_level=1):
    """Write ``encode_srgb8(radiance, exposure)`` as a PNG file (`png_bytes`).

    ``compress_level`` is zlib's, 0 to 9 (1 by default: fast, a somewhat larger file).

    Raises
    ------
    ValueError
        If ``path`` does not end in ``.png``.
    """
    import os

    if os.path.splitext(os.fspath(path))[1].lower() != ".png":
        raise ValueError(f"path must end in .png: save_png writes PNG only (got {os.fspath(path)!r}); "
                         "use encode_srgb8() and Pillow for other formats")
    data = png_bytes(radiance, exposure, compress_level)
    with open(path, "wb") as handle:
        handle.write(data)


def png_bytes(radiance, exposure=1.0, compress_level=1):
    """``encode_srgb8(radiance, exposure)`` as the bytes of a PNG file (what `save_png` writes): rows filtered
    with PNG's *Sub* filter, deflated in pieces on threads (`glphong.core.png.encode_png`).

    Returns
    -------
    bytes
    """
    level = _validate.positive_int("compress_level", compress_level, 0, 9)
    return encode_png(encode_srgb8(radiance, exposure), level)


def save_npy(path, radiance):
    """Write raw float32 radiance ``(H, W, 3)`` as a ``.npy`` file."""
    np.save(path, np.asarray(radiance, dtype=np.float32))
