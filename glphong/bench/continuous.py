"""The continuous version in the work-precision report (``glphong bench``; docs/design.md section 13).

The bench's two spheres on a plane lit by one extended light: a rectangle, a sphere or a sky.  Each method at each
knob setting is scored against the exact integral of the same G-buffer (`glphong.checks.verify.exact_image`, a
float64 quadrature over the light of every term's float64 twin: the reference of the continuous version, as the ray
cast is of the discrete one), over the covered pixels, and timed (median frame time after warm-up), in one process:

- closed forms: Lambert's edge formula and Arvo's recurrence under the rectangle (the lecture's Phong, integer q);
- sampled: the same scene with ``method='sampled'`` (every term over ``samples^2`` cells), knob ``samples``;
- under the sphere: Lambert in closed form, the lobe sampled, knob ``samples``;
- under the sky (`sky_map`, y up): the irradiance cube map (knob ``resolution``) and the harmonics' lobe (knob
  ``order``), the harmonics for both (``irradiance='sh'``, knob ``order``), and the averaged map for every term
  (``method='sampled'``, knob ``samples``).  The sky's exact integral costs about 35 ms a pixel, so its errors are
  measured on a 64 x 48 rendering of the same scene (24 x 18 quick) and its frame times at the bench's size.

Points have the keys of the ray-cast points (`glphong.bench.work_precision`), the case naming the light and the material.
"""
from contextlib import ExitStack

import numpy as np

from glphong.checks.verify import exact_image
from glphong.core.timing import median_seconds
from glphong.gpu.renderer import Renderer
from glphong.lights import EnvironmentLight, RectLight, SphereLight
from glphong.lights.environment import Y_UP
from glphong.materials.phong import Phong
from glphong.twin.environment import texel_directions

__all__ = ["continuous_cases", "continuous_methods", "continuous_points", "sky_map"]


def sky_map(height=32):
    """The bench's sky, ``height x 2 height`` texels [W/(m^2 sr)]: blue brightening toward the zenith, a white
    horizon band and a sun of 2000 over 3 x 3 texels at 35 deg elevation."""
    d = texel_directions(height, 2 * height)
    up = np.maximum(d[..., 2], 0.0)[..., None]
    sky = 0.3 + 0.7 * up * np.array([0.35, 0.55, 1.0]) + 0.4 * np.exp(-np.abs(d[..., 2:]) * 8.0)
    row, col = int(round(height * (55.0 / 180.0))), height // 3
    sky[row - 1:row + 2, col - 1:col + 2] = 2000.0
    return sky


def continuous_cases(quick=False):
    """``(name, light factory, material, scored_on)``: the rectangle, the sphere and the sky, Phong q = 20 and q = 500
    (the sky: q = 20); ``scored_on`` the image size the errors are measured on, None for the bench's own (the sky's
    exact integral costs about 35 ms a pixel: 64 x 48, 24 x 18 quick)."""
    rect = lambda **kw: RectLight((0.0, 1.6, 0.6), (1.6, 0.0, 0.0), (0.0, -0.25, 0.9), 6.0, **kw)  # noqa: E731
    sphere = lambda **kw: SphereLight((0.6, 1.2, 1.4), 0.35, 8.0, **kw)  # noqa: E731
    sky = sky_map(16 if quick else 32)
    environment = lambda **kw: EnvironmentLight(sky, rotation=Y_UP, scale=0.05, **kw)  # noqa: E731
    qs = (20.0,) if quick else (20.0, 500.0)
    return [(f"{name} light, Phong q={q:g}", light, Phong((0.18, 0.12, 0.08), 0.6, q), None) for name, light in
            (("rect", rect), ("sphere", sphere)) for q in qs] + \
        [("environment light, Phong q=20", environment, Phong((0.18, 0.12, 0.08), 0.6, 20.0),
          (24, 18) if quick else (64, 48))]


def continuous_methods(quick=False):
    """``(method name, knob, values, fixed options, light)``; a method applies to the cases whose name starts with
    its light."""
    samples = (1, 2) if quick else (1, 2, 4, 8, 16)
    return [("area light, closed forms (edge formula + Arvo)", "samples", (1,), {}, "rect"),
            ("area light, sampled (midpoint rule)", "samples", samples, {"method": "sampled"}, "rect"),
            ("sphere light, Lambert exact + lobe sampled", "samples", samples, {}, "sphere"),
            ("environment, irradiance map + harmonics lobe", "order", (2, 8) if quick else (2, 4, 8, 16),
             {"resolution": 17}, "environment"),
            ("environment, irradiance map resolution", "resolution", (3, 9) if quick else (3, 5, 9, 17),
             {"order": 16}, "environment"),
            ("environment, harmonics for both", "order", (2,) if quick else (2, 4, 8, 16), {"irradiance": "sh"},
             "environment"),
            ("environment, averaged map (sampled)", "samples", (1, 2) if quick else (1, 2, 4, 8, 16),
             {"method": "sampled"}, "environment")]


def _errors(image, exact, mask):
    err = np.linalg.norm(image - exact, axis=-1)[mask]
    mag = np.linalg.norm(exact, axis=-1)[mask]
    bright = mag > 1e-2 * mag.max()
    rel = err[bright] / mag[bright]
    return {"relative_rms": float(np.sqrt(np.sum(err ** 2) / np.sum(mag ** 2))),
            "p99_relative": float(np.percentile(rel, 99)), "max_relative": float(rel.max()),
            "interior_pixels": int(mask.sum()), "relative_pixels": int(bright.sum())}


def continuous_points(bench_scene, width, height, repeats=5, quick=False, backend="egl"):
    """Every (method, knob value, case) point of the continuous version.

    Parameters
    ----------
    bench_scene : callable
        ``bench_scene(material, lights)`` -> the bench's scene (`glphong.bench.work_precision.family_scene`).
    width, height, repeats : int
    quick : bool
        Fewer cases and knob values.
    backend : str

    Returns
    -------
    list of dict
    """
    points = []
    scorers = {}
    with ExitStack() as stack:
        renderer = stack.enter_context(Renderer(width, height, backend=backend))
        for case, light, material, scored_on in continuous_cases(quick):
            exact = None
            if scored_on is not None and scored_on not in scorers:
                scorers[scored_on] = stack.enter_context(Renderer(*scored_on, backend=backend))
            scoring = renderer if scored_on is None else scorers[scored_on]
            for name, knob, values, options, kind in continuous_methods(quick):
                if not case.startswith(kind):
                    continue
                for value in values:
                    scene = bench_scene(material, [light(**{knob: value}, **options)])
                    renderer.render(scene)
                    seconds = median_seconds(lambda: renderer.render(scene), repeats)
                    frame = scoring.render(scene)
                    if exact is None:  # one exact image per case: the geometry and the light are the same
                        exact, _ = exact_image(scene, scoring.gbuffer(scene))
                    mask = frame.mask & np.any(exact > 0, axis=-1)
                    points.append({"method": name, "knob": knob, "knob_value": value, "case": case, "seconds": seconds,
                                   **_errors(frame.radiance.astype(np.float64), exact, mask)})
    return points
