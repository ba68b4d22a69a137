"""Greyscale PNG files of 8 and 16 bits, as the BOP benchmark stores depth images and masks.

BOP's depth images are 16-bit greyscale PNGs of ``round(depth_mm / depth_scale)`` (bop_toolkit
``bop_toolkit_lib/inout.py``, ``save_depth``: ``np.round(im).astype(np.uint16)`` written by PyPNG with
``greyscale=True, bitdepth=16``; ``load_depth`` reads it back as float and the caller multiplies by the image's
``depth_scale`` from ``scene_camera.json``).  Its masks are 8-bit greyscale PNGs, 255 inside and 0 outside
(``scripts/calc_gt_masks.py``: ``inout.save_im(mask_path, 255 * mask.astype(np.uint8))``).

`encode_gray_png` writes both and `read_gray_png` reads any greyscale PNG back, with Pillow (an 8-bit image is its
mode 'L', a 16-bit one its 'I;16': a greyscale PNG of bit depth 16).
"""
import io

import numpy as np
from PIL import Image

from glphong.core import validate as _validate

__all__ = ["encode_gray_png", "read_gray_png", "depth_to_png_units", "UINT16_MAX"]

#: the largest value a 16-bit depth PNG holds
UINT16_MAX = 65535


def encode_gray_png(image, level=6):
    """The bytes of a greyscale PNG file of an 8-bit or 16-bit image.

    Parameters
    ----------
    image : (H, W) uint8 or uint16 ndarray
        Row 0 at the top; the PNG's bit depth follows the dtype (8 or 16).
    level : int
        zlib's compression level, 0 (stored) to 9 (default 6).

    Returns
    -------
    bytes

    Raises
    ------
    TypeError
        ``image`` not a uint8 or uint16 ndarray.
    ValueError
        ``image`` not two-dimensional, or empty.
    """
    if not isinstance(image, np.ndarray) or image.dtype not in (np.uint8, np.uint16):
        got = type(image).__name__ + (f" of {image.dtype}" if isinstance(image, np.ndarray) else "")
        raise TypeError(f"image must be a uint8 or uint16 numpy array (got {got})")
    if image.ndim != 2 or image.size == 0:
        raise ValueError(f"image must be a non-empty (H, W) array (got shape {image.shape})")
    level = _validate.positive_int("level", level, 0, 9)
    stream = io.BytesIO()
    Image.fromarray(np.ascontiguousarray(image)).save(stream, format="PNG", compress_level=level)  # 'L' or 'I;16'
    return stream.getvalue()


def read_gray_png(path):
    """A greyscale PNG file's samples: (H, W) uint8 for an 8-bit file, uint16 for a 16-bit one.

    Raises
    ------
    ValueError
        The file is not a greyscale PNG of 8 or 16 bits (the path and what was found named).
    """
    with Image.open(path) as im:
        if im.format != "PNG":
            raise ValueError(f"{path}: expected a PNG file (got {im.format})")
        mode = im.mode
        if mode == "L":
            return np.asarray(im, dtype=np.uint8).copy()
        if mode in ("I;16", "I;16B", "I"):
            values = np.asarray(im)
            if values.size and (values.min() < 0 or values.max() > UINT16_MAX):
                raise ValueError(f"{path}: expected a 16-bit greyscale PNG (got values beyond 0..65535)")
            return values.astype(np.uint16)
    raise ValueError(f"{path}: expected a greyscale PNG of 8 or 16 bits (got Pillow mode {mode!r})")


def depth_to_png_units(depth_m, depth_scale):
    """Depth in metres as a 16-bit BOP depth image: ``round(1000 depth / depth_scale)``.

    Parameters
    ----------
    depth_m : (H, W) array_like of float
        Depth along the camera's viewing axis [m], 0 where nothing is seen; finite and >= 0.
    depth_scale : float
        Millimetres per unit of the image, > 0 (BOP's ``depth_scale``: ``depth_mm = value * depth_scale``).

    Returns
    -------
    (H, W) uint16 ndarray

    Raises
    ------
    ValueError
        A negative or non-finite depth, or one beyond ``65535 depth_scale`` mm (the message gives the smallest
        ``depth_scale`` that holds the image).
    """
    scale = _validate.scalar("depth_scale", depth_scale, low=0.0, low_inclusive=False)
    depth = np.asarray(depth_m, dtype=np.float64)
    if depth.ndim != 2:
        raise ValueError(f"depth must be an (H, W) array (got shape {depth.shape})")
    if not np.all(np.isfinite(depth)) or (depth.size and depth.min() < 0.0):
        raise ValueError("depth must be finite and >= 0 [m] (0 where nothing is seen)")
    units = np.round(depth * (1000.0 / scale))  # bop_toolkit inout.save_depth: np.round(im).astype(np.uint16)
    if units.size and units.max() > UINT16_MAX:
        far = float(depth.max()) * 1000.0
        raise ValueError(f"the depth reaches {far:.6g} mm, beyond what a 16-bit PNG holds at depth_scale={scale:g} "
                         f"({UINT16_MAX * scale:.6g} mm): pass depth_scale >= {far / UINT16_MAX:.6g} "
                         "(mm per unit), or bring zfar / the scene closer")
    return units.astype(np.uint16)
