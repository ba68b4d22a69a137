"""Render a mesh file with several materials and several kinds of light.

Three copies of a model (default: examples/data/torus.obj) in Lambert, Phong and
Blinn-Torrance materials on a matte floor, lit by a point light (E = Phi/(4 pi d^2)),
an unattenuated light (the lecture's L_i), a directional light and an ambient L_a.
Writes a PNG and the raw float32 radiance, and prints the cross-check against the
float64 twin.

Run:  python examples/model_scene.py [model-file] [out.png]
"""
import sys
from pathlib import Path

import numpy as np
import trimesh

import glphong

HERE = Path(__file__).resolve().parent


def translation(x, y, z):
    pose = np.eye(4)
    pose[:3, 3] = (x, y, z)
    return pose


def build_scene(model_path):
    mesh = trimesh.load(model_path, force="mesh")
    mesh.apply_translation(-mesh.bounding_box.centroid)
    mesh.apply_scale(1.6 / mesh.scale)

    camera = glphong.PerspectiveCamera.look_at(eye=(0.0, 2.2, 4.5), target=(0.0, 0.0, 0.0), yfov=np.radians(45))
    scene = glphong.Scene(
        camera,
        lights=[
            glphong.PointLight(position=(2.0, 3.0, 2.0), power=(600.0, 560.0, 500.0)),
            glphong.UnattenuatedPointLight(position=(-3.0, 2.0, 1.0), radiance=(0.4, 0.5, 0.9)),
            glphong.DirectionalLight(direction=(0.3, -1.0, -0.5), irradiance=1.0),
        ],
        ambient=glphong.AmbientLight(0.2),
    )
    materials = [
        glphong.Lambert(kd=(0.05, 0.20, 0.05)),
        glphong.Phong(kd=(0.20, 0.06, 0.04), ks=0.4, q=80),
        glphong.BlinnPhong(kd=(0.04, 0.06, 0.22), ks=0.4, q=300),
    ]
    for x, material in zip((-1.9, 0.0, 1.9), materials):
        scene.add(mesh, material, pose=translation(x, 0.0, 0.0), name=type(material).__name__)
    floor = trimesh.creation.box(extents=(8.0, 0.05, 5.0))
    scene.add(floor, glphong.Lambert(kd=0.08, ka=0.01), pose=translation(0.0, -0.75, 0.0), smooth=False, name="floor")
    return scene


def main(model_path=HERE / "data" / "torus.obj", out="model_scene.png"):
    scene = build_scene(model_path)
    with glphong.Renderer(640, 360) as renderer:
        frame = renderer.render(scene)
        report = glphong.verify(scene, renderer)
        programs = [key.describe() for key in renderer.programs.keys()]
    frame.save_png(out, exposure=1.5)
    frame.save_npy(Path(out).with_suffix(".npy"))
    print(f"wrote {out}; {len(programs)} programs compiled:")
    for line in programs:
        print("   ", line)
    print(f"cross-check against the float64 twin: {report}")
    return report.passed


if __name__ == "__main__":
    if not main(*sys.argv[1:]):
        sys.exit(1)  # the cross-check failed
