"""What saving a frame as PNG costs against rendering it (issue 29, part 2).

Usage: python benchmarks/frame_saving.py [--size WxH] [--repeats N] [--frames N] [--backend egl|osmesa] [--floor]

One process, interleaved rounds, medians:

- the render of a 640x480 frame (a Phong sphere on a Lambert floor, one point light; ``Renderer.render``);
- ``Frame.save_png`` of it (the exact sRGB encode in row blocks on threads, then glphong's PNG writer), and its two
  parts;
- the same image through Pillow at the same zlib level (1), for the PNG writer's comparison
  (these four: `glphong.bench.png_cost`, which ``glphong bench --speed`` reports too);
- with ``--floor`` (instead of the turntables), the floor under a save, interleaved with the render and the save:
  the contiguous copy of the radiance (a strided view of the RGBA read-back), that copy and one table lookup per value (``np.take``
  of a byte table by the values' top 20 bits: the least an exact per-value encode does), and zlib at level 1 of
  the encoded image's bytes in one call (the deflate's share, one thread);
- a turntable of ``--frames`` frames through `glphong.batch.render_many` (worker processes, each rendering the next frame
  while its writer thread encodes and writes the last) as PNG and as ``.npy`` (a raw copy: the render's own cost).
"""
import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

import glphong
from glphong.batch import render_many
from glphong.bench import png_cost


def scene(angle=0.0):
    """The benchmark's scene, its camera turned by ``angle`` degrees (a picklable ``scene_fn``)."""
    a = np.radians(angle)
    out = glphong.Scene(glphong.PerspectiveCamera.look_at((4 * np.sin(a), 1.0, 4 * np.cos(a)), (0, 0, 0)),
                        lights=[glphong.PointLight((2, 3, 4), 300.0)], ambient=glphong.AmbientLight(0.02))
    out.add(glphong.primitives.sphere(4), glphong.Phong(0.2, 0.5, 40.0))
    out.add(glphong.primitives.plane(10.0), glphong.Lambert(0.2))
    return out


def floor(width, height, repeats, backend):
    """Print the floor under `Frame.save_png` against the render and the save (see the module), medians [ms]."""
    import statistics
    import zlib

    from glphong.core.imaging import encode_srgb8
    from glphong.core.timing import alternating_times

    table = np.zeros(1 << 20, np.uint8)
    with tempfile.TemporaryDirectory() as folder, glphong.Renderer(width, height, backend=backend) as renderer:
        shown = scene()
        frame = renderer.render(shown)
        codes = encode_srgb8(frame.radiance).tobytes()
        times = alternating_times({
            "render": lambda: renderer.render(shown), "save_png": lambda: frame.save_png(Path(folder) / "f.png"),
            "contiguous copy": lambda: np.ascontiguousarray(frame.radiance),
            "copy and one table lookup": lambda: np.take(table, np.ascontiguousarray(frame.radiance).view(np.uint32) >> 12),
            "zlib level 1": lambda: zlib.compress(codes, 1)}, repeats, warmup=2)
    ms = {k: 1e3 * statistics.median(t) for k, t in times.items()}
    print("| floor step | ms | / render |")
    print("|---|---|---|")
    for name, value in ms.items():
        print(f"| {name} | {value:.2f} | {value / ms['render']:.2f} |")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--size", default="640x480")
    parser.add_argument("--repeats", type=int, default=20)
    parser.add_argument("--frames", type=int, default=48)
    parser.add_argument("--backend", default="egl")
    parser.add_argument("--floor", action="store_true", help="the floor under a save (see the module)")
    args = parser.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
    cost = png_cost(width, height, args.repeats, scene=scene(), backend=args.backend)
    print(f"{width}x{height}, {args.backend}, {args.repeats} interleaved rounds after warm-up (median)")
    print("| step | ms | / render |")
    print("|---|---|---|")
    for name, key in (("render", "render_ms"), ("save_png", "save_ms"), ("encode_srgb8", "encode_ms"),
                      ("encode_png", "write_ms"), ("pillow_png", "deflate_ms")):
        print(f"| {name} | {cost[key]:.2f} | {cost[key] / cost['render_ms']:.2f} |")
    print(f"PNG size: glphong {cost['png_bytes']} bytes, Pillow {cost['pillow_bytes']} bytes (zlib level 1 both)")
    if args.floor:
        floor(width, height, args.repeats, args.backend)
        return

    # one process, one renderer: frames per second rendering alone, saving each PNG after its render, and saving on a
    # writer thread while the next frame renders (what render_many's workers do)
    from concurrent.futures import ThreadPoolExecutor

    scenes = [scene(360.0 * k / args.frames) for k in range(args.frames)]
    loop = {}
    with tempfile.TemporaryDirectory() as folder, glphong.Renderer(width, height, backend=args.backend) as renderer, \
            ThreadPoolExecutor(1) as writer:
        renderer.render(scenes[0])
        for _ in range(2):
            for mode in ("render", "serial", "overlapped"):
                start, pending = time.perf_counter(), None
                for k, sc in enumerate(scenes):
                    frame = renderer.render(sc)
                    target = Path(folder) / f"{k}.png"
                    if mode == "serial":
                        frame.save_png(target)
                    elif mode == "overlapped":
                        if pending is not None:
                            pending.result()
                        pending = writer.submit(frame.save_png, target)
                if pending is not None:
                    pending.result()
                loop.setdefault(mode, []).append(args.frames / (time.perf_counter() - start))
    best = {mode: max(r) for mode, r in loop.items()}
    print(f"one process, {args.frames} frames (best of 2): rendering alone {best['render']:.1f} frames/s; with PNG "
          f"saved after each render {best['serial']:.1f} ({best['serial'] / best['render']:.2f}); saved on a writer "
          f"thread {best['overlapped']:.1f} ({best['overlapped'] / best['render']:.2f})")

    specs = [360.0 * k / args.frames for k in range(args.frames)]
    rates = {}
    for fmt in ("npy", "png", "npy", "png"):  # interleaved, twice
        with tempfile.TemporaryDirectory() as folder:
            start = time.perf_counter()
            render_many(scene, specs, width, height, folder, fmt=fmt, progress=False, backend=args.backend)
            rates.setdefault(fmt, []).append(args.frames / (time.perf_counter() - start))
    best = {fmt: max(r) for fmt, r in rates.items()}
    print(f"render_many, {args.frames} frames (best of 2): .npy {best['npy']:.1f} frames/s, .png {best['png']:.1f} "
          f"frames/s, ratio {best['png'] / best['npy']:.2f}")


if __name__ == "__main__":
    main()
