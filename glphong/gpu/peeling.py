"""Blended surfaces (glTF ``alphaMode: BLEND``, `glphong.AlphaBlend`) composited exactly, per pixel, by depth peeling
(docs/design.md section 16).

After the opaque and alpha-masked objects are drawn (their depth buffer kept), the blended objects' layers are
peeled front to back, one per pass, until an occlusion query finds no fragment left.  Per layer, with a depth buffer
of the peel's own that starts as a copy of the opaque one (a blit):

1. the peel (`blend_key` kind 2, glsl/mesh_fragment.glsl ``ALPHA_BLEND == 2``): every blended fragment strictly
   behind the previous layer's window depth ``z_prev`` (an exact float32 comparison in the shader) and not behind the
   depth buffer (LEQUAL, writing) writes its window depth ``z`` into a float32 target MIN-blended from 2.  The target
   then holds the nearest such depth exactly as float32 holds it, whatever the order of drawing: the 24-bit depth
   buffer only rejects fragments in a farther quantum than one already drawn, never the nearest; it ends holding the
   nearest fragment's quantum, as the rasteriser rounds it.  The query counts the fragments;
2. the layer (kind 1): drawn with the depth test EQUAL against that buffer (no write), so the rasteriser shades only
   the fragments in the layer's quantum and skips the others before their shader runs; the shader keeps the one whose
   depth equals the layer's exactly, ``(a L, a)`` premultiplied, composited front to back by the blend unit into a
   float32 accumulator: ``C += (1 - A) a L``, ``A += (1 - A) a``.

Then the accumulator goes over the opaque image: ``C_out = C + (1 - A) C_opaque`` (blend ONE, ONE_MINUS_SRC_ALPHA),
which is the glTF specification's "over" applied back to front, reassociated.  A frame with ``n`` layers draws the
blended objects ``2 n + 1`` times, plus ``n + 1`` depth blits and one composite pass.  A pixel with more than
``max_layers`` layers keeps its nearest ``max_layers``: the peel past the cap finds where fragments are left, the
frame's ``blend_cut`` map, and a warning says how many pixels.

With transmissive objects (`glphong.gpu.transmission`) a frame peels twice: into the transmission's background the
layers behind the nearest transmissive surface of each pixel and in front of the opaque depth (all of them where no
transmissive surface covers the pixel), then, over the frame, those in front of the opaque and transmissive depth
(`merged_peels`).  The background's first peel starts from the transmissive surfaces' nearest window depth instead of
-1 (``start``): drawn by their peel programs into a float32 target cleared to -1, depth-tested LESS against a copy of
the opaque depth and writing it (the nearest depth quantum's first fragment), then again EQUAL and MIN-blended (every
fragment of that quantum: the nearest exactly, as the peel's own target holds it).

Not exact: two blended fragments at the same float32 window depth in one pixel (coincident surfaces) are one layer,
the last drawn; a blended fragment in the opaque surface's 24-bit depth quantum is kept (as the opaque surfaces' own
ties are decided either way).
"""
import warnings
from dataclasses import dataclass, replace

import moderngl
import numpy as np

from glphong.gpu.shadows import ShadowMap
from glphong.shaders.keys import EncodeKey

__all__ = ["BLEND_LAYERS", "MAX_BLEND_LAYERS", "blended", "blended_objects", "blend_key", "CompositeKey", "Peeling",
           "check_blend_options", "per_pixel_option", "blend_fields", "BlendCapWarning", "merged_peels"]


class BlendCapWarning(UserWarning):
    """Pixels had more blended layers than the renderer's ``blend_layers``: their farthest ones were left out."""

#: blended layers composited per pixel by default (`glphong.Renderer`'s ``blend_layers``)
BLEND_LAYERS = 16
#: the most ``blend_layers`` may be
MAX_BLEND_LAYERS = 256
#: the peel target's clear value: behind every window depth (which lies in [0, 1])
_FAR = 2.0


def blended(obj):
    """Whether a scene object's material is blended (has an `glphong.AlphaBlend`)."""
    return obj.material.alpha_blend is not None


def blended_objects(scene):
    """Indices of the scene's blended objects (list of int)."""
    return [i for i, obj in enumerate(scene.objects) if blended(obj)]


def check_blend_options(renderer, scene):
    """ValueError naming the option where ``renderer`` cannot draw the blended objects of ``scene``."""
    if not blended_objects(scene):
        return
    for obj in scene.objects:
        if blended(obj) and obj.material.alpha_blend.textured and obj.mesh.uvs is None:
            raise ValueError(f"object {obj.name!r}: its blended material's alpha is textured, and its mesh has no "
                             "uvs: give its MeshData uvs=, or a constant alpha")
    wrong = per_pixel_option(renderer)
    if wrong:
        raise ValueError(f"the scene has blended materials (alpha_blend, glTF alphaMode BLEND), which depth "
                         f"peeling draws with per-pixel, specialised programs and one sample a pixel; this "
                         f"renderer has {wrong[0]}: use {wrong[1]}")


def per_pixel_option(renderer):
    """``(option, fix)`` of the first option of ``renderer`` that a pass drawing per pixel over a drawn image (the
    peel, `glphong.gpu.transmission`) cannot take, naming it and its fix; None where there is none."""
    for wrong, name, fix in ((renderer.samples > 1, f"samples={renderer.samples}", "samples=1 (supersample= "
                              "anti-aliases)"),
                             (renderer.shading != "pixel", "shading='vertex'", "shading='pixel'"),
                             (not renderer.specialise, "specialise=False", "specialise=True")):
        if wrong:
            return name, fix
    return None


def blend_fields(blend, supersample=1):
    """The `glphong.Frame` fields of a peel's ``(layers, cut)`` (None: the scene has no blended object, and the frame
    none of them): ``blend_layers`` and ``blend_cut``, (H, W) bool at the output size (a pixel is cut where any of its
    ``supersample``^2 internal pixels is); warns (`BlendCapWarning`) with the count of cut pixels."""
    if blend is None:
        return {}
    layers, cut = blend
    height, width = (None, None) if cut is None else (cut.shape[0] // supersample, cut.shape[1] // supersample)
    if cut is not None and supersample > 1:
        cut = cut.reshape(height, supersample, width, supersample).any(axis=(1, 3))
    if cut is not None:
        warnings.warn(f"{int(cut.sum())} pixels have more than {layers} blended layers: their farthest layers are "
                      "left out (Frame.blend_cut maps them; raise Renderer(blend_layers=...))", BlendCapWarning,
                      stacklevel=4)
    return {"blend_layers": layers, "blend_cut": cut}


def merged_peels(first, second):
    """The ``(layers, cut)`` of a frame that peeled twice (None: a peel that did not run): the most layers, and the
    pixels either cut (`blend_fields` reads it)."""
    if first is None or second is None:
        return second if first is None else first
    cuts = [cut for cut in (first[1], second[1]) if cut is not None]
    return max(first[0], second[0]), (np.logical_or.reduce(cuts) if cuts else None)


def blend_key(key, kind, textured=False):
    """The program key of a blended object's layer (``kind`` 1: shaded at the layer's depth, premultiplied; 3 where
    ``textured``, its alpha from a texture) or peel (2: its window depth alone, so everything the shading needs is
    left out) from its radiance ``key``."""
    if kind == 1:
        return replace(key, alpha_blend=3 if textured else 1, pass_planes=(), has_object=False,
                       has_uv=key.has_uv or textured)
    return replace(key, alpha_blend=2, terms=(), lights=(), has_ka=False, has_normal=False, has_tangent=False,
                   has_uv=False, has_color=False, normal_map=False, has_face=False, two_sided=False, shadow_size=0,
                   shadow_filter=0, numerics=(), pass_planes=(), has_object=False, alpha_mask=0)


@dataclass(frozen=True)
class CompositeKey(EncodeKey):
    """Key of the pass that puts the blended layers over the opaque image (glsl/blend_composite.glsl): a full-screen
    pass like the 8-bit encoding's (`glphong.shaders.keys.EncodeKey`), with its own fragment stage."""

    def defines(self):
        return []

    def fragment_chunks(self):
        return ("blend_composite",)

    def describe(self):
        return "blend composite"


class Peeling:
    """The peel's targets and query of one renderer: two float32 depth textures (ping-pong) and a float32 RGBA
    accumulator at the internal size, and the framebuffers that pair them with the opaque draw's depth buffer.

    Parameters
    ----------
    mgl : moderngl.Context
    """

    def __init__(self, mgl):
        self._mgl = mgl
        self._textures = {}
        self._framebuffers = {}
        self._query = None

    def _texture(self, name, size, components):
        texture = self._textures.get((name, size))
        if texture is None:
            texture = self._textures[(name, size)] = self._mgl.texture(size, components, dtype="f4")
            texture.filter = (moderngl.NEAREST, moderngl.NEAREST)
            texture.repeat_x = texture.repeat_y = False
        return texture

    def _framebuffer(self, color, depth, write=False):
        """The framebuffer of ``color`` (a texture or renderbuffer, or None) and ``depth`` (or None), writing depth
        with ``write``."""
        # textures and renderbuffers name their GL objects apart: a texture and a renderbuffer may share a glo
        key = tuple(None if a is None else (type(a).__name__, a.glo) for a in (color, depth)) + (write,)
        fbo = self._framebuffers.get(key)
        if fbo is None:
            fbo = self._framebuffers[key] = self._mgl.framebuffer([] if color is None else [color], depth)
            fbo.depth_mask = write
        return fbo

    def draw(self, target, size, draw, max_layers, composite, fullscreen, into=None, start=None):
        """Peel and composite the blended layers over ``target``'s first attachment (the opaque image, drawn), or over
        the texture ``into``.

        Parameters
        ----------
        target : moderngl.Framebuffer
            The radiance draw's framebuffer: a float32 RGBA texture first, and the opaque depth buffer.
        size : (int, int)
            Its size [px].
        draw : callable
            ``draw(kind, depth)``: draw the blended objects with their ``kind`` (`blend_key`) programs, binding
            ``depth`` (a `glphong.gpu.shadows.ShadowMap` of a depth texture) to ``u_blend_depth``.
        max_layers : int
            The cap.
        composite : glphong.gpu.programs.Program
            The `CompositeKey` program; ``fullscreen(composite)`` its vertex array.
        into : moderngl.Texture, optional
            An RGBA32F texture of ``size`` to composite over instead of ``target``'s first attachment (the
            transmission's background, `glphong.gpu.transmission.Transmission.draw`); ``target``'s depth still
            decides what is peeled.
        start : callable, optional
            ``start(depth)``: draw the transmissive objects with their peel programs
            (`glphong.gpu.transmission.TRANSMIT_DEPTH`), binding ``depth`` to ``u_blend_depth``; the first peel then
            keeps only the fragments strictly behind their nearest window depth in front of ``target``'s
            (`_start_depth`), every fragment where none covers the pixel.

        Returns
        -------
        layers : int
            The layers composited (the most of any pixel).
        cut : (H, W) bool ndarray or None
            Where fragments were left past the cap, row 0 at the top (None where none were).
        """
        mgl = self._mgl
        depth_buffer = target.depth_attachment
        z = [self._texture("z0", size, 1), self._texture("z1", size, 1)]
        accumulator = self._texture("accumulator", size, 4)
        layer_depth = self._textures.get(("layer depth", size))
        if layer_depth is None:
            layer_depth = self._textures[("layer depth", size)] = self._mgl.depth_renderbuffer(size)
        peel = [self._framebuffer(t, layer_depth, write=True) for t in z]
        layer = self._framebuffer(accumulator, layer_depth)
        # the depth blit: moderngl blits depth only between framebuffers with colour attachments, so each gets a
        # scratch one (4 bytes a pixel, copied along and never read)
        scratch = [self._textures.get(("scratch", i, size)) for i in (0, 1)]
        for i in (0, 1):
            if scratch[i] is None:
                scratch[i] = self._textures[("scratch", i, size)] = mgl.renderbuffer(size, 4)
        opaque_depth = self._framebuffer(scratch[0], depth_buffer)
        depth_copy = self._framebuffer(scratch[1], layer_depth, write=True)
        if self._query is None:
            self._query = mgl.query(samples=True)
        previous, current = 1, 0
        peel[previous].use()
        peel[previous].clear(-1.0, -1.0, -1.0, -1.0)
        layer.use()
        layer.clear(0.0, 0.0, 0.0, 0.0)
        layers, cut = 0, None
        mgl.enable(moderngl.DEPTH_TEST | moderngl.BLEND)
        try:
            bound = z[previous] if start is None else self._start_depth(size, start, z[previous], opaque_depth,
                                                                          depth_copy, layer_depth)
            while True:
                peel[current].use()
                peel[current].clear(_FAR, _FAR, _FAR, _FAR)  # (and its depth: the blit comes after)
                depth_copy.use()  # its depth mask on: a blit, like a clear, writes depth only where the mask allows
                mgl.copy_framebuffer(depth_copy, opaque_depth)  # the opaque depth, which the peel then lowers
                peel[current].use()
                mgl.blend_func = moderngl.ONE, moderngl.ONE
                mgl.blend_equation = moderngl.MIN
                mgl.depth_func = "<="
                with self._query:
                    draw(2, ShadowMap(bound, None))
                if self._query.samples == 0:
                    break
                if layers == max_layers:
                    data = np.empty((size[1], size[0]), np.float32)
                    peel[current].read_into(data, components=1, dtype="f4")
                    cut = data[::-1] < _FAR
                    break
                # the depth buffer holds the layer's depth as the rasteriser rounds it: tested EQUAL, only the
                # fragments in the layer's depth quantum are shaded (the rest skipped), and the exact test picks one
                mgl.depth_func = "=="
                layer.use()
                mgl.blend_equation = moderngl.FUNC_ADD
                mgl.blend_func = moderngl.ONE_MINUS_DST_ALPHA, moderngl.ONE  # front to back: C += (1 - A) c
                draw(1, ShadowMap(z[current], None))
                layers += 1
                previous, current = current, previous
                bound = z[previous]
            mgl.disable(moderngl.DEPTH_TEST)
            mgl.depth_func = "<"
            self._framebuffer(target.color_attachments[0] if into is None else into, None).use()
            mgl.blend_equation = moderngl.FUNC_ADD
            mgl.blend_func = moderngl.ONE, moderngl.ONE_MINUS_SRC_ALPHA  # the layers over the opaque image
            accumulator.use(location=0)
            composite.bind({"u_layers": 0})
            fullscreen(composite).render(moderngl.TRIANGLES, vertices=3)
        finally:
            mgl.depth_func = "<"
            mgl.blend_equation = moderngl.FUNC_ADD
            mgl.blend_func = moderngl.DEFAULT_BLENDING
            mgl.disable(moderngl.BLEND)
            mgl.enable(moderngl.DEPTH_TEST)
        return layers, cut

    def _start_depth(self, size, start, empty, opaque_depth, depth_copy, layer_depth):
        """The window depth the background's first peel starts from (module): the nearest fragment ``start`` draws in
        front of the opaque depth, as float32 holds it, -1 where there is none; ``empty`` a depth texture cleared to
        -1 (no fragment discarded), ``opaque_depth`` and ``depth_copy`` the blit's framebuffers onto ``layer_depth``.
        Called with the depth test and blending on (`draw`'s state); returns the float32 texture of ``size``."""
        mgl = self._mgl
        texture = self._texture("start", size, 1)
        fbo = self._framebuffer(texture, layer_depth, write=True)
        fbo.use()
        fbo.clear(-1.0, -1.0, -1.0, -1.0)  # (and its depth: the blit comes after)
        depth_copy.use()
        mgl.copy_framebuffer(depth_copy, opaque_depth)
        fbo.use()
        mgl.disable(moderngl.BLEND)
        mgl.depth_func = "<"  # as the transmissive objects' own draw: the nearest quantum's first fragment written
        start(ShadowMap(empty, None))
        mgl.enable(moderngl.BLEND)
        mgl.blend_func = moderngl.ONE, moderngl.ONE
        mgl.blend_equation = moderngl.MIN
        mgl.depth_func = "=="  # every fragment of that quantum: the least depth exactly
        start(ShadowMap(empty, None))
        return texture

    def gl_object_count(self):
        """GL objects held: textures, framebuffers and the query."""
        return len(self._textures) + len(self._framebuffers) + (self._query is not None)

    def release(self):
        """Release the framebuffers (not the depth buffers they share with the renderer's targets), the textures and
        the query (context entered)."""
        for fbo in self._framebuffers.values():
            fbo.release()
        for texture in self._textures.values():
            texture.release()
        if self._query is not None and hasattr(self._query, "release"):  # moderngl < 5.9 has no Query.release
            self._query.release()
        self._framebuffers.clear()
        self._textures.clear()
        self._query = None
