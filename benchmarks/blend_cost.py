"""What blended surfaces cost: frame time of depth peeling against the same scene drawn opaque, and against the number
of layers (docs/speed.md, "Blended surfaces").

The scene: ``n`` lit quads (Lambert, one point light) stacked in depth over a Lambert floor, every quad covering the
middle 80 % of the image, so the middle pixels have ``n`` blended layers; each quad blended (``AlphaBlend(0.3)``) or
the same quads opaque (the baseline: the same triangles, drawn once with the depth test).  A peeled frame draws the
quads ``2 n + 1`` times (a peel and a layer per layer, the last peel finding nothing), plus a composite pass.  For
each image size and ``n``, the opaque and the blended scenes are rendered alternately in one process after a warm-up
(render + float32 readback); reported: medians, the quartiles, and the extra time per layer.

Not measured: many small blended objects (each peel draws all of them), lights with shadows, GPUs (llvmpipe only).

Run:  python benchmarks/blend_cost.py [--repeats 9] [--backend egl] [--sizes 256 512] [--layers 1 2 4 8 16]
"""
import argparse

import numpy as np

import glphong
from glphong import primitives
from glphong.core.timing import alternating_times, quartiles_ms


def scene(layers, blended):
    """``layers`` quads over a floor, blended (alpha 0.3) or opaque."""
    out = glphong.Scene(glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), yfov=0.9),
                        [glphong.PointLight((0.5, 0.8, 2.5), 40.0)])
    for k in range(layers):
        pose = np.eye(4)
        pose[2, 3] = 0.1 + 0.1 * k
        blend = glphong.AlphaBlend(0.3) if blended else None
        out.add(primitives.plane(2.0, segments=4), glphong.Lambert(0.2 + 0.02 * k, alpha_blend=blend), pose=pose)
    out.add(primitives.plane(6.0, segments=8), glphong.Lambert(0.6))
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=9)
    parser.add_argument("--backend", default="auto")
    parser.add_argument("--sizes", type=int, nargs="+", default=[256, 512])
    parser.add_argument("--layers", type=int, nargs="+", default=[1, 2, 4, 8, 16])
    args = parser.parse_args()
    for size in args.sizes:
        with glphong.Renderer(size, size, backend=args.backend, blend_layers=max(args.layers)) as renderer:
            if size == args.sizes[0]:
                print(f"{renderer.backend} ({renderer.context.renderer_name})\n\n| image | layers | opaque [ms] "
                      "(q1-q3) | blended [ms] (q1-q3) | ratio | extra per layer [ms] |\n|---|---|---|---|---|---|")
            for layers in args.layers:
                opaque, blended = scene(layers, False), scene(layers, True)
                assert renderer.render(blended).blend_layers == layers
                times = alternating_times({"opaque": lambda: renderer.render(opaque),
                                           "blended": lambda: renderer.render(blended)},
                                          repeats=args.repeats, warmup=1)
                (a1, a, a3), (b1, b, b3) = quartiles_ms(times["opaque"]), quartiles_ms(times["blended"])
                print(f"| {size} | {layers} | {a:.1f} ({a1:.1f}-{a3:.1f}) | {b:.1f} ({b1:.1f}-{b3:.1f}) | "
                      f"{b / a:.2f} | {(b - a) / layers:.1f} |", flush=True)


if __name__ == "__main__":
    main()
