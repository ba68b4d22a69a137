"""Pixel-by-pixel cross-check of a GPU render against the float64 twin (docs/design.md section 4)."""
from dataclasses import dataclass

import numpy as np

from glphong.checks import reference
from glphong.checks.tolerances import BAND, point_band
from glphong.gpu.renderer import Renderer

__all__ = ["VerifyReport", "verify", "compare", "relative_error"]


@dataclass(frozen=True)
class VerifyReport:
    """Error maps and summary figures of one cross-check.

    Attributes
    ----------
    gpu : (H, W, 3) float32 ndarray
        The renderer's radiance.
    reference : (H, W, 3) float64 ndarray
        The twin's radiance on the G-buffer of the same render.
    low, high : (H, W, 3) float64 ndarray
        The tolerance band.
    relative_error : (H, W, 3) float64 ndarray
        ``|gpu - ref| / |ref|`` where ``ref != 0``; ``0`` where both are 0, ``inf`` where only
        ref is 0; NaN outside the coverage mask.
    outside : (H, W) bool ndarray
        Covered pixels with a channel outside the band (or not finite while the band is).
    mask : (H, W) bool ndarray
        Covered pixels.
    mask_mismatch : int
        Pixels covered in the radiance render but not in the G-buffer, or the reverse.
    shadow_band : (H, W) bool ndarray or None
        Pixels where a shadowing light's visibility is uncertain: a shadow boundary, seen from the light, within
        the filter's reach plus one texel, or an occluder nearer than the derived bias (docs/design.md section 12).
    """

    gpu: np.ndarray
    reference: np.ndarray
    low: np.ndarray
    high: np.ndarray
    relative_error: np.ndarray
    outside: np.ndarray
    mask: np.ndarray
    mask_mismatch: int
    shadow_band: np.ndarray = None

    @property
    def covered_pixels(self):
        """Number of covered pixels."""
        return int(self.mask.sum())

    @property
    def outside_count(self):
        """Number of covered pixels outside the band."""
        return int(self.outside.sum())

    @property
    def max_relative_error(self):
        """Largest finite relative error over covered channels with a non-zero reference."""
        e = self.relative_error[self.mask]
        e = e[np.isfinite(e)]
        return float(e.max()) if e.size else 0.0

    @property
    def rms_relative_error(self):
        """Root mean square of the finite relative errors over covered channels."""
        e = self.relative_error[self.mask]
        e = e[np.isfinite(e)]
        return float(np.sqrt(np.mean(e ** 2))) if e.size else 0.0

    @property
    def nonfinite_count(self):
        """Covered GPU channels that are NaN or Inf."""
        return int((~np.isfinite(self.gpu[self.mask])).sum())

    @property
    def passed(self):
        """True when every covered pixel lies in the band and the coverage masks agree."""
        return self.outside_count == 0 and self.mask_mismatch == 0

    @property
    def shadow_band_count(self):
        """Covered pixels where a shadow map may decide either way (a shadow boundary or a contact within the
        band, docs/design.md section 12), reported apart: the band holds them between shadowed and lit."""
        return 0 if self.shadow_band is None else int((self.shadow_band & self.mask).sum())

    def summary(self):
        """The summary figures as a dict."""
        return {"covered_pixels": self.covered_pixels, "shadow_band": self.shadow_band_count,
                "max_relative_error": self.max_relative_error,
                "rms_relative_error": self.rms_relative_error, "outside_band": self.outside_count,
                "nonfinite": self.nonfinite_count, "mask_mismatch": self.mask_mismatch, "passed": self.passed}

    def __str__(self):
        s = self.summary()
        return (f"{'PASS' if s['passed'] else 'FAIL'}: {s['covered_pixels']} px, max rel err {s['max_relative_error']:.3g}, "
                f"rms rel err {s['rms_relative_error']:.3g}, outside band {s['outside_band']}, "
                f"non-finite {s['nonfinite']}, mask mismatch {s['mask_mismatch']}")


def relative_error(value, reference):
    """Elementwise ``|value - reference| / |reference|``: 0 where the two are equal (0 against 0
    included), ``inf`` where only the reference is 0.

    Parameters
    ----------
    value, reference : array_like, same shape

    Returns
    -------
    ndarray of float64
    """
    value = np.asarray(value, dtype=np.float64)
    reference = np.asarray(reference, dtype=np.float64)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(value == reference, 0.0, np.abs(value - reference) / np.abs(reference))


def compare(gpu, reference_radiance, low, high, mask):
    """Relative error map and out-of-band pixels of ``gpu`` against the twin.

    Parameters
    ----------
    gpu : (H, W, 3) ndarray
    reference_radiance, low, high : (H, W, 3) float64 ndarray
    mask : (H, W) bool ndarray

    Returns
    -------
    relative_error : (H, W, 3) float64 ndarray
    outside : (H, W) bool ndarray
    """
    g = gpu.astype(np.float64)
    rel = np.where(mask[..., None], relative_error(g, reference_radiance), np.nan)
    in_band = (g >= low) & (g <= high)
    outside = mask & ~np.all(in_band, axis=-1)
    return rel, outside


def verify(scene, renderer, band=BAND):
    """Render ``scene``, shade its G-buffer with the float64 twin, compare under the band.

    Parameters
    ----------
    scene : glphong.Scene
    renderer : glphong.Renderer
    band : glphong.checks.tolerances.BandConstants

    Returns
    -------
    VerifyReport

    Raises
    ------
    ValueError
        If the renderer shades per vertex, multisamples or supersamples: the twin reproduces
        one per-pixel evaluation at each pixel centre, which only ``shading='pixel'``,
        ``samples=1``, ``supersample=1`` render.
    """

    if not isinstance(renderer, Renderer):
        raise TypeError(f"renderer must be a glphong.Renderer (got {type(renderer).__name__})")
    if renderer.shading != "pixel" or renderer.samples != 1 or renderer.supersample != 1:
        raise ValueError("verify needs a Renderer with shading='pixel', samples=1 and supersample=1 "
                         f"(got {renderer!r}); compare other options with glphong.checks.raycast instead")
    with renderer._lock:  # one call: no resize from another thread between the two passes
        frame = renderer.render(scene)
        gbuffer = renderer.gbuffer(scene)
    ref, low, high, shadow_band = twin_and_band(scene, gbuffer, band, renderer.shadow_settings)
    mask = frame.mask & gbuffer.mask
    rel, outside = compare(frame.radiance, ref, low, high, mask)
    return VerifyReport(gpu=frame.radiance, reference=ref, low=low, high=high, relative_error=rel,
                        outside=outside, mask=mask, mask_mismatch=int((frame.mask != gbuffer.mask).sum()),
                        shadow_band=shadow_band)


def twin_and_band(scene, gbuffer, band=BAND, shadows=None):
    """The float64 twin of a G-buffer, its tolerance band and the shadow band, in one pass over the objects (the
    shadowing lights' rays are cast once).

    Returns
    -------
    reference : (H, W, 3) float64 ndarray
        `glphong.checks.reference.shade`.
    low, high : (H, W, 3) float64 ndarray
        `glphong.checks.tolerances.radiance_band`.
    shadow_band : (H, W) bool ndarray
        Pixels where a shadowing light's visibility is uncertain (the band holds it between 0 and 1).
    """
    ref = np.zeros(gbuffer.position.shape)
    low, high = np.zeros_like(ref), np.zeros_like(ref)
    shadow_band = np.zeros(gbuffer.mask.shape, bool)
    for selection, obj, key, u, position, f, n_valid in reference.shade_inputs(scene, gbuffer, band=band, shadows=shadows):
        ref[selection] = reference.shade_point(position, f, n_valid, u.get("u_eye"), key, u, obj.material)
        low[selection], high[selection] = point_band(key, u, position, f, n_valid, obj.material, band)
        for v in f.visibility or ():
            if v is not None:
                shadow_band[selection] |= v[1] != v[2]
    return ref, low, high, shadow_band
