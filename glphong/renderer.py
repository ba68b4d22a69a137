"""Offscreen rendering: scene -> program keys -> cached programs -> float32 images.

One render: for each object, the scene gives its `ProgramKey`; the cache gives the
program; the scene gives the uniforms, bound strictly; only the vertex attributes
the program reads are bound; the draw goes to an RGBA32F target that is read back
as float32 with row 0 at the top.
"""
import weakref
from dataclasses import dataclass, replace

import moderngl
import numpy as np

from . import _validate
from .contexts import create_context
from .key import FORMULATIONS, uber_key
from .programs import ProgramCache

__all__ = ["Renderer", "Frame", "GBuffer"]


@dataclass(frozen=True)
class Frame:
    """A rendered image.

    Attributes
    ----------
    radiance : (H, W, 3) float32 ndarray
        Linear radiance [W/(m^2 sr)], row 0 at the top, never clamped.
    mask : (H, W) bool ndarray
        Pixels covered by geometry.
    """

    radiance: np.ndarray
    mask: np.ndarray

    def to_srgb8(self, exposure=1.0):
        """8-bit sRGB image, (H, W, 3) uint8 (see `glphong.imaging.encode_srgb8`)."""
        from .imaging import encode_srgb8
        return encode_srgb8(self.radiance, exposure)

    def save_png(self, path, exposure=1.0):
        """Tone-map with ``exposure``, encode with the exact sRGB curve, write a PNG."""
        from .imaging import save_png
        save_png(path, self.radiance, exposure)

    def save_npy(self, path):
        """Write the raw float32 radiance ``(H, W, 3)`` as ``.npy``."""
        from .imaging import save_npy
        save_npy(path, self.radiance)


@dataclass(frozen=True)
class GBuffer:
    """The per-pixel inputs the shader used.

    Attributes
    ----------
    position : (H, W, 3) float32 ndarray
        World-space surface point [m] (0 where not covered).
    normal : (H, W, 3) float32 ndarray
        World-space unit normal after renormalisation and the two-sided flip; 0 where
        the interpolated normal was zero or not finite (ambient-only pixels).
    object_index : (H, W) int ndarray
        Index into ``scene.objects``, -1 where not covered.
    mask : (H, W) bool ndarray
        Pixels covered by geometry.
    """

    position: np.ndarray
    normal: np.ndarray
    object_index: np.ndarray
    mask: np.ndarray


class _MeshBuffers:
    """GPU buffers of one MeshData and its vertex arrays per program.

    A vertex attribute is uploaded the first time a program that reads it draws the mesh:
    a scene whose programs never read normals (no lights) never uploads them.
    """

    _SOURCES = {"in_position": "positions", "in_normal": "normals"}

    def __init__(self, mgl, mesh):
        self.owner = weakref.ref(mesh)
        self.buffers = {}
        self.index_buffer = mgl.buffer(mesh.indices.tobytes())
        self.vertex_arrays = {}

    def buffer(self, mgl, name):
        if name not in self.buffers:
            self.buffers[name] = mgl.buffer(getattr(self.owner(), self._SOURCES[name]).tobytes())
        return self.buffers[name]

    def vertex_array(self, mgl, program):
        vao = self.vertex_arrays.get(program.key)
        if vao is None:
            content = [(self.buffer(mgl, name), "3f", name) for name in program.key.attributes()]
            vao = self.vertex_arrays[program.key] = mgl.vertex_array(
                program.gl_program, content, self.index_buffer, index_element_size=4)
        return vao

    def release(self):
        for vao in self.vertex_arrays.values():
            vao.release()
        for buf in (*self.buffers.values(), self.index_buffer):
            buf.release()


class Renderer:
    """Offscreen renderer of glphong scenes.

    Parameters
    ----------
    width, height : int
        Image size in pixels, 1 to 16384.
    backend : {'auto', 'egl', 'osmesa'}
        OpenGL backend (see `glphong.contexts.create_context`).
    formulation : {'stable', 'naive'}
        'stable' (default): DESIGN section 3.  'naive': the textbook float32 formulation,
        for measuring what stability costs and buys; not for real use.
    specialise : bool
        True (default): one program per distinct `ProgramKey`, containing only what the
        object needs.  False: every object drawn with the uber-shader (all terms, both
        lobes, up to 8 lights per kind, switched by uniforms), for measuring what
        specialisation buys.

    Examples
    --------
    >>> with glphong.Renderer(256, 256) as r:            # doctest: +SKIP
    ...     frame = r.render(scene)
    """

    def __init__(self, width, height, backend="auto", formulation="stable", specialise=True):
        self._size = self._check_size(width, height)
        self.formulation = _validate.choice("formulation", formulation, FORMULATIONS)
        if not isinstance(specialise, (bool, np.bool_)):
            raise TypeError(f"specialise must be a bool, True or False (got {specialise!r})")
        self.specialise = bool(specialise)
        self.context = create_context(backend)
        self._mgl = self.context.mgl
        self.programs = ProgramCache(self._mgl)
        self._meshes = {}
        self._targets = {}

    @staticmethod
    def _check_size(width, height):
        return (_validate.positive_int("width", width, 1, 16384), _validate.positive_int("height", height, 1, 16384))

    @property
    def width(self):
        """Image width in pixels."""
        return self._size[0]

    @property
    def height(self):
        """Image height in pixels."""
        return self._size[1]

    @property
    def backend(self):
        """Name of the OpenGL backend in use ('egl' or 'osmesa')."""
        return self.context.backend

    def resize(self, width, height):
        """Change the image size; the render targets are rebuilt on next use."""
        size = self._check_size(width, height)
        if size != self._size:
            with self.context:
                self._release_targets()
            self._size = size

    def render(self, scene):
        """Render the scene's shaded radiance.

        Returns
        -------
        Frame
        """
        rgba = self._draw(scene, "radiance")[0]
        return Frame(radiance=np.ascontiguousarray(rgba[..., :3]), mask=rgba[..., 3] > 0.0)

    def gbuffer(self, scene):
        """Render the per-pixel shading inputs of the scene.

        Returns
        -------
        GBuffer
        """
        position, normal = self._draw(scene, "gbuffer")
        mask = position[..., 3] > 0.0
        object_index = np.where(mask, np.rint(position[..., 3]).astype(np.int64) - 1, -1)
        return GBuffer(position=np.ascontiguousarray(position[..., :3]), normal=np.ascontiguousarray(normal[..., :3]),
                       object_index=object_index, mask=mask)

    def _draw(self, scene, output):
        from .scene import Scene

        if not isinstance(scene, Scene):
            raise TypeError(f"scene must be a glphong.Scene (got {type(scene).__name__})")
        if self.context is None:
            raise RuntimeError("this Renderer has been released")
        aspect = self.width / self.height
        with self.context:
            self._purge_dead_meshes()
            fbo = self._target(output)
            fbo.use()
            fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
            self._mgl.enable(moderngl.DEPTH_TEST)
            self._mgl.disable(moderngl.CULL_FACE)
            for index, obj in enumerate(scene.objects):
                key = self.program_key(scene, obj, output)
                program = self.programs.get(key)
                program.bind(scene.uniform_values(index, key, aspect), drop_unused=key.formulation == "naive")
                self._mesh_buffers(obj.mesh).vertex_array(self._mgl, program).render(moderngl.TRIANGLES)
            images = [np.frombuffer(fbo.read(components=4, attachment=i, dtype="f4"), dtype=np.float32)
                      .reshape(self.height, self.width, 4)[::-1] for i in range(len(fbo.color_attachments))]
            self.context.check_error(f"rendering {output}")
        return images

    def program_key(self, scene, obj, output="radiance"):
        """The key this renderer draws ``obj`` of ``scene`` with (its formulation and specialisation)."""
        if output == "radiance" and not self.specialise:
            return uber_key(output, self.formulation)
        key = scene.program_key(obj, output)
        return key if key.formulation == self.formulation else replace(key, formulation=self.formulation)

    def _target(self, output):
        fbo = self._targets.get(output)
        if fbo is None:
            count = 2 if output == "gbuffer" else 1
            colors = [self._mgl.renderbuffer(self._size, 4, dtype="f4") for _ in range(count)]
            fbo = self._targets[output] = self._mgl.framebuffer(colors, self._mgl.depth_renderbuffer(self._size))
        return fbo

    def _mesh_buffers(self, mesh):
        entry = self._meshes.get(id(mesh))
        if entry is None or entry.owner() is not mesh:
            if entry is not None:
                entry.release()
            entry = self._meshes[id(mesh)] = _MeshBuffers(self._mgl, mesh)
        return entry

    def _purge_dead_meshes(self):
        for mesh_id in [k for k, e in self._meshes.items() if e.owner() is None]:
            self._meshes.pop(mesh_id).release()

    def _release_targets(self):
        self.context.bind_idle_framebuffer()
        for fbo in self._targets.values():
            for attachment in (*fbo.color_attachments, fbo.depth_attachment):
                attachment.release()
            fbo.release()
        self._targets.clear()

    def gl_object_count(self):
        """Number of GL objects this renderer holds (programs, buffers, vertex arrays, targets)."""
        meshes = sum(1 + len(e.buffers) + len(e.vertex_arrays) for e in self._meshes.values())
        targets = sum(2 + len(f.color_attachments) for f in self._targets.values())
        return len(self.programs) + meshes + targets

    def release(self):
        """Release every GL object and the context; idempotent."""
        if self.context is None:
            return
        with self.context:
            for entry in self._meshes.values():
                entry.release()
            self._meshes.clear()
            self._release_targets()
            self.programs.release()
        self.context.release()
        self.context = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.release()

    def __repr__(self):
        state = "released" if self.context is None else self.backend
        return f"Renderer({self.width}x{self.height}, {state})"
