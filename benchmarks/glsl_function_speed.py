"""Rows per second of `glphong.testing.glsl_function` on ``vec3 f(vec3, vec3, float)``, and the cost of the first
compile, on each backend.

Usage: python benchmarks/glsl_function_speed.py [--rows N] [--repeats R] [--backend egl|osmesa|both]

For each backend: the time of `glsl_function` (parse, expand, compile and link) and of a first one-row call (Mesa
compiles the machine code at the first draw), then R calls on N rows each (upload, draw, read back, decode; the
median and the best), in the vertex stage and the fragment stage.  Run with ``MESA_SHADER_CACHE_DISABLE=true`` for
a cold compile (Mesa otherwise reuses its on-disk cache).  Inputs
are float64 arrays, as a user passes them (the call rounds them to float32).
"""
import argparse
import time

import numpy as np

from glphong.gpu.contexts import BackendUnavailableError
from glphong.testing import glsl_function

SOURCE = """
vec3 shade(vec3 n, vec3 l, float q)
{
    vec3 h = normalize(n + l);
    return vec3(max(dot(n, l), 0.0)) + pow(max(dot(n, h), 0.0), q) * cross(n, l);
}
"""


def measure(backend, stage, rows, repeats):
    rng = np.random.default_rng(0)
    n, l, q = rng.normal(size=(rows, 3)), rng.normal(size=(rows, 3)), rng.uniform(1, 100, rows)
    start = time.perf_counter()
    fn = glsl_function(SOURCE, "shade", backend=backend, stage=stage)
    fn(n[:1], l[:1], q[:1])  # llvmpipe compiles the shaders' machine code at the first draw
    compile_s = time.perf_counter() - start
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        out = fn(n, l, q)
        times.append(time.perf_counter() - start)
    fn.release()
    assert out.shape == (rows, 3)
    return compile_s, float(np.median(times)), float(np.min(times))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--rows", type=int, default=1_000_000)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--backend", default="both")
    args = parser.parse_args()
    backends = ("egl", "osmesa") if args.backend == "both" else (args.backend,)
    print(f"glsl_function on vec3 f(vec3, vec3, float), {args.rows} rows per call, {args.repeats} calls")
    print("| backend | stage | compile and first draw [s] | call, median [s] | call, best [s] | rows/s (median) |")
    print("|---|---|---|---|---|---|")
    for backend in backends:
        for stage in ("vertex", "fragment"):
            try:
                compile_s, median, best = measure(backend, stage, args.rows, args.repeats)
            except BackendUnavailableError as exc:
                print(f"| {backend} | {stage} | unavailable: {exc} | | | |")
                continue
            print(f"| {backend} | {stage} | {compile_s:.3f} | {median:.3f} | {best:.3f} | {args.rows / median:.3g} |")


if __name__ == "__main__":
    main()
