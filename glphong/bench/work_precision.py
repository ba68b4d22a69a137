"""Error against run time: the work-precision report (``glphong bench``).

A fixed scene family (two spheres on a plane, Phong and Blinn, q from 10 to 1e5, 1 or 8 point
lights) is rendered by every method at each setting of its accuracy knob.  Each image is
compared with a converged float64 ray cast of the exact geometry (`glphong.checks.raycast`): relative
RMS, p99 and max error over pixels both cover, silhouette pixels counted apart.  Each method's
frame time is the median of repeated runs after a warm-up, all in one process.  Outputs: a CSV
and a JSON of every point, a work-precision diagram (log error against log time, one curve per
method, matplotlib), a scaling table (frame time against pixels, triangles and lights) and the
speed ratios against a hand-written moderngl floor and against pyrender.
"""
import csv
import json
import math
from dataclasses import asdict, dataclass, field

import numpy as np

from glphong.scene import primitives
from glphong.scene.camera import PerspectiveCamera
from glphong.lights import AmbientLight, PointLight
from glphong.materials.blinn import BlinnPhong
from glphong.materials.phong import Phong
from glphong.scene.scene import Scene
from glphong.core.timing import alternating_medians, median_seconds, progress_bar
from glphong.bench.continuous import continuous_points
from glphong.bench.floor import HandWrittenRenderer
from glphong.bench.matte import MATTE_SAMPLE_VALUES, format_matte, matte_points
from glphong.bench.pyrender_peer import PyrenderRenderer, pyrender_decode, pyrender_unavailable
from glphong.checks import reference as ref
from glphong.checks.raycast import AnalyticObject, Plane, Sphere, compare_to_reference, render_reference
from glphong.gpu.contexts import available_backends
from glphong.gpu.renderer import Renderer

__all__ = ["BenchCase", "standard_cases", "quick_cases", "Method", "methods", "run_bench", "BenchReport",
           "scaling_table", "speed_targets", "family_camera", "family_scene", "SPHERES", "PLANE_Y", "PLANE_SIZE"]

SPHERES = (((-0.75, 0.0, 0.0), 0.65), ((0.8, -0.15, 0.3), 0.5))
PLANE_Y = -0.65
PLANE_SIZE = 6.0


@dataclass(frozen=True)
class BenchCase:
    """One scene of the family.

    Attributes
    ----------
    family : {'phong', 'blinn'}
    q : float
    lights : int
        Number of point lights (1 to 8).
    """

    family: str
    q: float
    lights: int

    @property
    def name(self):
        return f"{self.family} q={self.q:g} lights={self.lights}"

    def material(self):
        cls = {"phong": Phong, "blinn": BlinnPhong}[self.family]  # the family's label -> its material class
        return cls(kd=(0.18, 0.12, 0.08), ks=0.6, q=self.q, ka=0.003)

    def camera(self):
        return family_camera()

    def light_list(self):
        out = []
        for k in range(self.lights):
            a = 2 * math.pi * k / self.lights + 0.6
            out.append(PointLight((2.5 * math.cos(a), 2.5 + 0.3 * k, 2.5 * math.sin(a) + 1.5), 120.0 / self.lights))
        return out

    def scene(self, tessellation):
        """The scene with spheres tessellated at ``tessellation`` (icosphere level) and a plane
        of ``2^tessellation`` segments per side."""
        return family_scene(self.material(), self.light_list(), tessellation, AmbientLight(0.02))

    def analytic_objects(self):
        """The exact geometry for `glphong.checks.raycast.render_reference`."""

        material = self.material()
        objects = [AnalyticObject(Sphere(center, radius), material) for center, radius in SPHERES]
        objects.append(AnalyticObject(Plane((0.0, PLANE_Y, 0.0), (0.0, 1.0, 0.0), PLANE_SIZE / 2), material))
        return objects


def family_camera():
    """The family's camera."""
    return PerspectiveCamera.look_at((0.0, 1.6, 4.2), (0.0, -0.2, 0.0), yfov=math.radians(40.0))


def family_scene(material, lights, tessellation=4, ambient=None):
    """The family's geometry (two spheres on a plane, the bench's camera) drawn with ``material`` under ``lights``:
    spheres tessellated at ``tessellation`` (icosphere level), a plane of ``2^tessellation`` segments per side."""
    scene = Scene(family_camera(), lights=lights, ambient=ambient)
    for center, radius in SPHERES:
        pose = np.eye(4)
        pose[:3, 3] = center
        scene.add(primitives.sphere(tessellation, radius), material, pose=pose)
    pose = np.eye(4)
    pose[:3, :3] = [[1, 0, 0], [0, 0, 1], [0, -1, 0]]  # z-up plane -> y-up
    pose[1, 3] = PLANE_Y
    scene.add(primitives.plane(PLANE_SIZE, 2 ** min(tessellation, 7)), material, pose=pose)
    return scene


def standard_cases():
    """The full family: Phong and Blinn, q in {10, 1e3, 1e5}, 1 and 8 lights (12 scenes)."""
    return [BenchCase(f, q, n) for f in ("phong", "blinn") for q in (10.0, 1e3, 1e5) for n in (1, 8)]


def quick_cases():
    """A tiny family for tests: one Phong and one Blinn scene."""
    return [BenchCase("phong", 100.0, 1), BenchCase("blinn", 1e4, 2)]


@dataclass(frozen=True)
class Method:
    """A way to produce an image, with its accuracy knob.

    Attributes
    ----------
    name : str
    knob : str
        'tessellation' or 'supersample'.
    values : tuple
        Knob settings, cheapest first.
    kind : str
        'glphong', 'twin', 'floor' or 'pyrender'.
    options : dict
        Renderer options (backend, shading, samples, ...), or the twin's dtype.
    """

    name: str
    knob: str
    values: tuple
    kind: str
    options: dict = field(default_factory=dict)


def methods(quick=False):
    """The methods of the report (fewer knob settings with ``quick``)."""
    tess = (2, 4) if quick else (1, 2, 3, 4, 5, 6)
    few = (2, 4) if quick else (2, 4, 6)
    return [
        Method("per-pixel GLSL, EGL", "tessellation", tess, "glphong", {"backend": "egl"}),
        Method("per-pixel GLSL, OSMesa", "tessellation", few, "glphong", {"backend": "osmesa"}),
        Method("Gouraud GLSL, EGL", "tessellation", tess, "glphong", {"backend": "egl", "shading": "vertex"}),
        Method("per-pixel GLSL, supersampled, EGL", "supersample", (1, 2) if quick else (1, 2, 3, 4), "glphong",
               {"backend": "egl", "tessellation": 4 if quick else 6}),
        Method("per-pixel GLSL, 4x MSAA, EGL", "tessellation", few, "glphong", {"backend": "egl", "samples": 4}),
        Method("numpy twin float32 (on the GPU G-buffer)", "tessellation", few, "twin", {"dtype": "float32"}),
        Method("numpy twin float64 (on the GPU G-buffer)", "tessellation", few, "twin", {"dtype": "float64"}),
        Method("hand-written moderngl floor, EGL", "tessellation", few, "floor", {"backend": "egl"}),
        Method("pyrender 4x MSAA, 8-bit, EGL", "tessellation", few, "pyrender", {"platform": "egl"}),
    ]


@dataclass
class BenchReport:
    """Every measured point and the derived tables."""

    width: int
    height: int
    points: list = field(default_factory=list)
    scaling: list = field(default_factory=list)
    targets: list = field(default_factory=list)
    skipped: list = field(default_factory=list)
    matte: list = field(default_factory=list)

    def curves(self):
        """Per method and knob value: geometric-mean relative RMS over the cases and mean frame time."""
        out = {}
        for p in self.points:
            out.setdefault((p["method"], p["knob_value"]), []).append(p)
        rows = []
        for (method, value), pts in out.items():
            errors = [max(p["relative_rms"], 1e-12) for p in pts]
            rows.append({"method": method, "knob": pts[0]["knob"], "knob_value": value,
                         "relative_rms": float(np.exp(np.mean(np.log(errors)))),
                         "p99_relative": float(np.median([p["p99_relative"] for p in pts])),
                         "seconds": float(np.mean([p["seconds"] for p in pts])), "cases": len(pts)})
        return rows

    def write(self, prefix):
        """Write ``prefix.csv`` (every point), ``prefix.json`` (everything) and ``prefix.png`` (diagram)."""
        with open(f"{prefix}.csv", "w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=list(self.points[0]))
            writer.writeheader()
            writer.writerows(self.points)
        with open(f"{prefix}.json", "w") as f:
            json.dump(asdict(self) | {"curves": self.curves()}, f, indent=1)
        self.plot(f"{prefix}.png")
        return [f"{prefix}.csv", f"{prefix}.json", f"{prefix}.png"]

    def plot(self, path):
        """The work-precision diagram: log relative RMS error against log frame time."""
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(8.5, 5.5), dpi=110)
        curves = {}
        for row in self.curves():
            curves.setdefault(row["method"], []).append(row)
        for method, rows in curves.items():
            rows.sort(key=lambda r: r["knob_value"])
            ax.loglog([1000 * r["seconds"] for r in rows], [r["relative_rms"] for r in rows], "o-", label=method)
            for r in rows:
                ax.annotate(f"{r['knob'][0]}{r['knob_value']}", (1000 * r["seconds"], r["relative_rms"]),
                            fontsize=6, xytext=(3, 3), textcoords="offset points")
        ax.set_xlabel(f"frame time [ms] ({self.width}x{self.height}, median after warm-up)")
        ax.set_ylabel("relative RMS error vs the exact reference (ray cast; area lights: exact integral)")
        ax.set_title("glphong work-precision (t = tessellation level, s = supersampling factor)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(path)
        plt.close(fig)

    def format_tables(self):
        """The curves, the scaling table and the speed targets as text."""
        lines = [f"work-precision points ({self.width}x{self.height}; error: geometric mean over cases):",
                 f"{'method':44s} {'knob':>14s} {'rel RMS':>10s} {'p99':>10s} {'ms':>9s}"]
        for r in self.curves():
            lines.append(f"{r['method']:44s} {r['knob'] + '=' + str(r['knob_value']):>14s} {r['relative_rms']:10.3g} "
                         f"{r['p99_relative']:10.3g} {1000 * r['seconds']:9.2f}")
        if self.scaling:
            lines.append("\nscaling (per-pixel GLSL, EGL):")
            lines += [f"  {s['axis']:10s} {s['value']:>10} -> {1000 * s['seconds']:8.2f} ms" for s in self.scaling]
        if self.targets:
            lines.append("\nspeed (same process, median after warm-up, readback included):")
            lines += [f"  {t['name']:58s} {t['value']:6.2f}{t['unit']}   ({t['detail']})" for t in self.targets]
        if self.matte:
            lines += ["", format_matte(self.matte)]
        lines += [f"skipped: {s}" for s in self.skipped]
        return "\n".join(lines)


def _glphong_runner(method, width, height, value):
    opts = dict(method.options)
    tessellation = opts.pop("tessellation", value if method.knob == "tessellation" else 4)
    supersample = value if method.knob == "supersample" else 1
    renderer = Renderer(width, height, supersample=supersample, **opts)
    return renderer, tessellation


def _measure(method, case, value, width, height, reference, repeats):
    """Render one case with one method at one knob value: (image, mask, seconds, cleanup)."""

    if method.kind == "glphong":
        renderer, tessellation = _glphong_runner(method, width, height, value)
        try:
            scene = case.scene(tessellation)
            frame = renderer.render(scene)
            seconds = median_seconds(lambda: renderer.render(scene), repeats)
            image, mask = frame.radiance, frame.mask
        finally:
            renderer.release()
    elif method.kind == "twin":
        dtype = np.dtype(method.options["dtype"])
        with Renderer(width, height, backend="egl") as renderer:
            scene = case.scene(value)

            def run():
                return ref.shade(scene, renderer.gbuffer(scene), dtype=dtype)

            image = run().astype(np.float64)
            seconds = median_seconds(run, max(1, repeats // 3), warmup=1)
            mask = renderer.gbuffer(scene).mask
    elif method.kind == "floor":
        floor = HandWrittenRenderer(width, height, backend=method.options["backend"])
        try:
            floor.prepare(case.scene(value))
            image = floor.render()
            seconds = median_seconds(floor.render, repeats)
            mask = np.any(image != 0, axis=-1)
        finally:
            floor.release()
    else:  # pyrender

        renderer = PyrenderRenderer(width, height, platform=method.options["platform"])
        try:
            renderer.prepare(case.scene(value))
            rgb8 = renderer.render()
            seconds = median_seconds(renderer.render, repeats)
            image = pyrender_decode(rgb8)  # pyrender clamps and encodes x^(1/2.2), not the sRGB curve: undo that
            mask = np.any(rgb8 != 0, axis=-1)
        finally:
            renderer.release()
    # p99 and max over pixels whose reference exceeds 1% of the image maximum (terminator pixels fade to 0)
    errors = compare_to_reference(np.asarray(image, dtype=np.float64), mask, reference, relative_floor=1e-2)
    return {"method": method.name, "knob": method.knob, "knob_value": value, "case": case.name,
            "seconds": seconds, **errors}


def _available(method):
    """None if the method can run here, else the reason."""

    if method.kind == "pyrender":
        reason = pyrender_unavailable(method.options["platform"])  # imports nothing: that would fix PyOpenGL's platform
        if reason is not None:
            return f"{method.name}: {reason}"
    backend = method.options.get("backend", "egl")
    reason = available_backends().get(backend)
    return None if reason is None else f"{method.name}: backend {backend} unavailable: {reason}"


def run_bench(width=256, height=192, cases=None, method_list=None, repeats=5, reference_samples=6,
              scaling=True, targets=True, progress=True, continuous=True, matte=True):
    """Run the work-precision report.

    Parameters
    ----------
    width, height : int
        Image size of the family.
    cases : list of BenchCase, optional
        Default `standard_cases`.
    method_list : list of Method, optional
        Default `methods`.
    repeats : int
        Timed repeats per point (median).
    reference_samples : int
        Ray-cast samples per pixel axis of the converged reference.
    scaling, targets : bool
        Also measure the scaling table and the speed ratios.
    continuous : bool
        Also the area lights' methods against their exact integrals (`glphong.bench.continuous`).
    matte : bool
        Also the matte pass's error against run time (`glphong.bench.matte`).
    progress : bool
        Show a tqdm progress bar (when tqdm is installed).

    Returns
    -------
    BenchReport
    """

    cases = standard_cases() if cases is None else cases
    method_list = methods() if method_list is None else method_list
    report = BenchReport(width, height)
    runnable = []
    for m in method_list:
        reason = _available(m)
        if reason:
            report.skipped.append(reason)
        else:
            runnable.append(m)
    bar = progress_bar(len(cases) * sum(len(m.values) for m in runnable), progress)
    for case in cases:
        reference = render_reference(case.camera(), case.analytic_objects(), case.light_list(), AmbientLight(0.02),
                                     width, height, samples_per_axis=reference_samples)
        for m in runnable:
            for value in m.values:
                report.points.append(_measure(m, case, value, width, height, reference, repeats))
                if bar:
                    bar.update()
    if bar:
        bar.close()
    if continuous:  # the lecture's continuous version: area lights against their exact integrals
        report.points += continuous_points(family_scene, width, height, repeats, quick=len(cases) <= 2)
    if matte:
        report.matte = matte_points(samples=(4, 32) if len(cases) <= 2 else MATTE_SAMPLE_VALUES, repeats=repeats)
    if scaling:
        report.scaling = scaling_table(repeats=repeats, quick=len(cases) <= 2)
    if targets:
        report.targets, skipped = speed_targets(repeats=repeats, quick=len(cases) <= 2)
        report.skipped += skipped
    return report


def scaling_table(repeats=5, quick=False):
    """Frame time of per-pixel GLSL (EGL) against pixel count, triangle count and light count."""

    rows = []
    case = BenchCase("phong", 100.0, 1)
    sizes = (64, 128) if quick else (128, 256, 512, 1024)
    levels = (1, 3) if quick else (2, 3, 4, 5, 6, 7)
    lights = (1, 2) if quick else (1, 2, 4, 8)
    scene = case.scene(4)
    for size in sizes:
        with Renderer(size, size, backend="egl") as r:
            rows.append({"axis": "pixels", "value": size * size, "seconds": median_seconds(lambda: r.render(scene), repeats)})
    with Renderer(256, 256, backend="egl") as r:
        for level in levels:
            s = case.scene(level)
            triangles = sum(o.mesh.triangle_count for o in s.objects)
            rows.append({"axis": "triangles", "value": triangles, "seconds": median_seconds(lambda: r.render(s), repeats)})
        for n in lights:
            s = BenchCase("phong", 100.0, n).scene(4)
            rows.append({"axis": "lights", "value": n, "seconds": median_seconds(lambda: r.render(s), repeats)})
    return rows


def speed_targets(repeats=7, quick=False):
    """Frame-time ratios measured in one process: glphong against the hand-written moderngl floor
    (same GLSL, float readback) and against pyrender (4x MSAA, 8-bit output), plus the float64 twin's
    throughput.  At least 21 alternating repeats per ratio.

    Returns
    -------
    rows : list of dict
    skipped : list of str
    """

    rows, skipped = [], []
    repeats = max(repeats, 21)  # ratios of frames ~10 ms apart need many alternating repeats on 2 shared cores
    case = BenchCase("phong", 100.0, 1)
    scene = case.scene(4)
    for size in ((128,) if quick else (512, 1024)):
        with Renderer(size, size, backend="egl") as r:
            floor = HandWrittenRenderer(size, size, backend="egl")
            textbook = HandWrittenRenderer(size, size, backend="egl", shader="textbook")
            try:
                floor.prepare(scene)
                textbook.prepare(scene)
                t = alternating_medians({"glphong": lambda: r.render(scene), "floor": floor.render,
                                         "textbook": textbook.render}, repeats)
            finally:
                floor.release()
                textbook.release()
            rows.append({"name": f"glphong / hand-written moderngl floor, {size}x{size}", "value": t["glphong"] / t["floor"],
                         "unit": "x",
                         "detail": f"{1000 * t['glphong']:.1f} ms vs {1000 * t['floor']:.1f} ms, same GLSL, float32 readback"})
            rows.append({"name": f"glphong / hand-written textbook-shader floor, {size}x{size}",
                         "value": t["glphong"] / t["textbook"], "unit": "x",
                         "detail": f"{1000 * t['glphong']:.1f} ms vs {1000 * t['textbook']:.1f} ms: the price of the stable formulation"})
        try:
            pyr = PyrenderRenderer(size, size, platform="egl")
        except (ImportError, RuntimeError) as exc:
            skipped.append(f"pyrender speed ratio at {size}x{size}: {exc}")
            continue
        with Renderer(size, size, backend="egl", samples=4) as r:
            try:
                pyr.prepare(scene)
                t = alternating_medians({"glphong": lambda: r.render_srgb8(scene), "pyrender": pyr.render}, repeats)
            finally:
                pyr.release()
            rows.append({"name": f"pyrender / glphong, 4x MSAA, 8-bit output, {size}x{size}",
                         "value": t["pyrender"] / t["glphong"], "unit": "x",
                         "detail": f"{1000 * t['pyrender']:.1f} ms vs {1000 * t['glphong']:.1f} ms"})
    size = 128 if quick else 512
    big = BenchCase("phong", 100.0, 8).scene(4)
    with Renderer(size, size, backend="egl") as r:
        g = r.gbuffer(big)
        seconds = median_seconds(lambda: ref.shade(big, g), max(1, repeats // 2), warmup=1)
    rate = g.mask.sum() * 8 / seconds / 1e6
    rows.append({"name": f"float64 twin throughput, {size}x{size}, 8 lights", "value": rate, "unit": " Mpx-lights/s",
                 "detail": f"{1000 * seconds:.0f} ms for {int(g.mask.sum())} covered pixels x 8 lights"})
    return rows, skipped
