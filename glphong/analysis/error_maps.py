"""Pictures of a verify report's error: the per-pixel relative error of the GPU against the twin on a log scale."""
import numpy as np

__all__ = ["error_image"]


def error_image(report, low=1e-8, high=1e-5):
    """The report's relative error as a grey picture: per pixel the largest channel's ``|GPU - twin| / |twin|`` on a
    log scale, black at ``low`` and below, white at ``high`` and above; black where no surface is.

    Parameters
    ----------
    report : glphong.VerifyReport
        `glphong.verify`'s answer (its ``relative_error`` (H, W, 3), NaN where a channel is not checked, and
        ``mask`` (H, W)).
    low, high : float
        The relative errors drawn black and white (0 < low < high).

    Returns
    -------
    (H, W, 3) float64 ndarray
        Grey levels in [0, 1], for `glphong.imaging.save_png` (or beside the render, divided by its peak).
    """
    if not 0.0 < low < high:
        raise ValueError(f"error_image: expected 0 < low < high, got low={low!r}, high={high!r}")
    error = np.fmax.reduce(np.where(report.mask[..., None], report.relative_error, 0.0), axis=-1)  # NaN: unchecked
    error = np.nan_to_num(error, nan=0.0)
    grey = np.clip(np.log10(np.maximum(error, low) / low) / np.log10(high / low), 0.0, 1.0)
    grey[~report.mask] = 0.0
    return np.repeat(grey[..., None], 3, axis=-1)
