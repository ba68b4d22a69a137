"""What per-scene specialisation buys: specialised programs against the uber-shader, in one process.

Three scenes at 1024x1024 (a sphere on a floor filling the view): Lambert only with one point
light; Phong with one point light; mixed materials (Lambert, Phong, Blinn, with and without k_a)
with 8 lights of three kinds plus ambient.  Each is rendered by a specialised renderer and an
uber-shader renderer (every built-in term: Lambert and both lobes, 8 lights per kind switched by uniforms), alternating,
after a warm-up; reported: median frame time (render + float32 readback), the ratio uber /
specialised, compile time and program-cache hits/misses.

Run:  python benchmarks/specialisation.py [--size 1024] [--repeats 15] [--backend egl] [--json out.json]
"""
import argparse
import json
import time

import numpy as np
import trimesh

import glphong
from glphong.core.timing import alternating_medians
from glphong.shaders.binding import binding


def _scene(materials, lights):
    camera = glphong.PerspectiveCamera.look_at((0.0, 1.2, 2.6), (0.0, -0.2, 0.0), yfov=np.radians(60))
    scene = glphong.Scene(camera, lights=lights, ambient=glphong.AmbientLight(0.05))
    sphere = trimesh.creation.icosphere(4)
    for i, m in enumerate(materials):
        pose = np.eye(4)
        pose[:3, 3] = (1.1 * i - 0.55 * (len(materials) - 1), 0.0, 0.0)
        pose[:3, :3] *= 0.5 if len(materials) > 1 else 1.0
        scene.add(sphere, m, pose=pose)
    floor = np.eye(4)
    floor[1, 3] = -1.05
    scene.add(trimesh.creation.box((8.0, 0.1, 8.0)), materials[0], pose=floor, smooth=False)
    return scene


def scenes():
    one = [glphong.PointLight((2.0, 3.0, 2.0), 200.0)]
    eight = ([glphong.PointLight((3.0 * np.cos(a), 2.5, 3.0 * np.sin(a)), 60.0) for a in np.linspace(0, 5, 4)]
             + [glphong.UnattenuatedPointLight((-2.0, 3.0, 1.0), 0.2), glphong.UnattenuatedPointLight((2.0, 1.0, 3.0), 0.1)]
             + [glphong.DirectionalLight((0.3, -1.0, -0.4), 0.5), glphong.DirectionalLight((-0.5, -0.2, -1.0), 0.3)])
    mixed = [glphong.Lambert(0.2), glphong.Phong(0.15, 0.4, 80.0), glphong.BlinnPhong(0.1, 0.5, 300.0, ka=0.01),
             glphong.Phong((0.2, 0.1, 0.05), 0.3, 1e4, ka=0.02)]
    return {
        "Lambert, 1 light": _scene([glphong.Lambert((0.3, 0.2, 0.1))], one),
        "Phong, 1 light": _scene([glphong.Phong((0.3, 0.2, 0.1), 0.5, 50.0)], one),
        "mixed, 8 lights": _scene(mixed, eight),
    }


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--backend", default="auto")
    parser.add_argument("--json", default=None)
    args = parser.parse_args()
    renderers = {"specialised": glphong.Renderer(args.size, args.size, backend=args.backend),
                 "uber": glphong.Renderer(args.size, args.size, backend=args.backend, specialise=False)}
    rows = []
    try:
        backend = renderers["specialised"].backend
        for name, scene in scenes().items():
            compile_s, first_s = {}, {}
            for k, r in renderers.items():
                before = r.programs.compile_seconds
                t = time.perf_counter()
                r.render(scene)  # warm-up: compile, link, upload, and Mesa's JIT at the first draw
                first_s[k] = time.perf_counter() - t
                compile_s[k] = r.programs.compile_seconds - before
                r.render(scene)
            med = alternating_medians({k: (lambda r=r: r.render(scene)) for k, r in renderers.items()},
                                      repeats=args.repeats, warmup=0)
            row = {"scene": name, "size": args.size, "backend": backend,
                   "specialised_ms": 1000 * med["specialised"], "uber_ms": 1000 * med["uber"],
                   "ratio_uber_over_specialised": med["uber"] / med["specialised"],
                   "compile_ms_specialised": 1000 * compile_s["specialised"], "compile_ms_uber": 1000 * compile_s["uber"],
                   "first_frame_ms_specialised": 1000 * first_s["specialised"], "first_frame_ms_uber": 1000 * first_s["uber"],
                   "programs_specialised": len({binding(scene).program_key(o) for o in scene.objects})}
            rows.append(row)
            print(f"{name:18s} {args.size}x{args.size} {backend}: specialised {row['specialised_ms']:.1f} ms, "
                  f"uber {row['uber_ms']:.1f} ms, uber/specialised {row['ratio_uber_over_specialised']:.2f}x; "
                  f"compile+link {row['compile_ms_specialised']:.0f} ms ({row['programs_specialised']} programs) "
                  f"vs {row['compile_ms_uber']:.0f} ms (1 program); first frame (incl. Mesa's JIT) "
                  f"{row['first_frame_ms_specialised']:.0f} vs {row['first_frame_ms_uber']:.0f} ms")
        for k, r in renderers.items():
            print(f"program cache ({k}): {r.programs.misses} compiled, {r.programs.hits} hits, "
                  f"{1000 * r.programs.compile_seconds:.0f} ms compiling in all")
    finally:
        for r in renderers.values():
            r.release()
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
