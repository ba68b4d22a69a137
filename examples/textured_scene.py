"""Textures and vertex colours: a textured floor, a vertex-coloured ball and a textured, vertex-tinted ball.

Usage: python examples/textured_scene.py [OUT_DIR]   (default: the current folder)

Renders the scene (textured.png), cross-checks it against the float64 twin (which samples the same texels
at the GPU's level of detail), writes it as glTF (textured.glb: meshes, materials in extras, textures,
camera, lights) and reads that file back, comparing the two renders.
"""
import sys
from pathlib import Path

import numpy as np

import glphong
from glphong import primitives
from glphong.scene.geometry import MeshData


def checker(size=128, cells=8):
    """An 8-bit sRGB image: warm and cool squares with a fine noise, so mip levels differ."""
    i, j = np.indices((size, size)) // (size // cells)
    warm = (i + j) % 2 == 0
    rgb = np.where(warm[..., None], [220, 150, 90], [60, 110, 170]).astype(np.float64)
    rgb += np.random.default_rng(0).normal(0, 12, rgb.shape)
    return np.clip(rgb, 0, 255).astype(np.uint8)


def build_scene():
    camera = glphong.PerspectiveCamera.look_at((0.0, -3.2, 1.6), (0.0, 0.0, 0.3), (0.0, 0.0, 1.0), yfov=0.75)
    scene = glphong.Scene(camera, [glphong.PointLight((1.5, -1.5, 3.0), 150.0)], ambient=glphong.AmbientLight(0.05))
    floor = primitives.plane(4.0, 4)
    scene.add(MeshData(floor.positions, floor.normals, floor.indices, uvs=floor.uvs * 3),
              glphong.Phong(kd=glphong.Texture(checker(), scale=0.25), ks=0.15, q=40.0), name="floor")
    ball = primitives.sphere(4, 0.5)
    heights = (ball.positions[:, 2] + 0.5)[:, None]
    colours = np.clip(np.hstack([heights, 1.0 - heights, 0.5 + 0 * heights]), 0.0, 1.0)  # linear, by height
    coloured = MeshData(ball.positions, ball.normals, ball.indices, uvs=ball.uvs, colors=colours)
    for x, material, name in ((-0.7, glphong.Lambert(kd=glphong.VertexColors(0.3)), "coloured"),
                              (0.7, glphong.Lambert(kd=glphong.Texture(checker(64, 4), 0.3, vertex_colors=True)),
                               "tinted")):
        pose = np.eye(4)
        pose[:3, 3] = (x, 0.0, 0.5)
        scene.add(coloured, material, pose=pose, name=name)
    return scene


def main(out_dir="."):
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    scene = build_scene()
    with glphong.Renderer(480, 320) as renderer:
        frame = renderer.render(scene)
        frame.save_png(out / "textured.png")
        report = glphong.verify(scene, renderer)
        path = glphong.save_gltf(scene, out / "textured.glb")
        again = renderer.render(glphong.load_scene(path)).radiance
    print(f"wrote {out / 'textured.png'}: {report}")
    difference = float(np.abs(again - frame.radiance).max() / frame.radiance.max())
    print(f"wrote {path}; reloaded render differs by {difference:.2g} of the peak radiance")
    return report, difference


if __name__ == "__main__":
    main(*sys.argv[1:2])
