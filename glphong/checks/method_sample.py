"""The method error of a random sample of pixels (issue 40): where the exact image of every pixel costs too much,
`glphong.verify` ``(..., exact_sample=N, seed=S)`` computes it at ``N`` covered pixels drawn uniformly without
replacement, and says so: `VerifyReport.exact_sample` is the sample's mask, the method error map is NaN outside it,
and its figures (`MethodErrorFigures`) carry the sample's size and two statements at 95 % confidence.

- The mean: the mean over the sampled pixels of each pixel's mean relative error over its finite channels, with the
  half-width of its 95 % interval ``1.96 s / sqrt(n) sqrt(1 - n / N)`` (``s`` the sample's standard deviation, the
  finite-population correction for ``n`` of ``N`` pixels; the normal approximation, fair for ``n`` of some tens on).
- The maximum: the largest error in the sample; the fraction of covered pixels above it is at most ``1 -
  0.05^(1/n)`` (about ``3 / n``) with 95 % confidence (the chance that ``n`` uniform draws all miss a set of that
  fraction is at most 5 %).  It bounds how many pixels are worse, never by how much.
"""
from collections import namedtuple

import numpy as np

__all__ = ["MethodErrorFigures", "sample_mask", "method_figures", "auto_sample_size", "AUTO_PIXEL_TEXELS",
           "AUTO_SAMPLE"]

#: covered pixels times environment-map texels above which `verify`'s default (``exact_sample='auto'``) takes a sample:
#: the exact lobe costs about 8e-8 s a pixel-texel here (95 to 118 s for 10,446 pixels under 256 x 512, llvmpipe's
#: machine of docs/speed.md), so about 16 s of exact lobe at this bound
AUTO_PIXEL_TEXELS = 2e8
#: the sample `verify`'s default takes beyond `AUTO_PIXEL_TEXELS`: 26 to 30 s under a 256 x 512 map, 117 to 169 s under
#: 1024 x 2048 (docs/speed.md); the share of pixels above its worst at most 0.3 % (95 %)
AUTO_SAMPLE = 1000


class MethodErrorFigures(namedtuple("MethodErrorFigures", "mean max")):
    """``(mean, max)`` of the method error over covered channels (unpacks as the pair); where the exact image is a
    sample, also ``sample`` (its pixels), ``covered`` (the covered pixels), ``mean_ci95`` (the 95 % half-width of the
    mean of the pixels' errors) and ``above_max95`` (the fraction of covered pixels that may exceed ``max``, 95 %);
    all None where every covered pixel was computed."""

    sample = covered = mean_ci95 = above_max95 = None

    def __repr__(self):
        head = f"MethodErrorFigures(mean={self.mean:.3g}, max={self.max:.3g}"
        if self.sample is None:
            return head + ")"
        return (head + f", a sample of {self.sample} of {self.covered} px: mean +- {self.mean_ci95:.3g} (95 %), at most "
                f"{self.above_max95:.3g} of the pixels above max (95 %))")


def sample_mask(mask, count, seed=0):
    """``count`` of the pixels of ``mask`` (H, W) bool, uniformly without replacement (``np.random.default_rng(seed)``):
    an (H, W) bool mask, or None where ``count`` is None or reaches every covered pixel."""
    covered = np.flatnonzero(mask)
    if count is None or count >= covered.size:
        return None
    if int(count) != count or count < 1:
        raise ValueError(f"exact_sample must be a positive whole number of pixels or None (got {count!r})")
    picked = np.random.default_rng(seed).choice(covered, size=int(count), replace=False)
    out = np.zeros(mask.shape, bool)
    out.flat[picked] = True
    return out


def method_figures(error, mask, sample=None):
    """`MethodErrorFigures` of a method error map ``error`` (H, W, 3) over ``mask`` (H, W) (0, 0 where no channel is
    finite), with the sample's statements where ``sample`` (H, W) bool is given."""
    where = mask if sample is None else mask & sample
    e = error[where]
    finite = np.isfinite(e)
    values = e[finite]
    out = MethodErrorFigures(float(values.mean()), float(values.max())) if values.size else MethodErrorFigures(0.0, 0.0)
    if sample is not None:
        n, total = int(where.sum()), int(mask.sum())
        with np.errstate(invalid="ignore"):
            per_pixel = np.nanmean(np.where(finite, e, np.nan), axis=1)
        per_pixel = per_pixel[np.isfinite(per_pixel)]
        spread = float(np.std(per_pixel, ddof=1)) if per_pixel.size > 1 else float("inf")
        out.sample, out.covered = n, total
        out.mean_ci95 = float(1.96 * spread / np.sqrt(max(n, 1)) * np.sqrt(max(0.0, 1.0 - n / max(total, 1))))
        out.above_max95 = float(1.0 - 0.05 ** (1.0 / max(n, 1)))
    return out


def auto_sample_size(scene, covered):
    """The sample `verify`'s default (``exact_sample='auto'``) takes: `AUTO_SAMPLE` pixels where the scene has a
    light whose exact integral visits texels (`LightModel.exact_texels`: an `EnvironmentLight`'s map), a material term
    whose exact integral is not the map's closed-form irradiance (a lobe, or a term the quadrature integrates), and
    ``covered`` (pixels) times those texels beyond `AUTO_PIXEL_TEXELS`; else None (every covered pixel: a Lambert-only
    scene's closed forms take 24.7 s at 256 x 256 under 256 x 512)."""
    texels = sum(light.exact_texels() for light in scene.lights)
    if not texels or covered * texels <= AUTO_PIXEL_TEXELS:
        return None

    def closed_irradiance(term):
        form = term.integral_form()
        return form is not None and form.form == "irradiance"

    if all(closed_irradiance(term) for obj in scene.objects for term in obj.material.components):
        return None
    return AUTO_SAMPLE
