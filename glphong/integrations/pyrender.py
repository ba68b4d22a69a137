"""glphong shading inside pyrender scenes.

A pyrender user keeps their scene, camera, lights, nodes and ``OffscreenRenderer``, gives the meshes
they choose a `GlphongMaterial`, and calls `enable` once on the renderer::

    import os
    os.environ["PYOPENGL_PLATFORM"] = "egl"          # or "osmesa"; before pyrender is imported
    import pyrender, trimesh, glphong
    from glphong.integrations.pyrender import GlphongMaterial, enable

    material = GlphongMaterial(glphong.Phong(kd=0.2, ks=0.5, q=80))
    scene.add(pyrender.Mesh.from_trimesh(tm, material=material))
    renderer = pyrender.OffscreenRenderer(640, 480)
    enable(renderer)                                   # once
    color, depth = renderer.render(scene)

Primitives with a `GlphongMaterial` are drawn by programs generated from glphong's own chunks and
`ProgramKey` (output ``'display'``: the same linear shading, then the exposure and the exact sRGB
curve, since pyrender's framebuffer is 8-bit), with glphong's strict uniform binding; every other
primitive keeps pyrender's shaders.  Lights map with the units of docs/design.md section 2:

- ``pyrender.PointLight(color, intensity)``: intensity I [W/sr] per channel ``color * intensity``,
  so ``Phi = 4 pi I`` (`glphong.PointLight`);
- ``pyrender.DirectionalLight(color, intensity)``: irradiance ``E = color * intensity`` [W/m^2],
  travelling along the node's -Z axis (`glphong.DirectionalLight`);
- ``pyrender.SpotLight(color, intensity, innerConeAngle, outerConeAngle)``: a `glphong.SpotLight` of intensity
  ``I = color * intensity`` taken as W/sr along the axis (pyrender's shader uses the candela value as the
  intensity, and KHR_lights_punctual's falloff, as glphong does), pointing along the node's -Z axis;
- ``scene.ambient_light``: ``L_a`` (`glphong.AmbientLight`).

Each pyrender light class is read by the glphong light kind whose ``pyrender_type`` it is
(`glphong.lights.LightModel.from_pyrender`).  pyrender ignores a light's range; so does the mapping.

Importing this module imports pyrender, so set ``PYOPENGL_PLATFORM`` first (pyrender reads it once).
pyrender 0.1.45's OSMesa platform needs PyOpenGL >= 3.1.5 (``pip install --no-deps PyOpenGL==3.1.10``).
"""
import os
import threading
from dataclasses import replace

import numpy as np
import pyrender
from pyrender.constants import ProgramFlags, RenderFlags
from pyrender.renderer import Renderer as _PyrenderRenderer

from glphong.formats.gltf_data import gl_sampling
from glphong.lights import AmbientLight, registered_lights
from glphong.core.validate import scalar
from glphong.scene.camera import PerspectiveCamera
from glphong.gpu.contexts import attach_current
from glphong.scene.geometry import MeshData
from glphong.shaders.key import program_key
from glphong.materials import GltfPBR, Material, NormalMap, Texture, TextureImage, VertexColors
from glphong.gpu.programs import ProgramCache
from glphong.scene.scene import Scene

__all__ = ["GlphongMaterial", "enable", "glphong_lights_of", "scene_from_pyrender", "gltf_pbr_of"]


class GlphongMaterial(pyrender.Material):
    """A pyrender material that draws its primitives with a glphong material.

    Parameters
    ----------
    material : glphong.Material
        Any glphong material: `Lambert`, `Phong`, `BlinnPhong` or a user's `MaterialModel`/`MaterialSum`.
    exposure : float
        Linear scale before the sRGB encoding into pyrender's 8-bit framebuffer, > 0.
    name : str, optional
    """

    def __init__(self, material, exposure=1.0, name=None):
        if not isinstance(material, Material):
            raise TypeError(f"material must be a glphong material such as glphong.Phong (got {type(material).__name__})")
        super().__init__(name=name, doubleSided=material.two_sided)
        self.glphong = material
        self.exposure = scalar("exposure", exposure, low=0.0, low_inclusive=False)

    def __repr__(self):
        return f"GlphongMaterial({self.glphong!r}, exposure={self.exposure:g})"

    @classmethod
    def from_pyrender(cls, material, exposure=1.0, vertex_colors=False):
        """The `GlphongMaterial` of a ``pyrender.MetallicRoughnessMaterial``: `gltf_pbr_of` it (glTF's Appendix B with
        its textures), to swap into a pyrender scene."""
        return cls(gltf_pbr_of(material, vertex_colors), exposure=exposure, name=material.name)

    @property
    def tex_flags(self):
        """pyrender reads this while drawing the primitive: only a renderer `enable` d may draw it."""
        if not getattr(_DRAWING, "enabled", False):
            raise RuntimeError(
                f"{self!r} is drawn by a pyrender renderer that glphong was not enabled on (pyrender would "
                "draw it black or with garbage): call glphong.integrations.pyrender.enable(renderer) once "
                "after creating the OffscreenRenderer")
        return pyrender.Material.tex_flags.fget(self)


#: set while an enabled renderer draws (per thread)
_DRAWING = threading.local()


def gltf_pbr_of(material, vertex_colors=False):
    """The `glphong.GltfPBR` of a ``pyrender.MetallicRoughnessMaterial`` (glTF's metallic-roughness, as pyrender holds
    it): ``baseColorFactor`` (rgb) times ``baseColorTexture`` (sRGB) times ``COLOR_0`` (``vertex_colors``: the
    primitive has them; glTF's rule, where pyrender 0.1.45 multiplies its whole result); ``metallicFactor`` and ``roughnessFactor``
    times the metallic-roughness texture's blue and green channels (pyrender keeps them as its two channels 'GB');
    ``emissiveFactor`` times ``emissiveTexture`` (sRGB); ``occlusionTexture``'s red channel; each texture's sampler
    (`glphong.formats.gltf_data.gl_sampling`); ``doubleSided`` as ``two_sided``; ``normalTexture`` as a
    `glphong.NormalMap` (pyrender keeps no normal scale: 1).  Alpha is not applied.

    Raises
    ------
    TypeError
        Another kind of pyrender material (a ``SpecularGlossinessMaterial``).
    """
    if not isinstance(material, pyrender.MetallicRoughnessMaterial):
        raise TypeError(f"glphong converts pyrender.MetallicRoughnessMaterial (glTF's metallic-roughness), not "
                        f"{type(material).__name__}")

    def image(texture, channels, srgb):
        if texture is None:
            return None
        pixels = np.asarray(texture.source)
        pixels = pixels[..., None] if pixels.ndim == 2 else pixels
        rgb = np.zeros(pixels.shape[:2] + (3,), pixels.dtype)
        for source, target in enumerate(channels):  # pyrender's channels, back in the places glTF gives them
            rgb[..., "rgb".index(target)] = pixels[..., source]
        wrap, filter_ = gl_sampling(texture.sampler.wrapS, texture.sampler.minFilter)
        return TextureImage(rgb, srgb=srgb, wrap=wrap, filter=filter_)

    base = tuple(np.clip(np.asarray(material.baseColorFactor, np.float64)[:3], 0.0, 1.0))
    texture = image(material.baseColorTexture, "rgb", True)
    base_color = Texture(texture, scale=base, vertex_colors=vertex_colors) if texture is not None else \
        VertexColors(scale=base) if vertex_colors else base
    metallic = min(float(material.metallicFactor), 1.0)
    roughness = min(float(material.roughnessFactor), 1.0)
    texture = image(material.metallicRoughnessTexture, "gb", False)
    if texture is not None:
        metallic, roughness = Texture(texture, metallic, channel="b"), Texture(texture, roughness, channel="g")
    emissive = tuple(np.asarray(material.emissiveFactor, np.float64))
    texture = image(material.emissiveTexture, "rgb", True) if any(emissive) else None
    emissive = Texture(texture, scale=emissive) if texture is not None else emissive
    texture = image(material.occlusionTexture, "r", False)
    occlusion = Texture(texture, channel="r") if texture is not None else 1.0
    texture = image(material.normalTexture, "rgb", False)
    return GltfPBR(base_color, metallic, roughness, emissive=emissive, occlusion=occlusion,
                   two_sided=bool(material.doubleSided), normal_map=NormalMap(texture) if texture is not None else None)


def glphong_lights_of(scene):
    """The glphong lights of a pyrender scene (SI units of docs/design.md section 2).

    Returns
    -------
    lights : list of glphong lights
    ambient : glphong.AmbientLight or None
    """
    kinds = {kind.pyrender_type: kind for kind in registered_lights() if kind.pyrender_type}
    out = []
    for node in scene.light_nodes:
        light, pose = node.light, scene.get_pose(node)
        value = np.asarray(light.color, dtype=np.float64) * float(light.intensity)
        kind = kinds.get(type(light).__name__)
        if kind is None:
            raise ValueError(f"pyrender light {node.name or ''!r} is a {type(light).__name__}, which no glphong light "
                             f"kind maps (mapped: {', '.join(sorted(kinds))})")
        out.append(kind.from_pyrender(value, light, pose))
    ambient = np.asarray(scene.ambient_light, dtype=np.float64)
    return out, (AmbientLight(ambient) if np.any(ambient > 0) else None)


def _glphong_camera(scene):
    camera = scene.main_camera_node.camera
    if not isinstance(camera, pyrender.PerspectiveCamera):
        raise ValueError(f"glphong materials need a pyrender.PerspectiveCamera (got {type(camera).__name__})")
    return PerspectiveCamera(camera.yfov, pose=scene.get_pose(scene.main_camera_node),
                             znear=camera.znear, zfar=camera.zfar if camera.zfar is not None else 1e6)


def scene_from_pyrender(scene, convert=False):
    """The glphong `Scene` of a pyrender scene's `GlphongMaterial` meshes, camera and lights.

    For rendering the same scene with `glphong.Renderer` (comparison, verification).  ``convert``: the meshes
    with a ``pyrender.MetallicRoughnessMaterial`` too, as `gltf_pbr_of` it (a mesh from a glTF file or a trimesh
    with a PBR material).
    """
    lights, ambient = glphong_lights_of(scene)
    out = Scene(_glphong_camera(scene), lights=lights, ambient=ambient)
    for node in scene.mesh_nodes:
        for primitive in node.mesh.primitives:
            material = primitive.material
            if convert and isinstance(material, pyrender.MetallicRoughnessMaterial) and primitive.normals is not None:
                material = GlphongMaterial.from_pyrender(material, vertex_colors=primitive.color_0 is not None)
            if isinstance(material, GlphongMaterial):
                indices = _triangles(primitive)
                colors = None if primitive.color_0 is None else np.asarray(primitive.color_0, dtype=np.float64)[:, :3]
                data = MeshData(primitive.positions, primitive.normals, indices, uvs=primitive.texcoord_0,
                                tangents=primitive.tangents, colors=colors)
                out.add(data, material.glphong, pose=scene.get_pose(node), name=node.name)
    return out


def _triangles(primitive):
    """A triangle primitive's (F, 3) vertex indices: its own (pyrender keeps them as float32, exact below 2^24
    vertices), or consecutive triples where it has none (``Mesh.from_trimesh(..., smooth=False)``: every triangle's
    own three vertices)."""
    if primitive.mode != pyrender.constants.GLTF.TRIANGLES:
        raise ValueError(f"glphong draws triangles; this primitive's mode is {primitive.mode} (points or lines: "
                         "pyrender.Mesh.from_points has no surface to shade)")
    if primitive.indices is None:
        count = len(primitive.positions)
        if count % 3:
            raise ValueError(f"a non-indexed triangle primitive needs a multiple of 3 vertices (got {count})")
        return np.arange(count, dtype=np.int64).reshape(-1, 3)
    return np.rint(np.asarray(primitive.indices, dtype=np.float64)).astype(np.int64).reshape(-1, 3)


class _ProgramAdapter:
    """A glphong program in the shape pyrender's draw loop expects (``_bind``, ``set_uniform``, ...).

    pyrender sets its own uniforms by name; this adapter keeps the camera ones and, when pyrender
    sets the model matrix ``M`` (its last call before the draw), binds every glphong uniform
    strictly.  pyrender's PBR material uniforms do not exist in these programs and are ignored.
    """

    def __init__(self, program):
        self.program = program
        self.material = None
        self.lights = None
        self._camera = {}

    def _in_context(self):
        return True

    def _add_to_context(self):
        pass

    def _remove_from_context(self):
        pass

    def _bind(self):
        from OpenGL.GL import glUseProgram

        glUseProgram(self.program.gl_program.glo)

    def _unbind(self):
        from OpenGL.GL import glUseProgram

        glUseProgram(0)

    def delete(self):
        pass

    def set_uniform(self, name, value, unsigned=False):
        if name in ("V", "P", "cam_pos"):
            self._camera[name] = np.asarray(value, dtype=np.float64)
        elif name == "M":
            self._bind_all(np.asarray(value, dtype=np.float64))

    def _bind_all(self, model):
        key, material = self.program.key, self.material
        values = {"u_model": model, "u_view_projection": self._camera["P"] @ self._camera["V"]}
        if key.has_normal:
            values["u_normal_matrix"] = np.linalg.inv(model[:3, :3]).T
        if key.needs_view:  # the homogeneous eye: pyrender's camera centre, or an orthographic view's axis
            projection, view = self._camera["P"], self._camera["V"]
            values["u_eye"] = np.append(view[2, :3], 0.0) if projection[3, 3] == 1.0 else \
                np.append(self._camera["cam_pos"], 1.0)
        values["u_exposure"] = material.exposure
        values.update(material.glphong.uniform_values(key))
        values.update(self.lights.light_uniform_values(key))
        self.program.bind(values)


class _GlphongRenderer(_PyrenderRenderer):
    """pyrender's renderer, drawing `GlphongMaterial` primitives with glphong programs."""

    def render(self, scene, flags, seg_node_map=None):
        glphong_scene = None
        if any(isinstance(p.material, GlphongMaterial) for n in scene.mesh_nodes for p in n.mesh.primitives):
            lights, ambient = glphong_lights_of(scene)
            glphong_scene = Scene(_glphong_camera(scene), lights=lights, ambient=ambient)
        self._glphong_scene = glphong_scene
        _DRAWING.enabled = True
        try:
            return super().render(scene, flags, seg_node_map)
        finally:
            _DRAWING.enabled = False

    def _get_primitive_program(self, primitive, flags, program_flags):
        material = primitive.material
        shaded = (program_flags & ProgramFlags.USE_MATERIAL
                  and not flags & (RenderFlags.DEPTH_ONLY | RenderFlags.FLAT | RenderFlags.SEG))
        if not (isinstance(material, GlphongMaterial) and shaded):
            return super()._get_primitive_program(primitive, flags, program_flags)
        if primitive.normals is None:
            raise ValueError("a primitive with a GlphongMaterial needs vertex normals")
        if primitive.poses is not None and len(primitive.poses) > 1:
            raise ValueError("GlphongMaterial primitives cannot be instanced (primitive.poses has "
                             f"{len(primitive.poses)} poses); use one mesh node per instance")
        scene = self._glphong_scene
        key = program_key(material.glphong, scene.light_counts(), scene.ambient_radiance, output="display")
        # pyrender packs the attributes a primitive has in this order, one location each
        present = [name for name, value in (("position", primitive.positions), ("normal", primitive.normals),
                                            ("tangent", primitive.tangents), ("uv", primitive.texcoord_0),
                                            ("uv1", primitive.texcoord_1), ("color", primitive.color_0))
                   if value is not None]
        key = replace(key, attribute_locations=tuple((name, present.index(name)) for name in ("tangent", "uv", "color")
                                                     if name in present and getattr(key, f"has_{name}")))
        if key.has_tangent and primitive.tangents is None:
            raise ValueError("a primitive with a GlphongMaterial whose terms need 'tangent' must have tangents "
                             "(pyrender.Primitive(tangents=...) or a glTF mesh with TANGENT)")
        if key.has_uv and primitive.texcoord_0 is None:
            raise ValueError("a primitive with a GlphongMaterial whose terms need 'uv' (or a textured parameter) "
                             "must have texcoord_0")
        # pyrender binds color_0 at location 5, where mesh_vertex.glsl reads the (linear) vertex colour
        if key.has_color and primitive.color_0 is None:
            raise ValueError("a primitive with a GlphongMaterial whose parameter takes vertex colours must have "
                             "color_0 (linear, in [0, 1]); pyrender.Mesh.from_trimesh drops a trimesh's vertex colours "
                             "when it is given material=: build the primitive with pyrender.Primitive(positions=..., "
                             "normals=..., indices=..., color_0=..., material=...)")
        if not hasattr(self, "_glphong_programs"):
            self._glphong_programs = ProgramCache(attach_current(os.environ.get("PYOPENGL_PLATFORM", "egl")))
            self._glphong_adapters = {}
        adapter = self._glphong_adapters.get(key)
        if adapter is None:
            adapter = self._glphong_adapters[key] = _ProgramAdapter(self._glphong_programs.get(key))
        adapter.material, adapter.lights = material, scene
        return adapter

    def _bind_lighting(self, scene, program, node, flags):
        if not isinstance(program, _ProgramAdapter):  # glphong programs take their lights from the adapter
            super()._bind_lighting(scene, program, node, flags)

    def delete(self):
        if hasattr(self, "_glphong_programs"):
            self._glphong_programs.release()
            del self._glphong_programs, self._glphong_adapters
        super().delete()


def enable(renderer):
    """Let a ``pyrender.OffscreenRenderer`` draw `GlphongMaterial` primitives with glphong's shading.

    Parameters
    ----------
    renderer : pyrender.OffscreenRenderer
        Any live offscreen renderer; meshes with pyrender's own materials are unaffected.

    Returns
    -------
    pyrender.OffscreenRenderer
        The same renderer.
    """
    if not isinstance(renderer, pyrender.OffscreenRenderer):
        raise TypeError(f"renderer must be a pyrender.OffscreenRenderer (got {type(renderer).__name__})")
    inner = renderer._renderer  # pyrender keeps its scene renderer here; swap its class, keep its state
    if inner is None:
        raise ValueError("the OffscreenRenderer has been deleted")
    if not isinstance(inner, _GlphongRenderer):
        inner.__class__ = _GlphongRenderer
    return renderer
