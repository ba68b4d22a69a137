"""The twin of a frame with transmissive and blended surfaces (docs/transmission.md, "With blended surfaces"), in the
order the GPU draws it (`glphong.gpu.renderer.Renderer._draw`):

1. the background: the blended layers composited over the scene without its transmissive objects
   (`glphong.checks.blend_twin.blend_twin` of `glphong.checks.transmission_twin.opaque_scene`), on each sample ray
   only those behind the nearest hit of a transmissive object where it lies in front of the opaque hit (`glass_start`,
   the GPU's depth-only pass), all of them elsewhere, each shaded in the whole scene (its shadow maps' casters, the
   transmissive objects included: `glphong.checks.transmission_twin.in_scene`): what the thin walls see
   (`layers_behind`, given to `glphong.checks.transmission_twin.transmission_check`);
2. the frame twin of the whole scene's G-buffer (its nearest opaque or transmissive surface) plus what the
   transmissive surfaces transmit of that background, and its band (the shading band plus the transmission's);
3. the blended layers nearer than that surface (a transmissive one occludes those behind it, which the background
   holds) composited over it (`frame_blend_twin`): the blend twin's composite and band.  Each layer is so counted
   once, behind the glass or in front of it.

A pixel is unchecked where the final blend twin leaves it so, or where a transmissive surface reads a background
pixel left unchecked (the low end of its band is not finite there).  The cap: the GPU peels twice, and its
``blend_cut`` is either peel's cut; so is the twin's (the background's where the frame's surfaces read it:
`background_need`).
"""
import dataclasses

import numpy as np

from glphong.checks.blend_twin import blend_twin
from glphong.checks.frame_twin import SAMPLE_OFFSETS, _hits, _world_triangles, culled_back_faces
from glphong.checks.transmission_twin import in_scene
from glphong.gpu.transmission import background_need, transmissive_objects

__all__ = ["glass_start", "layers_behind", "frame_blend_twin"]


def glass_start(scene, width, height):
    """The nearest hit of the transmissive objects of ``scene`` on every sample ray of a ``width`` x ``height`` frame
    (`glphong.checks.frame_twin.SAMPLE_OFFSETS`; a one-sided material's front faces only, as its transmissive draw
    culls the back ones, `glphong.gpu.drawing`): ``(t, depth)``, each (S, H, W) float64, the ray parameter and the
    view depth [m], inf where none (`glphong.checks.blend_twin.blend_hits`'s ``start``)."""
    corners, owner, _ = _world_triangles(scene, transmissive_objects(scene))
    (ray, t, tri, _, _, det, depth), _ = _hits(scene.camera, width, height, SAMPLE_OFFSETS, corners)
    keep = ~culled_back_faces(scene, owner[tri], det)
    ray, t, depth = ray[keep], t[keep], depth[keep]
    shape = (len(SAMPLE_OFFSETS), height, width)
    nearest_t, nearest_depth = np.full(shape, np.inf), np.full(shape, np.inf)
    np.minimum.at(nearest_t.reshape(-1), ray, t)
    np.minimum.at(nearest_depth.reshape(-1), ray, depth)
    return nearest_t, nearest_depth


def layers_behind(scene, renderer, shade, band):
    """``transmission_check``'s ``blend``: ``blend(opaque, (reference, low, high, covered))`` -> the `BlendTwin` of
    the blended layers of the scene ``opaque`` (``scene`` without its transmissive objects) behind the transmissive
    surfaces of ``scene`` (`glass_start`) over that twin, each layer shaded in ``scene`` (``shade(scene,
    in_scene(scene, gbuffer))`` -> `glphong.checks.verify.twin_and_band`'s four arrays): the GPU's background peel
    draws them with the whole scene's shadow maps, whose casters include the transmissive objects."""
    start = glass_start(scene, *renderer._size)
    return lambda opaque, under: blend_twin(opaque, renderer._size, renderer.blend_layers, under,
                                            lambda gbuffer: shade(scene, in_scene(scene, gbuffer)), band, start)


def frame_blend_twin(scene, renderer, frame, shade, band, transmission=None):
    """The `glphong.checks.blend_twin.BlendTwin` of the blended layers of ``scene`` over ``frame``.

    Parameters
    ----------
    scene : glphong.Scene
    renderer : glphong.Renderer
        Its size and ``blend_layers``.
    frame : tuple
        ``(reference, low, high, covered)``, (H, W, 3) float64 ndarrays and (H, W) bool: the twin of the opaque (and
        transmissive) surfaces.
    shade : callable
        ``shade(gbuffer)`` -> ``(reference, low, high, shadow_band)``.
    band : glphong.checks.tolerances.BandConstants
    transmission : glphong.checks.transmission_twin.TransmissionTwin, optional
        What ``frame`` holds of the transmissive surfaces (added already), its ``background_blend`` the background's
        layers; None: the scene has none (`blend_twin` alone).

    Returns
    -------
    BlendTwin
    """
    if transmission is None:
        return blend_twin(scene, renderer._size, renderer.blend_layers, frame, shade, band)
    reference, low, high, covered = frame
    # a transmissive pixel whose background band is not finite (an unchecked background pixel read) is unchecked;
    # its finite value stands in for the band so that a layer of alpha 1 over it gives no 0 * inf
    hidden = transmission.pixels & np.any(~np.isfinite(transmission.low) | np.isnan(transmission.high), axis=-1)
    # a band open above (the lights behind a lobe of roughness 0: infinite high) stays open above, likewise
    open_above = transmission.pixels & np.any(np.isposinf(high), axis=-1)
    low = np.where(hidden[..., None], reference, low)
    high = np.where((hidden | open_above)[..., None], reference, high)
    over = blend_twin(scene, renderer._size, renderer.blend_layers, (reference, low, high, covered), shade, band)
    behind = transmission.background_blend
    unchecked = over.unchecked | hidden
    low, high = over.low.copy(), over.high.copy()
    low[unchecked], high[unchecked | open_above] = -np.inf, np.inf
    read = background_need(scene, renderer._size[0]) != "none"  # the GPU peels the background only where read
    return dataclasses.replace(over, low=low, high=high, unchecked=unchecked,
                               cut=over.cut | (behind.cut if read else False),
                               layers=np.maximum(over.layers, behind.layers if read else 0),
                               shadow_band=over.shadow_band | behind.shadow_band)
