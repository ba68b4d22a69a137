"""Output encoding: explicit exposure, the exact sRGB curve, PNG and .npy files (DESIGN section 2).

Radiance stays linear float32 until here; nothing is clamped or gamma-encoded in a shader.
"""
import numpy as np

from . import _validate

__all__ = ["srgb_encode", "srgb_decode", "encode_srgb8", "save_png", "save_npy"]


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
    radiance = np.asarray(radiance, dtype=np.float64)
    if radiance.ndim != 3 or radiance.shape[2] != 3:
        raise ValueError(f"radiance must have shape (H, W, 3) (got shape {radiance.shape})")
    return np.rint(srgb_encode(exposure * radiance) * 255.0).astype(np.uint8)


def save_png(path, radiance, exposure=1.0):
    """Write ``encode_srgb8(radiance, exposure)`` as a PNG file with Pillow.

    Raises
    ------
    ValueError
        If ``path`` does not end in ``.png`` (Pillow would pick another, possibly lossy, format).
    """
    import os

    from PIL import Image

    if os.path.splitext(os.fspath(path))[1].lower() != ".png":
        raise ValueError(f"path must end in .png: save_png writes PNG only (got {os.fspath(path)!r}); "
                         "use encode_srgb8() and Pillow for other formats")
    Image.fromarray(encode_srgb8(radiance, exposure), mode="RGB").save(path, format="PNG")


def save_npy(path, radiance):
    """Write raw float32 radiance ``(H, W, 3)`` as a ``.npy`` file."""
    np.save(path, np.asarray(radiance, dtype=np.float32))
