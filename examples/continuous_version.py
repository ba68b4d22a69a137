"""The lecture's two versions of the reflected radiance, side by side.

The continuous version integrates over the incident light,
``L_r = integral f_r(w_i, w_r) L_i(w_i) cos(theta_i) dw_i``; the discrete version sums over point lights,
``L_r = sum_j f_r(l_j, v) E_j cos(theta_j)``.  The same two spheres on a floor are lit four ways:

0. a sky (``glphong.EnvironmentLight`` of the bench's sky map, a sun at 35 degrees): Lambert by the irradiance cube
   map, the Phong lobe by spherical harmonics, each with its error against the exact integral measured;
1. a rectangular panel of radiance ``L`` (``glphong.RectLight``): Lambert and the lecture's Phong lobe in closed
   form, exact;
2. a spherical lamp (``glphong.SphereLight``) of the same power;
3. the discrete version: 4 x 4 point lights at the panel's cell centres, each of the intensity ``L A_cell`` the cell
   sends straight down (the panel's midpoint rule).

Each render is checked by ``glphong.verify``, whose second error map compares the shader's method with the exact
integral (a float64 quadrature over the light, or the closed forms in float64 where they are exact): the panel's
is 0, its closed forms being exact.  The sky's exact
integral costs about 40 ms a pixel, so its render is verified at ``verify_size`` (20 x 15 by default).  The soft shadow-less
highlight of the panel against the sixteen sharp highlights of the point lights is the difference the lecture
draws between the two versions.

Run:  python examples/continuous_version.py [out.png]
"""
import sys

import numpy as np

import glphong
from glphong import primitives
from glphong.lights.environment import Y_UP
from glphong.bench import sky_map

L = 6.0  # the panel's radiance [W/(m^2 sr)]
CENTER, U, V = np.array([0.0, 1.6, 0.6]), np.array([1.6, 0.0, 0.0]), np.array([0.0, -0.25, 0.9])  # emits along U x V: down


def scene_under(lights):
    """Two Phong spheres on a Phong floor under ``lights``."""
    camera = glphong.PerspectiveCamera.look_at((0.0, 1.6, 4.2), (0.0, -0.2, 0.0), yfov=np.radians(40.0))
    scene = glphong.Scene(camera, lights)
    material = glphong.Phong((0.18, 0.12, 0.08), 0.6, 40.0)
    for center, radius in (((-0.75, 0.0, 0.0), 0.65), ((0.8, -0.15, 0.3), 0.5)):
        pose = np.eye(4)
        pose[:3, 3] = center
        scene.add(primitives.sphere(4, radius), material, pose=pose)
    pose = np.eye(4)
    pose[:3, :3] = [[1, 0, 0], [0, 0, 1], [0, -1, 0]]
    pose[1, 3] = -0.65
    scene.add(primitives.plane(6.0, 8), material, pose=pose)
    return scene


def point_lights(cells=4):
    """The panel's midpoint rule as point lights: at each cell centre, the intensity the cell sends along its normal
    (``L A / cells^2`` W/sr), as an isotropic point of power ``4 pi`` times that."""
    area = np.linalg.norm(np.cross(U, V))
    out = []
    for a in range(cells):
        for b in range(cells):
            at = CENTER + U * ((a + 0.5) / cells - 0.5) + V * ((b + 0.5) / cells - 0.5)
            out.append(glphong.PointLight(at, 4 * np.pi * L * area / cells ** 2))
    return out


def main(out=None, width=240, height=180, verify_size=(20, 15)):
    panel = glphong.RectLight(CENTER, U, V, L)
    lamp = glphong.SphereLight.from_power(CENTER, 0.2, float(panel.power()[0]))
    sky = glphong.EnvironmentLight(sky_map(), rotation=Y_UP, scale=0.012, order=16, resolution=17)
    images = []
    with glphong.Renderer(width, height) as renderer, glphong.Renderer(*verify_size) as small:
        for label, lights in (("sky (EnvironmentLight)", [sky]), ("panel (RectLight)", [panel]),
                              ("lamp (SphereLight)", [lamp]), ("16 point lights", point_lights())):
            scene = scene_under(lights)
            report = glphong.verify(scene, small if lights[0] is sky else renderer)
            print(f"{label:22s} {report}")
            assert report.passed
            images.append(renderer.render(scene).radiance)
    strip = np.concatenate(images, axis=1)  # radiance [W/(m^2 sr)], the four side by side
    if out:
        glphong.imaging.save_png(out, strip, exposure=1.5)
        print("wrote", out)
    return strip


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else None)
