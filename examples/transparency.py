"""Transparency composited per pixel: a glass-like sphere and two transparent panes that cross each other.

Usage: python examples/transparency.py [OUT_PNG]   (default: transparency.png)

Blended materials (``alpha_blend=glphong.AlphaBlend(alpha)``, glTF's alphaMode BLEND) are composited over what lies
behind them in depth order per pixel, not per object: the panes change order along the line where they cross, and the
sphere shows its far side through its near one (it is two-sided).  The image is the render beside the twin's error
map (``|GPU - twin| / |twin|`` per pixel, white at 1e-5 and above, on a log scale from 1e-8) and the pixels the twin
leaves unchecked (red: the samples of the pixel see different layers, or two layers' order is not determined in
float32).  docs/design.md section 16 says how.
"""
import sys

import numpy as np

import glphong
from glphong import primitives
from glphong.analysis.error_maps import error_image
from glphong.imaging import save_png


def build_scene():
    camera = glphong.PerspectiveCamera.look_at((0.4, -3.4, 1.5), (0.0, 0.0, 0.4), (0.0, 0.0, 1.0), yfov=0.7)
    scene = glphong.Scene(camera, [glphong.PointLight((1.5, -2.0, 3.0), 120.0)], ambient=glphong.AmbientLight(0.04))
    scene.add(primitives.plane(5.0, 4), glphong.Lambert(0.25), name="floor")
    behind = np.eye(4)
    behind[:3, 3] = (0.6, 0.9, 0.45)
    scene.add(primitives.sphere(4, 0.45), glphong.Phong(0.3, 0.3, 40.0), pose=behind, name="opaque ball")
    glass = np.eye(4)
    glass[:3, 3] = (-0.55, -0.2, 0.55)
    scene.add(primitives.sphere(4, 0.5), glphong.GltfPBR((0.75, 0.85, 1.0), 0.0, 0.15, two_sided=True,
                                                          alpha_blend=glphong.AlphaBlend(0.3)), pose=glass, name="glass")
    for turn, colour, name in ((0.5, (0.9, 0.2, 0.1), "red pane"), (-0.5, (0.1, 0.5, 0.9), "blue pane")):
        pose = np.eye(4)
        c, s = np.cos(turn), np.sin(turn)
        pose[:3, :3] = [[c, 0.0, s], [s, 0.0, -c], [0.0, 1.0, 0.0]]  # upright, its normal turned about z by `turn`
        pose[:3, 3] = (0.5, 0.1, 0.5)
        scene.add(primitives.plane(0.9), glphong.Lambert(np.array(colour) / np.pi, two_sided=True,
                                                         alpha_blend=glphong.AlphaBlend(0.5)), pose=pose, name=name)
    return scene


def main(out_path="transparency.png", width=400, height=300):
    scene = build_scene()
    with glphong.Renderer(width, height) as renderer:
        report = glphong.verify(scene, renderer)
    errors = error_image(report, low=1e-8, high=1e-5)
    errors[report.blend.unchecked] = (1.0, 0.0, 0.0)
    peak = float(report.gpu.max())
    save_png(out_path, np.concatenate([report.gpu / peak, errors], axis=1))
    print(f"wrote {out_path}: {report}; blend {report.summary()['blend']}")
    return report


if __name__ == "__main__":
    main(*sys.argv[1:2])
