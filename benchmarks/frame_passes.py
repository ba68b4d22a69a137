"""Frame time with the frame passes against the radiance alone (docs/data_for_training.md, "What it costs").

Ten icospheres (subdivision 4: 5120 triangles each) under a point light, 256x256, llvmpipe or whatever the backend
gives; the cases interleaved in one process, each rendered 20 times after a warm-up, the median printed
(``python benchmarks/frame_passes.py [backend] [repeats]``); with ``--matte``: the matte pass at s = 32 and 8
against the radiance; with ``--family``: the speed family of docs/speed.md at 512x512 with and without the passes; with ``--pyrender``: radiance, depth and instance against pyrender's colour render and SEG
render of the same scene.
"""
import sys

import numpy as np

import glphong
from glphong import primitives
from glphong.core.timing import alternating_times

CASES = {
    "radiance": ("radiance",),
    "radiance, instance, depth": ("radiance", "instance", "depth"),
    "every pass but uv and backward flow, without the radiance": (
        "depth", "distance", "normal", "normal_camera", "instance", "category", "object_coordinates", "nocs", "flow"),
    "every pass but uv and backward flow": (
        "radiance", "depth", "distance", "normal", "normal_camera", "instance", "category", "object_coordinates",
        "nocs", "flow"),
}
#: with ``--matte``: the matte pass against the radiance (its own run: a 300 ms case between 7 ms ones slows them)
MATTE_CASES = {
    "radiance": ("radiance",),
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


def main(backend="egl", repeats=20, cases=CASES):
    scene = spheres_scene()
    renderers = {s: glphong.Renderer(256, 256, backend=backend, matte_samples=s)
                 for s in {32, *(SAMPLES.values() if cases is MATTE_CASES else ())}}
    renderer = renderers[32]
    later = spheres_scene()  # the same meshes, the same poses: flow 0, its arithmetic all the same
    for obj_now, obj_later in zip(scene.objects, later.objects):
        assert obj_now.mesh is obj_later.mesh
    render = {name: (lambda p=passes, r=renderers[SAMPLES.get(name, 32)]: r.render(
        scene, passes=p, next_scene=later if "flow" in p else None)) for name, passes in cases.items()}
    times = alternating_times(render, repeats, warmup=1)
    base = np.median(times["radiance"])
    print(f"{renderer.gl_renderer if hasattr(renderer, 'gl_renderer') else backend}, 256x256, "
          f"{len(scene.objects)} spheres, median of {repeats}")
    for name in cases:
        median = np.median(times[name])
        print(f"| {name} | {1e3 * median:.1f} | {median / base:.2f}x |")




def family(backend="egl", repeats=9, size=512):
    """The speed family of docs/speed.md (`glphong.bench.speed.speed_scenes`) with the passes: per scene, the
    radiance alone, with depth and instance, and with every pass but uv and backward flow (flow against the scene
    itself: the same arithmetic), interleaved in one process, medians [ms]."""
    from glphong.bench.speed import speed_scenes
    cases = {name: CASES[name] for name in ("radiance", "radiance, instance, depth", "every pass but uv and backward flow")}
    renderer = glphong.Renderer(size, size, backend=backend)
    print(f"{backend}, {size}x{size}, median of {repeats}; ms and the ratio to the radiance alone")
    print("| scene | " + " | ".join(cases) + " |")
    for name, scene in speed_scenes().items():
        runs = {case: (lambda p=passes: renderer.render(scene, passes=p, next_scene=scene if "flow" in p else None))
                for case, passes in cases.items()}
        times = alternating_times(runs, repeats, warmup=1)
        base = np.median(times["radiance"])
        print(f"| {name} | " + " | ".join(f"{1e3 * np.median(t):.1f} ({np.median(t) / base:.2f}x)"
                                          for t in times.values()) + " |")


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
    times = alternating_times({"glphong radiance, depth, instance (one draw)": ours,
                               "pyrender colour + depth, then SEG": theirs}, repeats, warmup=0)
    peer.release()
    print(f"{backend}, 256x256, {len(scene.objects)} spheres, median of {repeats}; ids agree on {100 * agree:.2f} % "
          f"of pixels; pyrender's colour render {'4x multisampled' if peer.samples > 1 else 'one sample a pixel'}")
    for name, values in times.items():
        print(f"| {name} | {1e3 * np.median(values):.1f} |")


if __name__ == "__main__":
    arguments = [a for a in sys.argv[1:] if a not in ("--pyrender", "--matte", "--family")]
    backend = arguments[0] if arguments else "egl"
    repeats = int(arguments[1]) if len(arguments) > 1 else 20
    if "--pyrender" in sys.argv:
        against_pyrender(backend, repeats)
    elif "--family" in sys.argv:
        family(backend, repeats)
    else:
        main(backend, repeats, MATTE_CASES if "--matte" in sys.argv else CASES)
