"""The lecture's "Phong Examples" slide with glphong's public API.

A grid of spheres: the light swings away from the viewing direction down the rows,
the shininess q grows along the columns; Phong on the left, Blinn-Torrance on the
right.  Every tile is also cross-checked against the numpy float64 twin.

Run:  python examples/phong_examples.py [out.png]
"""
import sys

import numpy as np
import trimesh

import glphong

Q_VALUES = [5, 20, 100, 500, 5000]
LIGHT_ANGLES_DEG = [10, 35, 60, 85]
TILE = 128


def sphere_tile(material, light_angle_deg):
    """A unit sphere seen from +z, lit by a 3 W/m^2 point light light_angle_deg off the view axis."""
    a = np.radians(light_angle_deg)
    light_dir = np.array([np.sin(a) / np.sqrt(2), np.sin(a) / np.sqrt(2), np.cos(a)])
    distance = 20.0
    power = 3.0 * 4 * np.pi * distance**2  # E = Phi / (4 pi d^2) = 3 W/m^2 at the sphere
    camera = glphong.PerspectiveCamera.look_at(eye=(0, 0, 4), target=(0, 0, 0), yfov=np.radians(32))
    scene = glphong.Scene(camera, lights=[glphong.PointLight(distance * light_dir, power)],
                          ambient=glphong.AmbientLight(0.15))
    scene.add(trimesh.creation.icosphere(subdivisions=5), material)
    return scene


def main(out="phong_examples_example.png"):
    rows = []
    worst = 0.0
    with glphong.Renderer(TILE, TILE) as renderer:
        for angle in LIGHT_ANGLES_DEG:
            row = []
            for model in (glphong.Phong, glphong.BlinnPhong):
                for q in Q_VALUES:
                    scene = sphere_tile(model(kd=(0.20, 0.05, 0.035), ks=0.5, q=q), angle)
                    row.append(renderer.render(scene).radiance)
                    report = glphong.verify(scene, renderer)
                    assert report.passed, report
                    worst = max(worst, report.max_relative_error)
            rows.append(np.concatenate(row, axis=1))
    glphong.imaging.save_png(out, np.concatenate(rows, axis=0), exposure=0.6)
    print(f"wrote {out}; every tile within the tolerance band, max relative error {worst:.3g}")


if __name__ == "__main__":
    main(*sys.argv[1:])
