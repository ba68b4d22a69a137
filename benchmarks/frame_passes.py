"""Frame time with the frame passes against the radiance alone (docs/data_for_training.md, "What it costs").

Ten icospheres (subdivision 4: 5120 triangles each) under a point light, 256x256, llvmpipe or whatever the backend
gives; the cases interleaved in one process, each rendered 20 times after a warm-up, the median printed
(``python benchmarks/frame_passes.py [backend] [repeats]``); with ``--pyrender``: radiance, depth and instance
against pyrender's colour render and SEG render of the same scene.
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
    "matte alone (s = 32, the default)": ("matte",),
    "matte alone (s = 8)": ("matte",),
    "radiance, depth, instance, matte (s = 32)": ("radiance", "depth", "instance", "matte"),
}
#: ``matte_samples`` of a case (the default elsewhere)
SAMPLES = {"matte alone (s = 8)": 8}


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
    renderers = {s: glphong.Renderer(256, 256, backend=backend, matte_samples=s) for s in {32, *SAMPLES.values()}}
    renderer = renderers[32]
    later = spheres_scene()  # the same meshes, the same poses: flow 0, its arithmetic all the same
    for obj_now, obj_later in zip(scene.objects, later.objects):
        assert obj_now.mesh is obj_later.mesh
    render = {name: (lambda p=passes, r=renderers[SAMPLES.get(name, 32)]: r.render(
        scene, passes=p, next_scene=later if "flow" in p else None)) for name, passes in CASES.items()}
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




def against_pyrender(backend="egl", repeats=20):
    """glphong's radiance, depth and instance passes (one draw) against pyrender's way to the same (a colour render
    with its depth, then a SEG render), the same scene, one process, interleaved; medians [ms]."""
    from glphong.bench.pyrender_peer import PyrenderRenderer
    scene = spheres_scene()
    renderer = glphong.Renderer(256, 256, backend=backend)
    peer = PyrenderRenderer(256, 256, platform=backend).prepare(scene)
    ours = lambda: renderer.render(scene, passes=("radiance", "depth", "instance"))  # noqa: E731
    theirs = peer.render_segmentation
    frame, (_, _, instance) = ours(), theirs()
    agree = float(np.mean(frame.instance == instance))
    times = {"glphong radiance, depth, instance (one draw)": [], "pyrender colour + depth, then SEG": []}
    for _ in range(repeats):
        for name, fn in zip(times, (ours, theirs)):
            start = time.perf_counter()
            fn()
            times[name].append(time.perf_counter() - start)
    peer.release()
    print(f"{backend}, 256x256, {len(scene.objects)} spheres, median of {repeats}; ids agree on {100 * agree:.2f} % "
          f"of pixels; pyrender's colour render {'4x multisampled' if peer.samples > 1 else 'one sample a pixel'}")
    for name, values in times.items():
        print(f"| {name} | {1e3 * np.median(values):.1f} |")


if __name__ == "__main__":
    arguments = [a for a in sys.argv[1:] if a != "--pyrender"]
    backend = arguments[0] if arguments else "egl"
    repeats = int(arguments[1]) if len(arguments) > 1 else 20
    (against_pyrender if "--pyrender" in sys.argv else main)(backend, repeats)
