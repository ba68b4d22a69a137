"""What `glphong.verify` costs against one render of the same scene (issue 40).

Scenes (a sphere of tessellation 4 and radius 0.5 seen from 3 m, filling about a fifth of the image):

- Phong sphere, 1 point light; Phong sphere, 8 point lights;
- GltfPBR sphere, a spot light;
- Phong sphere over a Lambert plane, a point light with ``shadows=True``;
- Lambert sphere, a RectLight; Phong sphere, a RectLight (closed forms: irradiance and the whole-q lobe).

For each image size, in one process: one render (`Renderer.render`: draw and float32 readback) timed as the median
of ``--repeats`` runs after a warm-up, and one `glphong.verify` as the median of ``--verify-repeats`` runs after one
warm-up; printed: both medians and their ratio.

``--save DIR`` writes each verify's arrays (reference, low, high, exact, outside, mask) to ``DIR/<scene>_<size>.npz``;
``--compare DIR`` checks the arrays against such a directory with ``np.array_equal`` (bit for bit) and prints the
verdict per scene; ``--profile SCENE`` runs cProfile over one verify of that scene at the first size instead.

Run:  python benchmarks/verify_speed.py [--backend egl] [--sizes 64 256] [--repeats 7] [--verify-repeats 3]
      [--scenes ...] [--save DIR | --compare DIR] [--profile SCENE]
"""
import argparse
import cProfile
import pstats
from pathlib import Path

import numpy as np

import glphong
from glphong import primitives
from glphong.core.timing import median_seconds

ARRAYS = ("reference", "low", "high", "exact", "outside", "mask", "shadow_band")
LIGHTS8 = [(1.5 * np.cos(a), 1.5 * np.sin(a), 1.0 + 0.5 * np.sin(3 * a))
           for a in np.linspace(0, 2 * np.pi, 8, endpoint=False)]


def _scene(material, lights, plane=False):
    camera = glphong.PerspectiveCamera.look_at((0.0, -1.2, 1.5), (0.0, 0.0, 0.45), up=(0.0, 0.0, 1.0))
    scene = glphong.Scene(camera, lights)
    pose = np.eye(4)
    pose[2, 3] = 0.5
    scene.add(primitives.sphere(4, radius=0.5), material, pose=pose)
    if plane:
        scene.add(primitives.plane(4.0, segments=8), glphong.Lambert(0.6))
    return scene


SCENES = {
    "phong_point": lambda: _scene(glphong.Phong(0.3, 0.4, 30.0), [glphong.PointLight((0.8, -1.0, 2.0), 20.0)]),
    "phong_8_points": lambda: _scene(glphong.Phong(0.3, 0.4, 30.0),
                                     [glphong.PointLight(p, 5.0) for p in LIGHTS8]),
    "gltf_spot": lambda: _scene(glphong.GltfPBR((0.8, 0.5, 0.2), 0.3, 0.4),
                                [glphong.SpotLight((0.8, -1.0, 2.0), (-0.8, 1.0, -1.5), 20.0, 0.3, 0.6)]),
    "phong_plane_shadow": lambda: _scene(glphong.Phong(0.3, 0.4, 30.0),
                                         [glphong.PointLight((0.3, 0.2, 2.0), 20.0, shadows=True)], plane=True),
    "lambert_rect": lambda: _scene(glphong.Lambert(0.6),
                                   [glphong.RectLight((0.3, -0.5, 1.6), (0.0, 0.6, 0.3), (1.0, 0.0, 0.0), 5.0)]),
    "phong_rect": lambda: _scene(glphong.Phong(0.3, 0.4, 20.0),
                                 [glphong.RectLight((0.3, -0.5, 1.6), (0.0, 0.6, 0.3), (1.0, 0.0, 0.0), 5.0)]),
}


def _arrays(report):
    return {name: getattr(report, name) for name in ARRAYS if getattr(report, name) is not None}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--backend", default="egl")
    parser.add_argument("--sizes", type=int, nargs="+", default=[64, 256])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--verify-repeats", type=int, default=3)
    parser.add_argument("--scenes", nargs="+", default=list(SCENES), choices=list(SCENES))
    parser.add_argument("--save", type=Path)
    parser.add_argument("--compare", type=Path)
    parser.add_argument("--profile", choices=list(SCENES))
    args = parser.parse_args()
    if args.profile:
        size = args.sizes[0]
        with glphong.Renderer(size, size, backend=args.backend) as renderer:
            scene = SCENES[args.profile]()
            glphong.verify(scene, renderer)
            profile = cProfile.Profile()
            profile.enable()
            glphong.verify(scene, renderer)
            profile.disable()
        pstats.Stats(profile).sort_stats("cumulative").print_stats(45)
        return
    if args.save:
        args.save.mkdir(parents=True, exist_ok=True)
    with glphong.Renderer(8, 8, backend=args.backend) as probe:
        print(f"backend: {probe.backend} ({probe.context.renderer_name})\n")
    print("| scene | size | render [ms] | verify [ms] | verify / render | passed |"
          + (" same arrays |" if args.compare else ""))
    print("|---|---|---|---|---|---|" + ("---|" if args.compare else ""))
    for size in args.sizes:
        with glphong.Renderer(size, size, backend=args.backend) as renderer:
            for name in args.scenes:
                scene = SCENES[name]()
                render = median_seconds(lambda: renderer.render(scene), repeats=args.repeats, warmup=2)
                reports = []
                check = median_seconds(lambda: reports.append(glphong.verify(scene, renderer)),
                                       repeats=args.verify_repeats, warmup=1)
                report = reports[-1]
                same = ""
                if args.save:
                    np.savez(args.save / f"{name}_{size}.npz", **_arrays(report))
                if args.compare:
                    before = np.load(args.compare / f"{name}_{size}.npz")
                    now = _arrays(report)
                    differ = [k for k in set(before.files) | set(now) if k not in before.files or k not in now
                              or not np.array_equal(before[k], now[k], equal_nan=True)]
                    same = " yes |" if not differ else f" NO: {', '.join(sorted(differ))} |"
                print(f"| {name} | {size} | {1000 * render:.1f} | {1000 * check:.0f} | {check / render:.0f}x | "
                      f"{report.passed} |{same}", flush=True)


if __name__ == "__main__":
    main()
