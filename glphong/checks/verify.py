"""Pixel-by-pixel cross-check of a GPU render against the float64 twin (docs/design.md section 4)."""
from dataclasses import dataclass, field

import numpy as np

from glphong.checks import reference
from glphong.checks.method_sample import auto_sample_size, method_figures, sample_mask
from glphong.checks.tolerances import BAND, point_band
from glphong.checks.transmission_blend import frame_blend_twin, layers_behind
from glphong.checks.transmission_twin import transmission_check
from glphong.checks.uniform_values import UniformValues
from glphong.checks.verify_passes import verify_passes
from glphong.gpu.passes import requested_passes
from glphong.gpu.peeling import blended_objects
from glphong.gpu.transmission import transmissive_objects
from glphong.gpu.renderer import Renderer

__all__ = ["VerifyReport", "verify", "compare", "relative_error", "TWIN_CHUNK"]

#: most pixels `twin_and_band` shades at once (an object's pixels in equal chunks): their temporaries (a few hundred
#: kB) stay clear of the C allocator's fresh pages, which a whole object's (MBs) take on every array, and the chunks'
#: fixed Python cost stays small (8192 against 4096: 0.87 to 0.98 of the twin's time; docs/speed.md, "Verify against
#: the render")
TWIN_CHUNK = 8192


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
    exact : (H, W, 3) float64 ndarray or None
        Where the scene has extended lights (docs/design.md section 13): the radiance with each extended light's
        exact integral (float64 quadrature) in place of the shader's method, which the twin reproduces.  The
        method's own error is `method_error` (the twin against this), apart from the GPU's float32 error (the
        twin against the GPU, under the band).
    exact_error : (H, W) float64 ndarray or None
        The quadrature's absolute error estimate per pixel.
    exact_sample : (H, W) bool ndarray or None
        Where ``verify(..., exact_sample=N)`` computed the exact image at a random sample of covered pixels only: the
        sample (`exact`, `exact_error` and `method_error` are NaN elsewhere; `method_error_figures` states the sample
        and its confidence, `glphong.checks.method_sample`); None where every covered pixel was computed.
    passes : dict of str to glphong.checks.verify_passes.PassReport
        Each frame pass ``verify(..., passes=...)`` asked for against its twin (empty without).
    blend : glphong.checks.blend_twin.BlendTwin or None
        Where the scene has blended materials: the twin of the composite (``reference``, ``low`` and ``high`` are
        its), the pixels it leaves unchecked, those the layer cap cut (``cut``, against the frame's ``blend_cut``:
        `blend_cut_mismatch`) and the cut composite's error against the whole one (``cap_error``).
    transmission : glphong.checks.transmission_twin.TransmissionTwin or None
        Where the scene has transmissive materials: what their thin walls transmit (added to ``reference``, ``low``
        and ``high``), their pixels and those seen through the filtered lookup (``rough``, docs/transmission.md).
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
    exact: np.ndarray = None
    exact_error: np.ndarray = None
    exact_sample: np.ndarray = None
    passes: dict = field(default_factory=dict)
    blend: object = None
    blend_cut_mismatch: int = 0
    transmission: object = None

    @property
    def method_error(self):
        """``|twin - exact| / |exact|`` (H, W, 3): the extended lights' methods against their exact integrals (NaN
        outside the mask and outside `exact_sample`; None without extended lights)."""
        if self.exact is None:
            return None
        where = self.mask if self.exact_sample is None else self.mask & self.exact_sample
        with np.errstate(invalid="ignore"):
            return np.where(where[..., None], relative_error(self.reference, self.exact), np.nan)

    def method_error_figures(self):
        """``(mean, max)`` of the finite `method_error` over covered channels (0 where twin and exact are both 0; the
        channels where only the exact value is 0 left out), or None without extended lights: a
        `glphong.checks.method_sample.MethodErrorFigures`, which where `exact_sample` is set also says the sample's
        size and the 95 % statements of its mean and its max."""
        if self.exact is None:
            return None
        return method_figures(self.method_error, self.mask, self.exact_sample)

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
        """True when every covered pixel lies in the band, the coverage masks agree and every pass checked passes."""
        return self.outside_count == 0 and self.mask_mismatch == 0 and self.blend_cut_mismatch == 0 and \
            all(p.passed for p in self.passes.values())

    @property
    def shadow_band_count(self):
        """Covered pixels where a shadow map may decide either way (a shadow boundary or a contact within the
        band, docs/design.md section 12), reported apart: the band holds them between shadowed and lit."""
        return 0 if self.shadow_band is None else int((self.shadow_band & self.mask).sum())

    def summary(self):
        """The summary figures as a dict (with ``method_mean_error`` and ``method_max_error`` where the scene has
        extended lights)."""
        out = {"covered_pixels": self.covered_pixels, "shadow_band": self.shadow_band_count,
               "max_relative_error": self.max_relative_error,
               "rms_relative_error": self.rms_relative_error, "outside_band": self.outside_count,
               "nonfinite": self.nonfinite_count, "mask_mismatch": self.mask_mismatch, "passed": self.passed}
        figures = self.method_error_figures()
        if figures is not None:
            out["method_mean_error"], out["method_max_error"] = figures
            if figures.sample is not None:  # the exact image of a random sample of pixels, said so
                out |= {"method_sample": figures.sample, "method_mean_ci95": figures.mean_ci95,
                        "method_above_max95": figures.above_max95}
        if self.passes:
            out["passes"] = {name: report.summary() for name, report in self.passes.items()}
        if self.blend is not None:
            cut = self.blend.cut
            out["blend"] = {"unchecked": int((self.blend.unchecked & self.mask).sum()), "cut": int(cut.sum()),
                            "cut_mismatch": self.blend_cut_mismatch, "layers": int(self.blend.layers.max(initial=0)),
                            "cap_max_error": float(np.nanmax(self.blend.cap_error[cut], initial=0.0))}
        return out

    def __str__(self):
        s = self.summary()
        method = (f"; method against exact: mean rel err {s['method_mean_error']:.3g}, max {s['method_max_error']:.3g}"
                  if "method_max_error" in s else "")
        if "method_sample" in s:
            method += (f" (a random sample of {s['method_sample']} px: mean +- {s['method_mean_ci95']:.2g}, at most "
                       f"{s['method_above_max95']:.2g} of the pixels above max, 95 %)")
        passes = "".join(f"; {name} {'pass' if p['passed'] else 'FAIL'} (max err {p['max_error']:.3g}, outside "
                         f"{p['outside']})" for name, p in s.get("passes", {}).items())
        return (f"{'PASS' if s['passed'] else 'FAIL'}: {s['covered_pixels']} px, max rel err {s['max_relative_error']:.3g}, "
                f"rms rel err {s['rms_relative_error']:.3g}, outside band {s['outside_band']}, "
                f"non-finite {s['nonfinite']}, mask mismatch {s['mask_mismatch']}{method}{passes}")


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


def verify(scene, renderer, band=BAND, exact=None, passes=None, next_scene=None, previous_scene=None, exact_sample="auto",
           seed=0):
    """Render ``scene``, shade its G-buffer with the float64 twin, compare under the band; where the scene has
    extended lights, also the twin against their exact integrals (the method error map); and each frame pass asked
    for against its own twin (`glphong.checks.verify_passes`).

    Parameters
    ----------
    scene : glphong.Scene
    renderer : glphong.Renderer
    band : glphong.checks.tolerances.BandConstants
    exact : bool, optional
        Compute the exact integrals (`VerifyReport.exact`); default: where the scene has extended lights.
    passes : sequence of str, optional
        Frame passes to check besides the radiance (`glphong.Renderer.render`'s names; 'radiance' is always checked).
    next_scene, previous_scene : Scene, optional
        What 'flow' and 'backward_flow' read (as in `glphong.Renderer.render`).
    exact_sample : int, None or 'auto'
        Compute the exact integrals at this many covered pixels only, drawn uniformly without replacement with
        ``np.random.default_rng(seed)`` (`VerifyReport.exact_sample`; the figures say so and how sure they are); None:
        every covered pixel; 'auto' (default): every covered pixel, except under an environment map whose exact lobe
        would cost more than `glphong.checks.method_sample.AUTO_PIXEL_TEXELS` pixel-texels, where a sample of
        `~glphong.checks.method_sample.AUTO_SAMPLE` pixels is taken and reported (`auto_sample_size`; docs/speed.md,
        "Verify with an environment light").
    seed : int, optional

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
    names = requested_passes(passes)
    with renderer._lock:  # one call: no resize from another thread between the two passes
        frame = renderer.render(scene, passes=("radiance",) + names, next_scene=next_scene,
                                previous_scene=previous_scene)
        gbuffer = renderer.gbuffer(scene)
    ref, low, high, shadow_band = twin_and_band(scene, gbuffer, band, renderer.shadow_settings)
    mask = frame.mask & gbuffer.mask
    mismatch = int((frame.mask != gbuffer.mask).sum())
    shade = lambda s, g: twin_and_band(s, g, band, renderer.shadow_settings)  # noqa: E731
    transmission = None
    if transmissive_objects(scene):  # what the thin walls transmit (glphong.checks.transmission_twin)
        transmission = transmission_check(scene, renderer, gbuffer, shade, band, exact, layers_behind(
            scene, renderer, shade, band) if blended_objects(scene) else None)  # (the layers over the background)
        exact = False
        ref, low, high = ref + transmission.transmitted, low + transmission.low, high + transmission.high
        if transmission.shadow_band is not None:  # the background's uncertain visibility seen through the glass
            shadow_band = shadow_band | transmission.shadow_band
    blend, cut_mismatch = None, 0
    if blended_objects(scene):  # the layers over the opaque (and transmissive) twin (glphong.checks.blend_twin)
        if exact:
            raise ValueError("exact integrals of extended lights are not computed for scenes with blended materials")
        exact = False
        blend = frame_blend_twin(scene, renderer, (ref, low, high, gbuffer.mask), lambda g: shade(scene, g), band,
                                 transmission)
        ref, low, high, shadow_band = blend.reference, blend.low, blend.high, shadow_band | blend.shadow_band
        covered = blend.coverage > 0.0
        mask = frame.mask & covered
        mismatch = int(((frame.mask != covered) & ~blend.unchecked).sum())
        gpu_cut = np.zeros_like(blend.cut) if frame.blend_cut is None else frame.blend_cut
        cut_mismatch = int(((gpu_cut != blend.cut) & ~blend.unchecked).sum())
    rel, outside = compare(frame.radiance, ref, low, high, mask)
    if exact is None:
        exact = any(light.extent == "extended" for light in scene.lights)
    if isinstance(exact_sample, str) and exact_sample != "auto":
        raise ValueError(f"exact_sample must be a positive whole number of pixels, None or 'auto' (got {exact_sample!r})")
    if exact and isinstance(exact_sample, str):
        exact_sample = auto_sample_size(scene, int(mask.sum()))
    sample = sample_mask(mask, exact_sample, seed) if exact else None
    exact_radiance, exact_error = exact_image(scene, gbuffer, renderer.shadow_settings, sample=sample) if exact else \
        (None, None)
    geometry = tuple(n for n in names if n != "radiance")
    return VerifyReport(gpu=frame.radiance, reference=ref, low=low, high=high, relative_error=rel,
                        outside=outside, mask=mask, mask_mismatch=mismatch, blend=blend,
                        blend_cut_mismatch=cut_mismatch, transmission=transmission,
                        shadow_band=shadow_band, exact=exact_radiance, exact_error=exact_error, exact_sample=sample,
                        passes=verify_passes(scene, frame, geometry, next_scene, previous_scene,
                                             renderer.matte_samples) if geometry else {})


def exact_image(scene, gbuffer, shadows=None, closed_forms=True, sample=None):
    """The radiance of a G-buffer with every extended light's exact integral (float64 quadrature, or the closed forms
    where they are exact, `glphong.checks.reference.exact_reflection`) in place of the shader's method (docs/design.md
    section 13): ``(radiance (H, W, 3), error estimate (H, W))``; ``closed_forms=False``: the quadrature throughout;
    ``sample`` (H, W) bool: at those pixels only (NaN elsewhere)."""
    out = np.zeros(gbuffer.position.shape)
    error = np.zeros(gbuffer.mask.shape)
    if sample is not None:
        out[~sample], error[~sample] = np.nan, np.nan
    for selection, obj, key, u, position, f, n_valid in reference.shade_inputs(scene, gbuffer, shadows=shadows,
                                                                                only=sample):
        def exact(*arguments):  # the exact integrals in place of the shader's methods, keeping the error estimate
            value, error[selection] = reference.exact_reflection(*arguments, lights=scene.lights,
                                                                 closed_forms=closed_forms)
            return value

        out[selection] = reference.shade_point(position, f, n_valid, u.get("u_eye"), key, u, obj.material, exact)
    return out, error


def twin_and_band(scene, gbuffer, band=BAND, shadows=None):
    """The float64 twin of a G-buffer, its tolerance band and the shadow band, in one pass over the objects (the
    shadowing lights' rays are cast once), each object's pixels `TWIN_CHUNK` at a time.

    Returns
    -------
    reference : (H, W, 3) float64 ndarray
        `glphong.checks.reference.shade`.
    low, high : (H, W, 3) float64 ndarray
        `glphong.checks.tolerances.radiance_band`.
    shadow_band : (H, W) bool ndarray
        Pixels where a shadowing light's visibility is uncertain (the band holds it between 0 and 1).
    """
    ref, low, high = (np.zeros(gbuffer.position.shape) for _ in range(3))  # zeroed pages from the kernel, as needed
    shadow_band = np.zeros(gbuffer.mask.shape, bool)
    ref_rows, low_rows, high_rows = (a.reshape(-1, 3) for a in (ref, low, high))  # rows of pixels, written by index
    for selection, obj, key, u, position, f, n_valid in reference.shade_inputs(scene, gbuffer, band=band, shadows=shadows):
        u = UniformValues(u)  # each term's and light's values read once for all the chunks
        pixels = np.flatnonzero(selection)  # in the order of the selection's pixels, as shade_inputs takes them
        step = -(-len(pixels) // -(-len(pixels) // TWIN_CHUNK))  # equal chunks of at most TWIN_CHUNK pixels
        for a in range(0, len(pixels), step):  # each pixel's arithmetic is its own: chunks change no bit
            part = slice(a, a + step)
            here, frame, valid = (position, f, n_valid) if len(pixels) <= step else \
                (position[part], f.select(part), n_valid[part])
            # the lights' directions and irradiance, and the view, computed once for the twin and its band
            lights = reference.incident_light(here, key, u, band=band) if key.num_lights else []
            view = reference.view_direction(here, valid, u.get("u_eye"), key) if key.num_lights else None
            ref_rows[pixels[part]] = reference.shade_point(here, frame, valid, u.get("u_eye"), key, u, obj.material,
                                                           incident=lights, view=view)
            low_rows[pixels[part]], high_rows[pixels[part]] = point_band(key, u, here, frame, valid, obj.material,
                                                                         band, incident=lights, view=view)
        for v in f.visibility or ():
            if v is not None:
                shadow_band.reshape(-1)[pixels[v[1] != v[2]]] = True
    return ref, low, high, shadow_band
