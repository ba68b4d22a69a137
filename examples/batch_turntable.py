"""A turntable of N frames rendered by worker processes (`glphong.batch.render_many`), then timed against a
serial loop in this process.

Run:  python examples/batch_turntable.py [frames] [out_dir] [--dask]
Each frame is float32 radiance (.npy) in out_dir; rerunning renders only the frames that are missing.
"""
import sys
import tempfile
import time

import glphong
from glphong.batch import render_many, turntable_scene


def main(frames=24, out_dir=None, size=256, dask=False):
    angles = [360.0 * k / frames for k in range(frames)]
    out_dir = out_dir or tempfile.mkdtemp(prefix="glphong-turntable-")
    start = time.perf_counter()
    paths = render_many(turntable_scene, angles, size, size, out_dir, frames_per_task=4, progress=False)
    pool = time.perf_counter() - start
    if dask:  # the same batch on a local Dask cluster (pip install 'glphong[dask]'), into its own folder
        start = time.perf_counter()
        render_many(turntable_scene, angles, size, size, tempfile.mkdtemp(prefix="glphong-dask-"), executor="dask",
                    workers=2, frames_per_task=4, progress=False)
        print(f"local Dask cluster, 2 workers: {frames / (time.perf_counter() - start):.1f} frames/s "
              "(starting the cluster included)")
    start = time.perf_counter()
    with glphong.Renderer(size, size) as renderer:
        for angle in angles:
            renderer.render(turntable_scene(angle))
    serial = time.perf_counter() - start
    print(f"{frames} frames of {size}x{size} in {out_dir}: process pool {frames / pool:.1f} frames/s "
          f"(including starting the workers), serial loop {frames / serial:.1f} frames/s")
    return paths


if __name__ == "__main__":
    arguments = [a for a in sys.argv[1:] if a != "--dask"]
    main(int(arguments[0]) if arguments else 24, arguments[1] if len(arguments) > 1 else None, dask="--dask" in sys.argv)
