"""Offscreen rendering: scene -> program keys -> cached programs -> float32 images.

One render: for each object, the scene's binding (`glphong.shaders.binding`) gives its `ProgramKey`; the
cache gives the program; the binding gives the uniforms, bound strictly; only the vertex attributes
the program reads are bound; the draw goes to an RGBA32F target that is read back
as float32 with row 0 at the top.
"""
import functools
import threading
import weakref

import moderngl
import numpy as np

from glphong.core import validate as _validate
from glphong.gpu.frame import Frame, GBuffer
from glphong.gpu.passes import check_passes, derive_passes, gbuffer_planes, requested_passes
from glphong.gpu.resources import (MeshBuffers, check_target_size, gl_object_count, make_target, orphan,
                                   read_attachment, release_orphans, release_resources, release_targets, target_bytes)
from glphong.gpu.contexts import check_not_forked, create_context
from glphong.gpu.counters import track as _track
from glphong.scene.culling import culling_decision
from glphong.shaders.binding import binding
from glphong.shaders.keys import EncodeKey
from glphong.shaders.options import FORMULATIONS, GBUFFER_PLANES, MAX_GBUFFER_TARGETS, PASS_PLANES
from glphong.shaders.numerics import NUMERICS
from glphong.gpu.shadows import ShadowMaps
from glphong.gpu.matte import MATTE_K, MATTE_SAMPLES, MAX_MATTE_K, MAX_MATTE_SAMPLES, TILE, Matte
from glphong.gpu.programs import ProgramCache
from glphong.gpu.drawing import draw_objects
from glphong.gpu.peeling import (BLEND_LAYERS, MAX_BLEND_LAYERS, CompositeKey, Peeling, blend_fields, blended_objects,
                                 check_blend_options, merged_peels)
from glphong.gpu.program_keys import renderer_program_key
from glphong.gpu.transmission import (TARGET_KEY, TRANSMIT, TRANSMIT_DEPTH, Transmission, background_need,
                                    check_transmission_options, transmissive_objects)
from glphong.scene.scene import Scene

__all__ = ["Renderer", "Frame", "GBuffer", "RendererReleasedError"]


class RendererReleasedError(RuntimeError):
    """A `Renderer` used after its `Renderer.release` (or the end of its ``with`` block): its context and GL
    objects are gone; the message names the call.  Make a new renderer."""


def _released(call):
    return RendererReleasedError(f"Renderer.{call} called after release(): this Renderer has been released (by "
                                 "release() or the end of its `with` block), its context and GL objects are gone; "
                                 "make a new Renderer")


def _one_call_at_a_time(method):
    """Run a Renderer method under its lock: a renderer is usable from any thread, one call at a time.

    The fork check comes first (a lock copied by fork while held would hang the child), then the GL
    objects of renderers the garbage collector found unreleased are released (`ORPHANS`); a renderer released
    raises `RendererReleasedError` naming the method (but for `release`, which may be called again)."""
    @functools.wraps(method)
    def locked(self, *args, **kwargs):
        check_not_forked()
        release_orphans()
        with self._lock:
            if self.context is None and method.__name__ != "release":
                raise _released(f"{method.__name__}()")
            return method(self, *args, **kwargs)
    return locked


class Renderer:
    """Offscreen renderer of glphong scenes.

    Threads: a renderer may be used from any thread; its calls are serialised by a lock (two threads
    rendering at once take turns), and its context is current only inside a call.  Processes: a
    renderer cannot cross ``fork``; in a child forked after any context was made, it raises
    `glphong.gpu.contexts.ForkedProcessError` (use the 'spawn' or 'forkserver' start methods).

    Parameters
    ----------
    width, height : int
        Image size in pixels, 1 to 16384.
    backend : {'auto', 'egl', 'osmesa'}
        OpenGL backend (see `glphong.gpu.contexts.create_context`).
    shading : {'pixel', 'vertex'}
        'pixel' (default): the model is evaluated per fragment.  'vertex': per vertex and
        interpolated (Gouraud): cheaper, and wrong inside triangles where the radiance is not
        linear (highlights smaller than a triangle vanish).
    samples : {1, 2, 4, 8}
        Multisample anti-aliasing samples per pixel (silhouettes only; shading stays one
        evaluation per pixel and triangle).  At most the context's GL_MAX_SAMPLES (4 on llvmpipe).
    supersample : int
        Render at ``supersample`` times the size in each direction and box-filter down
        (anti-aliases shading too), 1 to 8.
    formulation : {'stable', 'naive'}
        'stable' (default): docs/design.md section 3.  'naive': the textbook float32 formulation,
        for measuring what stability costs and buys; not for real use.
    numerics : {'auto', 'stable'}
        'auto' (default): per object, the pieces of the stable formulation that the scene's ranges prove
        unnecessary are compiled in their cheaper form (`glphong.shaders.numerics`, docs/design.md section 3,
        "Stability where a scene needs it"), which keeps every pixel inside the error band; `glphong.describe`
        shows each decision and its reason.  'stable': the stable formulation everywhere.
    culling : {'auto', 'off'}
        'auto' (default): cull the back faces of an object where they cannot be seen (a closed,
        outward-wound mesh wholly between the near and far planes; `glphong.scene.culling`), which
        changes no pixel but a silhouette pixel where a back triangle ties with the front one in
        depth (there the front face shows).  'off': draw every triangle.
    device : int or {'gpu', 'software'}, optional
        The EGL device to render on: an index of `glphong.gpu.devices`'s list, or the first device of a
        kind (EGL only; default: `glphong.gpu.contexts.create_context`'s).  A batch passes it through
        (``render_many(..., device=1)``).
    shadow_map_size : int
        Texels along a side of each shadow map (a cube map's face), 16 to 8192 and at most a third of the context's
        largest texture (a cube map's faces lie three across: 5461 on llvmpipe) (default 1024); only lights with
        ``shadows=True`` have maps (docs/design.md section 12).
    shadow_filter_radius : int
        Percentage-closer filtering over the (2 r + 1)^2 texels around the nearest, 0 to 8 (default 0: the
        nearest texel alone, hard shadows).
    specialise : bool
        True (default): one program per distinct `ProgramKey`, containing only what the
        object needs.  False: every object drawn with the uber-shader (every built-in term,
        the scene's own terms and up to 8 lights per kind compiled in, switched by uniforms),
        for measuring what specialisation buys.
    matte_samples : int
        Samples per pixel along each axis of the 'matte' pass, 1 to 64 (default `glphong.gpu.matte.MATTE_SAMPLES`,
        32: 1024 samples a pixel); an object's share of a pixel is off by at most about ``1 / (2 matte_samples)`` per
        straight boundary crossing the pixel (docs/design.md section 15).
    matte_k : int
        Objects kept per pixel by the 'matte' pass, 1 to 16 (default 4).
    blend_layers : int
        Blended layers (`glphong.AlphaBlend`, glTF alphaMode BLEND) composited per pixel, 1 to 256 (default 16): the
        nearest ones; a pixel with more has the rest left out, and the frame says where (`Frame.blend_cut`, and a
        warning with the count; `glphong.gpu.peeling`).

    Examples
    --------
    >>> with glphong.Renderer(256, 256) as r:            # doctest: +SKIP
    ...     frame = r.render(scene)
    """

    def __init__(self, width, height, backend="auto", shading="pixel", samples=1, supersample=1,
                 formulation="stable", specialise=True, culling="auto", device=None, shadow_map_size=1024,
                 shadow_filter_radius=0, numerics="auto", matte_samples=MATTE_SAMPLES, matte_k=MATTE_K,
                 blend_layers=BLEND_LAYERS):
        self.matte_samples = _validate.positive_int("matte_samples", matte_samples, 1, MAX_MATTE_SAMPLES)
        self.matte_k = _validate.positive_int("matte_k", matte_k, 1, MAX_MATTE_K)
        self.blend_layers = _validate.positive_int("blend_layers", blend_layers, 1, MAX_BLEND_LAYERS)
        self.shadow_map_size = _validate.positive_int("shadow_map_size", shadow_map_size, 16, 8192)
        self.shadow_filter_radius = _validate.positive_int("shadow_filter_radius", shadow_filter_radius, 0, 8)
        self.shading = _validate.choice("shading", shading, ("pixel", "vertex"))
        self.samples = _validate.choice("samples", _validate.positive_int("samples", samples, 1, 8), (1, 2, 4, 8))
        self.supersample = _validate.positive_int("supersample", supersample, 1, 8)
        self._size = self._check_size(width, height)
        self.formulation = _validate.choice("formulation", formulation, FORMULATIONS)
        self.numerics = _validate.choice("numerics", numerics, NUMERICS)
        self.culling = _validate.choice("culling", culling, ("auto", "off"))
        if not isinstance(specialise, (bool, np.bool_)):
            raise TypeError(f"specialise must be a bool, True or False (got {specialise!r})")
        self.specialise = bool(specialise)
        self.context = None
        self._lock = threading.RLock()
        check_not_forked()
        release_orphans()
        context = create_context(backend, device=device)
        try:
            with context:
                info = context.mgl.info
                self._max_size = min(info["GL_MAX_TEXTURE_SIZE"], info["GL_MAX_RENDERBUFFER_SIZE"],
                                     *info["GL_MAX_VIEWPORT_DIMS"])
                max_samples = context.mgl.max_samples
            if self.samples > max_samples:
                raise ValueError(f"samples must be at most this context's GL_MAX_SAMPLES = {max_samples} "
                                 f"({context.renderer_name}) (got {self.samples})")
            self._check_limits(self._size, context.renderer_name)
            if 3 * self.shadow_map_size > self._max_size:
                raise ValueError(f"shadow_map_size must be at most {self._max_size // 3} on this context ({context.renderer_name}): "
                                 f"a cube map's six faces lie three across in one texture of at most {self._max_size} "
                                 f"texels (got {self.shadow_map_size})")
        except BaseException:
            context.release()
            raise
        context.detach()  # current only inside a call, on whichever thread makes it
        self.context = context
        self._mgl = context.mgl
        self.programs = ProgramCache(self._mgl)
        self._meshes = {}
        self._targets = {}
        self._shadow_maps = ShadowMaps(self._mgl, self._targets)
        self._matte = Matte(self._mgl, self._targets, min(TILE, self._max_size))
        self._entries = weakref.WeakKeyDictionary()  # SceneObject -> {output: ObjectEntry}
        _track(self)  # glphong.gpu.counters.gl_objects_alive counts it while it lives

    def render_target_bytes(self, size=None):
        """Memory the render targets and one float32 readback need at ``size`` (default the current one) [bytes]
        (`glphong.gpu.resources.target_bytes`)."""
        return target_bytes(size or self._size, self.supersample, self.samples)

    def _check_limits(self, size, renderer_name):
        """The size against the context's limits and the memory it needs, before any work starts."""
        check_target_size(size, self.supersample, self.samples, self._max_size, renderer_name)

    def _check_size(self, width, height):
        size = (_validate.positive_int("width", width, 1, 16384), _validate.positive_int("height", height, 1, 16384))
        if max(size) * self.supersample > 16384:
            raise ValueError(f"width and height times supersample must be at most 16384 "
                             f"(got {size[0]}x{size[1]} x {self.supersample})")
        return size

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
        if self.context is None:
            raise _released("backend")
        return self.context.backend

    @property
    def _internal_size(self):
        return (self.width * self.supersample, self.height * self.supersample)

    @_one_call_at_a_time
    def resize(self, width, height):
        """Change the image size; the render targets are rebuilt on next use."""
        size = self._check_size(width, height)
        self._check_limits(size, self.context.renderer_name)
        if size != self._size:
            with self.context:
                self.release_targets()
            self._size = size

    @_one_call_at_a_time
    def render(self, scene, depth=False, normals=False, passes=None, next_scene=None, previous_scene=None):
        """Render the scene's shaded radiance (linear float32) and the frame passes asked for.

        Parameters
        ----------
        scene : Scene
        depth, normals : bool
            Also the 'depth' and 'normal' passes (as ``passes`` naming them).
        passes : sequence of str, optional
            The passes to return (`glphong.gpu.passes.PASSES`: 'radiance', 'depth', 'distance', 'normal',
            'normal_camera', 'uv', 'instance', 'category', 'object_coordinates', 'nocs', 'flow', 'backward_flow',
            'matte'), default ``('radiance',)``.  All but the radiance and the matte come from one G-buffer draw at
            the output size, one sample per pixel (the radiance draw itself where it allows), the matte from a draw
            of its own at ``matte_samples`` squared samples a pixel; without 'radiance' nothing is shaded.
        next_scene, previous_scene : Scene, optional
            The same objects in the same order at their poses in the next (previous) frame, and that frame's
            camera: what 'flow' ('backward_flow') reads.

        Returns
        -------
        Frame
            With blended materials (`glphong.AlphaBlend`), the radiance composites their layers per pixel in depth
            order (`glphong.gpu.peeling`; ``blend_layers`` and ``blend_cut`` say how many and where the cap cut), and
            the other passes are the nearest opaque surface's.
        """
        self._check_scene(scene)
        for name, flag in (("depth", depth), ("normals", normals)):
            if not isinstance(flag, (bool, np.bool_)):
                raise TypeError(f"{name} must be a bool, True or False (got {flag!r})")
        names = requested_passes(passes, depth, normals)
        check_passes(scene, names, next_scene, previous_scene)
        check_blend_options(self, scene)
        check_transmission_options(self, scene)
        geometry = [n for n in names if n not in ("radiance", "matte")]
        extra = self._draw_matte(scene) if "matte" in names else {}
        if geometry and "radiance" in names and self.samples == 1 and self.supersample == 1 \
                and self.shading == "pixel" and self.specialise:
            return self._render_with_planes(scene, names, geometry, next_scene, previous_scene, extra)
        if geometry:  # the lock is re-entrant
            gbuffer = self._gbuffer(scene, gbuffer_planes(geometry), copy=False)
            extra |= derive_passes(scene, gbuffer, geometry, next_scene, previous_scene)
        if "radiance" not in names:
            if geometry:
                mask = gbuffer.mask
            else:  # the matte alone: covered where any sample is
                mask = extra["matte_fractions"][..., 0] > 0.0
            return Frame(radiance=None, mask=mask, coverage=mask.astype(np.float32), passes=names, **extra)
        with self.context:
            fbo, blend = self._draw_radiance(scene)
            rgba = read_attachment(fbo, self._internal_size, components=4)
            self.context.check_error("rendering radiance")
        s = self.supersample
        if s > 1:
            rgba = rgba.reshape(self.height, s, self.width, s, 4).mean(axis=(1, 3), dtype=np.float64).astype(np.float32)
        # views of the one readback (rows flipped by strides): no copy after the driver's
        coverage = rgba[..., 3]
        return Frame(radiance=rgba[..., :3], mask=coverage > 0.0, coverage=coverage, passes=names,
                     **extra, **blend_fields(blend, s))

    def _draw_matte(self, scene):
        """The 'matte' pass's arrays (`glphong.gpu.matte.Matte.draw`), dict of frame attribute to array."""
        with self.context:
            self._purge_dead_meshes()
            ids, fractions = self._matte.draw(scene, self._size, self.matte_samples, self.matte_k, self.programs,
                                              self._vertex_array)
            self.context.check_error("drawing the matte pass")
        return {"matte_ids": ids, "matte_fractions": fractions}

    @property
    def silhouette_limit(self):
        """The largest image side [px] `silhouettes` draws (its target's: 2048, or the context's largest)."""
        return self._matte.tile

    @_one_call_at_a_time
    def silhouettes(self, scene, indices=None):
        """Each object's whole silhouette: where it covers the image drawn alone, one sample per pixel at its centre
        (the instance pass of the object alone, from one small draw each; `glphong.gpu.matte.Matte.silhouettes`);
        images up to `silhouette_limit` a side.

        Parameters
        ----------
        scene : Scene
        indices : sequence of int, optional
            The objects (default all).

        Returns
        -------
        list of (H, W) bool ndarray
        """
        self._check_scene(scene)
        indices = range(len(scene.objects)) if indices is None else indices
        culled = lambda obj: (self.culling == "auto" and culling_decision(obj, scene.camera)[0], obj.mirrored)  # noqa: E731 - as `_draw` decides
        with self.context:
            self._purge_dead_meshes()
            out = self._matte.silhouettes(scene, self._size, indices, self.programs, self._vertex_array, culled)
            self.context.check_error("drawing silhouettes")
        return out

    def _render_with_planes(self, scene, names, geometry, next_scene, previous_scene, extra):
        """The radiance and the geometry passes from one draw: each radiance program also writes the G-buffer planes
        the passes read (multiple render targets, `glphong.shaders.options.PASS_PLANES`), where one sample per pixel
        at the output size is what the radiance is drawn with too."""
        planes = gbuffer_planes(geometry)
        normal = any(n in ("normal", "normal_camera") for n in geometry)
        pass_planes = tuple(p for p in PASS_PLANES if p == "position" or (p == "normal" and normal) or p in planes)
        with self.context:
            fbo = self._target(("radiance", *pass_planes))
            blend = self._draw(scene, "radiance", fbo, planes=pass_planes)
            rgba = read_attachment(fbo, self._size, components=4)
            read = {name: read_attachment(fbo, self._size, components=4, attachment=1 + i)
                    for i, name in enumerate(pass_planes)}
            self.context.check_error("rendering radiance and the frame passes' planes")
        gbuffer = GBuffer.from_planes(read.pop("position"), read.pop("normal", None), read, copy=False)
        extra = extra | derive_passes(scene, gbuffer, geometry, next_scene, previous_scene) | blend_fields(blend)
        coverage = rgba[..., 3]
        return Frame(radiance=rgba[..., :3], mask=coverage > 0.0, coverage=coverage, passes=names, **extra)

    @_one_call_at_a_time
    def render_srgb8(self, scene, exposure=1.0, resolve="display"):
        """Render and encode on the GPU: exposure, exact sRGB curve, 8 bits; only the 8-bit target is read back.

        Parameters
        ----------
        scene : Scene
        exposure : float
            Linear scale applied before encoding, > 0.
        resolve : {'display', 'linear'}
            'display' (default): each fragment is shaded, exposed and encoded in the shading pass
            (OUTPUT_DISPLAY) into an 8-bit target, multisampled where ``samples > 1``, whose
            silhouette samples are averaged as display values, as pyrender and most real-time
            renderers do.  'linear': the linear float image is resolved (and box-filtered where
            ``supersample > 1``, which always takes this path) first and encoded by a separate pass
            (encode.glsl).  Interior pixels are the same either way; silhouette pixels of a
            multisampled image differ (the average of encoded values against the encoded average).
            'display' needs per-pixel shading, no supersampling and specialised programs; with any
            other option, or blended materials (composited in linear float), the linear path runs.
            Measured: 'display' saves the float target's clear, resolve and readback (see README).

        Returns
        -------
        (H, W, 3) uint8 ndarray
            Row 0 at the top; a view of the RGBA read-back (reading RGBA is a copy for the driver, RGB a conversion:
            0.3 ms at 512x512 on llvmpipe).
        """
        self._check_scene(scene)
        check_blend_options(self, scene)
        check_transmission_options(self, scene)
        exposure = _validate.scalar("exposure", exposure, low=0.0, low_inclusive=False)
        resolve = _validate.choice("resolve", resolve, ("display", "linear"))
        with self.context:
            if resolve == "display" and self.supersample == 1 and self.shading == "pixel" and self.specialise \
                    and not blended_objects(scene) and not transmissive_objects(scene):  # composited in linear float
                target = self._target("display")
                self._draw(scene, "display", target, {"u_exposure": exposure})
                if self.samples > 1:
                    resolved = self._target("srgb8")
                    self._mgl.copy_framebuffer(resolved, target)
                    target = resolved
                rgb = read_attachment(target, self._size, components=4, dtype="f1")[..., :3]
                self.context.check_error("rendering display values")
                return rgb
            fbo, blend = self._draw_radiance(scene)
            texture = fbo.color_attachments[0]
            blend_fields(blend, self.supersample)  # the warning where the cap cut pixels' layers
            out = self._target("srgb8")
            out.use()
            program = self.programs.get(EncodeKey(self.supersample))
            texture.use(location=0)
            program.bind({"u_radiance": 0, "u_exposure": exposure})
            self._mgl.disable(moderngl.DEPTH_TEST)
            self._fullscreen(program).render(moderngl.TRIANGLES, vertices=3)
            rgb = read_attachment(out, self._size, components=4, dtype="f1")[..., :3]  # 'f1': normalised bytes
            self.context.check_error("encoding sRGB")
        return rgb

    @_one_call_at_a_time
    def gbuffer(self, scene, planes=()):
        """Render the per-pixel shading inputs of the scene (one sample per pixel, output size): of its opaque and
        alpha-masked objects (blended ones are left out: the nearest opaque surface, docs/design.md section 16).

        Parameters
        ----------
        scene : Scene
        planes : iterable of str
            Planes to write besides those the scene's shading reads (`glphong.shaders.options.GBUFFER_PLANES`:
            'uv', 'object', ...), as the frame passes ask for them.

        Returns
        -------
        GBuffer
        """
        return self._gbuffer(scene, planes)

    def _gbuffer(self, scene, planes=(), copy=True):
        """`gbuffer`; ``copy=False``: its planes strided views of the read-back ones (`GBuffer.from_planes`)."""
        self._check_scene(scene)
        planes = frozenset(planes)
        needs = binding(scene).gbuffer_needs() | planes
        extras = [n for n in GBUFFER_PLANES if n in needs]
        if 2 + len(extras) > MAX_GBUFFER_TARGETS:  # every plane at once: a coat over a normal map with all the rest
            raise ValueError(f"this G-buffer would need {2 + len(extras)} planes (position, normal, "
                             f"{', '.join(extras)}), more than the {MAX_GBUFFER_TARGETS} one draw writes: ask for the "
                             "frame passes with samples=1 and supersample=1 (drawn beside the radiance) or from a "
                             "scene without the plane's need")
        with self.context:
            fbo = self._target(("gbuffer", *extras))
            self._draw(scene, "gbuffer", fbo, planes=planes)
            planes = [read_attachment(fbo, self._size, components=4, attachment=i) for i in range(2 + len(extras))]
            self.context.check_error("rendering the G-buffer")
        return GBuffer.from_planes(planes[0], planes[1], dict(zip(extras, planes[2:])), copy=copy)

    def program_key(self, scene, obj, output="radiance", planes=frozenset()):
        """The key this renderer draws ``obj`` of ``scene`` with (formulation, specialisation, shading); ``planes``: a
        G-buffer's planes beyond the scene's (`gbuffer`); `glphong.gpu.program_keys.renderer_program_key`."""
        return renderer_program_key(self, scene, obj, output, planes)

    def _check_scene(self, scene):
        if not isinstance(scene, Scene):
            raise TypeError(f"scene must be a glphong.Scene (got {type(scene).__name__})")

    def _draw_radiance(self, scene):
        """Draw the radiance; returns the single-sample framebuffer whose color is a texture, and the peel's
        ``(layers, cut)`` (`_draw`)."""
        target = self._target("radiance")
        blend = self._draw(scene, "radiance", target)
        if self.samples == 1:
            return target, blend
        resolved = self._target("resolve")
        self._mgl.copy_framebuffer(resolved, target)
        return resolved, blend

    @property
    def shadow_settings(self):
        """``(shadow_map_size, shadow_filter_radius)``: what the twin needs to mirror this renderer's shadows."""
        return self.shadow_map_size, self.shadow_filter_radius

    def _shadow_values(self, scene, output):
        """Draw the shadow maps the frame's programs read; their samplers' values (dict, empty without shadows).
        Every lit program shares the scene's light keys, so the maps are the scene's (`glphong.shaders.binding.SceneBinding.shadow_setups`)."""
        bound = binding(scene)
        lights = bound.light_keys()
        if output not in ("radiance", "display") or not any(k.shadowed for k in lights):
            return {}
        casters = [obj for obj in scene.objects if obj.casts_shadow]
        return self._shadow_maps.draw(bound.shadow_setups(lights, self.shadow_map_size), casters, self.programs,
                                      self._vertex_array)

    def _draw(self, scene, output, fbo, frame_values=None, planes=frozenset()):
        """Draw ``scene``'s objects into ``fbo`` (`glphong.gpu.drawing`); its radiance with blended objects then peels
        and composites their layers (`glphong.gpu.peeling`): returns ``(layers, cut)`` then, else None.  With
        transmissive objects too (docs/transmission.md): the blended layers behind the transmissive surfaces' depth
        (``start``, `glphong.gpu.peeling.Peeling.draw`) over the opaque image make the background, the transmissive
        objects are drawn, and the layers in front of the opaque and transmissive depth go over the frame
        (`merged_peels` of the two)."""
        self._purge_dead_meshes()
        shadow_values = self._shadow_values(scene, output)
        fbo.use()
        fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        self._mgl.enable(moderngl.DEPTH_TEST)
        self._mgl.disable(moderngl.CULL_FACE)
        draw_objects(self, scene, output, frame_values, shadow_values, planes)
        blending = output == "radiance" and bool(blended_objects(scene))

        def peel(target, into=None):  # the blended layers over target's image (or into), against its depth
            peeling = self._targets.get(("peeling",)) or self._targets.setdefault(("peeling",), Peeling(self._mgl))
            layers = lambda kind, depth: draw_objects(  # noqa: E731 - (into: those behind the glass alone, start)
                self, scene, output, {"u_blend_depth": depth}, shadow_values, blend=kind)
            return peeling.draw(target, target.size, layers, self.blend_layers, self.programs.get(CompositeKey()),
                                self._fullscreen, into,
                                None if into is None else (lambda depth: layers(TRANSMIT_DEPTH, depth)))
        behind = None
        if output == "radiance" and transmissive_objects(scene):  # over the opaque scene (glphong.gpu.transmission)
            transmission = self._targets.get(TARGET_KEY) or self._targets.setdefault(TARGET_KEY, Transmission(self._mgl))
            transmission.draw(fbo, fbo.size, lambda values: draw_objects(
                self, scene, output, (frame_values or {}) | values, shadow_values, planes, blend=TRANSMIT),
                background_need(scene, fbo.size[0]), self.programs, self._fullscreen, peel if blending else None)
            behind = transmission.blend
        return merged_peels(behind, peel(fbo)) if blending else None

    def _fullscreen(self, program):
        vao = self._targets.get(("fullscreen", program.key))
        if vao is None:
            vao = self._targets[("fullscreen", program.key)] = self._mgl.vertex_array(program.gl_program, [])
        return vao

    def _target(self, name):
        fbo = self._targets.get(name)
        if fbo is not None:
            return fbo
        try:
            fbo = self._targets[name] = make_target(self._mgl, name, self._size, self._internal_size, self.samples)
        except moderngl.Error as exc:
            raise RuntimeError(f"the driver could not make a {self._internal_size[0]}x{self._internal_size[1]} "
                               f"render target ({self.context.renderer_name}: {exc}); it needs about "
                               f"{self.render_target_bytes() / 2**30:.2f} GiB with the G-buffer and readback: "
                               "use a smaller size, supersample or samples") from None
        return fbo

    def _vertex_array(self, mesh, program):
        return self._mesh_buffers(mesh).vertex_array(self._mgl, program)

    def _mesh_buffers(self, mesh):
        entry = self._meshes.get(id(mesh))
        if entry is None or entry.owner() is not mesh:
            if entry is not None:
                entry.release()
            entry = self._meshes[id(mesh)] = MeshBuffers(self._mgl, mesh)
        return entry

    def _purge_dead_meshes(self):
        for mesh_id in [k for k, e in self._meshes.items() if e.owner() is None]:
            self._meshes.pop(mesh_id).release()

    def release_targets(self):
        """Release the render targets (made again on next use); nothing to do on a released renderer."""
        if self.context is not None:
            release_targets(self.context, self._targets)

    def gl_object_count(self):
        """Number of GL objects this renderer holds (programs, textures, buffers, vertex arrays, targets)."""
        return gl_object_count(self.programs, self._meshes, self._targets)

    @_one_call_at_a_time
    def release(self):
        """Release every GL object and the context; idempotent."""
        if self.context is None:
            return
        self._entries.clear()
        release_resources(self.context, self._meshes, self._targets, self.programs)
        self.context = None

    def __enter__(self):
        if self.context is None:
            raise _released("__enter__() (a `with` block)")
        return self

    def __exit__(self, *exc):
        self.release()

    def __del__(self):
        # dropped without release(): moderngl never frees GL objects on garbage collection, so hand them
        # to the next glphong call (GL work here could run inside someone else's draw), and say so the way
        # an unclosed file does
        if getattr(self, "context", None) is None:
            return
        state = (self.context, self._meshes, self._targets, self.programs)
        self.context = None
        orphan(*state)

    def __repr__(self):
        state = "released" if self.context is None else self.backend
        options = "".join([f", shading={self.shading!r}" if self.shading != "pixel" else "",
                           f", samples={self.samples}" if self.samples > 1 else "",
                           f", supersample={self.supersample}" if self.supersample > 1 else ""])
        return f"Renderer({self.width}x{self.height}, {state}{options})"
