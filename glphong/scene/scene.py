"""Scenes: a camera, lights, and meshes with materials.

A scene knows the program key of each of its objects and packs its lights into
the float32 uniform arrays that both the GPU and the numpy twin read.
"""
from dataclasses import dataclass

import numpy as np

from glphong.core import validate as _validate
from glphong.scene.camera import Camera
from glphong.scene.geometry import MeshData
from glphong.scene.from_trimesh import build_from_trimesh
from glphong.scene.shadows import shadow_setups
from glphong.shaders.key import GBUFFER_PLANES, light_keys, lod_slots, program_key
from glphong.lights import AmbientLight, LightModel, light_named
from glphong.materials import Material
from glphong.materials.surface import TextureImage
from glphong.materials.table import TableData
from glphong.materials import model_named
from glphong.shaders.key import UBER_MAX_LIGHTS

__all__ = ["Scene", "SceneObject"]

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
    """

    mesh: MeshData
    material: Material
    pose: np.ndarray
    name: str
    casts_shadow: bool = True

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

    def add(self, mesh, material, pose=None, smooth=True, name=None, casts_shadow=True):
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
        pose = np.array(_validate.affine_transform("pose", np.eye(4) if pose is None else pose), dtype=np.float64)
        pose.setflags(write=False)
        data = mesh if isinstance(mesh, MeshData) else MeshData.from_trimesh(mesh, smooth=bool(smooth))
        _check_mesh_serves(data, material, name or f"object{len(self._objects)}")
        obj = SceneObject(data, material, pose, name or f"object{len(self._objects)}", bool(casts_shadow))
        self._objects.append(obj)
        return obj

    @classmethod
    def from_trimesh(cls, trimesh_scene, camera=None, lights=None, ambient=None, materials=None, vertex_colors="srgb"):
        """A scene of a ``trimesh.Scene``: its nodes' transforms and parts (`glphong.scene.from_trimesh`)."""
        return build_from_trimesh(cls, trimesh_scene, camera, lights, ambient, materials, vertex_colors)

    def light_counts(self):
        """Number of lights of each kind the scene has, dict of kind name to int, in the shader's loop order."""
        return {k.name: k.count for k in self.light_keys()}

    def light_keys(self):
        """The `glphong.shaders.key.LightKey` of each kind present (computed once per state of the lights and of
        whether any object casts shadows)."""
        casters = any(obj.casts_shadow for obj in self._objects)
        state = (len(self._lights), casters)
        cached = getattr(self, "_light_keys", None)
        if cached is None or cached[0] != state:
            cached = self._light_keys = (state, light_keys(self._lights, casters))
        return cached[1]

    def shadow_setups(self, lights, size):
        """The `glphong.scene.shadows.ShadowSetup` of each shadowing light of ``lights`` (a program key's `LightKey`
        tuple) with maps of ``size`` texels, in slot order; made once per state of the scene (objects and lights are
        only ever added), not once per frame or object: the bounds walk every vertex."""
        state = (len(self._objects), len(self._lights), lights, size)
        cached = getattr(self, "_shadow_setups", None)
        if cached is None or cached[0] != state:
            cached = self._shadow_setups = (state, shadow_setups(self, lights, size))
        return cached[1]

    @property
    def ambient_radiance(self):
        """``L_a`` as a tuple of 3 float, or None."""
        return None if self.ambient is None else self.ambient.radiance

    def program_key(self, obj, output="radiance"):
        """The `ProgramKey` of one of this scene's objects."""
        needs = self.gbuffer_needs() if output == "gbuffer" else None
        return program_key(obj.material, self.light_keys(), self.ambient_radiance, output, needs)

    def gbuffer_needs(self):
        """Extra G-buffer outputs the scene's radiance programs read ('tangent', 'uv', 'color'; 'lod' where a
        parameter is textured), a frozenset.

        Computed once per state of the scene (objects and lights are only ever added; the ambient
        light may be replaced), not once per object drawn."""
        state = (len(self._objects), len(self._lights), self.ambient_radiance)
        cached = getattr(self, "_gbuffer_needs", None)
        if cached is None or cached[0] != state:
            lights, ambient = self.light_keys(), self.ambient_radiance
            keys = [program_key(o.material, lights, ambient) for o in self._objects]
            needs = frozenset(n for n in GBUFFER_PLANES if any(
                k.textured_inputs if n == "lod" else getattr(k, f"has_{n}") for k in keys))
            cached = self._gbuffer_needs = (state, needs)
        return cached[1]

    def light_uniform_values(self, key):
        """The light and ambient uniforms a radiance program with ``key`` declares.

        Returns
        -------
        dict of str to ndarray
            float32 arrays ``u_<kind>_<uniform>``, ``(N, 3)`` or ``(N,)``, of each kind the key loops over
            (`glphong.lights.LightModel.pack_uniforms`) and ``u_ambient`` ``(3,)``.
        """
        values = {}
        for light_key in key.lights:
            kind = light_named(light_key.name)
            mine = [light for light in self._lights if type(light) is kind]
            if mine:
                values.update(kind.pack_uniforms(mine, light_key.defines))
        if key.has_ambient:
            values["u_ambient"] = np.asarray(self.ambient_radiance, dtype=np.float32)
        return values

    def uniform_values(self, index, key, aspect):
        """Every uniform the program ``key`` declares for object ``index``, as float32.

        This is the single place where scene values become shader inputs; the numpy
        twin reads the same dictionary, so both shade identical float32 inputs.  It is the union
        of `frame_uniform_values` (the same for every object of a frame) and
        `object_uniform_values` (the object's own, which a renderer packs once per object).

        Parameters
        ----------
        index : int
            Object index in `objects`.
        key : glphong.shaders.key.ProgramKey
        aspect : float
            Image width / height.

        Returns
        -------
        dict of str to ndarray
            (a table parameter's value is its `glphong.materials.TableData`)
        """
        if key.uber:
            return self._uber_uniform_values(index, key, aspect)
        return self.frame_uniform_values(key, aspect) | self.object_uniform_values(index, key)

    def frame_uniform_values(self, key, aspect):
        """The uniforms of program ``key`` that every object of a frame shares: the camera's view-projection
        and eye, the lights and the ambient light (float32, dict of str to ndarray)."""
        values = {"u_view_projection": self.camera.projection_matrix(aspect) @ self.camera.view_matrix()}
        if key.output not in ("gbuffer", "shadow"):
            if key.needs_view:
                values["u_eye"] = self.camera.eye
            values.update(self.light_uniform_values(key))
            if key.shadow_slots:
                for setup in self.shadow_setups(key.lights, key.shadow_size):
                    values.update(setup.uniform_values())
        return {name: _validate.float32_uniform(v) for name, v in values.items()}

    def object_uniform_values(self, index, key):
        """The uniforms of program ``key`` that belong to object ``index``: its pose, normal matrix, material
        (or object id, in the G-buffer) (float32 arrays, and `TableData` for tables)."""
        obj = self._objects[index]
        values = {"u_model": obj.pose}
        if key.has_normal:
            values["u_normal_matrix"] = obj.normal_matrix
        if key.output == "gbuffer":
            values["u_object_id"] = float(index)
            values.update(obj.material.surface_uniform_values(key))  # the mapped normal, the alpha test
            if key.lod_textures:  # the radiance program's textures, whose levels of detail the G-buffer records
                spec = self.program_key(obj)
                textures = obj.material.uniform_values(spec)
                images = [textures[f"u_{term}_{param}_texture"] for term, param in spec.textured_inputs]
                for slot, i in enumerate(lod_slots(images)[1]):  # one texture per size (`lod_slots`)
                    values[f"u_lod_texture{slot}"] = images[i]
        else:
            values.update(obj.material.uniform_values(key))
        return {name: v if isinstance(v, (TableData, TextureImage)) else _validate.float32_uniform(v)
                for name, v in values.items()}

    def _uber_uniform_values(self, index, key, aspect):
        """The uber-shader's uniforms: the specialised key's values, zeros for the terms the object's
        material lacks, a switch per term, padded light arrays."""

        obj = self._objects[index]
        spec = self.program_key(obj, key.output)
        if max(self.light_counts().values(), default=0) > UBER_MAX_LIGHTS:
            raise ValueError(f"the uber-shader takes at most {UBER_MAX_LIGHTS} lights of each kind "
                             f"(scene has {self.light_counts()})")
        values = self.uniform_values(index, spec, aspect)
        values["u_normal_matrix"] = np.asarray(obj.normal_matrix, dtype=np.float32)
        if key.needs_view:
            values["u_eye"] = np.asarray(self.camera.eye, dtype=np.float32)
        values.setdefault("u_ka", np.asarray(obj.material.ka, dtype=np.float32))
        values.setdefault("u_ambient", np.asarray(self.ambient_radiance or (0.0, 0.0, 0.0), dtype=np.float32))

        for term in key.terms:
            model = model_named(term.name)
            for p in model.uniform_params():
                values.setdefault(model.uniform_name(p.name), np.zeros(3 if p.kind == "rgb" else (), np.float32))
            for t in model.tables:
                values.setdefault(model.uniform_name(t.name), TableData.zeros(t.shape, t.channels))
        for light_key in key.lights:  # every uniform of the kinds the uber-shader holds, padded; the count switches
            kind = light_named(light_key.name)
            mine = [light for light in self._lights if type(light) is kind]
            packed = kind.pack_uniforms(mine, light_key.defines) if mine else {}
            for p in kind.active_uniforms(light_key.defines):
                name = kind.uniform_name(p.name)
                padded = np.zeros((UBER_MAX_LIGHTS,) + ((3,) if p.glsl_type == "vec3" else ()), np.float32)
                padded[:len(mine)] = packed.get(name, padded[:0])
                values[name] = padded
            values[f"u_{light_key.name}_count"] = np.float32(len(mine))
        active = {t.name: t for t in spec.terms}
        flags = {"u_use_ka": spec.has_ka, "u_two_sided": spec.two_sided}
        for term in key.terms:
            flags[f"u_use_{term.name}"] = term.name in active and active[term.name].lit
            if term.ambient:
                flags[f"u_use_{term.name}_ambient"] = term.name in active and active[term.name].ambient
            if term.emission:
                flags[f"u_use_{term.name}_emission"] = term.name in active and bool(active[term.name].emission)
        values.update({name: np.float32(v) for name, v in flags.items()})
        return values


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
