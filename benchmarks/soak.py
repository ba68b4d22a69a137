"""Soak: hours of unattended rendering, printing the process's memory curve (not a test).

Cycles through scenes of every built-in material and light kind, per pixel and per vertex, with
G-buffers and cross-checks; every 50 frames the renderer is released and a new one made, and every
200 frames one is dropped without release (the garbage collector releases it).  Every ``--every``
seconds it prints the elapsed time, frames, resident memory (RSS from /proc/self/statm) and the
current renderer's GL object count; at the end the growth of RSS after the first interval.

Run:  python benchmarks/soak.py [--minutes 60] [--every 60] [--backend auto] [--csv soak.csv]
"""
import argparse
import gc
import time
import warnings

import numpy as np

import glphong
from glphong import primitives


def rss_mb():
    """Resident memory of this process [MiB]."""
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096 / 2**20


def scene(i):
    """The i-th scene of the cycle: one of four materials, one to three lights of the three kinds."""
    camera = glphong.PerspectiveCamera.look_at((np.sin(i), 0.6, 3.0 + np.cos(i)), (0.0, 0.0, 0.0))
    lights = [glphong.PointLight((1.5, 2.0, 2.0), 80.0), glphong.DirectionalLight((0.3, -1.0, -0.4), 0.5),
              glphong.UnattenuatedPointLight((-2.0, 1.0, 1.0), 0.3)][: 1 + i % 3]
    s = glphong.Scene(camera, lights=lights, ambient=glphong.AmbientLight(0.02) if i % 2 else None)
    material = [glphong.Lambert(0.3), glphong.Phong(0.2, 0.5, 10.0 + i % 97), glphong.BlinnPhong(0.2, 0.6, 300.0),
                glphong.materials.PhongLobe(0.8, 1e5)][i % 4]
    s.add(primitives.sphere(2 + i % 3), material)
    s.add(primitives.plane(4.0, 4), glphong.Lambert(0.1), pose=np.diag([1.0, 1.0, 1.0, 1.0]) - np.array(
        [[0, 0, 0, 0], [0, 0, 0, 0.6], [0, 0, 0, 0], [0, 0, 0, 0]]))
    return s


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=60.0, help="how long to run (default 60)")
    parser.add_argument("--every", type=float, default=60.0, help="seconds between report lines (default 60)")
    parser.add_argument("--backend", default="auto", choices=("auto", "egl", "osmesa"))
    parser.add_argument("--csv", default=None, help="also write the curve to this CSV path")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore", ResourceWarning)  # the dropped renderers are deliberate
    start = time.perf_counter()
    renderer = glphong.Renderer(96, 72, backend=args.backend)
    vertex = glphong.Renderer(96, 72, backend=args.backend, shading="vertex")
    rows, frames, next_report, failed = [], 0, 0.0, 0
    print("seconds  frames  rss_MiB  gl_objects")
    while True:
        elapsed = time.perf_counter() - start
        if elapsed >= next_report:
            gc.collect()
            rows.append((elapsed, frames, rss_mb(), renderer.gl_object_count()))
            print(f"{elapsed:7.0f} {frames:7d} {rows[-1][2]:8.1f} {rows[-1][3]:11d}", flush=True)
            next_report += args.every
        if elapsed >= 60.0 * args.minutes:
            break
        s = scene(frames)
        renderer.render(s)
        vertex.render(s)
        if frames % 10 == 0:
            failed += not glphong.verify(s, renderer).passed
        frames += 1
        if frames % 50 == 0:
            renderer.release()
            renderer = glphong.Renderer(96, 72, backend=args.backend)
        if frames % 200 == 0:
            glphong.Renderer(64, 64, backend=args.backend).render(s)  # dropped without release
    renderer.release()
    vertex.release()
    growth = rows[-1][2] - rows[1][2] if len(rows) > 2 else 0.0
    print(f"{frames} frames in {rows[-1][0]:.0f} s; {failed} failed cross-checks; RSS growth after the first "
          f"interval: {growth:+.1f} MiB")
    if args.csv:
        with open(args.csv, "w") as f:
            f.write("seconds,frames,rss_mib,gl_objects\n")
            f.writelines(f"{t:.1f},{n},{m:.2f},{g}\n" for t, n, m, g in rows)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
