"""Built-in scene functions for batches: `turntable_scene`, `orbit_scene` and `tabletop_scene`.

`turntable_scene` is two spheres on a plane seen from an azimuth; `orbit_scene` a scene file with its
camera turned about the geometry; `tabletop_scene` a few objects of three models at random rigid poses
on a table top, from a random view (a BOP-like image: ``render_many(..., fmt='bop', obj_ids='category')``).
All are picklable top-level ``scene_fn`` functions, which 'spawn' workers import by their module path.
"""
import math

import numpy as np
import trimesh

from glphong.formats.load import load_scene, scene_bounds
from glphong.materials.blinn import BlinnPhong
from glphong.materials.lambert import Lambert
from glphong.materials.phong import Phong
from glphong.scene import primitives
from glphong.scene.camera import PerspectiveCamera
from glphong.scene.geometry import MeshData
from glphong.lights import AmbientLight, PointLight
from glphong.scene.scene import Scene

__all__ = ["turntable_scene", "orbit_scene", "tabletop_scene", "TABLETOP_MODELS"]

#: the models of `tabletop_scene`'s objects, by category (1, 2, 3): their BOP obj_ids with ``obj_ids='category'``
TABLETOP_MODELS = {1: "sphere, radius 3 cm", 2: "box, 6 x 4 x 3 cm", 3: "cylinder, radius 2 cm, length 7 cm, lying"}
#: each model's mesh [m] (made on first use, once per process) and the height of its centre above the table
_TABLETOP = {}


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


def _tabletop_models():
    if not _TABLETOP:
        _TABLETOP[1] = (primitives.sphere(3, 0.03), 0.03)
        _TABLETOP[2] = (MeshData.from_trimesh(trimesh.creation.box((0.06, 0.03, 0.04)), smooth=False), 0.015)
        cylinder = trimesh.creation.cylinder(0.02, 0.07, sections=24)  # along z: lying on the table
        _TABLETOP[3] = (MeshData.from_trimesh(cylinder, smooth=False), 0.02)
    return _TABLETOP


def tabletop_scene(spec):
    """A built-in BOP-like scene: ``spec = seed`` or ``(seed, objects)`` (default 4 objects).

    Each object is one of `TABLETOP_MODELS` (its ``category``; instance ids 1, 2, ...) resting on the table top
    (the plane y = 0, not drawn) at a random turn about the vertical and a random place within 12 cm of the
    centre, at least 7 cm from the others (where it finds room); a Phong material of a random colour; a point
    light above and ambient light; a `PerspectiveCamera` (45 degrees) 0.35 to 0.55 m from the centre, 25 to 65
    degrees above the table, looking at a point near it.  Every pose is rigid (BOP's ``cam_R_m2c``); the same
    ``spec`` gives the same scene.  A picklable top-level ``scene_fn``.
    """
    seed, count = (spec, 4) if np.ndim(spec) == 0 else (spec[0], spec[1])
    rng = np.random.default_rng(int(seed))
    models = _tabletop_models()
    places, tries = [], 0
    while len(places) < int(count):
        place, tries = rng.uniform(-0.12, 0.12, 2), tries + 1
        if tries > 100 or all(np.hypot(*(place - p)) >= 0.07 for p in places):  # crowded: they may touch
            places.append(place)
    azimuth, elevation = rng.uniform(0.0, 2.0 * math.pi), math.radians(rng.uniform(25.0, 65.0))
    distance = rng.uniform(0.35, 0.55)
    eye = distance * np.array([math.cos(elevation) * math.sin(azimuth), math.sin(elevation),
                               math.cos(elevation) * math.cos(azimuth)])
    target = (rng.uniform(-0.03, 0.03), 0.02, rng.uniform(-0.03, 0.03))
    camera = PerspectiveCamera.look_at(eye, target, yfov=math.radians(45.0))
    scene = Scene(camera, [PointLight((0.3, 1.0, 0.5), 15.0)], ambient=AmbientLight(0.05))
    for k, (x, z) in enumerate(places):
        category = int(rng.integers(1, 4))
        mesh, lift = models[category]
        turn = rng.uniform(0.0, 2.0 * math.pi)
        pose = np.eye(4)
        pose[:3, :3] = [[math.cos(turn), 0.0, math.sin(turn)], [0.0, 1.0, 0.0], [-math.sin(turn), 0.0, math.cos(turn)]]
        pose[:3, 3] = (x, lift, z)
        scene.add(mesh, Phong(tuple(rng.uniform(0.1, 0.7, 3)), 0.3, 40.0), pose=pose, instance_id=k + 1,
                  category=category)
    return scene
