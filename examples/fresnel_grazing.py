"""The lecture's question about Phong's highlights at grazing angles, answered with a Fresnel factor.

Real glossy surfaces (a table top, a road, a sheet of paper) reflect far more at grazing angles than
head on; the lecture's Phong and Blinn lobes do not.  This script renders a glossy floor
(``BlinnPhong`` with kd = 0, ks = 1, q = 2000) under a distant light placed in the mirror direction of
the view, seen from 0, 60, 80 and 88 degrees off the normal, with and without
``fresnel=SchlickFresnel(0.04)`` (a dielectric such as plastic or glass: 4 % at normal incidence).  At
the peak pixel of each view it prints the peak radiance without Fresnel, the ratio with / without
(which is ``F(h.l)`` at that pixel, computed from the G-buffer's position) and writes a strip of the
eight images.

Run:  python examples/fresnel_grazing.py [out.png]
Its test: tests/materials/test_fresnel.py::test_a_fresnel_floor_brightens_toward_grazing.
"""
import sys

import numpy as np

import glphong
from glphong import primitives
from glphong.materials import SchlickFresnel

SIZE = (96, 64)
VIEW_ANGLES_DEG = (0.0, 60.0, 80.0, 88.0)
F0 = 0.04


def build_scene(view_angle_deg, fresnel):
    """The floor (z = 0, 40 m square) seen from ``view_angle_deg`` off its normal at 3 m, the light
    a directional one from the mirror direction."""
    theta = np.radians(view_angle_deg)
    eye = 3.0 * np.array([np.sin(theta), 0.0, np.cos(theta)])
    up = (0.0, 1.0, 0.0) if view_angle_deg == 0 else (0.0, 0.0, 1.0)
    camera = glphong.PerspectiveCamera.look_at(tuple(eye), (0.0, 0.0, 0.0), up=up, yfov=np.radians(20.0))
    towards_floor = (np.sin(theta), 0.0, -np.cos(theta))  # travels from the mirror of the eye toward the origin
    scene = glphong.Scene(camera, lights=[glphong.DirectionalLight(towards_floor, irradiance=1.0)])
    scene.add(primitives.plane(40.0, segments=8), glphong.BlinnPhong(0.0, 1.0, 2000.0, fresnel=fresnel), name="floor")
    return scene


def measure(renderer):
    """Per view angle: the peak radiance without Fresnel, with / without at that pixel, and F(h.l) there."""
    rows = []
    for angle in VIEW_ANGLES_DEG:
        plain = build_scene(angle, None)
        glossy = build_scene(angle, SchlickFresnel(F0))
        without = renderer.render(plain).radiance[..., 1].astype(np.float64)
        with_f = renderer.render(glossy).radiance[..., 1].astype(np.float64)
        y, x = np.unravel_index(np.argmax(without), without.shape)
        position = renderer.gbuffer(plain).position[y, x].astype(np.float64)
        v = plain.camera.position - position
        v /= np.linalg.norm(v)
        l = -np.asarray(plain.lights[0].direction, dtype=np.float64)
        l /= np.linalg.norm(l)
        h = (l + v) / np.linalg.norm(l + v)
        rows.append({"view_angle_deg": angle, "peak_without": float(without[y, x]), "ratio": float(with_f[y, x] / without[y, x]),
                     "fresnel_at_peak": float(F0 + (1 - F0) * (1 - np.dot(h, l)) ** 5), "pixel": (int(x), int(y)),
                     "images": (without, with_f)})
    return rows


def main(out="fresnel_grazing.png"):
    from PIL import Image

    with glphong.Renderer(*SIZE) as renderer:
        rows = measure(renderer)
    print("view angle   peak without F   with / without   F(h.l) at the peak")
    for r in rows:
        print(f"{r['view_angle_deg']:8.0f}    {r['peak_without']:14.4g}   {r['ratio']:14.4f}   {r['fresnel_at_peak']:10.4f}")
    strip = np.concatenate([np.concatenate(r["images"], axis=0) for r in rows], axis=1)
    display = glphong.imaging.srgb_encode(np.clip(strip / max(r["peak_without"] for r in rows), 0, 1))
    Image.fromarray((display * 255 + 0.5).astype(np.uint8)).save(out)
    print(f"wrote {out} (top row: no Fresnel; bottom row: SchlickFresnel({F0}); left to right {VIEW_ANGLES_DEG} degrees)")


if __name__ == "__main__":
    main(*sys.argv[1:2])
