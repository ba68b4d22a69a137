"""What shadows cost: frame time with and without them, per shadowing light, at two image sizes and four map sizes.

The scene: a Phong sphere over a Lambert floor (the test scene of tests/lights/test_shadows.py) lit by one, two or
four lights of one kind (point: a cube map of six faces per light; spot: the same; directional: one orthographic
map).  For each image size (512, 1024), each map size (512 to 4096) and each number of lights, the scene with
``shadows=True`` and the same scene without are rendered alternately in one process after a warm-up (render +
float32 readback; the maps are drawn every frame); reported: the median frame times, the extra time per
shadowing light, and the GPU memory of the maps (4 bytes a texel: 6 N^2 for a cube, N^2 for an orthographic one).

Not measured: scenes with many casters (the map pass draws every caster once per face), PCF radii above 1, GPUs.

Run:  python benchmarks/shadow_cost.py [--repeats 7] [--backend egl] [--sizes 512 1024] [--maps 512 1024 2048 4096]
"""
import argparse

import numpy as np

import glphong
from glphong import primitives
from glphong.core.timing import alternating_medians
from glphong.gpu.shadows import shadow_map_bytes
from glphong.shaders.binding import binding

POSITIONS = ((0.3, 0.2, 2.0), (-1.0, 0.5, 1.8), (0.8, -1.0, 1.5), (-0.4, -0.9, 2.2))


def scene(kind, count, shadows):
    lights = []
    for position in POSITIONS[:count]:
        axis = -np.asarray(position)
        lights.append({"point": lambda: glphong.PointLight(position, 30.0, shadows=shadows),
                       "spot": lambda: glphong.SpotLight(position, axis, 4.0, 0.3, 0.8, shadows=shadows),
                       "directional": lambda: glphong.DirectionalLight(axis, 1.0, shadows=shadows)}[kind]())
    out = glphong.Scene(glphong.PerspectiveCamera.look_at((0.0, -3.0, 3.0), (0.0, 0.0, 0.0)), lights)
    pose = np.eye(4)
    pose[2, 3] = 0.7
    out.add(primitives.sphere(4, radius=0.5), glphong.Phong(0.3, 0.4, 30.0), pose=pose)
    out.add(primitives.plane(4.0, segments=8), glphong.Lambert(0.6))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--backend", default="auto")
    parser.add_argument("--sizes", type=int, nargs="+", default=[512, 1024])
    parser.add_argument("--maps", type=int, nargs="+", default=[512, 1024, 2048, 4096])
    parser.add_argument("--kinds", nargs="+", default=["point", "spot", "directional"])
    parser.add_argument("--counts", type=int, nargs="+", default=[1, 2, 4])
    args = parser.parse_args()
    with glphong.Renderer(8, 8, backend=args.backend) as probe:
        print(f"backend: {probe.backend} ({probe.context.renderer_name})\n")
    print("| image | light | lights | map | without [ms] | with [ms] | extra per light [ms] | maps [MiB] |")
    print("|---|---|---|---|---|---|---|---|")
    for size in args.sizes:
        for map_size in args.maps:
            with glphong.Renderer(size, size, backend=args.backend, shadow_map_size=map_size) as renderer:
                for kind in args.kinds:
                    for count in args.counts:
                        plain, shadowed = scene(kind, count, False), scene(kind, count, True)
                        medians = alternating_medians({"without": lambda: renderer.render(plain),
                                                       "with": lambda: renderer.render(shadowed)},
                                                      repeats=args.repeats, warmup=1)
                        key = renderer.program_key(shadowed, shadowed.objects[1])
                        memory = shadow_map_bytes(binding(shadowed).shadow_setups(key.lights, key.shadow_size)) / 2 ** 20
                        extra = (medians["with"] - medians["without"]) / count
                        print(f"| {size} | {kind} | {count} | {map_size} | {1000 * medians['without']:.1f} | "
                              f"{1000 * medians['with']:.1f} | {1000 * extra:.1f} | {memory:.0f} |", flush=True)


if __name__ == "__main__":
    main()
