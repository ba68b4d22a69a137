"""Frame times of pyrender with glphong's embedding: what switching it on costs a scene without glphong materials,
and what glphong's materials cost against pyrender's own on pyrender's example scene, with and without shadows.

Usage: python benchmarks/pyrender_embedding_cost.py [egl|osmesa] [--repeats N] [--size WxH]

One process, one ``OffscreenRenderer`` per scene; the variants are interleaved round by round (a renderer's inner
class is switched between pyrender's and glphong's for the embedding's own cost), after one warm-up frame each; the table gives
the median of the rounds and the ratio of medians.  The scene is tests/pyrender_flags_check.py's stand-in for
pyrender's examples/example.py (its models are not installed with pyrender), lights from the side.
"""
import argparse
import sys
import time
from pathlib import Path

import numpy as np

from glphong.bench import import_pyrender

PLATFORM = sys.argv[1] if len(sys.argv) > 1 and sys.argv[1] in ("egl", "osmesa") else "egl"
pyrender = import_pyrender(PLATFORM)  # PYOPENGL_PLATFORM set before pyrender (and PyOpenGL) first load
OPTIONS = [a for a in sys.argv[1:] if a not in ("egl", "osmesa")]
sys.argv[1:] = [PLATFORM]  # what the imported check module reads
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))

from pyrender.renderer import Renderer as PyrenderRenderer  # noqa: E402

import pyrender_flags_check as example  # noqa: E402
from glphong.integrations.pyrender import GlphongMaterial, GlphongRenderer, enable  # noqa: E402


def pyrender_materials(scene):
    """The same scene with pyrender's own material on every glphong mesh (a grey dielectric, roughness 0.5)."""
    for node in scene.mesh_nodes:
        for primitive in node.mesh.primitives:
            if isinstance(primitive.material, GlphongMaterial):
                primitive.material = pyrender.MetallicRoughnessMaterial(baseColorFactor=[0.5, 0.5, 0.5, 1.0],
                                                                        metallicFactor=0.0, roughnessFactor=0.5)
    return scene


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--repeats", type=int, default=30)
    parser.add_argument("--size", default="640x480")
    args = parser.parse_args(OPTIONS)
    width, height = (int(v) for v in args.size.split("x"))
    # one renderer per scene: pyrender deletes and re-uploads a scene's meshes whenever a renderer is handed another
    # scene, so the two scenes keep a renderer each (EGL contexts do not share pyrender's vertex arrays)
    scenes = {"theirs": pyrender_materials(example.example_scene("side")), "ours": example.example_scene("side")}
    renderers = {name: enable(pyrender.OffscreenRenderer(width, height)) for name in scenes}

    def frame(which, flags, cls):
        renderer = renderers[which]
        renderer._renderer.__class__ = cls
        start = time.perf_counter()
        renderer.render(scenes[which], flags=flags)
        return time.perf_counter() - start

    variants = {
        "pyrender materials, embedding off": ("theirs", 0, PyrenderRenderer),
        "pyrender materials, embedding on": ("theirs", 0, GlphongRenderer),
        "glphong materials": ("ours", 0, GlphongRenderer),
        "pyrender materials, shadows, embedding off": ("theirs", example.SHADOWS, PyrenderRenderer),
        "pyrender materials, shadows, embedding on": ("theirs", example.SHADOWS, GlphongRenderer),
        "glphong materials, shadows": ("ours", example.SHADOWS, GlphongRenderer),
    }
    times = {name: [] for name in variants}
    for name, spec in variants.items():
        frame(*spec)  # warm-up: programs compiled, buffers uploaded
    for _ in range(args.repeats):
        for name, spec in variants.items():
            times[name].append(frame(*spec))
    for renderer in renderers.values():
        renderer._renderer.__class__ = GlphongRenderer
    median = {name: float(np.median(t)) * 1e3 for name, t in times.items()}
    print(f"pyrender embedding, {PLATFORM}, {width}x{height}, {args.repeats} interleaved rounds (median ms)")
    print("| variant | frame [ms] | ratio |")
    print("|---|---|---|")
    pairs = {"pyrender materials, embedding on": "pyrender materials, embedding off",
             "glphong materials": "pyrender materials, embedding off",
             "pyrender materials, shadows, embedding on": "pyrender materials, shadows, embedding off",
             "glphong materials, shadows": "pyrender materials, shadows, embedding off"}
    for name, value in median.items():
        ratio = f"{value / median[pairs[name]]:.3f} of '{pairs[name]}'" if name in pairs else ""
        print(f"| {name} | {value:.2f} | {ratio} |")


if __name__ == "__main__":
    main()
