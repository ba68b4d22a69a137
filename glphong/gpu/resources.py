"""The GL objects a renderer owns, and their release: a mesh's buffers and vertex arrays
(`MeshBuffers`, uploaded per attribute on first use), what a renderer keeps per drawn object (`ObjectEntry`), the
host memory its targets may take (`available_memory`), and the release of everything a renderer made,
also for renderers the garbage collector found unreleased (`ORPHANS`, released at the next glphong call
or at exit: the collector may run anywhere, inside pyrender's draw or on another thread, where GL work
is unsafe).
"""
import atexit
import functools
import threading
import warnings
import weakref
from dataclasses import dataclass

import moderngl
import numpy as np

from glphong.gpu.contexts import EGLDisplayTerminatedError

__all__ = ["MeshBuffers", "ObjectEntry", "available_memory", "target_bytes", "check_target_size", "make_target", "read_attachment", "release_resources", "release_targets",
           "release_orphans", "gl_object_count", "orphan", "ORPHANS", "ORPHANS_LOCK"]


def make_target(mgl, name, size, internal_size, samples):
    """A renderer's framebuffer ``name``: ``('gbuffer', *planes)`` (RGBA32F position, normal and each plane, with
    depth, at the output ``size``), ``('radiance', *planes)`` (RGBA32F radiance and each of the frame passes' planes,
    one sample per pixel at the output size), 'radiance' (RGBA32F at the ``internal_size``, multisampled renderbuffers with
    ``samples > 1``, else a texture), 'resolve' (its single-sampled texture), 'display' (8-bit, multisampled like
    the radiance) or 'srgb8' (8-bit at the output size)."""
    if isinstance(name, tuple) and name[0] == "gbuffer":
        colors = [mgl.renderbuffer(size, 4, dtype="f4") for _ in range(len(name) + 1)]
        return mgl.framebuffer(colors, mgl.depth_renderbuffer(size))
    if isinstance(name, tuple) and name[0] == "radiance":  # one sample per pixel, the frame passes' planes beside
        texture = mgl.texture(size, 4, dtype="f4")
        texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        planes = [mgl.renderbuffer(size, 4, dtype="f4") for _ in range(len(name) - 1)]
        return mgl.framebuffer([texture, *planes], mgl.depth_renderbuffer(size))
    if name == "radiance" and samples > 1:
        return mgl.framebuffer([mgl.renderbuffer(internal_size, 4, samples=samples, dtype="f4")],
                               mgl.depth_renderbuffer(internal_size, samples=samples))
    if name == "display":  # 8-bit display values, multisampled like the radiance target
        return mgl.framebuffer([mgl.renderbuffer(size, 4, samples=samples if samples > 1 else 0)],
                               mgl.depth_renderbuffer(size, samples=samples if samples > 1 else 0))
    if name in ("radiance", "resolve"):
        texture = mgl.texture(internal_size, 4, dtype="f4")
        texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
        return mgl.framebuffer([texture], mgl.depth_renderbuffer(internal_size) if name == "radiance" else None)
    return mgl.framebuffer([mgl.renderbuffer(size, 4)])  # srgb8


def read_attachment(fbo, size, components, attachment=0, dtype="f4"):
    """The attachment of ``fbo`` as a new writable (H, W, components) array (``size`` (W, H)), row 0 at the top (a
    view with a negative row stride: GL's rows run bottom-up), read straight into it."""
    data = np.empty((size[1], size[0], components), np.float32 if dtype == "f4" else np.uint8)
    fbo.read_into(data, components=components, attachment=attachment, dtype=dtype)
    return data[::-1]


@dataclass(eq=False)
class ObjectEntry:
    """What a renderer draws one scene object with (see `glphong.gpu.drawing.draw_list`)."""

    state: tuple
    index: int
    key: object
    program: object
    pack: tuple
    vertex_array: object
    mirrored: bool
    sphere: tuple = None  # ((x, y, z), radius) in the world where the mesh's back faces may be culled
    checked: object = None
    camera: object = None  # the camera the key's 'view' piece was decided for (numerics='auto')
    view: tuple = None  # (camera, aspect, record or None): the triangles drawn for that view (`glphong.gpu.drawing`)
    bounds: tuple = None  # ((x, y, z), radius): the mesh's bounding sphere in the world, once it is asked for


def target_bytes(size, supersample, samples):
    """Memory a renderer's render targets and one float32 readback need at ``size`` (W, H) [bytes].

    Radiance target RGBA32F plus depth at the internal (supersampled) size, times the samples, a resolve target when
    multisampling, the 8-bit display target and depth times the samples and its resolve, the G-buffer (up to four
    RGBA32F planes and depth) at the output size, and the float32 readback of the internal size.  Not counted: the
    depth peel's targets (`glphong.gpu.peeling`: two float depth planes, an RGBA32F accumulator, a depth buffer and two
    4-byte scratch planes, 36 bytes a pixel), made on a scene's first blended frame and released with the targets.
    """
    w, h = size
    internal = w * h * supersample ** 2
    radiance = internal * (16 + 4) * samples + (internal * 16 if samples > 1 else 0)
    display = w * h * (4 + 4) * samples + w * h * 4  # render_srgb8's 8-bit target and its resolve
    return radiance + display + w * h * (4 * 16 + 4) + internal * 16


def check_target_size(size, supersample, samples, max_size, renderer_name):
    """``size`` (W, H) times ``supersample`` against the context's largest target ``max_size`` and the memory
    `target_bytes` needs against `available_memory`; ValueError saying which."""
    internal = (size[0] * supersample, size[1] * supersample)
    if max(internal) > max_size:
        raise ValueError(f"width and height times supersample must be at most this context's largest "
                         f"render target, {max_size} pixels ({renderer_name}) (got {internal[0]}x{internal[1]})")
    needed = target_bytes(size, supersample, samples)
    available = available_memory()
    if available is not None and needed > 0.8 * available:
        raise ValueError(f"a {size[0]}x{size[1]} renderer (supersample {supersample}, samples {samples}) "
                         f"needs about {needed / 2**30:.1f} GiB for its render targets and readback; this machine "
                         f"has {available / 2**30:.1f} GiB available (at most 80% of it may be used)")


def available_memory():
    """``MemAvailable`` of /proc/meminfo [bytes] (llvmpipe's render targets live in host memory), or None."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        return None
    return None


class MeshBuffers:
    """GPU buffers of one MeshData and its vertex arrays per program.

    A vertex attribute is uploaded the first time a program that reads it draws the mesh:
    a scene whose programs never read normals (no lights) never uploads them.
    """

    #: attribute -> (MeshData attribute, moderngl format)
    _SOURCES = {"in_position": ("positions", "3f"), "in_normal": ("normals", "3f"), "in_tangent": ("tangents", "4f"),
                "in_uv": ("uvs", "2f"), "in_color": ("colors", "3f")}

    def __init__(self, mgl, mesh):
        self.owner = weakref.ref(mesh)
        self.buffers = {}
        self.index_buffer = mgl.buffer(mesh.indices.tobytes())
        self.vertex_arrays = {}
        self.subsets = {}  # token -> (vertex array, index buffer) of the triangles in a view (`glphong.gpu.view_cull`)
        self.kept = {}  # (pose, view) bytes -> the triangles in that view, shared by every program that draws it

    #: what a mesh without tangents or UVs supplies to a program that reads them for another object's
    #: sake (the G-buffer, the uber-shader): tangent 0 (the shader then uses the basis around n), uv 0
    _DEFAULTS = {"in_tangent": (0.0, 0.0, 0.0, 1.0), "in_uv": (0.0, 0.0), "in_color": (1.0, 1.0, 1.0)}

    def buffer(self, mgl, name):
        if name not in self.buffers:
            mesh = self.owner()
            data = getattr(mesh, self._SOURCES[name][0])
            if data is None:
                data = np.tile(np.float32(self._DEFAULTS[name]), (len(mesh.positions), 1))
            self.buffers[name] = mgl.buffer(np.ascontiguousarray(data, dtype=np.float32).tobytes())
        return self.buffers[name]

    def vertex_array(self, mgl, program):
        vao = self.vertex_arrays.get(program.key)
        if vao is None:
            # only what the linked program reads: a declared need its GLSL never reads is compiled out
            content = [(self.buffer(mgl, name), self._SOURCES[name][1], name) for name in program.key.attributes()
                       if name in program.gl_program]
            vao = self.vertex_arrays[program.key] = mgl.vertex_array(
                program.gl_program, content, self.index_buffer, index_element_size=4)
        return vao

    def subset(self, mgl, program, token, indices):
        """A vertex array of ``program`` drawing the triangles ``indices`` ((3 K,) uint32, K > 0) of this mesh, kept
        under ``token`` (replacing, and releasing, what the token held); returns the record ``(vao, index buffer)``,
        which its user compares by identity with ``subsets.get(token)`` before drawing with it."""
        old = self.subsets.pop(token, None)
        if old is not None:
            for obj in old:
                obj.release()
        ibo = mgl.buffer(np.ascontiguousarray(indices, np.uint32).tobytes())
        content = [(self.buffer(mgl, name), self._SOURCES[name][1], name) for name in program.key.attributes()
                   if name in program.gl_program]
        record = self.subsets[token] = (mgl.vertex_array(program.gl_program, content, ibo, index_element_size=4), ibo)
        return record

    def release(self):
        for vao in self.vertex_arrays.values():
            vao.release()
        for vao, ibo in self.subsets.values():
            vao.release()
            ibo.release()
        self.subsets.clear()
        for buf in (*self.buffers.values(), self.index_buffer):
            buf.release()


#: the resources of renderers dropped without release(), released at the next glphong call: the
#: garbage collector may run anywhere (inside pyrender's draw, on another thread), where GL work is unsafe
ORPHANS = []
ORPHANS_LOCK = threading.Lock()


def release_targets(context, targets):
    """Release a renderer's framebuffers and full-screen vertex arrays (context entered)."""
    for name, obj in targets.items():
        if name[0] in ("fullscreen", "peeling"):  # a full-screen vertex array; the peel's targets (`glphong.gpu.peeling`)
            obj.release()
        else:
            context.release_framebuffer(obj)
    targets.clear()


def release_resources(context, meshes, targets, programs):
    """Release every GL object of a renderer, then recycle its context (`Renderer.release` and the
    orphans of renderers dropped without it).  A context whose EGL display was terminated has lost its
    objects already: it is only marked released."""
    try:
        with context:
            for entry in meshes.values():
                entry.release()
            meshes.clear()
            release_targets(context, targets)
            programs.release()
    except EGLDisplayTerminatedError:
        context._released = True
        return
    context.recycle()  # every GL object is released: the context may serve another renderer


def gl_object_count(programs, meshes, targets):
    """Number of GL objects a renderer holds: its programs (a `glphong.gpu.programs.ProgramCache`) and their textures,
    its meshes' buffers and vertex arrays (dict of `MeshBuffers`), its targets' framebuffers and attachments."""
    mesh_objects = sum(1 + len(e.buffers) + len(e.vertex_arrays) + 2 * len(e.subsets) for e in meshes.values())
    target_objects = sum(1 if name[0] == "fullscreen" else f.gl_object_count() if name[0] == "peeling" else
                         1 + len(f.color_attachments) + (f.depth_attachment is not None) for name, f in targets.items())
    return len(programs) + len(programs.textures) + mesh_objects + target_objects


def orphan(context, meshes, targets, programs):
    """Hand a renderer dropped without ``release()`` to the next glphong call (`ORPHANS`), and warn as an unclosed
    file does: moderngl never frees GL objects on garbage collection, and GL work inside the collector could run
    inside someone else's draw."""
    with ORPHANS_LOCK:
        ORPHANS.append(functools.partial(release_resources, context, meshes, targets, programs))
    try:
        warnings.warn("a glphong.Renderer was never released: its GL objects are released at the next "
                      "glphong call (call release() or use 'with glphong.Renderer(...) as r:')",
                      ResourceWarning, stacklevel=3)
    except Exception:  # noqa: BLE001 - warnings turned into errors must not keep the resources
        pass


@atexit.register
def release_orphans():
    with ORPHANS_LOCK:
        orphans = ORPHANS[:]
        ORPHANS.clear()
    for release in orphans:
        try:
            release()
        except Exception:  # noqa: BLE001 - a context the driver lost cannot be released further
            pass
