"""Frame time with the frame passes against the radiance alone (docs/data_for_training.md, "What it costs").

Ten icospheres (subdivision 4: 5120 triangles each) under a point light, 256x256, llvmpipe or whatever the backend
gives; the cases interleaved in one process, each rendered 20 times after a warm-up, the median printed
(``python benchmarks/frame_passes.py [backend] [repeats]``).
"""
import sys
import time

import numpy as np

import glphong
from glphong import primitives

CASES = {
    "radiance": ("radiance",),
    "radiance, instance, depth": ("radiance", "instance", "depth"),
    "every pass but uv and backward flow, without the radiance": (
        "depth", "distance", "normal", "normal_camera", "instance", "category", "object_coordinates", "nocs", "flow"),
    "every pass but uv and backward flow": (
        "radiance", "depth", "distance", "normal", "normal_camera", "instance", "category", "object_coordinates",
        "nocs", "flow"),
}


def spheres_scene():
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.5, 6.0), (0.0, 0.0, 0.0), yfov=0.8)
    scene = glphong.Scene(camera, [glphong.PointLight((2.0, 2.0, 3.0), 50.0)])
    sphere = primitives.sphere(4, 0.5)
    for i in range(10):
        pose = np.eye(4)
        pose[:3, 3] = ((i % 5) - 2.0, (i // 5) - 0.5, 0.0)
        scene.add(sphere, glphong.Phong(0.2, 0.4, 20.0), pose=pose)
    return scene


def main(backend="egl", repeats=20):
    scene = spheres_scene()
    renderer = glphong.Renderer(256, 256, backend=backend)
    later = spheres_scene()  # the same meshes, the same poses: flow 0, its arithmetic all the same
    for obj_now, obj_later in zip(scene.objects, later.objects):
        assert obj_now.mesh is obj_later.mesh
    render = {name: (lambda p=passes: renderer.render(scene, passes=p, next_scene=later if "flow" in p else None))
              for name, passes in CASES.items()}
    times = {name: [] for name in CASES}
    for name in CASES:
        render[name]()
    for _ in range(repeats):
        for name in CASES:
            start = time.perf_counter()
            render[name]()
            times[name].append(time.perf_counter() - start)
    base = np.median(times["radiance"])
    print(f"{renderer.gl_renderer if hasattr(renderer, 'gl_renderer') else backend}, 256x256, "
          f"{len(scene.objects)} spheres, median of {repeats}")
    for name in CASES:
        median = np.median(times[name])
        print(f"| {name} | {1e3 * median:.1f} | {median / base:.2f}x |")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "egl", int(sys.argv[2]) if len(sys.argv) > 2 else 20)
