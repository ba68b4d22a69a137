"""Frame time on a family of scenes against peers (``glphong bench --speed``).

The family (`speed_scenes`), each at 512x512 and 1024x1024:

- ``sphere``: one sphere covering about 30% of the image (sparse coverage);
- ``plane``: a plane filling the image (every pixel shaded);
- ``100 spheres``: 100 small spheres;
- ``1M triangles``: one mesh of 1,310,720 triangles (an icosphere of level 8);
- ``1000 objects``: 1000 small spheres of 80 triangles, three materials;
- ``8 lights``: the sphere under 8 point lights;
- ``fine plane``: a Phong (q = 50) plane filling the view, subdivided into 131,072 triangles of about two pixels at
  512x512, under one point light (per-pixel arithmetic and small triangles).

Every scene is drawn with Phong and Blinn-Phong materials, ambient light and point lights.  Per scene
and size, in one process and in interleaved rounds (each round renders once with every method), after
warm-up, the median frame time and its spread (the 25th to 75th percentile, relative) of:

- ``glphong float``: `Renderer.render`, one sample, linear float32 radiance with coverage (``numerics='auto'``, the
  default: docs/design.md section 3, "Stability where a scene needs it");
- ``glphong stable``: the same with ``numerics='stable'`` (the stable formulation everywhere);
- ``naive floor``: `glphong.bench.floor.HandWrittenRenderer` with the textbook shader (``pow(dot(v, r),
  q)``, ``normalize``): the same meshes and a float target, uniforms packed once, no culling;
- ``glphong 4x 8-bit``: `Renderer.render_srgb8` with 4x MSAA (the display resolve);
- ``pyrender`` and ``pyrender 2-sided``: pyrender's ``OffscreenRenderer`` at its defaults (4x MSAA on
  EGL, 8-bit, back faces culled) and with ``doubleSided`` materials (nothing culled).

The ratios: glphong float / naive floor; pyrender / glphong 4x 8-bit (above 1: glphong is faster).
`python_per_object` measures glphong's Python overhead per object and frame against the minimal loop
(the floor with glphong's own GLSL, culling off on both sides), `png_cost` the cost of `Frame.save_png`
against the render, `scaling_fits` fitted costs per object, per pixel and light, per triangle.
"""
import io
import math
import os
import statistics
import tempfile
from dataclasses import asdict, dataclass, field

import numpy as np
from PIL import Image

from glphong.scene import primitives
from glphong.scene.camera import PerspectiveCamera
from glphong.lights import AmbientLight, PointLight
from glphong.materials.blinn import BlinnPhong
from glphong.materials.lambert import Lambert
from glphong.materials.phong import Phong
from glphong.scene.scene import Scene
from glphong.core.timing import alternating_times, median_seconds, progress_bar
from glphong.bench.floor import HandWrittenRenderer
from glphong.bench.pyrender_peer import PyrenderRenderer, import_pyrender
from glphong.core.imaging import encode_srgb8
from glphong.core.png import encode_png
from glphong.gpu.renderer import Renderer
from glphong.scene.geometry import MeshData

__all__ = ["SCENES", "speed_scenes", "SpeedReport", "run_speed", "python_per_object", "png_cost", "scaling_fits"]

#: the family, in table order
SCENES = ("sphere", "plane", "100 spheres", "1M triangles", "1000 objects", "8 lights", "fine plane")

_PHONG = Phong(kd=(0.18, 0.12, 0.08), ks=0.5, q=60.0)
_BLINN = BlinnPhong(kd=(0.08, 0.12, 0.18), ks=0.5, q=200.0)


def _translate(x, y, z, scale=1.0):
    pose = np.diag([scale, scale, scale, 1.0])
    pose[:3, 3] = (x, y, z)
    return pose


def _lights(count):
    out = []
    for k in range(count):
        a = 2 * math.pi * k / count + 0.6
        out.append(PointLight((3.0 * math.cos(a), 2.5, 3.0 * math.sin(a) + 2.0), 150.0 / count))
    return out


def _big_mesh(level):
    import trimesh

    return MeshData.from_trimesh(trimesh.creation.icosphere(subdivisions=level, radius=1.0))


def speed_scenes(quick=False):
    """The family as ``{name: Scene}`` (``quick``: the 1M-triangle mesh is 20,480 triangles, 100 objects
    stand for 1000)."""
    camera = PerspectiveCamera.look_at((0.0, 0.0, 4.2), (0.0, 0.0, 0.0), yfov=math.radians(40.0))
    ambient = AmbientLight(0.03)
    scenes = {}
    s = Scene(camera, _lights(2), ambient)
    s.add(primitives.sphere(5, 0.95), _PHONG)
    scenes["sphere"] = s
    s = Scene(PerspectiveCamera.look_at((0.0, 0.0, 1.0), (0.0, 0.0, 0.0), yfov=math.radians(60.0)), _lights(2), ambient)
    s.add(primitives.plane(4.0, 8), _BLINN)
    scenes["plane"] = s
    s = Scene(camera, _lights(2), ambient)
    rng = np.random.default_rng(1)
    small = primitives.sphere(3, 1.0)
    for i in range(100):
        x, y = rng.uniform(-1.6, 1.6, 2)
        s.add(small, _PHONG if i % 2 else _BLINN, pose=_translate(x, y, rng.uniform(-1.0, 0.5), 0.14))
    scenes["100 spheres"] = s
    s = Scene(camera, _lights(2), ambient)
    s.add(_big_mesh(5 if quick else 8), _BLINN)
    scenes["1M triangles"] = s
    s = Scene(camera, _lights(2), ambient)
    tiny = primitives.sphere(1, 1.0)
    materials = (_PHONG, _BLINN, Lambert(0.2))
    count = 100 if quick else 1000
    for i in range(count):
        x, y = rng.uniform(-1.7, 1.7, 2)
        s.add(tiny, materials[i % 3], pose=_translate(x, y, rng.uniform(-1.0, 0.5), 0.05))
    scenes["1000 objects"] = s
    s = Scene(camera, _lights(8), ambient)
    s.add(primitives.sphere(5, 0.95), _PHONG)
    scenes["8 lights"] = s
    s = Scene(PerspectiveCamera.look_at((0.0, 0.0, 1.0), (0.0, 0.0, 0.0), yfov=math.radians(60.0)),
              [PointLight((0.8, 0.6, 1.5), 60.0)], ambient)
    s.add(primitives.plane(4.0, 32 if quick else 256), Phong(kd=(0.18, 0.12, 0.08), ks=0.5, q=50.0))
    scenes["fine plane"] = s
    return scenes


@dataclass
class SpeedReport:
    """The family table and the other measurements of a speed run."""

    renderer: str
    rows: list = field(default_factory=list)
    python_per_object: dict = field(default_factory=dict)
    png: dict = field(default_factory=dict)
    fits: dict = field(default_factory=dict)
    skipped: list = field(default_factory=list)

    def format(self):
        """The tables as text."""
        head = (f"{'scene':14s} {'size':>5s} {'float ms':>9s} {'floor ms':>9s} {'float/floor':>12s} {'stable/floor':>13s} "
                f"{'4x8 ms':>8s} {'pyr ms':>8s} {'pyr/4x8':>8s} {'pyr2s ms':>9s} {'pyr2s/4x8':>10s}  spread")
        lines = [f"frame times on {self.renderer}: median of interleaved rounds after warm-up, spread = "
                 "largest (p75 - p25) / median of the row", head]
        for r in self.rows:
            t = r["ms"]
            pyr = (f"{t['pyrender']:8.1f} {t['pyrender'] / t['glphong 4x 8-bit']:8.2f} "
                   f"{t['pyrender 2-sided']:9.1f} {t['pyrender 2-sided'] / t['glphong 4x 8-bit']:10.2f}") \
                if "pyrender" in t else f"{'-':>8s} {'-':>8s} {'-':>9s} {'-':>10s}"
            lines.append(f"{r['scene']:14s} {r['size']:5d} {t['glphong float']:9.1f} {t['naive floor']:9.1f} "
                         f"{t['glphong float'] / t['naive floor']:12.2f} {t['glphong stable'] / t['naive floor']:13.2f} "
                         f"{t['glphong 4x 8-bit']:8.1f} {pyr}  "
                         f"{max(r['spread'].values()):.0%}")
        if self.python_per_object:
            p = self.python_per_object
            lines.append(f"\nPython per object and frame: {p['us_per_object']:.1f} us ({p['objects']} objects at "
                         f"{p['size']}x{p['size']}: glphong {p['glphong_ms']:.1f} ms, minimal loop {p['floor_ms']:.1f} ms)")
        if self.png:
            p = self.png
            lines.append(f"save_png {p['size']}: {p['save_ms']:.1f} ms = {p['ratio']:.2f} x the render "
                         f"({p['render_ms']:.1f} ms; sRGB encode {p['encode_ms']:.1f} ms, glphong's PNG writer "
                         f"{p['write_ms']:.1f} ms; Pillow at compress_level 1 {p['deflate_ms']:.1f} ms)")
        if self.fits:
            lines.append("\nfitted costs (least squares, glphong float):")
            lines += [f"  {name}: {f['value']:.3g} {f['unit']} (from {f['points']})" for name, f in self.fits.items()]
        lines += [f"skipped: {s}" for s in self.skipped]
        return "\n".join(lines)

    def to_json(self):
        import json

        return json.dumps(asdict(self), indent=1)


def _spread(times):
    q = statistics.quantiles(times, n=4)
    return (q[2] - q[0]) / statistics.median(times)


def run_speed(sizes=(512, 1024), repeats=9, quick=False, pyrender=True, progress=True):
    """Measure the family table (see the module).

    Parameters
    ----------
    sizes : tuple of int
    repeats : int
        Interleaved rounds per scene and size.
    quick : bool
        Small stand-ins (`speed_scenes`), for a test.
    pyrender : bool
        Include pyrender (EGL; skipped with the reason where it is missing).

    Returns
    -------
    SpeedReport
    """

    scenes = speed_scenes(quick)
    report = SpeedReport("")
    pyrender_class = None
    if pyrender:
        try:
            import_pyrender("egl")
            pyrender_class = PyrenderRenderer
        except (ImportError, RuntimeError) as exc:
            report.skipped.append(f"pyrender: {exc}")
    bar = progress_bar(len(sizes) * len(scenes), progress, unit="scene")
    for size in sizes:
        float_renderer = Renderer(size, size, backend="egl")
        stable_renderer = Renderer(size, size, backend="egl", numerics="stable")
        msaa = Renderer(size, size, backend="egl", samples=4)
        report.renderer = float_renderer.context.renderer_name + ", EGL"
        peers = []
        try:
            for name, scene in scenes.items():
                floor = HandWrittenRenderer(size, size, backend="egl", shader="textbook").prepare(scene)
                runs = {"glphong float": lambda s=scene: float_renderer.render(s), "naive floor": floor.render,
                        "glphong stable": lambda s=scene: stable_renderer.render(s),
                        "glphong 4x 8-bit": lambda s=scene: msaa.render_srgb8(s)}
                if pyrender_class is not None:
                    default = pyrender_class(size, size, "egl").prepare(scene)
                    two_sided = pyrender_class(size, size, "egl", double_sided=True).prepare(scene)
                    peers = [default, two_sided]
                    runs |= {"pyrender": default.render, "pyrender 2-sided": two_sided.render}
                try:
                    times = alternating_times(runs, repeats, warmup=2)
                finally:
                    floor.release()
                    for peer in peers:
                        peer.release()
                    peers = []
                report.rows.append({"scene": name, "size": size,
                                    "ms": {k: 1e3 * statistics.median(t) for k, t in times.items()},
                                    "spread": {k: _spread(t) for k, t in times.items()},
                                    "triangles": int(sum(o.mesh.triangle_count for o in scene.objects)),
                                    "objects": len(scene.objects)})
                if bar:
                    bar.update()
        finally:
            float_renderer.release()
            stable_renderer.release()
            msaa.release()
    if bar:
        bar.close()
    report.python_per_object = python_per_object(scenes["1000 objects"], repeats=repeats)
    report.png = png_cost(repeats=repeats)
    report.fits = scaling_fits(quick=quick, repeats=max(5, repeats // 2))
    return report


def python_per_object(scene, size=64, repeats=9):
    """glphong's Python overhead per object and frame: (glphong - minimal loop) / objects, both drawing the
    same programs without culling at a small size (the GPU's share alike), interleaved.

    Returns
    -------
    dict
        ``us_per_object``, ``objects``, ``size``, ``glphong_ms``, ``floor_ms``.
    """

    with Renderer(size, size, backend="egl", culling="off") as renderer:
        floor = HandWrittenRenderer(size, size, backend="egl").prepare(scene)
        try:
            times = alternating_times({"glphong": lambda: renderer.render(scene), "floor": floor.render},
                                      max(repeats, 15), warmup=3)
        finally:
            floor.release()
    g, f = statistics.median(times["glphong"]), statistics.median(times["floor"])
    return {"us_per_object": 1e6 * (g - f) / len(scene.objects), "objects": len(scene.objects), "size": size,
            "glphong_ms": 1e3 * g, "floor_ms": 1e3 * f}


def png_cost(width=640, height=480, repeats=9, scene=None, backend="egl"):
    """`Frame.save_png` (to a temporary file) and its parts against the render of ``scene`` at ``width`` x
    ``height``, in interleaved rounds after warm-up (``glphong bench --speed``; benchmarks/frame_saving.py).

    Parameters
    ----------
    width, height, repeats : int
    scene : glphong.Scene, optional
        Default: the family's ``sphere`` (`speed_scenes`).
    backend : str

    Returns
    -------
    dict
        Median milliseconds: ``render_ms``, ``save_ms`` (`Frame.save_png`), its two parts ``encode_ms`` (the exact
        sRGB encode, `glphong.core.imaging.encode_srgb8`) and ``write_ms`` (glphong's PNG writer,
        `glphong.core.png.encode_png`, zlib level 1), and ``deflate_ms`` (Pillow's PNG writer at the same level, for
        comparison); ``ratio`` (save / render), ``size`` (``'WxH'``) and the file sizes ``png_bytes`` (glphong's)
        and ``pillow_bytes``.
    """
    scene = speed_scenes(quick=True)["sphere"] if scene is None else scene
    with Renderer(width, height, backend=backend) as renderer, tempfile.TemporaryDirectory() as folder:
        frame = renderer.render(scene)
        codes = encode_srgb8(frame.radiance)
        path = os.path.join(folder, "frame.png")

        def pillow():
            out = io.BytesIO()
            Image.fromarray(codes).save(out, format="PNG", compress_level=1)
            return out

        times = alternating_times({
            "render": lambda: renderer.render(scene),
            "save": lambda: frame.save_png(path),
            "encode": lambda: encode_srgb8(frame.radiance),
            "write": lambda: encode_png(codes, 1),
            "deflate": pillow},
            repeats, warmup=2)
        sizes = {"png_bytes": len(encode_png(codes, 1)), "pillow_bytes": len(pillow().getvalue())}
    ms = {k: 1e3 * statistics.median(t) for k, t in times.items()}
    return {"render_ms": ms["render"], "save_ms": ms["save"], "encode_ms": ms["encode"], "write_ms": ms["write"],
            "deflate_ms": ms["deflate"], "ratio": ms["save"] / ms["render"], "size": f"{width}x{height}", **sizes}


def scaling_fits(quick=False, repeats=5):
    """Fitted costs of glphong's float render (EGL), by least squares on frame times:

    - per object: the ``1000 objects`` family at 100 to 1000 objects (64x64);
    - per pixel and light: the full-screen plane at 256^2 to 1024^2 pixels with 1, 2, 4 and 8 lights;
    - per triangle: icospheres of 20k to 1.3M triangles covering 30% of a 256x256 image.

    Returns
    -------
    dict of str to dict
        ``value``, ``unit``, ``points`` (what was fitted).
    """

    def slope(x, t):
        return float(np.polyfit(np.asarray(x, float), np.asarray(t, float), 1)[0])

    fits = {}
    base = speed_scenes(quick=True)
    counts = (20, 100) if quick else (100, 250, 500, 1000)
    times = []
    with Renderer(64, 64, backend="egl") as r:
        for n in counts:
            s = Scene(base["sphere"].camera, _lights(2), AmbientLight(0.03))
            tiny = primitives.sphere(1, 1.0)
            rng = np.random.default_rng(2)
            for i in range(n):
                x, y = rng.uniform(-1.7, 1.7, 2)
                s.add(tiny, (_PHONG, _BLINN)[i % 2], pose=_translate(x, y, 0.0, 0.05))
            times.append(median_seconds(lambda s=s: r.render(s), repeats, warmup=2))
    fits["per object"] = {"value": 1e6 * slope(counts, times), "unit": "us", "points": f"{counts} objects, 64x64"}
    sizes = (64, 128) if quick else (256, 512, 1024)
    lights = (1, 2) if quick else (1, 2, 4, 8)
    x, t = [], []
    for size in sizes:
        with Renderer(size, size, backend="egl") as r:
            for n in lights:
                s = Scene(base["plane"].camera, _lights(n), AmbientLight(0.03))
                s.add(primitives.plane(4.0, 8), _BLINN)
                x.append(size * size * n)
                t.append(median_seconds(lambda s=s: r.render(s), repeats, warmup=2))
    fits["per pixel and light"] = {"value": 1e9 * slope(x, t), "unit": "ns",
                                   "points": f"full-screen plane, {sizes} pixels squared x {lights} lights"}
    levels = (3, 4) if quick else (5, 6, 7, 8)
    x, t = [], []
    with Renderer(256, 256, backend="egl") as r:
        for level in levels:
            s = Scene(base["sphere"].camera, _lights(2), AmbientLight(0.03))
            s.add(_big_mesh(level), _BLINN, pose=_translate(0.0, 0.0, 0.0, 0.95))
            x.append(s.objects[0].mesh.triangle_count)
            t.append(median_seconds(lambda s=s: r.render(s), repeats, warmup=2))
    fits["per triangle"] = {"value": 1e9 * slope(x, t), "unit": "ns", "points": f"icospheres of {x} triangles, 256x256"}
    return fits
