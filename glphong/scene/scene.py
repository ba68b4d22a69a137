"""Scenes: a camera, lights, and meshes with materials, and the ways to build them.

A scene is data.  How its objects and lights become programs and uniforms is the program side's business
(`glphong.shaders.binding`, docs/design.md section 6).
"""
from dataclasses import dataclass

import numpy as np

from glphong.core import validate as _validate
from glphong.scene.camera import Camera
from glphong.scene.geometry import MeshData
from glphong.scene.from_trimesh import build_from_trimesh
from glphong.lights import AmbientLight, LightModel, registered_lights
from glphong.materials import Material

__all__ = ["Scene", "SceneObject", "MAX_ID"]

#: the largest instance id or category (the passes are uint32; 0 is the background)
MAX_ID = 2 ** 32 - 1

_LIGHT_WORDS = "glphong lights (PointLight, SpotLight, DirectionalLight, UnattenuatedPointLight or a LightModel of yours)"


@dataclass(frozen=True, eq=False)
class SceneObject:
    """One mesh drawn with one material.

    Attributes
    ----------
    mesh : MeshData
    material : glphong.materials.Material
    pose : (4, 4) ndarray
        Object-to-world affine transform, float64, read-only (a renderer caches what it derives from it:
        move an object by adding it again with another pose).
    name : str
    casts_shadow : bool
        Drawn into the shadow maps of the scene's shadowing lights (default True).
    instance_id : int
        The object's id in the frame's ``instance`` pass and the masks written from it: 1 to ``2^32 - 1``, unique
        in its scene (0 is the background).
    category : int
        Its class in the ``category`` pass (COCO's ``category_id``): 0 to ``2^32 - 1``.
    """

    mesh: MeshData
    material: Material
    pose: np.ndarray
    name: str
    casts_shadow: bool = True
    instance_id: int = 1
    category: int = 0

    @property
    def mirrored(self):
        """True when the pose mirrors (its 3x3 block has a negative determinant): front faces wind
        clockwise on screen."""
        return bool(np.linalg.det(self.pose[:3, :3]) < 0)

    @property
    def normal_matrix(self):
        """Inverse-transpose of the pose's 3x3 block, (3, 3) float64."""
        return np.linalg.inv(self.pose[:3, :3]).T


class Scene:
    """A camera, any number of lights, and objects.

    Parameters
    ----------
    camera : Camera
        A `PerspectiveCamera`, `IntrinsicsCamera` or `OrthographicCamera`.
    lights : sequence of glphong.lights.LightModel
        `PointLight`, `SpotLight`, `DirectionalLight`, `UnattenuatedPointLight` or a user's kind.
    ambient : AmbientLight, optional
        The ambient ``L_a`` of the term ``k_d L_a``.
    """

    def __init__(self, camera, lights=(), ambient=None):
        if not isinstance(camera, Camera):
            raise TypeError(f"camera must be a glphong camera such as PerspectiveCamera or OrthographicCamera "
                            f"(got {type(camera).__name__})")
        if ambient is not None and not isinstance(ambient, AmbientLight):
            raise TypeError(f"ambient must be a glphong.AmbientLight or None (got {type(ambient).__name__})")
        try:
            light_list = list(lights) if not isinstance(lights, (LightModel, AmbientLight, str, bytes)) else None
        except TypeError:
            light_list = None
        if light_list is None:
            raise TypeError(f"lights must be a sequence of {_LIGHT_WORDS} "
                            f"(got {type(lights).__name__}; wrap a single light in a list)")
        for i, light in enumerate(light_list):
            if not isinstance(light, LightModel):
                raise TypeError(f"lights[{i}] must be one of the {_LIGHT_WORDS} (got {type(light).__name__})")
        self.camera = camera
        self.ambient = ambient
        self._lights = []
        self._objects = []
        self._ids = {}  # instance id -> the object's name: `add` checks an id in constant time
        for light in light_list:
            self.add_light(light)

    @property
    def lights(self):
        """The lights, in the order they were added (tuple)."""
        return tuple(self._lights)

    @property
    def objects(self):
        """The objects, in the order they were added (tuple of SceneObject)."""
        return tuple(self._objects)

    def add_light(self, light):
        """Add a light: any `glphong.lights.LightModel` (`PointLight`, `SpotLight`, ...)."""
        if not isinstance(light, LightModel):
            raise TypeError(f"light must be one of the {_LIGHT_WORDS} (got {type(light).__name__})")
        self._lights.append(light)
        return light

    def add(self, mesh, material, pose=None, smooth=True, name=None, casts_shadow=True, instance_id=None, category=0):
        """Add a mesh drawn with a material.

        Parameters
        ----------
        mesh : trimesh.Trimesh or MeshData
        material : glphong.materials.Material
            Any material: a built-in or a user's `glphong.materials.MaterialModel` / `MaterialSum`.
        pose : (4, 4) array_like, optional
            Object-to-world affine transform (default identity).
        smooth : bool
            Interpolated vertex normals (default) or flat face normals; ignored for MeshData.
        name : str, optional
        casts_shadow : bool
            Whether the object is drawn into the shadow maps of lights with ``shadows=True`` (default True); every
            object receives shadows.
        instance_id : int, optional
            Its id in the ``instance`` pass (`glphong.Renderer.render`): 1 to ``2^32 - 1``, unique in the scene;
            default ``1 +`` the object's index.
        category : int
            Its class in the ``category`` pass, 0 to ``2^32 - 1`` (default 0).

        Returns
        -------
        SceneObject
        """
        if not isinstance(material, Material):
            raise TypeError(f"material must be a glphong material such as Lambert or Phong (got {type(material).__name__})")
        if not isinstance(smooth, (bool, np.bool_)):
            raise TypeError(f"smooth must be a bool, True or False (got {smooth!r})")
        if name is not None and not isinstance(name, str):
            raise TypeError(f"name must be a str or None (got {type(name).__name__})")
        if not isinstance(casts_shadow, (bool, np.bool_)):
            raise TypeError(f"casts_shadow must be a bool, True or False (got {casts_shadow!r})")
        if not isinstance(mesh, MeshData):
            import trimesh

            if not isinstance(mesh, trimesh.Trimesh):
                raise TypeError(f"mesh must be a trimesh.Trimesh or a glphong.scene.geometry.MeshData (got {type(mesh).__name__})")
        label = name or f"object{len(self._objects)}"
        instance_id = self._instance_id(label, instance_id)
        category = _validate.positive_int(f"object {label!r}: category", category, 0, MAX_ID)
        pose = np.array(_validate.affine_transform("pose", np.eye(4) if pose is None else pose), dtype=np.float64)
        pose.setflags(write=False)
        data = mesh if isinstance(mesh, MeshData) else MeshData.from_trimesh(mesh, smooth=bool(smooth))
        _check_mesh_serves(data, material, label)
        obj = SceneObject(data, material, pose, label, bool(casts_shadow), instance_id, category)
        self._objects.append(obj)
        self._ids[instance_id] = obj.name
        return obj

    def _instance_id(self, label, value):
        """``value`` checked (an int in [1, MAX_ID], not another object's), or the default ``1 +`` the index."""
        if value is None:
            value = len(self._objects) + 1
            default = " (the default, 1 + its index: give instance_id= to choose another)"
        else:
            value = _validate.positive_int(f"object {label!r}: instance_id", value, 1, MAX_ID)
            default = ""
        if value in self._ids:  # constant time: a file of many nodes adds its objects in linear time
            raise ValueError(f"object {label!r}: instance_id {value}{default} is already object "
                             f"{self._ids[value]!r}'s; ids are unique in a scene")
        return value

    @classmethod
    def from_trimesh(cls, trimesh_scene, camera=None, lights=None, ambient=None, materials=None, vertex_colors="srgb"):
        """A scene of a ``trimesh.Scene``: its nodes' transforms and parts (`glphong.scene.from_trimesh`)."""
        return build_from_trimesh(cls, trimesh_scene, camera, lights, ambient, materials, vertex_colors)

    def light_counts(self):
        """Number of lights of each kind the scene has, dict of kind name to int, in the shader's loop order (the
        registry's)."""
        counts = {}
        for kind in registered_lights():
            mine = sum(type(light) is kind for light in self._lights)
            if mine:
                counts[kind.name] = mine
        return counts

    @property
    def ambient_radiance(self):
        """``L_a`` as a tuple of 3 float, or None."""
        return None if self.ambient is None else self.ambient.radiance


def _check_mesh_serves(mesh, material, name):
    """A mesh must carry what the material's terms and its normal map need (tangents or UVs)."""
    if material.normal_map is not None and (mesh.uvs is None or not mesh.has_tangents):
        raise ValueError(f"object {name!r}: the material has a normal map, which needs the mesh's UVs and a tangent "
                         "frame: give MeshData uvs= (tangents are then derived) or tangents=, or use glphong.primitives")
    for term in material.components:
        if term.vanishes():
            continue  # left out of every program: it needs nothing
        if "tangent" in term.needs and not mesh.has_tangents:
            raise ValueError(f"object {name!r}: the material term {term.name!r} needs a tangent frame, but the mesh has "
                             "neither tangents nor UVs: give MeshData tangents= or uvs=, a trimesh with UVs, or use "
                             "glphong.primitives (analytic tangents)")
        if "uv" in term.needs and mesh.uvs is None:
            raise ValueError(f"object {name!r}: the material term {term.name!r} needs UVs, but the mesh has none: "
                             "give MeshData uvs=, a trimesh with UVs, or use glphong.primitives")
        for param, value in term.surface_inputs().items():
            if value.texture is not None and mesh.uvs is None:
                raise ValueError(f"object {name!r}: {term.name}.{param} is textured, but the mesh has no UVs: give "
                                 "MeshData uvs=, a trimesh with UVs, or use glphong.primitives")
            if value.vertex_colors and mesh.colors is None:
                raise ValueError(f"object {name!r}: {term.name}.{param} takes vertex colours, but the mesh has none: "
                                 "give MeshData colors= or a trimesh with vertex colours")
