"""What saving a frame as PNG costs against rendering it (issue 29, part 2).

Usage: python benchmarks/frame_saving.py [--size WxH] [--repeats N] [--frames N] [--backend egl|osmesa]

One process, interleaved rounds, medians:

- the render of a 640x480 frame (a Phong sphere on a Lambert floor, one point light; ``Renderer.render``);
- ``Frame.save_png`` of it (the exact sRGB encode in row blocks on threads, then glphong's PNG writer), and its two
  parts;
- the same image through Pillow at the same zlib level (1), for the PNG writer's comparison;
- a turntable of ``--frames`` frames through `glphong.batch.render_many` (worker processes, each rendering the next frame
  while its writer thread encodes and writes the last) as PNG and as ``.npy`` (a raw copy: the render's own cost).
"""
import argparse
import io
import tempfile
import time
from pathlib import Path

import numpy as np
from PIL import Image

import glphong
from glphong.core.imaging import encode_srgb8
from glphong.batch import render_many
from glphong.core.png import encode_png


def scene(angle=0.0):
    """The benchmark's scene, its camera turned by ``angle`` degrees (a picklable ``scene_fn``)."""
    a = np.radians(angle)
    out = glphong.Scene(glphong.PerspectiveCamera.look_at((4 * np.sin(a), 1.0, 4 * np.cos(a)), (0, 0, 0)),
                        lights=[glphong.PointLight((2, 3, 4), 300.0)], ambient=glphong.AmbientLight(0.02))
    out.add(glphong.primitives.sphere(4), glphong.Phong(0.2, 0.5, 40.0))
    out.add(glphong.primitives.plane(10.0), glphong.Lambert(0.2))
    return out


def median_ms(times):
    return 1e3 * float(np.median(times))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--size", default="640x480")
    parser.add_argument("--repeats", type=int, default=20)
    parser.add_argument("--frames", type=int, default=48)
    parser.add_argument("--backend", default="egl")
    args = parser.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
    times = {k: [] for k in ("render", "save_png", "encode_srgb8", "encode_png", "pillow_png")}
    with tempfile.TemporaryDirectory() as folder, glphong.Renderer(width, height, backend=args.backend) as renderer:
        s = scene()
        frame = renderer.render(s)
        path = Path(folder) / "frame.png"
        for _ in range(args.repeats):
            start = time.perf_counter()
            frame = renderer.render(s)
            times["render"].append(time.perf_counter() - start)
            start = time.perf_counter()
            frame.save_png(path)
            times["save_png"].append(time.perf_counter() - start)
            start = time.perf_counter()
            image = encode_srgb8(frame.radiance)
            times["encode_srgb8"].append(time.perf_counter() - start)
            start = time.perf_counter()
            ours = encode_png(image, 1)
            times["encode_png"].append(time.perf_counter() - start)
            start = time.perf_counter()
            pillow = io.BytesIO()
            Image.fromarray(image).save(pillow, format="PNG", compress_level=1)
            times["pillow_png"].append(time.perf_counter() - start)
    render = median_ms(times["render"])
    print(f"{width}x{height}, {args.backend}, {args.repeats} interleaved rounds (median)")
    print("| step | ms | / render |")
    print("|---|---|---|")
    for name, t in times.items():
        print(f"| {name} | {median_ms(t):.2f} | {median_ms(t) / render:.2f} |")
    print(f"PNG size: glphong {len(ours)} bytes, Pillow {len(pillow.getvalue())} bytes (zlib level 1 both)")

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
