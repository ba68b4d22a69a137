"""Built-in scene functions for batches: `turntable_scene` and `orbit_scene`.

`turntable_scene` is two spheres on a plane seen from an azimuth; `orbit_scene` a scene file with its
camera turned about the geometry.  Both are picklable top-level ``scene_fn`` functions, which 'spawn'
workers import by their module path.
"""
import math

import numpy as np
from glphong.formats.load import load_scene, scene_bounds
from glphong.materials.blinn import BlinnPhong
from glphong.materials.lambert import Lambert
from glphong.materials.phong import Phong
from glphong.scene import primitives
from glphong.scene.camera import PerspectiveCamera
from glphong.lights import AmbientLight, PointLight
from glphong.scene.scene import Scene

__all__ = ["turntable_scene", "orbit_scene"]


def turntable_scene(angle):
    """A built-in scene for batches and examples: a Phong and a Blinn-Phong sphere on a plane under a point
    light and ambient light, seen from ``angle`` degrees of azimuth (a picklable top-level ``scene_fn``)."""
    a = math.radians(float(angle))
    camera = PerspectiveCamera.look_at((3.5 * math.sin(a), 1.6, 3.5 * math.cos(a)), (0.0, 0.0, 0.0),
                                       yfov=math.radians(40.0))
    scene = Scene(camera, [PointLight((2.0, 3.0, 2.0), 250.0)], ambient=AmbientLight(0.03))
    for x, material in ((-0.7, Phong((0.20, 0.06, 0.04), 0.5, 60.0)), (0.7, BlinnPhong((0.04, 0.08, 0.20), 0.5, 240.0))):
        pose = np.diag([0.6, 0.6, 0.6, 1.0])
        pose[:3, 3] = (x, 0.0, 0.0)
        scene.add(primitives.sphere(4), material, pose=pose)
    floor = np.eye(4)
    floor[:3, :3] = [[1, 0, 0], [0, 0, 1], [0, -1, 0]]
    floor[1, 3] = -0.6
    scene.add(primitives.plane(6.0, 4), Lambert(0.08), pose=floor)
    return scene


def orbit_scene(spec):
    """``spec = (path, angle[, load_scene keywords])``: the scene file at ``path`` (`glphong.load_scene`) with the
    camera turned by ``angle`` degrees about the vertical axis through the geometry's centre (a picklable
    ``scene_fn`` for turntables of files: ``glphong render FILE --frames N``)."""
    path, angle = spec[:2]
    scene = load_scene(path, **(spec[2] if len(spec) > 2 else {}))
    camera = scene.camera
    target = camera.position - camera.pose[:3, 2] * np.linalg.norm(camera.position - scene_bounds(scene)[0])
    a = math.radians(float(angle))
    turn = np.array([[math.cos(a), 0.0, math.sin(a)], [0.0, 1.0, 0.0], [-math.sin(a), 0.0, math.cos(a)]])
    eye = target + turn @ (camera.position - target)
    scene.camera = PerspectiveCamera.look_at(eye, target, yfov=camera.yfov, znear=camera.znear, zfar=camera.zfar)
    return scene
