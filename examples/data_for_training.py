"""A small 6D-pose dataset: three objects moving over two frames, written as a BOP scene, and the frame's passes
side by side.

Each frame is rendered once with the radiance, depth, instance, NOCS and flow passes (one draw: the radiance
programs write the planes the passes read) and the matte (each object's share of each pixel, from 32 x 32 samples a
pixel), checked against the float64 twins (`glphong.verify`, every pass; the matte against the exact coverage), and
written with `glphong.datasets.write_bop` (rgb, 16-bit depth, amodal and visible masks, scene_camera.json,
scene_gt.json, scene_gt_info.json, as the BOP toolkit reads them).  The picture shows frame 0: the shaded image, the
depth (near bright, the background black), the instance ids (a colour each, from the pixel centre), the coverage (the
matte: each pixel the ids' colours weighted by their shares, so edges blend as much as each object covers), the NOCS
(object coordinates in the unit cube of each mesh's box, as RGB) and the flow to frame 1 (hue: direction,
saturation: length).

Run:  python examples/data_for_training.py [picture.png] [bop_folder]
"""
import sys
import tempfile

import numpy as np
import trimesh
from PIL import Image

import glphong
from glphong import primitives
from glphong.datasets import write_bop
from glphong.scene.geometry import MeshData

SIZE = (160, 120)
SPHERE = primitives.sphere(3, 0.35)
BOX = MeshData.from_trimesh(trimesh.creation.box((0.5, 0.35, 0.4)), smooth=False)
CAPSULE = MeshData.from_trimesh(trimesh.creation.capsule(height=0.5, radius=0.15, count=(16, 16)))
PASSES = ("radiance", "depth", "instance", "matte", "nocs", "flow")


def pose(angle, shift):
    """A rotation of ``angle`` [rad] about the axis (0.3, 1, 0.2) and a translation ``shift`` [m], (4, 4)."""
    axis = np.array([0.3, 1.0, 0.2]) / np.linalg.norm([0.3, 1.0, 0.2])
    out = trimesh.transformations.rotation_matrix(angle, axis)
    out[:3, 3] = shift
    return out


def build_scene(t):
    """Frame ``t`` (0, 1, ...): a sphere, a box and a capsule on their own paths, an OpenCV camera."""
    camera = glphong.IntrinsicsCamera(240.0, 240.0, 79.5, 59.5, *SIZE,
                                      pose=glphong.PerspectiveCamera.look_at((0.2, 0.8, 2.6), (0.0, 0.0, 0.0)).pose)
    scene = glphong.Scene(camera, [glphong.PointLight((1.5, 2.5, 2.5), 150.0)], ambient=glphong.AmbientLight(0.05))
    scene.add(SPHERE, glphong.Phong(0.5, 0.3, 30.0), pose=pose(0.2 * t, (-0.55 + 0.05 * t, 0.0, 0.0)), category=1)
    scene.add(BOX, glphong.Lambert(0.6), pose=pose(0.5 + 0.15 * t, (0.35, -0.05, 0.15)), category=2)
    scene.add(CAPSULE, glphong.BlinnPhong(0.4, 0.4, 60.0), pose=pose(1.0 - 0.1 * t, (0.0, 0.1 + 0.04 * t, -0.5)),
              category=3)
    return scene


def colours(ids):
    """A distinct colour for each id (0: black), (H, W, 3) float in [0, 1]."""
    palette = np.array([[0, 0, 0], [0.9, 0.3, 0.2], [0.2, 0.7, 0.3], [0.25, 0.4, 0.95], [0.9, 0.8, 0.2]])
    return palette[np.minimum(ids, len(palette) - 1)]


def coverage_colours(ids, fractions):
    """Each pixel's matte as colour: the ids' colours (`colours`) weighted by their shares, (H, W, 3) in [0, 1]."""
    return np.sum(colours(ids) * fractions[..., None], axis=-2)


def flow_colours(flow):
    """Hue from the flow's direction, saturation from its length (the largest finite one: 1), (H, W, 3) in [0, 1];
    NaN (behind the other camera) black."""
    finite = np.isfinite(flow).all(axis=-1)
    angle = np.where(finite, np.arctan2(flow[..., 1], flow[..., 0]), 0.0)
    length = np.where(finite, np.hypot(flow[..., 0], flow[..., 1]), 0.0)
    saturation = length / max(length.max(), 1e-12)
    hue = (angle / (2 * np.pi)) % 1.0
    # HSV with value 1 to RGB: each channel 1 - s * clamp(|6 h - k| ..) as the hexcone model gives
    k = np.array([5.0, 3.0, 1.0])
    channel = np.clip(np.minimum((k + 6.0 * hue[..., None]) % 6.0, 4.0 - (k + 6.0 * hue[..., None]) % 6.0), 0, 1)
    return np.where(finite[..., None], 1.0 - saturation[..., None] * channel, 0.0)


def main(picture="data_for_training.png", bop_folder=None):
    bop_folder = bop_folder or tempfile.mkdtemp(prefix="glphong-bop-")
    frames = [build_scene(t) for t in range(3)]
    with glphong.Renderer(*SIZE) as renderer:
        for t in range(2):
            paths = write_bop(bop_folder, frames[t], renderer, scene_id=0, im_id=t)
            report = glphong.verify(frames[t], renderer, passes=PASSES[1:], next_scene=frames[t + 1])
            print(f"frame {t}: {report}")
            assert report.passed
        frame = renderer.render(frames[0], passes=PASSES, next_scene=frames[1])
    print(f"BOP scene in {bop_folder}: {paths['scene_gt']}, {len(paths['mask_visib'])} objects an image")
    shaded = glphong.imaging.srgb_encode(np.clip(frame.radiance, 0.0, 1.0))
    depth = np.where(frame.mask, 1.0 - (frame.depth - frame.depth[frame.mask].min()) / np.ptp(frame.depth[frame.mask])
                     * 0.8, 0.0)
    panels = [shaded, np.repeat(depth[..., None], 3, axis=-1), colours(frame.instance),
              coverage_colours(frame.matte_ids, frame.matte_fractions), np.where(frame.mask[..., None], frame.nocs, 0.0), np.where(frame.mask[..., None], flow_colours(frame.flow), 0.0)]
    gap = np.ones((SIZE[1], 4, 3))
    strip = np.concatenate([p for panel in panels for p in (panel, gap)][:-1], axis=1)
    Image.fromarray((np.clip(strip, 0.0, 1.0) * 255 + 0.5).astype(np.uint8)).save(picture)
    print(f"wrote {picture}: shaded, depth, instance, coverage, NOCS, flow to the next frame")
    return frame


if __name__ == "__main__":
    main(*sys.argv[1:3])
