"""Frames per second of a batch writing BOP scenes against the same batch writing PNGs (docs/speed.md, "BOP batches").

The same specs, `glphong.batch.tabletop_scene` (4 objects of three models at random rigid poses on a table top, a
random view; at 256x256 about one object in fifteen reaches beyond the image's border), rendered by
``render_many(..., fmt='png')`` and ``render_many(..., fmt='bop', obj_ids='category')`` on one warm 'spawn' worker
(`glphong.batch.workers._spawn_pool`, started once and given as the executor, so that neither figure holds the pool's
start or the renderers' first programs), the two alternating in each round; the median of the rounds per backend.
Then the pieces of a BOP image in this process, one after another (no writer thread): the frame (radiance, depth,
instance), the whole silhouettes (`glphong.datasets.bop_masks.silhouettes`, the large canvas on a renderer of its own
as in a batch's worker, and how many objects it drew alone at the image's size and on the large canvas), the PNG encodes
and ``scene_gt_info``, the writes; the PNG frame's render and save; and, for comparison, the silhouettes as
`write_bop` made them before (one render per object alone, and one per object on the large canvas).

Run:  python benchmarks/bop_batch.py [--backends egl osmesa] [--frames 48] [--size 256] [--rounds 5]
"""
import argparse
import os
import statistics
import sys
import tempfile
import time

import glphong
from glphong.batch import render_many, tabletop_scene
from glphong.batch.workers import _spawn_pool
from glphong.datasets.bop import bop_camera_matrix, image_entries, image_files
from glphong.datasets.bop_files import image_folders, write_files
from glphong.datasets.bop_masks import silhouettes
from glphong.scene.camera import IntrinsicsCamera


def batch_rates(backend, frames, size, rounds, frames_per_task, workers=1):
    """``{'png': [fps, ...], 'bop': [...]}`` over ``rounds`` alternating rounds on a warm pool of ``workers``."""
    specs = list(range(frames))
    rates = {"png": [], "bop": []}
    pool = _spawn_pool(workers)
    try:
        with tempfile.TemporaryDirectory() as folder:
            def run(fmt, name):
                extra = {"obj_ids": "category"} if fmt == "bop" else {}
                start = time.perf_counter()
                render_many(tabletop_scene, specs, size, size, os.path.join(folder, name), executor=pool, fmt=fmt,
                            frames_per_task=frames_per_task, progress=False, backend=backend, **extra)
                return frames / (time.perf_counter() - start)

            run("png", "warm-png")
            run("bop", "warm-bop")
            for k in range(rounds):
                for fmt in (("png", "bop") if k % 2 == 0 else ("bop", "png")):
                    rates[fmt].append(run(fmt, f"{fmt}-{k}"))
    finally:
        pool.shutdown()
    return rates


def silhouettes_before(scene, renderer, k):
    """The whole silhouettes as `write_bop` made them before `glphong.datasets.bop_masks`: each object rendered
    alone at the image's size, and again on the canvas three times its size (the renderer resized there and
    back)."""
    width, height = renderer.width, renderer.height
    large = IntrinsicsCamera(k[0, 0], k[1, 1], k[0, 2] + width, k[1, 2] + height, 3 * width, 3 * height,
                             pose=scene.camera.pose, znear=scene.camera.znear, zfar=scene.camera.zfar)

    def alone(obj, camera):
        single = glphong.Scene(camera, scene.lights, scene.ambient)
        single.add(obj.mesh, obj.material, pose=obj.pose, instance_id=obj.instance_id)
        return renderer.render(single, passes=("instance",)).instance != 0

    inside = [alone(obj, scene.camera) for obj in scene.objects]
    renderer.resize(3 * width, 3 * height)
    try:
        big = [alone(obj, large) for obj in scene.objects]
    finally:
        renderer.resize(width, height)
    return inside, big


def pieces(backend, frames, size):
    """Milliseconds per frame of each piece of a BOP image and of a PNG frame, in this process."""
    renderer = glphong.Renderer(size, size, backend=backend)
    large = glphong.Renderer(3 * size, 3 * size, backend=backend)
    scenes = [tabletop_scene(i) for i in range(frames)]
    times, calls, renders = {}, {"image": 0, "large": 0}, {}

    def timed(name, call):
        start = time.perf_counter()
        out = call()
        times[name] = times.get(name, 0.0) + time.perf_counter() - start
        return out

    for target in (renderer, large):
        render, draw = target.render, target.silhouettes

        def counting(*args, _render=render, _name="large" if target is large else "image", **keywords):
            calls[_name] += 1
            return _render(*args, **keywords)

        def drawing(scene, indices, _draw=draw, _name="large" if target is large else "image"):
            calls[_name] += len(indices)  # an object drawn alone
            return _draw(scene, indices)

        target.render, target.silhouettes = counting, drawing
    with tempfile.TemporaryDirectory() as folder:
        dirs = image_folders(os.path.join(folder, "000000"))
        for path in dirs.values():
            os.makedirs(path)
        for repeat in range(2):  # the first to warm up
            times.clear()
            renders.update(image=0, large=0)
            for i, scene in enumerate(scenes):
                timed("BOP: scene_camera and scene_gt", lambda: image_entries(scene, size, size, "category", 0.1))
                frame = timed("BOP: the frame (radiance, depth, instance)",
                              lambda: renderer.render(scene, passes=("radiance", "depth", "instance")))
                k = bop_camera_matrix(scene.camera, size, size)
                counted = dict(calls)
                shapes = timed("BOP: whole silhouettes", lambda: silhouettes(scene, renderer, k, True, lambda: large,
                                                                                 visible=frame.instance))
                for name in renders:
                    renders[name] += calls[name] - counted[name]
                files, _ = timed("BOP: PNG encodes and scene_gt_info",
                                 lambda: image_files(scene, frame, shapes, i, 0.1, 1.0))
                timed("BOP: writing the files", lambda: write_files(
                    [(os.path.join(dirs[kind], name), data) for (kind, name), data in files.items()]))
                png = timed("PNG: the frame", lambda: renderer.render(scene))
                timed("PNG: save_png", lambda: png.save_png(os.path.join(folder, f"{i}.png")))
            for scene in scenes:  # last: it resizes the renderer, whose targets are then made again
                k = bop_camera_matrix(scene.camera, size, size)
                timed("(before: one render per object and canvas)", lambda: silhouettes_before(scene, renderer, k))
    for target in (renderer, large):
        del target.render
        target.release()
    return {name: 1000.0 * t / frames for name, t in times.items()}, {k: v / frames for k, v in renders.items()}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--backends", nargs="+", default=["egl", "osmesa"])
    parser.add_argument("--frames", type=int, default=48)
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--frames-per-task", type=int, default=8)
    parser.add_argument("--workers", type=int, default=1)
    args = parser.parse_args(argv)
    print(f"{os.cpu_count()} cores, {args.size}x{args.size}, {args.frames} frames of tabletop_scene (4 objects), "
          f"{args.workers} warm worker(s), {args.frames_per_task} frames a task, {args.rounds} alternating rounds, "
          "medians")
    for backend in args.backends:
        rates = batch_rates(backend, args.frames, args.size, args.rounds, args.frames_per_task, args.workers)
        png, bop = statistics.median(rates["png"]), statistics.median(rates["bop"])
        print(f"\n{backend}: render_many fmt='png' {png:.1f} frames/s, fmt='bop' {bop:.1f} frames/s: "
              f"BOP {bop / png:.2f}x PNG (rounds: png {', '.join(f'{r:.1f}' for r in rates['png'])}; "
              f"bop {', '.join(f'{r:.1f}' for r in rates['bop'])})")
        times, renders = pieces(backend, args.frames, args.size)
        print(f"  in this process, ms per frame (silhouettes: {renders['image']:.2f} objects drawn alone at the image's "
              f"size, {renders['large']:.2f} on the large canvas, per frame):")
        for name, ms in times.items():
            print(f"    {name:45s} {ms:6.2f}")
        print(f"    {'BOP: total':45s} {sum(v for k, v in times.items() if k.startswith('BOP')):6.2f}")
        print(f"    {'PNG: total':45s} {sum(v for k, v in times.items() if k.startswith('PNG')):6.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
