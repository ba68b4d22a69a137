"""The floor of glphong's overhead: `HandWrittenRenderer`, the minimal moderngl program that draws a glphong scene
with glphong's own generated GLSL.

Every one-time step (compilation, uploads, uniform packing) happens in `HandWrittenRenderer.prepare`, and
`HandWrittenRenderer.render` only binds, writes precomputed uniform bytes, draws and reads back.  Its frame time is
the floor that glphong's per-frame overhead (key computation, strict uniform binding, validation) is measured
against (``glphong bench``): the keys of a default `glphong.Renderer` (``numerics='auto'``).  ``shader='textbook'``
draws with the naive formulation instead, the floor of a textbook implementation.
"""
from dataclasses import replace

import moderngl
import numpy as np

from glphong.gpu.contexts import create_context
from glphong.shaders.assembly import assemble
from glphong.shaders.binding import binding
from glphong.shaders.numerics import with_numerics

__all__ = ["HandWrittenRenderer", "SHADERS"]

#: shader variants of `HandWrittenRenderer`
SHADERS = ("glphong", "textbook")


class HandWrittenRenderer:
    """The fastest honest moderngl rendering of a glphong scene: the floor of glphong's overhead.

    Parameters
    ----------
    width, height : int
        Image size in pixels.
    backend : {'egl', 'osmesa', 'auto'}
        Passed to `glphong.gpu.contexts.create_context`; the renderer owns the context.
    shader : {'glphong', 'textbook'}
        'glphong': the stable programs glphong draws with.  'textbook': the same keys with
        ``formulation='naive'`` (the textbook GLSL), the floor of a naive implementation.

    Notes
    -----
    `prepare` does every one-time step; `render` only makes the context current, binds and
    clears the target, enables the depth test, then per object writes the precomputed
    uniform bytes and draws, and reads the float32 target back.  The scene is captured at
    `prepare`: later changes to it are not seen until `prepare` is called again.
    """

    def __init__(self, width, height, backend="egl", shader="glphong"):
        if shader not in SHADERS:
            raise ValueError(f"shader must be one of {', '.join(map(repr, SHADERS))} (got {shader!r})")
        self.width = int(width)
        self.height = int(height)
        self.shader = shader
        self.context = create_context(backend)
        self._mgl = self.context.mgl
        self._programs = {}
        self._buffers = []
        self._vaos = []
        self._draws = ()
        self._fbo = None

    @property
    def backend(self):
        """Name of the OpenGL backend in use ('egl' or 'osmesa')."""
        return self.context.backend

    def key(self, scene, obj):
        """The `ProgramKey` this renderer draws ``obj`` with."""
        key = binding(scene).program_key(obj)
        return replace(key, formulation="naive") if self.shader == "textbook" else with_numerics(key, scene, obj)

    def prepare(self, scene):
        """Compile, upload and pack everything ``scene`` needs; replaces a previous scene."""
        if self.context is None:
            raise RuntimeError("this HandWrittenRenderer has been released")
        aspect = self.width / self.height
        with self.context:
            self._release_scene()
            mgl = self._mgl
            colour = mgl.renderbuffer((self.width, self.height), 4, dtype="f4")
            self._fbo = mgl.framebuffer([colour], mgl.depth_renderbuffer((self.width, self.height)))
            mgl.disable(moderngl.CULL_FACE)
            meshes, draws = {}, []
            for index, obj in enumerate(scene.objects):
                key = self.key(scene, obj)
                program = self._programs.get(key)
                if program is None:
                    defines, generated = key.defines(), key.generated_chunks()
                    program = self._programs[key] = mgl.program(
                        vertex_shader=assemble(key.vertex_chunks(), defines, generated),
                        fragment_shader=assemble(key.fragment_chunks(), defines, generated))
                mesh = meshes.get(id(obj.mesh))
                if mesh is None:
                    mesh = meshes[id(obj.mesh)] = {"indices": mgl.buffer(obj.mesh.indices.tobytes())}
                    self._buffers.append(mesh["indices"])
                content = []
                for name, source, fmt in (("in_position", "positions", "3f"), ("in_normal", "normals", "3f"),
                                          ("in_tangent", "tangents", "4f"), ("in_uv", "uvs", "2f")):
                    if name in key.attributes() and name in program:
                        if source not in mesh:
                            mesh[source] = mgl.buffer(getattr(obj.mesh, source).tobytes())
                            self._buffers.append(mesh[source])
                        content.append((mesh[source], fmt, name))
                vao = mgl.vertex_array(program, content, mesh["indices"], index_element_size=4)
                self._vaos.append(vao)
                uniforms = []
                for name, value in binding(scene).uniform_values(index, key, aspect).items():
                    if program.get(name, None) is None:
                        if key.formulation == "naive":
                            continue  # the compiler removed an input the naive program never reads
                        raise KeyError(f"program {key.describe()!r} has no uniform {name!r}")
                    uniform = program[name]
                    data = np.asarray(value, dtype=np.float32)
                    if data.ndim == 2 and data.shape[0] == data.shape[1] and uniform.dimension == data.size:
                        data = data.T  # row-major matrix -> GL column-major
                    uniforms.append((uniform, np.ascontiguousarray(data).tobytes()))
                draws.append((tuple(uniforms), vao))
            self._draws = tuple(draws)
        return self

    def render(self):
        """Draw the prepared scene; return its radiance, (H, W, 3) float32, row 0 at the top."""
        fbo = self._fbo
        if fbo is None:
            raise RuntimeError("call prepare(scene) first (or this HandWrittenRenderer has been released)")
        with self.context:
            fbo.use()
            fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
            self._mgl.enable(moderngl.DEPTH_TEST)
            for uniforms, vao in self._draws:
                for uniform, data in uniforms:
                    uniform.write(data)
                vao.render()
            rgba = np.frombuffer(fbo.read(components=4, dtype="f4"), dtype=np.float32)
        return np.ascontiguousarray(rgba.reshape(self.height, self.width, 4)[::-1, :, :3])

    def _release_scene(self):
        for vao in self._vaos:
            vao.release()
        for buffer in self._buffers:
            buffer.release()
        for program in self._programs.values():
            program.release()
        if self._fbo is not None:
            self.context.release_framebuffer(self._fbo)
        self._programs, self._buffers, self._vaos, self._draws, self._fbo = {}, [], [], (), None

    def release(self):
        """Release every GL object and the context; idempotent."""
        if self.context is None:
            return
        with self.context:
            self._release_scene()
        self.context.release()
        self.context = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.release()

    def __repr__(self):
        state = "released" if self.context is None else self.backend
        return f"HandWrittenRenderer({self.width}x{self.height}, shader={self.shader!r}, {state})"
