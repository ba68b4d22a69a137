"""What transmissive surfaces cost: frame time of a scene with ``n`` transmissive spheres against the same scene drawn
opaque, and the transmission pass's background made on the GPU (the default) against the path before it (the opaque
image read back, its pyramid made on the host in float32 and every level uploaded: ``Transmission.method = "host"``)
(docs/transmission.md, "The pass and its cost").

The scene: ``n`` spheres (GltfPBR, 1280 triangles each, 0.25 m) in a row over a Lambert floor of vertex colours, one
point light, a perspective view; the spheres glass (``transmission=1``) of roughness 0 (the frame needs the
background's level 0 alone), of roughness 0.3 (its pyramid), or a volume (thickness 0.2: its pyramid, looked up where
the refracted ray leaves), or the same spheres opaque (transmission 0: the baseline, the same triangles drawn once).
For each image size, ``n`` and glass, the opaque frame, the GPU path's and the host path's are rendered alternately
in one process after a warm-up (render with the float32 readback of ``Renderer.render``); reported: medians, the
quartiles, the ratios.

Not measured: GPUs (llvmpipe only), shadows, textured glass.

Run:  python benchmarks/transmission_cost.py [--repeats 9] [--backend egl] [--sizes 256 512] [--counts 1 4 16]
"""
import argparse

import numpy as np

import glphong
from glphong import primitives
from glphong.core.timing import alternating_times, quartiles_ms
from glphong.gpu.transmission import TARGET_KEY
from glphong.scene.geometry import MeshData

GLASS = {"roughness 0": dict(roughness=0.0, transmission=1.0), "roughness 0.3": dict(roughness=0.3, transmission=1.0),
         "volume": dict(roughness=0.0, transmission=1.0, thickness=0.2, attenuation_color=(0.9, 0.7, 0.5),
                        attenuation_distance=0.5)}


def scene(count, glass):
    """``count`` spheres in a row over a floor, of the glass ``glass`` (keywords of `GltfPBR`; {}: opaque)."""
    out = glphong.Scene(glphong.PerspectiveCamera.look_at((0.0, -2.2, 1.4), (0.0, 0.0, 0.2), yfov=0.9),
                        [glphong.PointLight((1.0, -1.0, 2.0), 40.0)])
    floor = primitives.plane(4.0, segments=16)
    colors = np.random.default_rng(3).uniform(0.1, 1.0, (len(floor.positions), 3))
    out.add(MeshData(floor.positions, floor.normals, floor.indices, colors=colors),
            glphong.Lambert(glphong.VertexColors(0.5)))
    sphere = primitives.sphere(3, 0.25)
    for k in range(count):
        pose = np.eye(4)
        pose[:3, 3] = (-1.5 + 3.0 * (k + 0.5) / count, 0.3 * (k % 2), 0.3)
        out.add(sphere, glphong.GltfPBR((0.9, 0.95, 1.0), 0.0, **(glass or dict(roughness=0.3))), pose=pose)
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=9)
    parser.add_argument("--backend", default="auto")
    parser.add_argument("--sizes", type=int, nargs="+", default=[256, 512])
    parser.add_argument("--counts", type=int, nargs="+", default=[1, 4, 16])
    parser.add_argument("--glass", nargs="+", default=list(GLASS), choices=list(GLASS))
    args = parser.parse_args()
    for size in args.sizes:
        with glphong.Renderer(size, size, backend=args.backend) as renderer:
            if size == args.sizes[0]:
                print(f"{renderer.backend} ({renderer.context.renderer_name})\n\n| image | n | glass | opaque [ms] "
                      "(q1-q3) | transmissive [ms] (q1-q3) | before: host pyramid [ms] (q1-q3) | ratio to opaque | "
                      "before / now |\n|---|---|---|---|---|---|---|---|")
            for count in args.counts:
                opaque = scene(count, {})
                for name in args.glass:
                    glass = scene(count, GLASS[name])
                    renderer.render(glass)
                    transmission = renderer._targets[TARGET_KEY]

                    def gpu():
                        transmission.method = "gpu"
                        renderer.render(glass)

                    def host():
                        transmission.method = "host"
                        renderer.render(glass)

                    times = alternating_times({"opaque": lambda: renderer.render(opaque), "gpu": gpu, "host": host},
                                              repeats=args.repeats, warmup=1)
                    (a1, a, a3), (b1, b, b3), (c1, c, c3) = (quartiles_ms(times[k]) for k in ("opaque", "gpu", "host"))
                    print(f"| {size} | {count} | {name} | {a:.1f} ({a1:.1f}-{a3:.1f}) | {b:.1f} ({b1:.1f}-{b3:.1f}) | "
                          f"{c:.1f} ({c1:.1f}-{c3:.1f}) | {b / a:.2f} | {c / b:.2f} |", flush=True)


if __name__ == "__main__":
    main()
