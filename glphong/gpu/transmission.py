"""Transmissive surfaces (glTF ``KHR_materials_transmission``, thin walls; `glphong.materials.gltf_transmission`,
docs/transmission.md): the opaque scene first, then the transmissive surfaces seeing it through themselves.

A frame of a scene with transmissive objects draws, into the radiance target:

1. every other object (opaque and alpha-masked), as a frame without them;
2. the background, where a drawn program reads it (`background_need`): that image (RGBA32F, the internal size) copied
   on the GPU into level 0 of one mipmapped texture (GL_LINEAR_MIPMAP_LINEAR, clamped to the edge), through a pixel
   buffer; where a program may look it up above level 0 (roughness above 0, a volume), its pyramid of 2x2 box means,
   each level drawn from the one above by glsl/transmission_pyramid.glsl, the same float32 bits as the host's
   `glphong.materials.gltf_transmission.background_levels` (tested); a frame whose every transmissive surface reads
   the texel at its own pixel (roughness 0 or ior 1, thin walls) makes level 0 alone, one whose surfaces read no
   background (``KHR_materials_diffuse_transmission`` alone) makes nothing; where the scene has blended objects too,
   their layers behind the nearest transmissive surface of each pixel (all of them where none covers it) and in front
   of the opaque depth are peeled and composited over level 0 before its pyramid (`glphong.gpu.peeling.Peeling.draw`
   with ``into`` and ``start``, a depth-only pass of the transmissive objects): what lies behind the glass, each layer
   seen once (docs/transmission.md, "With blended surfaces"; the renderer then peels those in front over the frame,
   against the opaque and transmissive depth);
3. the transmissive objects, depth-tested against the opaque depth and writing it, their radiance programs (the
   define ``GLTF_PBR_TRANSMISSION``) reading the background at their own pixel (transmission_thin.glsl): the nearest
   transmissive surface of a pixel is drawn, and it sees the opaque scene alone (a transmissive surface behind another
   is not seen through it: the glTF Sample Viewer's and Filament's rule, which the twin follows).

``Transmission.method = "host"`` keeps the path before (the image read back, its pyramid made on the host in float32
and every level uploaded, every frame): the reference the GPU path is tested against, bit for bit, and benchmarked
against (benchmarks/transmission_cost.py).  A scene without transmissive objects draws as before, bit for bit (its
programs contain none of this).  Not on a surface that is blended too, nor with multisampling,
per-vertex shading or the uber-shader (a clear error names the option).
"""
import math
from dataclasses import dataclass

import moderngl
import numpy as np

from glphong.definitions.material_base import constant_part
from glphong.gpu.peeling import blended, per_pixel_option
from glphong.gpu.shadows import ShadowMap
from glphong.materials.gltf_transmission import background_levels, gltf_transmission_lod, transmissive
from glphong.shaders.keys import EncodeKey

__all__ = ["TRANSMIT", "TRANSMIT_DEPTH", "transmissive_objects", "drawn_in", "one_sided_transmissive",
           "check_transmission_options", "background_need", "PyramidKey", "Transmission", "TARGET_KEY"]

#: `glphong.gpu.drawing.draw_list`'s selector of the transmissive objects (0 the others, 1 and 2 blended layers)
TRANSMIT = 4
#: the transmissive objects drawn by their peel programs (`glphong.gpu.peeling.blend_key` kind 2): their window depth
#: alone, where the background's peel of the blended layers starts (`glphong.gpu.peeling.Peeling.draw`'s ``start``)
TRANSMIT_DEPTH = TRANSMIT | 2
#: the renderer's target key of its `Transmission` (released and counted with the peel's, `glphong.gpu.resources`)
TARGET_KEY = ("peeling", "transmission")


def transmissive_objects(scene):
    """Indices of the scene's transmissive objects (list of int)."""
    return [i for i, obj in enumerate(scene.objects) if transmissive(obj.material)]


def drawn_in(obj, blend, output):
    """Whether ``draw_list`` draws ``obj`` with selector ``blend`` for ``output``: a transmissive object only with
    `TRANSMIT` (or `TRANSMIT_DEPTH`) in a radiance draw (and as an opaque one in every other output: the G-buffer, the
    matte)."""
    if blend & TRANSMIT:
        return transmissive(obj.material)
    if blended(obj) != bool(blend):
        return False
    return bool(blend) or output != "radiance" or not transmissive(obj.material)


def one_sided_transmissive(material):
    """Whether ``material`` is transmissive and one-sided (glTF's ``doubleSided: false``): its back faces are culled in
    the transmission pass, as a blended one's (`glphong.gpu.drawing`), and so in the G-buffer the radiance's twin
    reads."""
    return transmissive(material) and not material.two_sided


def check_transmission_options(renderer, scene):
    """ValueError naming the option where ``renderer`` cannot draw the transmissive objects of ``scene`` (every kind of
    light is transmitted, an extended one through its weighted directions behind the surface,
    `glphong.shaders.generated`)."""
    chosen = transmissive_objects(scene)
    if not chosen:
        return
    name = scene.objects[chosen[0]].name
    used = scene.objects[chosen[0]].material.extensions()
    named = " and ".join(f"KHR_materials_{e}" for e in ("transmission", "diffuse_transmission") if e in used)
    both = [scene.objects[i] for i in chosen if blended(scene.objects[i])]
    if both:  # blended objects beside them are drawn (Transmission.draw's peel); one surface cannot be both
        raise ValueError(f"object {both[0].name!r} is transmissive and blended (alpha_blend, glTF alphaMode BLEND): "
                         "glphong draws a surface either through the transmission pass or as a blended layer, not "
                         "both; give it alpha_blend=None (the glTF Sample Viewer draws it as transmissive)")
    wrong = per_pixel_option(renderer)
    if wrong:
        raise ValueError(f"object {name!r} is transmissive ({named}), which is drawn over the "
                         f"opaque scene with per-pixel, specialised programs and one sample a pixel; this renderer "
                         f"has {wrong[0]}: use {wrong[1]}")


def background_need(scene, width):
    """What the transmission pass of a frame of ``scene`` reads of the background, ``width`` [px] its width: 'none'
    (no drawn program reads it: KHR_materials_diffuse_transmission alone, or no transmissive object), 'texel' (every
    surface of KHR_materials_transmission reads the texel at its own pixel: thin walls, level of detail 0) or
    'pyramid' (a volume, or a level of detail above 0: its roughness factor, an upper bound of a textured roughness,
    as `gltf_transmission_lod` forms it in float32, whose rule grows with the roughness)."""
    need = "none"
    levels = np.float32(math.log2(width))
    for index in transmissive_objects(scene):
        material = scene.objects[index].material
        used = material.extensions()
        if "transmission" not in used:
            continue
        roughness = np.float32(constant_part(material.roughness))
        if "volume" in used or gltf_transmission_lod(roughness, np.float32(material.ior), levels) > 0:
            return "pyramid"
        need = "texel"
    return need


@dataclass(frozen=True)
class PyramidKey(EncodeKey):
    """Key of the pass that draws one level of the background's pyramid from the level above
    (glsl/transmission_pyramid.glsl): a full-screen pass like the 8-bit encoding's
    (`glphong.shaders.keys.EncodeKey`), with its own fragment stage."""

    def defines(self):
        return []

    def fragment_chunks(self):
        return ("transmission_pyramid",)

    def describe(self):
        return "transmission background pyramid"


class Transmission:
    """The background texture of one renderer (its levels at the internal size), and what copies the opaque image
    into it and draws its pyramid.

    Parameters
    ----------
    mgl : moderngl.Context

    Attributes
    ----------
    method : str
        'gpu' (the default: the background copied and its pyramid drawn on the GPU, only as far as the frame's
        programs read it) or 'host' (the path before: read back, `background_levels` in float32 on the host, every
        level uploaded, every frame; the reference of the tests and benchmarks).
    made : str or None
        What the last frame made: 'none', 'texel' (level 0), 'pyramid' (every level); None before the first.
    blend : tuple or None
        The last frame's peel of the blended surfaces into the background (`glphong.gpu.peeling.Peeling.draw`'s
        ``(layers, cut)``); None where it had none.
    """

    def __init__(self, mgl):
        self._mgl = mgl
        self._texture = None
        self._buffer = None
        self._scratch = None
        self.method = "gpu"
        self.made = None
        self.blend = None

    def _background(self, size, mipmaps):
        """The mipmapped RGBA32F texture of ``size`` (made again where the size changed), filtered through its
        levels where ``mipmaps`` (else its level 0 alone is ever looked up)."""
        if self._texture is None or self._texture.size != size:
            self._release_targets()
            self._texture = self._mgl.texture(size, 4, dtype="f4")
            self._texture.build_mipmaps()  # allocates every level; each is written before it is read
            self._texture.repeat_x = self._texture.repeat_y = False
            self._buffer = self._mgl.buffer(reserve=16 * size[0] * size[1])
        flt = (moderngl.LINEAR_MIPMAP_LINEAR if mipmaps else moderngl.LINEAR, moderngl.LINEAR)
        if self._texture.filter != flt:
            self._texture.filter = flt
        return self._texture

    def _host_levels(self, target, size, composited=False):
        """The path before: the opaque image (``composited``: level 0, the blended surfaces over it) read back, its
        float32 pyramid uploaded level by level."""
        opaque = np.empty((size[1], size[0], 4), np.float32)
        texture = self._background(size, True)
        if composited:
            texture.read_into(opaque, level=0)
        else:
            target.read_into(opaque, components=4, attachment=0, dtype="f4")
        for k, level in enumerate(background_levels(opaque, np.float32)):
            texture.write(np.ascontiguousarray(level, np.float32), level=k)
        return texture

    def _gpu_levels(self, target, size, pyramid, program, fullscreen, composited=False):
        """The opaque image copied into level 0 through the pixel buffer (GL to GL; ``composited``: level 0 holds the
        blended surfaces over it already) and, with ``pyramid``, each level ``k + 1`` drawn from level ``k``
        (glsl/transmission_pyramid.glsl) into a scratch target and copied in."""
        texture = self._background(size, pyramid)
        if not composited:
            target.read_into(self._buffer, components=4, attachment=0, dtype="f4")
            texture.write(self._buffer, level=0)
        if not pyramid:
            return texture
        first = (max(size[0] // 2, 1), max(size[1] // 2, 1))
        if self._scratch is None or self._scratch.size != first:
            if self._scratch is not None:
                self._release_scratch()
            color = self._mgl.texture(first, 4, dtype="f4")
            color.filter = (moderngl.NEAREST, moderngl.NEAREST)
            self._scratch = self._mgl.framebuffer([color])
        self._scratch.use()
        try:
            texture.use(location=0)
            vertex_array = fullscreen(program)
            width, height, k = size[0], size[1], 0
            while width > 1 or height > 1:
                width, height = max(width // 2, 1), max(height // 2, 1)
                self._scratch.viewport = (0, 0, width, height)
                program.bind({"u_background": 0, "u_level": k})
                vertex_array.render(moderngl.TRIANGLES, vertices=3)
                self._scratch.read_into(self._buffer, viewport=(0, 0, width, height), components=4, dtype="f4")
                k += 1
                texture.write(self._buffer, level=k)
        finally:  # the scratch target never stays bound (binding a released one is GL_INVALID_OPERATION)
            target.use()
        return texture

    def _composite(self, target, size, mipmaps, peel):
        """Level 0 of the background: ``target``'s opaque image copied in, and the blended layers behind the nearest
        transmissive surface (all where none covers the pixel) and in front of its opaque depth composited over it
        there (``peel(target, into)``, `glphong.gpu.peeling.Peeling.draw` with its ``start``)."""
        texture = self._background(size, mipmaps)
        target.read_into(self._buffer, components=4, attachment=0, dtype="f4")
        texture.write(self._buffer, level=0)
        self.blend = peel(target, texture)
        target.use()

    def draw(self, target, size, draw, need="pyramid", programs=None, fullscreen=None, peel=None):
        """Make the background of ``target``'s opaque image (its first attachment, drawn) as far as ``need`` asks, and
        draw the transmissive objects over it.

        Parameters
        ----------
        target : moderngl.Framebuffer
            The radiance draw's framebuffer (single-sampled), bound.
        size : (int, int)
            Its size [px].
        draw : callable
            ``draw(values)``: draw the transmissive objects (`TRANSMIT`) with the frame uniforms ``values`` added
            (none where ``need`` is 'none').
        need : str
            `background_need` of the frame: 'none', 'texel' or 'pyramid'.
        programs : glphong.gpu.programs.ProgramCache
            The renderer's programs, of which 'pyramid' takes the `PyramidKey` program; ``fullscreen(program)`` its
            vertex array.
        peel : callable, optional
            Where the scene has blended objects: ``peel(target, into)`` peels their layers behind the transmissive
            surfaces' nearest depth and in front of ``target``'s (the opaque one) and composites them over the
            texture ``into`` (`glphong.gpu.peeling.Peeling.draw` with ``start``), returning its ``(layers, cut)``
            (kept in `blend`); the background is then that composite (not made where ``need`` is 'none' and the
            method 'gpu': nothing reads it).

        Returns
        -------
        str
            What was made (`made`).
        """
        self.blend = None
        composited = peel is not None and (self.method == "host" or need != "none")
        if composited:
            self._composite(target, size, self.method == "host" or need == "pyramid", peel)
        if self.method == "host":
            texture, self.made = self._host_levels(target, size, composited), "pyramid"
        elif need == "none":
            texture, self.made = None, "none"
        else:
            pyramid = need == "pyramid"
            program = programs.get(PyramidKey()) if pyramid else None
            texture, self.made = self._gpu_levels(target, size, pyramid, program, fullscreen, composited), need
        target.use()
        draw({} if texture is None else {"u_transmission_background": ShadowMap(texture, None),
                                         "u_transmission_levels": float(math.log2(size[0]))})
        return self.made

    def gl_object_count(self):
        """GL objects held: the background texture and its pixel buffer, the scratch target and its texture."""
        return 2 * int(self._texture is not None) + 2 * int(self._scratch is not None)

    def _release_scratch(self):
        for texture in self._scratch.color_attachments:
            texture.release()
        self._scratch.release()
        self._scratch = None

    def _release_targets(self):
        if self._texture is not None:
            self._texture.release()
            self._buffer.release()
        if self._scratch is not None:
            self._release_scratch()
        self._texture = self._buffer = None

    def release(self):
        """Release the background texture, its pixel buffer and the scratch target (context entered)."""
        self._release_targets()
