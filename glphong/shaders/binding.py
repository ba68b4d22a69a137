"""How a scene feeds the programs: each object's `ProgramKey` and every uniform a program declares.

A `glphong.Scene` is data (a camera, lights, objects); this module is the program side's reading of it
(docs/design.md section 6).  `binding` gives the `SceneBinding` of a scene, made once per scene and kept while the
scene lives; it makes the keys (`glphong.shaders.key.program_key` over the scene's materials and lights), packs the
lights, the camera and each object's pose and material into the float32 uniforms that both the GPU and the numpy
twin read, pads the uber-shader's uniforms, and keeps what it derived while the scene's state allows (objects and
lights are only ever added; the ambient light may be replaced).
"""
import threading
import weakref

import numpy as np

from glphong.core import validate as _validate
from glphong.lights import light_named
from glphong.materials import model_named
from glphong.definitions.surface import TextureImage
from glphong.definitions.table import TableData
from glphong.scene.shadows import shadow_setups
from glphong.shaders.builders import light_keys, lod_slots, program_key
from glphong.shaders.options import GBUFFER_PLANES, UBER_MAX_LIGHTS

__all__ = ["SceneBinding", "binding"]

_BINDINGS = weakref.WeakKeyDictionary()
_BINDINGS_LOCK = threading.Lock()


def binding(scene):
    """The `SceneBinding` of ``scene`` (a `glphong.Scene`), made on first use and kept while the scene lives."""
    with _BINDINGS_LOCK:
        found = _BINDINGS.get(scene)
        if found is None:
            found = _BINDINGS[scene] = SceneBinding(scene)
        return found


class SceneBinding:
    """The program keys and uniforms of one scene.

    Parameters
    ----------
    scene : glphong.Scene

    Notes
    -----
    Each cache is keyed by the part of the scene's state it was derived from (the number of objects and lights, the
    ambient radiance, whether any object casts shadows), so adding an object or a light or replacing the ambient light
    is seen at the next call.
    """

    def __init__(self, scene):
        self._scene = weakref.ref(scene)
        self._light_keys = None
        self._shadow_setups = None
        self._gbuffer_needs = None

    @property
    def scene(self):
        """The scene (`glphong.Scene`)."""
        return self._scene()

    def light_keys(self):
        """The `glphong.shaders.key.LightKey` of each light kind present (computed once per state of the lights and
        of whether any object casts shadows)."""
        scene = self.scene
        casters = any(obj.casts_shadow for obj in scene.objects)
        state = (len(scene.lights), casters)
        if self._light_keys is None or self._light_keys[0] != state:
            self._light_keys = (state, light_keys(scene.lights, casters))
        return self._light_keys[1]

    def shadow_setups(self, lights, size):
        """The `glphong.scene.shadows.ShadowSetup` of each shadowing light of ``lights`` (a program key's `LightKey`
        tuple) with maps of ``size`` texels, in slot order; made once per state of the scene, not once per frame or
        object: the bounds walk every vertex."""
        scene = self.scene
        state = (len(scene.objects), len(scene.lights), lights, size)
        if self._shadow_setups is None or self._shadow_setups[0] != state:
            self._shadow_setups = (state, shadow_setups(scene, lights, size))
        return self._shadow_setups[1]

    def program_key(self, obj, output="radiance"):
        """The `ProgramKey` of one of the scene's objects (before a renderer's own options,
        `glphong.Renderer.program_key`)."""
        needs = self.gbuffer_needs() if output == "gbuffer" else None
        return program_key(obj.material, self.light_keys(), self.scene.ambient_radiance, output, needs)

    def gbuffer_needs(self):
        """Extra G-buffer outputs the scene's radiance programs read ('tangent', 'uv', 'color'; 'lod' where a
        parameter is textured), a frozenset; computed once per state of the scene, not once per object drawn."""
        scene = self.scene
        state = (len(scene.objects), len(scene.lights), scene.ambient_radiance)
        if self._gbuffer_needs is None or self._gbuffer_needs[0] != state:
            lights, ambient = self.light_keys(), scene.ambient_radiance
            keys = [program_key(o.material, lights, ambient) for o in scene.objects]
            needs = frozenset(n for n in GBUFFER_PLANES if any(
                k.textured_inputs if n == "lod" else getattr(k, f"has_{n}") for k in keys))
            self._gbuffer_needs = (state, needs)
        return self._gbuffer_needs[1]

    def light_uniform_values(self, key):
        """The light and ambient uniforms a radiance program with ``key`` declares.

        Returns
        -------
        dict of str to ndarray
            float32 arrays ``u_<kind>_<uniform>``, ``(N, 3)`` or ``(N,)``, of each kind the key loops over
            (`glphong.lights.LightModel.pack_uniforms`) and ``u_ambient`` ``(3,)``.
        """
        scene = self.scene
        values = {}
        for light_key in key.lights:
            kind = light_named(light_key.name)
            mine = [light for light in scene.lights if type(light) is kind]
            if mine:
                values.update(kind.pack_uniforms(mine, light_key.defines))
        if key.has_ambient:
            values["u_ambient"] = np.asarray(scene.ambient_radiance, dtype=np.float32)
        return values

    def uniform_values(self, index, key, aspect):
        """Every uniform the program ``key`` declares for object ``index``, as float32.

        This is the single place where scene values become shader inputs; the numpy twin reads the same
        dictionary, so both shade identical float32 inputs.  It is the union of `frame_uniform_values` (the same
        for every object of a frame) and `object_uniform_values` (the object's own, which a renderer packs once per
        object).

        Parameters
        ----------
        index : int
            Object index in ``scene.objects``.
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
        camera = self.scene.camera
        values = {"u_view_projection": camera.projection_matrix(aspect) @ camera.view_matrix()}
        if key.output not in ("gbuffer", "shadow"):
            if key.needs_view:
                values["u_eye"] = camera.eye
            values.update(self.light_uniform_values(key))
            if key.shadow_slots:
                for setup in self.shadow_setups(key.lights, key.shadow_size):
                    values.update(setup.uniform_values())
        return {name: _validate.float32_uniform(v) for name, v in values.items()}

    def object_uniform_values(self, index, key):
        """The uniforms of program ``key`` that belong to object ``index``: its pose, normal matrix, material
        (or object id, in the G-buffer) (float32 arrays, and `TableData` for tables)."""
        obj = self.scene.objects[index]
        values = {"u_model": obj.pose}
        if key.has_normal:
            values["u_normal_matrix"] = obj.normal_matrix
        if key.output == "gbuffer" or key.pass_planes:
            values["u_object_id"] = float(index)
        if key.output == "gbuffer":
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
        scene = self.scene
        obj = scene.objects[index]
        spec = self.program_key(obj, key.output)
        counts = {k.name: k.count for k in self.light_keys()}  # cached per state, not recounted per object
        if max(counts.values(), default=0) > UBER_MAX_LIGHTS:
            raise ValueError(f"the uber-shader takes at most {UBER_MAX_LIGHTS} lights of each kind "
                             f"(scene has {counts})")
        values = self.uniform_values(index, spec, aspect)
        values["u_normal_matrix"] = np.asarray(obj.normal_matrix, dtype=np.float32)
        if key.needs_view:
            values["u_eye"] = np.asarray(scene.camera.eye, dtype=np.float32)
        values.setdefault("u_ka", np.asarray(obj.material.ka, dtype=np.float32))
        values.setdefault("u_ambient", np.asarray(scene.ambient_radiance or (0.0, 0.0, 0.0), dtype=np.float32))

        for term in key.terms:
            model = model_named(term.name)
            for p in model.uniform_params():
                values.setdefault(model.uniform_name(p.name), np.zeros(3 if p.kind == "rgb" else (), np.float32))
            for t in model.tables:
                values.setdefault(model.uniform_name(t.name), TableData.zeros(t.shape, t.channels))
        for light_key in key.lights:  # every uniform of the kinds the uber-shader holds, padded; the count switches
            kind = light_named(light_key.name)
            mine = [light for light in scene.lights if type(light) is kind]
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
