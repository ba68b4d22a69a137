"""`glphong.verify` under an EnvironmentLight (issue 40): render and verify time and peak memory of a Lambert sphere and
Phong spheres (q = 20, 100) lit by synthetic sky maps (a gradient, a little noise and a small bright sun) of 64 x 32
to 1024 x 2048 texels (W x H), rendered at 64 x 64 and 256 x 256.  Each case runs in its own process under a time
limit: one past it prints "over N s" instead of hanging.

    python benchmarks/verify_environment.py [--limit 300] [--sizes 64,256] [--maps 32x64,256x512,1024x2048]
        [--materials lambert,phong20,phong100] [--backend egl] [--sample N] [--before]

Prints one line per case: render s (median of 3, the light's host data cached), verify s (one run, the cube map
built inside it), peak resident memory of the process [MB] (``resource.getrusage``), method-error figures.
``--sample N``: ``verify(..., exact_sample=N, seed=0)`` (the exact image at N random covered pixels); ``--before``: the
exact image by the quadrature of every term (``exact_image(..., closed_forms=False)``, what a Phong material took
before the mixed-material split).
"""
import argparse
import json
import resource
import subprocess
import sys
import time

import numpy as np


def sky(H, W, seed=0):
    from glphong.twin import environment as env
    d = env.texel_directions(H, W)
    s = 0.3 + np.maximum(d[..., 2], 0.0)[..., None] * np.array([0.4, 0.6, 1.2])
    s = s + 0.05 * np.random.default_rng(seed).random((H, W, 3))
    sun = np.array([0.5, 0.3, 0.8])
    sun /= np.linalg.norm(sun)
    s[np.einsum("hwc,c->hw", d, sun) > np.cos(0.05 + np.pi / H)] = (400.0, 380.0, 330.0)
    return s


def scene(material, H, W):
    import glphong
    from glphong import primitives
    camera = glphong.PerspectiveCamera.look_at((0.0, -2.0, 2.5), (0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0), yfov=0.8)
    sc = glphong.Scene(camera, [glphong.EnvironmentLight(sky(H, W))])
    sc.add(primitives.sphere(3, 0.6), material)
    return sc


def material(name):
    import glphong
    return glphong.Lambert(0.8) if name == "lambert" else glphong.Phong(0.3, 0.5, float(name[len("phong"):]))


def one(name, size, H, W, backend, sample=None, before=False):
    import glphong
    if before:
        from glphong.checks import verify as module
        original = module.exact_image
        module.exact_image = lambda *a, **k: original(*a, **(k | {"closed_forms": False}))
    renderer = glphong.Renderer(size, size, backend=backend)
    sc = scene(material(name), H, W)
    start = time.perf_counter()
    report = glphong.verify(sc, renderer, exact_sample=sample)
    verify_s = time.perf_counter() - start
    times = []
    for _ in range(3):
        start = time.perf_counter()
        renderer.render(sc)
        times.append(time.perf_counter() - start)
    mean, worst = figures = report.method_error_figures()
    error = report.exact_error[np.isfinite(report.exact_error) & report.mask]
    exact = np.max(np.abs(report.exact), axis=-1)[np.isfinite(report.exact_error) & report.mask]
    return {"render_s": float(np.median(times)), "verify_s": verify_s, "pixels": report.covered_pixels,
            "sample": figures.sample, "mean_ci95": figures.mean_ci95, "above_max95": figures.above_max95,
            "exact_rel_estimate": float(np.max(error / np.maximum(exact, 1e-300), initial=0.0)),
            "passed": report.passed, "method_mean": mean, "method_max": worst,
            "peak_mb": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--limit", type=float, default=300.0)
    parser.add_argument("--sizes", default="64,256")
    parser.add_argument("--maps", default="32x64,256x512,1024x2048", help="H x W")
    parser.add_argument("--materials", default="lambert,phong20,phong100")
    parser.add_argument("--backend", default="egl")
    parser.add_argument("--sample", type=int, default=None)
    parser.add_argument("--before", action="store_true")
    parser.add_argument("--one", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.one:
        name, size, H, W = args.one.split(":")
        print(json.dumps(one(name, int(size), int(H), int(W), args.backend, args.sample, args.before)))
        return
    for name in args.materials.split(","):
        for size in map(int, args.sizes.split(",")):
            for shape in args.maps.split(","):
                H, W = map(int, shape.split("x"))
                label = f"{name:9s} {size:4d}^2 map {W}x{H}"
                try:
                    extra = (["--sample", str(args.sample)] if args.sample else []) + (["--before"] if args.before else [])
                    run = subprocess.run([sys.executable, __file__, "--one", f"{name}:{size}:{H}:{W}", "--backend",
                                          args.backend] + extra, capture_output=True, text=True, timeout=args.limit)
                except subprocess.TimeoutExpired:
                    print(f"{label}: over {args.limit:.0f} s", flush=True)
                    continue
                if run.returncode:
                    print(f"{label}: failed\n{run.stderr[-2000:]}", flush=True)
                    continue
                r = json.loads(run.stdout.strip().splitlines()[-1])
                print(f"{label}: render {r['render_s'] * 1e3:.1f} ms, verify {r['verify_s']:.1f} s "
                      f"({r['verify_s'] / r['render_s']:.0f}x), peak {r['peak_mb']:.0f} MB, {r['pixels']} px, "
                      f"{'pass' if r['passed'] else 'FAIL'}, method err mean {r['method_mean']:.3g} max "
                      f"{r['method_max']:.3g}, exact error estimate {r['exact_rel_estimate']:.2g} relative"
                      + (f", a sample of {r['sample']} px (mean +- {r['mean_ci95']:.2g}, at most {r['above_max95']:.2g} "
                         "of the pixels above max, 95 %)" if r["sample"] else ""), flush=True)


if __name__ == "__main__":
    main()
