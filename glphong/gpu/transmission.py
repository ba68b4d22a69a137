"""Transmissive surfaces (glTF ``KHR_materials_transmission``, thin walls; `glphong.materials.gltf_transmission`,
docs/transmission.md): the opaque scene first, then the transmissive surfaces seeing it through themselves.

A frame of a scene with transmissive objects draws, into the radiance target:

1. every other object (opaque and alpha-masked), as a frame without them;
2. the background: that image (RGBA32F, the internal size) read back once, its pyramid of 2x2 box means made on the
   host in float32 (`glphong.materials.gltf_transmission.background_levels`) and uploaded as one mipmapped texture
   (GL_LINEAR_MIPMAP_LINEAR, clamped to the edge);
3. the transmissive objects, depth-tested against the opaque depth and writing it, their radiance programs (the
   define ``GLTF_PBR_TRANSMISSION``) reading the background at their own pixel (transmission_thin.glsl): the nearest
   transmissive surface of a pixel is drawn, and it sees the opaque scene alone (a transmissive surface behind another
   is not seen through it: the glTF Sample Viewer's and Filament's rule, which the twin follows).

A scene without transmissive objects draws as before, bit for bit (its programs contain none of this).  Not with
blended materials in the same scene, multisampling, per-vertex shading or the uber-shader (a clear error names the
option).
"""
import math

import moderngl
import numpy as np

from glphong.gpu.peeling import blended, per_pixel_option
from glphong.gpu.shadows import ShadowMap
from glphong.materials.gltf_transmission import background_levels, transmissive

__all__ = ["TRANSMIT", "transmissive_objects", "drawn_in", "check_transmission_options", "Transmission",
           "TARGET_KEY"]

#: `glphong.gpu.drawing.draw_list`'s selector of the transmissive objects (0 the others, 1 and 2 blended layers)
TRANSMIT = 4
#: the renderer's target key of its `Transmission` (released and counted with the peel's, `glphong.gpu.resources`)
TARGET_KEY = ("peeling", "transmission")


def transmissive_objects(scene):
    """Indices of the scene's transmissive objects (list of int)."""
    return [i for i, obj in enumerate(scene.objects) if transmissive(obj.material)]


def drawn_in(obj, blend, output):
    """Whether ``draw_list`` draws ``obj`` with selector ``blend`` for ``output``: a transmissive object only with
    `TRANSMIT` in a radiance draw (and as an opaque one in every other output: the G-buffer, the matte)."""
    if blend == TRANSMIT:
        return transmissive(obj.material)
    if blended(obj) != bool(blend):
        return False
    return bool(blend) or output != "radiance" or not transmissive(obj.material)


def check_transmission_options(renderer, scene, radiance=True):
    """ValueError naming the option where ``renderer`` cannot draw the transmissive objects of ``scene`` (``radiance``:
    the frame draws the radiance, which needs a light)."""
    chosen = transmissive_objects(scene)
    if not chosen:
        return
    name = scene.objects[chosen[0]].name
    used = scene.objects[chosen[0]].material.extensions()
    named = " and ".join(f"KHR_materials_{e}" for e in ("transmission", "diffuse_transmission") if e in used)
    if any(blended(obj) for obj in scene.objects):
        raise ValueError(f"object {name!r} is transmissive ({named}) and the scene has blended "
                         "materials (alpha_blend, glTF alphaMode BLEND): glphong does not draw both in one frame yet")
    extended = [light for light in scene.lights if light.extent == "extended"]
    if radiance and extended:
        raise ValueError(f"object {name!r} is transmissive ({named}) and the scene has a "
                         f"{type(extended[0]).__name__}: glphong transmits point, spot and directional lights through "
                         "a surface, not area or environment lights yet (their light behind the surface would be "
                         "left out); light the scene with punctual lights, or give the material transmission=0")
    if radiance and not scene.lights:
        raise ValueError(f"object {name!r} is transmissive ({named}) and the scene has no light: "
                         "its program reads the view only where a light is lit; add a light")
    wrong = per_pixel_option(renderer)
    if wrong:
        raise ValueError(f"object {name!r} is transmissive ({named}), which is drawn over the "
                         f"opaque scene with per-pixel, specialised programs and one sample a pixel; this renderer "
                         f"has {wrong[0]}: use {wrong[1]}")


class Transmission:
    """The background texture of one renderer (its levels at the internal size).

    Parameters
    ----------
    mgl : moderngl.Context
    """

    def __init__(self, mgl):
        self._mgl = mgl
        self._texture = None

    def _background(self, levels):
        """The mipmapped texture holding ``levels`` (GL row order), made again where the size changed."""
        size = (levels[0].shape[1], levels[0].shape[0])
        if self._texture is None or self._texture.size != size:
            if self._texture is not None:
                self._texture.release()
            self._texture = self._mgl.texture(size, 4, dtype="f4")
            self._texture.build_mipmaps()  # allocates every level; each is written below
            self._texture.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
            self._texture.repeat_x = self._texture.repeat_y = False
        for k, level in enumerate(levels):
            self._texture.write(np.ascontiguousarray(level, np.float32), level=k)
        return self._texture

    def draw(self, target, size, draw):
        """Read the opaque image of ``target`` (its first attachment, drawn), make the background, and draw the
        transmissive objects over it.

        Parameters
        ----------
        target : moderngl.Framebuffer
            The radiance draw's framebuffer (single-sampled), bound.
        size : (int, int)
            Its size [px].
        draw : callable
            ``draw(values)``: draw the transmissive objects (`TRANSMIT`) with the frame uniforms ``values`` added.

        Returns
        -------
        (H, W, 4) float32 ndarray
            The background's level 0, GL row order (row 0 at the bottom).
        """
        opaque = np.empty((size[1], size[0], 4), np.float32)
        target.read_into(opaque, components=4, attachment=0, dtype="f4")
        texture = self._background(background_levels(opaque, np.float32))
        target.use()
        draw({"u_transmission_background": ShadowMap(texture, None),
              "u_transmission_levels": float(math.log2(size[0]))})
        return opaque

    def gl_object_count(self):
        """GL objects held: the background texture."""
        return int(self._texture is not None)

    def release(self):
        """Release the background texture (context entered)."""
        if self._texture is not None:
            self._texture.release()
        self._texture = None
