"""glTF's layered materials beside their twin's error: a clear coat, a sheen and a glass wall.

Usage: python examples/gltf_layers.py [OUT_PNG]   (default: gltf_layers.png)

Three spheres of `glphong.GltfPBR` with the KHR_materials extensions that real glTF files carry
(docs/gltf_extensions.md, docs/transmission.md): a red base under a clear coat (``KHR_materials_clearcoat``), a dark
fabric with a sheen (``KHR_materials_sheen``: the Charlie lobe and its albedo scaling), and a thin glass wall
(``KHR_materials_transmission``, roughness 0: the opaque scene behind it is seen through it, exactly), over a
checkered floor.  The picture is the render beside the twin's error map (`glphong.analysis.error_maps.error_image`:
``|GPU - twin| / |twin|`` per pixel, black at 1e-8 and below, white at 1e-5 and above, on a log scale).
"""
import sys

import numpy as np

import glphong
from glphong import primitives
from glphong.analysis.error_maps import error_image
from glphong.imaging import save_png


def checker(cells=8, size=256):
    """A grey checker texture (sRGB, (size, size, 3) uint8)."""
    index = (np.arange(size) * cells // size)
    squares = (index[:, None] + index[None, :]) % 2
    return np.where(squares[..., None] == 1, 200, 60).astype(np.uint8).repeat(3, axis=-1)


def build_scene():
    camera = glphong.PerspectiveCamera.look_at((0.0, -3.6, 1.6), (0.0, 0.0, 0.35), (0.0, 0.0, 1.0), yfov=0.65)
    lights = [glphong.PointLight((1.8, -2.2, 3.0), 140.0), glphong.PointLight((-2.5, -1.0, 1.5), 40.0)]
    scene = glphong.Scene(camera, lights, ambient=glphong.AmbientLight(0.03))
    floor = glphong.GltfPBR(glphong.Texture(checker(), 1.0), 0.0, 0.8)
    scene.add(primitives.plane(5.0, 4), floor, name="floor")
    materials = {
        "clear coat": glphong.GltfPBR((0.7, 0.05, 0.03), 0.0, 0.6, clearcoat=1.0, clearcoat_roughness=0.05),
        "sheen": glphong.GltfPBR((0.05, 0.06, 0.2), 0.0, 0.9, sheen_color=(0.9, 0.8, 0.6), sheen_roughness=0.4),
        "glass": glphong.GltfPBR((0.9, 0.95, 1.0), 0.0, 0.0, transmission=1.0, two_sided=True),
    }
    for x, (name, material) in zip((-1.1, 0.0, 1.1), materials.items()):
        pose = np.eye(4)
        pose[:3, 3] = (x, 0.0, 0.5)
        scene.add(primitives.sphere(4, 0.45), material, pose=pose, name=name)
    return scene


def main(out_path="gltf_layers.png", width=480, height=240):
    scene = build_scene()
    with glphong.Renderer(width, height) as renderer:
        report = glphong.verify(scene, renderer)
    peak = float(np.percentile(report.gpu[report.mask], 99.5))
    save_png(out_path, np.concatenate([np.minimum(report.gpu / peak, 1.0), error_image(report)], axis=1))
    print(f"wrote {out_path}: {report}")
    return report


if __name__ == "__main__":
    main(*sys.argv[1:2])
