"""pyrender's renderer, drawing `GlphongMaterial` primitives with glphong's programs: `enable` one
``OffscreenRenderer``, or `enable_everywhere` for every one created from then on (or inside a ``with`` block).

Primitives with a `GlphongMaterial` are drawn by programs generated from glphong's own chunks and `ProgramKey`
(output ``'display'``: the same linear shading, then the exposure and the exact sRGB curve, since pyrender's
framebuffer is 8-bit), with glphong's strict uniform binding; every other primitive keeps pyrender's shaders.
pyrender's render flags are honoured for glphong surfaces: the shadow flags with glphong's own maps
(`glphong.integrations.pyrender.shadows`), ``FLAT`` unlit (each surface's answer to an ambient light of radiance
pi: the albedo of Lambert's ``kd`` and of glTF's base colour, what pyrender's flat shader draws), ``DEPTH_ONLY``
and ``SEG`` by pyrender's own programs.
"""
import os
import threading
import warnings
from dataclasses import replace

import numpy as np
import pyrender
import pyrender.offscreen
from pyrender.constants import ProgramFlags, RenderFlags
from pyrender.renderer import Renderer as _PyrenderRenderer

from glphong.core import validate
from glphong.gpu.contexts import attach_current
from glphong.gpu.programs import ProgramCache
from glphong.lights import AmbientLight
from glphong.scene.scene import Scene
from glphong.shaders.builders import program_key

from glphong.integrations.pyrender.materials import DRAWING, GlphongMaterial
from glphong.integrations.pyrender.scenes import glphong_camera_of, glphong_lights_of
from glphong.integrations.pyrender.shadows import EmbeddedShadows
from glphong.shaders.binding import binding

__all__ = ["GlphongRenderer", "enable", "enable_everywhere", "disable_everywhere"]

#: the ambient radiance a ``RenderFlags.FLAT`` frame answers with: pi, so ``L = pi k`` is an albedo
FLAT_AMBIENT = np.pi


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
        self.shadow_values = {}
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
        key, material, scene = self.program.key, self.material, self.lights
        values = {"u_model": model, "u_view_projection": self._camera["P"] @ self._camera["V"]}
        if key.has_normal:
            values["u_normal_matrix"] = np.linalg.inv(model[:3, :3]).T
        if key.needs_view:  # the homogeneous eye: pyrender's camera centre, or an orthographic view's axis
            projection, view = self._camera["P"], self._camera["V"]
            values["u_eye"] = np.append(view[2, :3], 0.0) if projection[3, 3] == 1.0 else \
                np.append(self._camera["cam_pos"], 1.0)
        values["u_exposure"] = material.exposure
        values.update(material.glphong.uniform_values(key))
        values.update(binding(scene).light_uniform_values(key))
        if key.shadow_slots:
            for setup in binding(scene).shadow_setups(key.lights, key.shadow_size):
                values.update(setup.uniform_values())
            values.update(self.shadow_values)
        self.program.bind(values)


class GlphongRenderer(_PyrenderRenderer):
    """pyrender's scene renderer, drawing `GlphongMaterial` primitives with glphong programs.

    `enable` gives a live renderer this class; `enable_everywhere` makes pyrender create it.  Its glphong
    settings are class attributes that `enable` sets per renderer.

    Attributes
    ----------
    shadow_map_size : int
        Texels along a side of glphong's shadow maps (a cube map's face), as `glphong.Renderer`'s (default 1024).
    shadow_filter_radius : int
        Percentage-closer filter radius in texels (default 0).
    """

    shadow_map_size = 1024
    shadow_filter_radius = 0

    def render(self, scene, flags, seg_node_map=None):
        self._glphong_scene = self._glphong_shadow_values = None
        ours = any(isinstance(p.material, GlphongMaterial) for n in scene.mesh_nodes if n.mesh.is_visible
                   for p in n.mesh.primitives)
        if ours and not flags & (RenderFlags.DEPTH_ONLY | RenderFlags.SEG):
            self._glphong_scene = self._shading_scene(scene, flags)
        if flags & RenderFlags.SHADOWS_POINT and scene.point_light_nodes:
            flags &= ~RenderFlags.SHADOWS_POINT  # pyrender raises NotImplementedError for point-light shadows
            if any(not isinstance(p.material, GlphongMaterial) for n in scene.mesh_nodes if n.mesh.is_visible
                   for p in n.mesh.primitives if p.mode == pyrender.constants.GLTF.TRIANGLES):
                warnings.warn("RenderFlags.SHADOWS_POINT: glphong's surfaces get point-light shadows, pyrender's own "
                              "surfaces get none (pyrender 0.1.45 has no point-light shadow maps)", stacklevel=3)
        DRAWING.enabled = True
        try:
            return super().render(scene, flags, seg_node_map)
        finally:
            DRAWING.enabled = False

    def _shading_scene(self, scene, flags):
        """The glphong scene the frame's glphong programs take their lights (and shadow casters) from."""
        camera = glphong_camera_of(scene, (self.viewport_width, self.viewport_height))
        if flags & RenderFlags.FLAT:
            return Scene(camera, lights=[], ambient=AmbientLight(FLAT_AMBIENT))
        lights, ambient = glphong_lights_of(scene, flags)
        out = Scene(camera, lights=lights, ambient=ambient)
        if any(light.shadows for light in lights):
            self._glphong_state()[1].add_casters(out, scene)
        return out

    def _glphong_state(self):
        """``(programs, shadows)``: made on first use in pyrender's context, released with the renderer."""
        if not hasattr(self, "_glphong_programs"):
            mgl = attach_current(os.environ.get("PYOPENGL_PLATFORM", "egl"))
            self._glphong_programs = ProgramCache(mgl)
            self._glphong_shadows = EmbeddedShadows(mgl)
            self._glphong_adapters = {}
        return self._glphong_programs, self._glphong_shadows

    def _update_context(self, scene, flags):
        super()._update_context(scene, flags)  # pyrender's vertex arrays exist from here on: draw glphong's maps
        if self._glphong_scene is not None and any(light.shadows for light in self._glphong_scene.lights):
            programs, shadows = self._glphong_state()
            self._glphong_shadow_values = shadows.draw(self._glphong_scene, programs, self.shadow_map_size)

    def _get_primitive_program(self, primitive, flags, program_flags):
        material = primitive.material
        drawn = program_flags & ProgramFlags.USE_MATERIAL and not flags & (RenderFlags.DEPTH_ONLY | RenderFlags.SEG)
        if not (isinstance(material, GlphongMaterial) and drawn):
            return super()._get_primitive_program(primitive, flags, program_flags)
        if primitive.normals is None:
            raise ValueError("a primitive with a GlphongMaterial needs vertex normals")
        if primitive.poses is not None and len(primitive.poses) > 1:
            raise ValueError("GlphongMaterial primitives cannot be instanced (primitive.poses has "
                             f"{len(primitive.poses)} poses); use one mesh node per instance")
        scene = self._glphong_scene
        key = program_key(material.glphong, binding(scene).light_keys(), scene.ambient_radiance, output="display")
        if key.shadow_slots:
            key = replace(key, shadow_size=self.shadow_map_size, shadow_filter=self.shadow_filter_radius)
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
        programs, _ = self._glphong_state()
        adapter = self._glphong_adapters.get(key)
        if adapter is None:
            adapter = self._glphong_adapters[key] = _ProgramAdapter(programs.get(key))
        adapter.material, adapter.lights = material, scene
        adapter.shadow_values = self._glphong_shadow_values or {}
        return adapter

    def _bind_lighting(self, scene, program, node, flags):
        if not isinstance(program, _ProgramAdapter):  # glphong programs take their lights from the adapter
            super()._bind_lighting(scene, program, node, flags)

    def delete(self):
        if hasattr(self, "_glphong_programs"):
            self._glphong_shadows.release()
            self._glphong_programs.release()
            del self._glphong_programs, self._glphong_adapters, self._glphong_shadows
        super().delete()


_SETTINGS = ("shadow_map_size", "shadow_filter_radius")


def _recreate_enabled(renderer, settings):
    """``renderer._create``, for an enabled renderer: pyrender makes a new scene renderer on OSMesa whenever the
    viewport size changes (its platform cannot resize), and that one is enabled too."""
    create = type(renderer)._create

    def _create():
        create(renderer)
        _enable_inner(renderer, settings)
    return _create


def _enable_inner(renderer, settings):
    inner = renderer._renderer  # pyrender keeps its scene renderer here; swap its class, keep its state
    if inner is None:
        raise ValueError("the OffscreenRenderer has been deleted")
    if not isinstance(inner, GlphongRenderer):
        inner.__class__ = GlphongRenderer
    for name, value in settings.items():
        setattr(inner, name, value)


def _settings(shadow_map_size, shadow_filter_radius):
    return {"shadow_map_size": validate.positive_int("shadow_map_size", shadow_map_size, 16, 8192),
            "shadow_filter_radius": validate.positive_int("shadow_filter_radius", shadow_filter_radius, 0, 8)}


def enable(renderer, shadow_map_size=1024, shadow_filter_radius=0):
    """Let a ``pyrender.OffscreenRenderer`` draw `GlphongMaterial` primitives with glphong's shading.

    Parameters
    ----------
    renderer : pyrender.OffscreenRenderer
        Any live offscreen renderer; meshes with pyrender's own materials are unaffected.  It stays enabled when
        pyrender re-creates its inner renderer (OSMesa, on a change of viewport size).
    shadow_map_size : int
        Texels along a side of glphong's shadow maps, 16 to 8192, used where pyrender's shadow flags are set.
    shadow_filter_radius : int
        Percentage-closer filter radius of those maps, 0 to 8 texels.

    Returns
    -------
    pyrender.OffscreenRenderer
        The same renderer.
    """
    if not isinstance(renderer, pyrender.OffscreenRenderer):
        raise TypeError(f"renderer must be a pyrender.OffscreenRenderer (got {type(renderer).__name__})")
    settings = _settings(shadow_map_size, shadow_filter_radius)
    _enable_inner(renderer, settings)
    renderer._create = _recreate_enabled(renderer, settings)
    return renderer


class _Everywhere:
    """What `enable_everywhere` returns: leaving it as a context manager restores what was there before."""

    def __init__(self, previous):
        self._previous = previous

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        disable_everywhere(self._previous)
        return False


_LOCK = threading.Lock()


def enable_everywhere(shadow_map_size=1024, shadow_filter_radius=0):
    """Make every ``pyrender.OffscreenRenderer`` created from now on draw `GlphongMaterial` primitives (as `enable`
    does to one): for code that creates its renderers where you cannot reach them (a dataset generator, a test
    suite).  Renderers that already exist are left as they are (`enable` them).

    Used as a context manager, it holds inside the block only::

        with enable_everywhere():
            color, depth = third_party_render(scene)   # creates its own OffscreenRenderer

    Parameters
    ----------
    shadow_map_size, shadow_filter_radius : int
        As `enable`'s.

    Returns
    -------
    context manager
        Leaving it restores the class pyrender created before the call.
    """
    settings = _settings(shadow_map_size, shadow_filter_radius)
    with _LOCK:
        previous = pyrender.offscreen.Renderer
        pyrender.offscreen.Renderer = type("GlphongRenderer", (GlphongRenderer,), dict(settings))
    return _Everywhere(previous)


def disable_everywhere(previous=_PyrenderRenderer):
    """Undo `enable_everywhere`: an ``OffscreenRenderer`` created from now on is pyrender's own (those already made
    keep what they have)."""
    with _LOCK:
        pyrender.offscreen.Renderer = previous
