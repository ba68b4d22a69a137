"""Fragment cost of the stable formulation against the naive textbook one, in one process.

A full-screen Phong plane lit by 4 point lights (every pixel runs the whole light loop and
lobe) is rendered with each formulation, alternating, after a warm-up; reported: median
frame time (render + float32 readback) over the repeats and the ratio stable / naive.
The stability table itself comes from ``glphong stability --naive``.

Run:  python benchmarks/stability_cost.py [--size 1024] [--repeats 15] [--backend egl]
"""
import argparse

import numpy as np
import trimesh

import glphong
from glphong.core.timing import alternating_medians


def plane_scene(material):
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 1.0), (0.0, 0.0, 0.0), yfov=np.radians(90))
    lights = [glphong.PointLight((x, y, 0.5), 20.0) for x, y in ((-0.5, -0.5), (0.5, -0.5), (-0.5, 0.5), (0.5, 0.5))]
    scene = glphong.Scene(camera, lights=lights, ambient=glphong.AmbientLight(0.05))
    scene.add(trimesh.creation.box((4.0, 4.0, 0.01)), material, smooth=False)
    return scene


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--backend", default="auto")
    args = parser.parse_args()
    materials = {"Phong q=1e4": glphong.Phong(0.2, 0.5, 1e4), "Blinn q=100": glphong.BlinnPhong(0.2, 0.5, 100.0),
                 "Lambert": glphong.Lambert(0.3)}
    renderers = {f: glphong.Renderer(args.size, args.size, backend=args.backend, formulation=f)
                 for f in ("stable", "naive")}
    try:
        for name, material in materials.items():
            scene = plane_scene(material)
            medians = alternating_medians({f: (lambda r=r: r.render(scene)) for f, r in renderers.items()},
                                          repeats=args.repeats, warmup=2)
            stable, naive = medians["stable"], medians["naive"]
            print(f"{name:12s} {args.size}x{args.size}, 4 point lights on {renderers['stable'].backend}: "
                  f"stable {1000 * stable:.1f} ms, naive {1000 * naive:.1f} ms, ratio stable/naive {stable / naive:.3f}")
    finally:
        for r in renderers.values():
            r.release()


if __name__ == "__main__":
    main()
