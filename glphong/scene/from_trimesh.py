"""Scenes from trimesh objects, and the default view a scene without camera or light gets.

`build_from_trimesh` (`glphong.Scene.from_trimesh`) keeps a ``trimesh.Scene``'s node transforms and
parts; a part's material comes from ``materials`` (a mapping by part or material name, or a function of
the name and the trimesh geometry), else from its trimesh material: a ``SimpleMaterial`` (OBJ) as
`MtlPhong` from its 8-bit colours, a ``PBRMaterial`` (glTF) as ``Lambert(baseColor / pi)`` (each with its
image as a texture the colour multiplies, where the mesh has UVs), else ``Lambert(0.5 / pi)``; vertex
colours are decoded as 8-bit sRGB unless ``vertex_colors='linear'``.

`default_view`: unless given, the camera looks at the centre of the geometry's bounding sphere (radius
``r``) from ``3 r`` along ``(0.3, 0.4, 1)`` (it fills 87% of a 45-degree view), a point light above and
beside it delivers ``E = 1 W/m^2`` at the centre, and the ambient light is ``L_a = 0.1``.

The scene class is passed in (`glphong.Scene` passes itself), so this module does not import it.
"""
import math

import numpy as np

from glphong.core.filesafety import SceneFileError
from glphong.materials import Material, Texture
from glphong.materials.lambert import Lambert
from glphong.materials.mtl import MtlPhong
from glphong.scene.camera import PerspectiveCamera
from glphong.scene.culling import points_sphere
from glphong.scene.geometry import MeshData
from glphong.lights import AmbientLight, PointLight

__all__ = ["build_from_trimesh", "default_view", "DEFAULT_VIEW_EXTENT", "scene_bounds", "empty_scene", "with_default_view"]


def empty_scene(scene_class, camera, lights, ambient):
    """An empty ``scene_class`` with the given camera (a stand-in until `with_default_view` places the
    default one) and lights."""
    return scene_class(camera if camera is not None else PerspectiveCamera(1.0), lights or (), ambient)


def scene_bounds(scene):
    """``(centre (3,), radius)``: a world-space sphere about the centre of the scene's bounding box holding
    every vertex of every object (radius at least 1e-6 m)."""

    points = [(obj.pose[:3, :3] @ obj.mesh.positions.T).T + obj.pose[:3, 3] for obj in scene.objects]
    centre, radius = points_sphere(np.concatenate(points) if points else np.zeros((1, 3)))
    return centre, max(radius, 1e-6)


#: the largest scene extent [m] (bounding sphere's radius and centre) that gets a default view: its light, some 5 radii
#: away, has the power 4 pi d^2 that float32 still holds (a light's limit, 4.3e39 W, is reached near d = 1.8e19 m)
DEFAULT_VIEW_EXTENT = 1e18


def default_view(scene, source=None):
    """A camera, a point light and an ambient light for a scene that has none (see the module):
    ``(camera, [light], ambient)``.

    Raises
    ------
    ValueError
        (`glphong.filesafety.SceneFileError` naming ``source``, the file the scene came from, where given) The
        scene's extent is beyond `DEFAULT_VIEW_EXTENT` or not finite: no default camera and light exist in float32.
    """

    centre, radius = scene_bounds(scene)
    if not (np.all(np.isfinite(centre)) and np.isfinite(radius)) or max(radius, *np.abs(centre)) > DEFAULT_VIEW_EXTENT:
        message = (f"the scene's bounding sphere (centre {np.array2string(np.asarray(centre), precision=3)}, radius "
                   f"{radius:.3g} m) lies beyond {DEFAULT_VIEW_EXTENT:g} m, where no default camera and light can be "
                   "placed in float32: give camera= and lights=")
        raise SceneFileError(source, message) if source is not None else ValueError(message)
    direction = np.array([0.3, 0.4, 1.0]) / np.linalg.norm([0.3, 0.4, 1.0])
    distance = 3.0 * radius  # the bounding sphere fills 87% of a 45-degree view
    camera = PerspectiveCamera.look_at(centre + distance * direction, centre, yfov=math.radians(45.0),
                                       znear=0.01 * radius, zfar=distance + 4 * radius)
    light = centre + distance * direction + radius * np.array([1.0, 1.5, 0.0])
    d = np.linalg.norm(light - centre)
    return camera, [PointLight(tuple(light), 4 * math.pi * d * d)], AmbientLight(0.1)


def with_default_view(scene, camera, lights, ambient, source=None):
    """``scene`` with `default_view`'s camera where none was given, and its lights and ambient light where
    no lights were given either (``source``: the file the scene came from, named in `default_view`'s error)."""
    if camera is None:
        view_camera, view_lights, view_ambient = default_view(scene, source)
        scene.camera = view_camera
        if lights is None:
            for light in view_lights:
                scene.add_light(light)
            if ambient is None:
                scene.ambient = view_ambient
    return scene


def _trimesh_material(geometry):
    visual = getattr(geometry, "visual", None)
    material = getattr(visual, "material", None)
    kind = type(material).__name__
    has_uv = getattr(visual, "uv", None) is not None

    def textured(scale, image):  # the material's image times its colour, where the mesh has UVs
        return Texture(np.asarray(image.convert("RGB")), scale=scale) if image is not None and has_uv else scale

    if kind == "SimpleMaterial":
        rgb = lambda c: tuple(np.asarray(c, dtype=np.float64)[:3] / 255.0)  # noqa: E731
        return MtlPhong(textured(rgb(material.diffuse), getattr(material, "image", None)), rgb(material.specular),
                        float(material.glossiness or 0.0), rgb(material.ambient))
    if kind == "PBRMaterial":
        factor = material.baseColorFactor if material.baseColorFactor is not None else (255, 255, 255, 255)
        kd = tuple(np.asarray(factor, dtype=np.float64)[:3] / 255.0 / math.pi)
        return Lambert(textured(kd, material.baseColorTexture))
    return Lambert(0.5 / math.pi)


def build_from_trimesh(scene_class, trimesh_scene, camera=None, lights=None, ambient=None, materials=None,
                       vertex_colors="srgb"):
    """A ``scene_class`` (`glphong.Scene`) of a ``trimesh.Scene`` (or ``Trimesh``): every node's geometry with its world
    transform, named after the node; materials as in the module notes.

    Parameters
    ----------
    scene_class : type
        `glphong.Scene` (or a subclass): `glphong.Scene.from_trimesh` passes itself.
    trimesh_scene : trimesh.Scene or trimesh.Trimesh
    camera : glphong camera, optional
        Default: `default_view`'s (also its light and ambient light when ``lights`` is None).
    lights : sequence of lights, optional
    ambient : glphong.AmbientLight, optional
    materials : dict of str to Material, or callable, optional
        By geometry name or material name; a callable gets ``(name, geometry)`` and returns a Material
        (or None for the default).
    vertex_colors : {'srgb', 'linear'}
        The encoding of the meshes' vertex colours (`glphong.scene.geometry.MeshData.from_trimesh`).
    """
    import trimesh

    if isinstance(trimesh_scene, trimesh.Trimesh):
        trimesh_scene = trimesh.Scene(trimesh_scene)
    if not isinstance(trimesh_scene, trimesh.Scene):
        raise TypeError(f"trimesh_scene must be a trimesh.Scene or trimesh.Trimesh (got {type(trimesh_scene).__name__})")
    parts = []
    for node in trimesh_scene.graph.nodes_geometry:
        transform, geometry_name = trimesh_scene.graph[node]
        geometry = trimesh_scene.geometry[geometry_name]
        if not isinstance(geometry, trimesh.Trimesh) or len(geometry.faces) == 0:
            continue  # point clouds and paths have no surface to shade
        material = None
        if callable(materials):
            material = materials(geometry_name, geometry)
        elif materials:
            material_name = getattr(getattr(geometry.visual, "material", None), "name", None)
            material = materials.get(geometry_name, materials.get(material_name))
        if material is None:
            material = _trimesh_material(geometry)
        if not isinstance(material, Material):
            raise TypeError(f"materials gave {type(material).__name__} for {geometry_name!r}: it must give a "
                            "glphong material")
        parts.append((geometry, material, np.asarray(transform, dtype=np.float64), str(node)))
    scene = empty_scene(scene_class, camera, lights, ambient)
    for geometry, material, transform, name in parts:
        scene.add(MeshData.from_trimesh(geometry, colors=vertex_colors), material, pose=transform, name=name)
    return with_default_view(scene, camera, lights, ambient)


