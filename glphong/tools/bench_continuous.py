"""The continuous version in the work-precision report (``glphong bench``; docs/design.md section 13).

The bench's two spheres on a plane lit by one area light: a rectangle or a sphere.  Each method at each knob setting
is scored against the exact integral of the same G-buffer (`glphong.checks.verify.exact_image`, a float64 quadrature
over the light of every term's float64 twin: the reference of the continuous version, as the ray cast is of the
discrete one), over the covered pixels, and timed (median frame time after warm-up), in one process:

- closed forms: Lambert's edge formula and Arvo's recurrence under the rectangle (the lecture's Phong, integer q);
- sampled: the same scene with ``method='sampled'`` (every term over ``samples^2`` cells), knob ``samples``;
- under the sphere: Lambert in closed form, the lobe sampled, knob ``samples``.

Points have the keys of the ray-cast points (`glphong.tools.bench`), the case naming the light and the material.
"""
import numpy as np

from glphong.checks.verify import exact_image
from glphong.core.timing import median_seconds
from glphong.gpu.renderer import Renderer
from glphong.lights import RectLight, SphereLight
from glphong.materials.phong import Phong

__all__ = ["continuous_cases", "continuous_methods", "continuous_points"]


def continuous_cases(quick=False):
    """``(name, light factory, material)``: the rectangle and the sphere, Phong q = 20 and q = 500."""
    rect = lambda samples, method: RectLight((0.0, 1.6, 0.6), (1.6, 0.0, 0.0), (0.0, -0.25, 0.9), 6.0,  # noqa: E731
                                             samples=samples, method=method)
    sphere = lambda samples, method: SphereLight((0.6, 1.2, 1.4), 0.35, 8.0, samples=samples, method=method)  # noqa: E731
    qs = (20.0,) if quick else (20.0, 500.0)
    return [(f"{name} light, Phong q={q:g}", light, Phong((0.18, 0.12, 0.08), 0.6, q)) for name, light in
            (("rect", rect), ("sphere", sphere)) for q in qs]


def continuous_methods(quick=False):
    """``(method name, knob, values, light method)``; a method applies to the cases whose name it names."""
    samples = (1, 2) if quick else (1, 2, 4, 8, 16)
    return [("area light, closed forms (edge formula + Arvo)", "samples", (1,), "auto", "rect"),
            ("area light, sampled (midpoint rule)", "samples", samples, "sampled", "rect"),
            ("sphere light, Lambert exact + lobe sampled", "samples", samples, "auto", "sphere")]


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
        ``bench_scene(material, lights)`` -> the bench's scene (`glphong.tools.bench.BenchCase.scene` geometry).
    width, height, repeats : int
    quick : bool
        Fewer cases and knob values.
    backend : str

    Returns
    -------
    list of dict
    """
    points = []
    with Renderer(width, height, backend=backend) as renderer:
        for case, light, material in continuous_cases(quick):
            exact = None
            for name, knob, values, method, kind in continuous_methods(quick):
                if not case.startswith(kind):
                    continue
                for value in values:
                    scene = bench_scene(material, [light(value, method)])
                    frame = renderer.render(scene)
                    seconds = median_seconds(lambda: renderer.render(scene), repeats)
                    if exact is None:  # one exact image per case: the geometry and the light's extent are the same
                        exact, _ = exact_image(scene, renderer.gbuffer(scene))
                    mask = frame.mask & np.any(exact > 0, axis=-1)
                    points.append({"method": name, "knob": knob, "knob_value": value, "case": case, "seconds": seconds,
                                   **_errors(frame.radiance.astype(np.float64), exact, mask)})
    return points
