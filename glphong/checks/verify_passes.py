"""Each frame pass of a render against its float64 twin (docs/design.md section 15).

The GPU's passes (`glphong.gpu.passes`) are compared pixel by pixel with the twin's (`glphong.checks.frame_twin`): a
float64 ray cast through each pixel centre and four points ``SUBPIXEL`` px from it (where the rasteriser may place
its sample), computed without the GPU's pass code.  A float pass passes where every channel lies in the twin's band
(the spread over those samples and over depth-buffer ties, widened by the float32 rounding of the GPU's inputs); an
id pass ('instance', 'category') where the GPU's id is one of the ids the twin's samples see (0: none).  The twin's
NaN marks a value it does not check (the normal of a normal-mapped material); the flow's NaN (a point behind the
other camera) must be the GPU's too.

The 'matte' pass is checked against the exact coverage (`glphong.checks.coverage_twin.exact_coverage`, float64):
per pixel, the largest difference of an object's share (an object the GPU does not list counts as 0, or, where the
GPU's k entries are all taken, as anything up to its smallest listed share), within `glphong.gpu.matte.matte_tolerance`
of the renderer's ``matte_samples``.
"""
from dataclasses import dataclass

import numpy as np

from glphong.checks.coverage_twin import exact_coverage, top_k
from glphong.checks.frame_twin import SAMPLE_OFFSETS, cast_pixels, pass_bands, twin_passes
from glphong.gpu.matte import matte_tolerance

__all__ = ["PassReport", "verify_passes", "matte_error", "compare_matte", "ID_PASSES"]

#: the passes whose pixels are ids, checked by membership
ID_PASSES = ("instance", "category")
_EXPECTED_NAN = ("flow", "backward_flow")


@dataclass(frozen=True)
class PassReport:
    """One pass of a render against its twin.

    Attributes
    ----------
    name : str
    gpu : (H, W) or (H, W, C) ndarray
        The renderer's pass.
    reference : (H, W) or (H, W, C) float64 ndarray
        The twin's value at the pixel centre.
    low, high : (H, W) or (H, W, C) float64 ndarray, or None
        The band of a float pass (None for an id pass).
    allowed : (H, W, K) int64 ndarray or None
        An id pass's ids the twin's samples see (-1 padding).
    error : (H, W) float64 ndarray or None
        The 'matte' pass's largest error of an object's share in each pixel (module docstring).
    tolerance : float or None
        The 'matte' pass's allowed error (`glphong.gpu.matte.matte_tolerance`).
    outside : (H, W) bool ndarray
        Pixels outside the band (a channel) or with an id not allowed.
    unchecked : (H, W) bool ndarray
        Pixels the twin does not check (its NaN where the GPU's value is not NaN by contract).
    """

    name: str
    gpu: np.ndarray
    reference: np.ndarray
    outside: np.ndarray
    unchecked: np.ndarray
    low: np.ndarray = None
    high: np.ndarray = None
    allowed: np.ndarray = None
    error: np.ndarray = None
    tolerance: float = None

    @property
    def passed(self):
        """True where no pixel is outside."""
        return not self.outside.any()

    @property
    def outside_count(self):
        return int(self.outside.sum())

    @property
    def max_error(self):
        """The largest ``|gpu - reference|`` over checked pixels and channels, in the pass's unit (ids: the count of
        pixels whose id differs from the centre sample's; the matte: the largest error of a share)."""
        if self.error is not None:
            return float(self.error.max()) if self.error.size else 0.0
        if self.allowed is not None:
            return float(np.sum((self.gpu.astype(np.int64) != self.reference) & ~self.unchecked))
        with np.errstate(invalid="ignore"):
            error = np.abs(self.gpu.astype(np.float64) - self.reference)
        error = error[~self.unchecked]
        error = error[np.isfinite(error)]
        return float(error.max()) if error.size else 0.0

    def summary(self):
        return {"passed": self.passed, "max_error": self.max_error, "outside": self.outside_count,
                "unchecked": int(self.unchecked.sum())}


def verify_passes(scene, frame, names, next_scene=None, previous_scene=None, matte_samples=None):
    """The `PassReport` of each pass ``names`` (all but the radiance) of ``frame`` (a `glphong.Frame` rendered with
    them), dict of name to report; ``matte_samples``: the renderer's, for the 'matte' pass."""
    height, width = frame.mask.shape
    out = {}
    geometry = [n for n in names if n != "matte"]
    if geometry:
        hits = cast_pixels(scene, width, height, SAMPLE_OFFSETS)
        values = twin_passes(scene, hits, geometry, next_scene, previous_scene)
        bands = pass_bands(scene, hits, geometry, next_scene, previous_scene, nearest=values)
        out = {name: _compare(name, getattr(frame, name), values[name][0], bands[name]) for name in geometry}
    if "matte" in names:
        if matte_samples is None:
            raise ValueError("verifying the 'matte' pass needs the renderer's matte_samples")
        out["matte"] = compare_matte(scene, frame.matte_ids, frame.matte_fractions, matte_samples)
    return out


def matte_error(ids, fractions, exact_ids, exact_fractions):
    """Per pixel, the largest error of an object's share in a matte against the exact coverage.

    Parameters
    ----------
    ids, fractions : (H, W, k) ndarray
        The matte (uint32 ids, float32 shares; 0 padding).
    exact_ids, exact_fractions : (H, W, K) ndarray
        `glphong.checks.coverage_twin.exact_coverage`'s (every object seen).

    Returns
    -------
    (H, W) float64 ndarray
        ``max |f - f_exact|`` over the objects of either list; an object the matte does not list counts as 0, or,
        where its ``k`` entries are all taken (all shares > 0), as anything from 0 to its smallest share.
    """
    ids = ids.astype(np.int64)
    fractions = fractions.astype(np.float64)
    exact_ids = exact_ids.astype(np.int64)
    listed = fractions > 0
    same = (ids[..., :, None] == exact_ids[..., None, :]) & listed[..., :, None] & (exact_fractions[..., None, :] > 0)
    exact_of_listed = np.sum(np.where(same, exact_fractions[..., None, :], 0.0), axis=-1)  # (H, W, k)
    error = np.max(np.where(listed, np.abs(fractions - exact_of_listed), 0.0), axis=-1)
    unlisted = (exact_fractions > 0) & ~np.any(same, axis=-2)  # (H, W, K): seen exactly, not in the matte
    full = np.all(listed, axis=-1)
    floor = np.where(full, np.min(np.where(listed, fractions, np.inf), axis=-1), 0.0)
    missed = np.max(np.where(unlisted, np.maximum(exact_fractions - floor[..., None], 0.0), 0.0), axis=-1)
    return np.maximum(error, missed)


def compare_matte(scene, ids, fractions, samples):
    """The 'matte' pass's `PassReport`: ``ids``, ``fractions`` (H, W, k) against the exact coverage of ``scene``,
    allowed `glphong.gpu.matte.matte_tolerance` (``samples``)."""
    height, width, k = ids.shape
    exact_ids, exact_fractions = exact_coverage(scene, width, height)
    error = matte_error(ids, fractions, exact_ids, exact_fractions)
    tolerance = matte_tolerance(samples)
    reference = top_k(exact_ids, exact_fractions, k)[1]
    return PassReport("matte", fractions, reference, error > tolerance, np.zeros(error.shape, bool), error=error,
                      tolerance=tolerance)


def _compare(name, gpu, reference, band):
    if name in ID_PASSES:
        allowed = band
        ok = np.any(allowed == gpu.astype(np.int64)[..., None], axis=-1)
        return PassReport(name, gpu, reference, ~ok, np.zeros(ok.shape, bool), allowed=allowed)
    low, high = band
    g = gpu.astype(np.float64)
    channels = (lambda a: a) if g.ndim == 2 else (lambda a: np.any(a, axis=-1))
    all_channels = (lambda a: a) if g.ndim == 2 else (lambda a: np.all(a, axis=-1))
    twin_nan = channels(np.isnan(reference) | np.isnan(low) | np.isnan(high))
    if name in _EXPECTED_NAN:  # the twin's NaN (behind the other camera) must be the GPU's
        nan_agrees = all_channels(np.isnan(g)) & all_channels(np.isnan(reference))
        inside = all_channels((g >= low) & (g <= high))
        outside = ~(inside | nan_agrees)
        return PassReport(name, gpu, reference, outside, np.zeros(outside.shape, bool), low, high)
    inside = all_channels((g >= low) & (g <= high))
    return PassReport(name, gpu, reference, ~inside & ~twin_nan, twin_nan, low, high)
