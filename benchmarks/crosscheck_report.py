"""Cross-check figures per material and backend, and the default figure's frame time.

For each backend and material, renders a sphere on a floor under four lights of three kinds
plus ambient at 512x512, cross-checks the GPU image against the float64 twin, and prints
max/RMS relative error and the count of pixels outside the tolerance band.  Then times the
default "Phong Examples" figure (median of 5 after a warm-up).

Run:  python benchmarks/crosscheck_report.py [--size 512] [--json out.json]
"""
import argparse
import json
import statistics
import time

import numpy as np
import trimesh

import glphong
from glphong.analysis.figures import phong_examples

MATERIALS = {
    "Lambert": glphong.Lambert(kd=(0.3, 0.2, 0.1), ka=0.01),
    "Phong q=60": glphong.Phong(kd=(0.2, 0.1, 0.05), ks=(0.5, 0.6, 0.7), q=60.0),
    "Phong q=1e6": glphong.Phong(kd=0.1, ks=1.0, q=1e6),
    "BlinnPhong q=400": glphong.BlinnPhong(kd=0.1, ks=0.8, q=400.0, ka=0.01),
    "BlinnPhong q=1e7": glphong.BlinnPhong(kd=0.1, ks=1.0, q=1e7),
}


def scene_for(material):
    camera = glphong.PerspectiveCamera.look_at((0.3, 0.8, 3.2), (0.0, 0.0, 0.0), yfov=0.9)
    scene = glphong.Scene(camera, ambient=glphong.AmbientLight(0.05), lights=[
        glphong.PointLight((2.0, 2.5, 3.0), (80.0, 60.0, 40.0)), glphong.PointLight((-3.0, -1.0, 2.0), 30.0),
        glphong.UnattenuatedPointLight((0.0, 4.0, 1.0), 0.3), glphong.DirectionalLight((-0.2, -0.3, -1.0), 0.7)])
    scene.add(trimesh.creation.icosphere(5), material)
    floor = np.eye(4)
    floor[1, 3] = -1.1
    scene.add(trimesh.creation.box((4.0, 0.1, 4.0)), material, pose=floor, smooth=False)
    return scene


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=512)
    parser.add_argument("--json", default=None)
    args = parser.parse_args()
    rows = []
    for backend in ("egl", "osmesa"):
        with glphong.Renderer(args.size, args.size, backend=backend) as r:
            for name, material in MATERIALS.items():
                s = glphong.verify(scene_for(material), r).summary()
                rows.append({"backend": backend, "material": name, **s})
                print(f"{backend:7s} {name:18s} px={s['covered_pixels']:7d} max_rel={s['max_relative_error']:.3g} "
                      f"rms_rel={s['rms_relative_error']:.3g} outside_band={s['outside_band']} "
                      f"nonfinite={s['nonfinite']} {'PASS' if s['passed'] else 'FAIL'}")
            phong_examples(r, tile=128)  # warm-up
            times = []
            for _ in range(5):
                t = time.perf_counter()
                phong_examples(r, tile=128)
                times.append(time.perf_counter() - t)
            median = statistics.median(times)
            rows.append({"backend": backend, "default_figure_seconds": median})
            print(f"{backend:7s} default figure (40 tiles of 128x128, icosphere level 5): median {median:.3f} s, "
                  f"{1000 * median / 40:.1f} ms per tile")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    main()
