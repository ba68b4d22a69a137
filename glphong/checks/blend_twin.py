"""The float64 twin of blended surfaces (`glphong.AlphaBlend`, glTF alphaMode BLEND): every ray hit along each pixel's
sample rays, sorted in float64, each shaded by the shading twin and composited "over" (docs/design.md section 16).

For each sample ray of `glphong.checks.frame_twin.SAMPLE_OFFSETS` (the pixel centre and the four points the rasteriser
may snap it to) the ray is cast against every opaque and blended triangle (`glphong.checks.frame_twin`'s caster, both
faces); the hits of a blended object nearer than the nearest opaque hit are its layers, in increasing ``t``; a back
face (not `front`) of a one-sided blended material is not a layer (culled, as glTF's ``doubleSided: false``); a hit
of the same object at the same point as the previous one (``t2 - t1 <= SAME_POINT t1``: a shared edge) is that layer
again; with a start surface (``start``: the background of a transmissive one, `glphong.checks.transmission_blend`),
the hits at or before it are no layers either.  Layer ``k`` of every sample becomes a G-buffer of its own (the hit
point, the interpolated normal flipped on back faces of two-sided materials, the uv and vertex colour, the triangle's
own normal) shaded by `glphong.checks.verify.twin_and_band`, the same twin and band as an opaque surface's.  Composite,
front to back with ``a_k`` the material's alpha as float32 holds it:

    C = sum_k (prod_{j<k} (1 - a_j)) a_k L_k + prod_k (1 - a_k) L_opaque,

``L_opaque`` the twin of the GPU's opaque G-buffer (0 where none): the glTF specification's "over", back to front,
reassociated.  The band: the composite of the layers' lows and of their highs (the weights are positive), the least
and the greatest over the samples, widened by ``8 (n + 1) eps`` of the composite of the largest magnitudes (the blend
unit's float32 products and sums, ``n`` the layers).

A pixel is *unchecked* (reported, band infinite) where its samples do not see the same layers (a silhouette, the line
where two blended surfaces cross), or where two consecutive layers, or the last layer and the opaque surface, lie
within the depth buffer's resolution of each other (`glphong.checks.frame_twin.depth_tie`: their order is not
determined in float32).  The renderer's layer cap: the twin composites the nearest ``blend_layers`` as the GPU does;
`BlendTwin.cut` marks the pixels with more, and `BlendTwin.cap_error` the cut composite's relative error against the
full one.
"""
from dataclasses import dataclass

import numpy as np

from glphong.checks.frame_twin import (SAME_POINT, SAMPLE_OFFSETS, PixelHits, _fill, _hits, _normal, _per_vertex,
                                       _world_triangles, culled_back_faces, depth_tie)
from glphong.checks.tolerances import BAND
from glphong.definitions.surface import surface_texture_band
from glphong.gpu.frame import GBuffer
from glphong.gpu.matte import drawn_objects
from glphong.gpu.peeling import blended_objects
from glphong.shaders.binding import binding
from glphong.twin.band import EPS
from glphong.twin.functions import safe_normalize

__all__ = ["BlendTwin", "BlendHits", "blend_hits", "blend_twin", "composite"]


@dataclass(frozen=True)
class BlendHits:
    """The blended layers of every sample ray.

    Attributes
    ----------
    layers : list of glphong.checks.frame_twin.PixelHits
        Layer ``k`` (0 the nearest) of every sample, arrays (S, H, W); ``object_index`` -1 where a ray has fewer layers.
    count : (S, H, W) int64 ndarray
        The layers of each sample ray.
    face : list of (S, H, W, 3) float64 ndarray
        Per layer, the hit triangle's own unit normal (either orientation).
    ambiguous : (H, W) bool ndarray
        The pixels whose layers the samples do not agree on, or whose order float32 cannot determine (module).
    """

    layers: list
    count: np.ndarray
    face: list
    ambiguous: np.ndarray


def blend_hits(scene, width, height, offsets=SAMPLE_OFFSETS, start=None):
    """Cast every sample ray of every pixel against the opaque and blended objects (module): `BlendHits`.

    ``start``, optional: ``(t, depth)``, each (S, H, W) float64 (inf where none), the ray parameter and view depth [m]
    of a surface not in ``scene`` (a transmissive one, `glphong.checks.transmission_blend`) that the layers of a ray
    start behind where it lies in front of the opaque hit: a blended hit at or before it is no layer, and a ray is
    tied where a blended hit, or the opaque one, lies within the depth buffer's resolution of it."""
    camera = scene.camera
    opaque = drawn_objects(scene, lambda obj: f"object {obj.name!r} has a textured alpha mask: verify of blended "
                                              "materials does not follow textured alpha masks yet")
    drawn = sorted(opaque + blended_objects(scene))
    corners, owner, local = _world_triangles(scene, drawn)
    (ray, t, tri, u, v, det, depth), (o, d) = _hits(camera, width, height, offsets, corners)
    order = np.lexsort((t, ray))
    ray, t, tri, u, v, det, depth = (a[order] for a in (ray, t, tri, u, v, det, depth))
    objects = scene.objects
    is_blend = np.array([obj.material.alpha_blend is not None for obj in objects] + [False])
    two_sided = np.array([obj.material.two_sided for obj in objects] + [False])
    mirrored = np.array([obj.mirrored for obj in objects] + [False])
    obj = owner[tri]
    front = (det > 0.0) != mirrored[obj]
    keep = ~is_blend[obj] | front | two_sided[obj]  # a one-sided blended material's back faces are culled
    keep &= ~culled_back_faces(scene, obj, det)  # and a one-sided transmissive one's
    same = np.r_[False, (ray[1:] == ray[:-1]) & (obj[1:] == obj[:-1]) & (t[1:] - t[:-1] <= SAME_POINT * t[:-1])]
    keep &= ~same
    ray, t, tri, u, v, det, depth, obj = (a[keep] for a in (ray, t, tri, u, v, det, depth, obj))
    rays = len(offsets) * width * height
    opaque_t = np.full(rays, np.inf)
    opaque_depth = np.full(rays, np.inf)
    hit_opaque = ~is_blend[obj]
    np.minimum.at(opaque_t, ray[hit_opaque], t[hit_opaque])
    np.minimum.at(opaque_depth, ray[hit_opaque], depth[hit_opaque])
    layer = is_blend[obj] & (t < opaque_t[ray])
    tied = np.zeros(rays, bool)
    if start is not None:
        layer &= _behind_start(camera, start, ray, t, depth, layer, opaque_t, opaque_depth, tied)
    ray, t, tri, u, v, det, depth, obj = (a[layer] for a in (ray, t, tri, u, v, det, depth, obj))
    run_start = np.r_[True, ray[1:] != ray[:-1]] if len(ray) else np.zeros(0, bool)  # each ray's first layer
    first = np.maximum.accumulate(np.where(run_start, np.arange(len(ray)), 0)) if len(ray) else np.zeros(0, np.int64)
    rank = np.arange(len(ray)) - first
    count = np.bincount(ray, minlength=rays)
    # order undetermined in float32: consecutive layers, or the last layer and the opaque surface, tie in depth
    pair = ~run_start
    np.logical_or.at(tied, ray[pair], depth_tie(camera, depth[np.flatnonzero(pair) - 1], depth[pair]))  # any pair
    last = np.r_[ray[1:] != ray[:-1], True] if len(ray) else np.zeros(0, bool)
    finite = last & np.isfinite(opaque_depth[ray])
    tied[ray[finite]] |= depth_tie(camera, depth[finite], opaque_depth[ray[finite]])
    samples = len(offsets)
    shape = (samples, height, width)
    most = int(count.max()) if rays else 0
    signature = np.full((rays, max(most, 1)), -1, np.int64)
    signature[ray, rank] = 2 * obj + front_of(det, mirrored[obj])
    signature = signature.reshape(samples, height * width, -1)
    ambiguous = np.any(signature != signature[:1], axis=(0, 2)) | tied.reshape(samples, -1).any(axis=0)
    layers, faces = [], []
    for k in range(most):
        at = rank == k
        hits = _fill(shape, o, d, ray[at], t[at], u[at], v[at], det[at], tri[at], owner, local, mirrored)
        none = np.zeros(shape, np.int64) - 1
        layers.append(PixelHits(np.array(offsets), *hits, none, none, np.zeros(shape + (3,)), np.zeros(shape),
                                np.zeros(shape + (3,)), np.zeros(shape, bool)))
        face = np.zeros((rays, 3))
        c = corners[tri[at]]
        face[ray[at]] = safe_normalize(np.cross(c[:, 1] - c[:, 0], c[:, 2] - c[:, 0]))[1]
        faces.append(face.reshape(shape + (3,)))
    return BlendHits(layers, count.reshape(shape), faces, ambiguous.reshape(height, width))


def _behind_start(camera, start, ray, t, depth, layer, opaque_t, opaque_depth, tied):
    """`blend_hits`'s ``start``: (M,) bool, whether each hit lies behind the start surface of its ray (or the ray's
    start surface is none, or not in front of the opaque hit); marks ``tied`` (rays,) where a layer, or the opaque
    surface under a layer, ties with the start surface in depth."""
    start_t, start_depth = (np.reshape(a, -1) for a in start)
    ahead = start_t < opaque_t  # (the GPU's depth-only pass of the start surface is tested against the opaque depth)
    near = np.flatnonzero(layer & ahead[ray])
    z = start_depth[ray[near]]
    tied[ray[near[depth_tie(camera, np.minimum(depth[near], z), np.maximum(depth[near], z))]]] = True
    both = np.flatnonzero(np.isfinite(start_depth) & np.isfinite(opaque_depth) & (np.bincount(
        ray[layer], minlength=len(tied)) > 0))
    a, b = start_depth[both], opaque_depth[both]
    tied[both[depth_tie(camera, np.minimum(a, b), np.maximum(a, b))]] = True
    return ~ahead[ray] | (t > start_t[ray])


def front_of(det, mirrored):
    """Whether a hit is on its object's counter-clockwise side, as 0 or 1 (int64)."""
    return ((det > 0.0) != mirrored).astype(np.int64)


def _layer_gbuffer(scene, hits, face, s):
    """Sample ``s`` of one layer's hits as the `GBuffer` the shading twin reads (float64 planes)."""
    mask = hits.object_index[s] >= 0
    bound = binding(scene)
    keys = {i: bound.program_key(scene.objects[i]) for i in np.unique(hits.object_index[s][mask])}
    for i, key in keys.items():
        obj = scene.objects[i]
        unsupported = [name for name, wrong in (("textured parameters", bool(key.textured_inputs)),
                                               ("a normal map", key.normal_map),
                                               ("tangents", key.has_tangent)) if wrong]
        if unsupported:
            raise ValueError(f"object {obj.name!r} is blended and its material has {', '.join(unsupported)}: verify "
                             "of blended materials does not follow them yet (the ray cast has no texture footprint "
                             "or tangent frame)")
    planes = {"face": face[s]}
    if any(key.has_uv for key in keys.values()):
        planes["uv"] = _per_vertex(scene, hits, 2, lambda o: o.mesh.uvs if o.mesh.uvs is not None
                                   else np.zeros((len(o.mesh.positions), 2)))[s]
    if any(key.has_color for key in keys.values()):
        planes["color"] = _per_vertex(scene, hits, 3, lambda o: o.mesh.colors if o.mesh.colors is not None
                                      else np.ones((len(o.mesh.positions), 3)))[s]
    return GBuffer(position=hits.position[s], normal=_normal(scene, hits)[s], object_index=hits.object_index[s],
                   mask=mask, **planes)


def composite(alphas, values, behind):
    """Front-to-back "over": ``sum_k (prod_{j<k} (1 - a_j)) a_k L_k + prod_k (1 - a_k) L_behind``.

    Parameters
    ----------
    alphas : list of (...) float64 ndarray
        Each layer's alpha (0 where the layer is absent).
    values : list of (..., 3) float64 ndarray
        Each layer's radiance.
    behind : (..., 3) float64 ndarray
        What lies behind the layers.

    Returns
    -------
    colour : (..., 3) float64 ndarray
    alpha : (...) float64 ndarray
        ``1 - prod_k (1 - a_k)``.
    """
    colour = np.zeros(np.shape(behind))
    cover = np.zeros(np.shape(behind)[:-1])
    for a, value in zip(alphas, values):
        colour = colour + ((1.0 - cover) * a)[..., None] * value
        cover = cover + (1.0 - cover) * a
    return colour + (1.0 - cover)[..., None] * behind, cover


@dataclass(frozen=True)
class BlendTwin:
    """The twin of a frame with blended surfaces.

    Attributes
    ----------
    reference, low, high : (H, W, 3) float64 ndarray
        The composite at the pixel centre and its band (infinite where `unchecked`).
    coverage : (H, W) float64 ndarray
        The composite's alpha at the pixel centre (1 where an opaque surface lies behind the layers).
    unchecked : (H, W) bool ndarray
        Pixels whose layers are not determined (module).
    layers : (H, W) int64 ndarray
        The layers of the centre ray.
    cut : (H, W) bool ndarray
        Pixels with more layers than the renderer's ``blend_layers``.
    cap_error : (H, W, 3) float64 ndarray
        The capped composite's relative error against the whole one, 0 where not `cut`.
    shadow_band : (H, W) bool ndarray
        Pixels where a layer's shadow test may decide either way.
    """

    reference: np.ndarray
    low: np.ndarray
    high: np.ndarray
    coverage: np.ndarray
    unchecked: np.ndarray
    layers: np.ndarray
    cut: np.ndarray
    cap_error: np.ndarray
    shadow_band: np.ndarray


def _alphas(scene, layer, band):
    """``(alpha, spread)`` of one layer's hits, each (S, H, W): the material's alpha as the GPU reads it (the float32
    constant, times the red texel value bilinearly filtered at the hit's uv where it is textured) and how far the
    GPU's filtered value may lie from it (`glphong.definitions.surface.surface_texture_band`; 0 for a constant)."""
    index = layer.object_index
    alpha, spread = np.zeros(index.shape), np.zeros(index.shape)
    for i in np.unique(index[index >= 0]):
        obj, hit = scene.objects[i], index == i
        blend = obj.material.alpha_blend
        scale = float(np.float32(blend.alpha.scale if blend.textured else blend.alpha))
        alpha[hit] = scale
        if blend.textured:
            image = blend.alpha.texture
            if image.filter != "bilinear" and len(image.levels) > 1:
                raise ValueError(f"object {obj.name!r} is blended with a mipmapped alpha texture (filter "
                                 f"{image.filter!r}): verify of blended materials follows bilinear alpha textures "
                                 "only (the ray cast has no texture footprint for the level of detail)")
            uv = _per_vertex(scene, layer, 2, lambda o: o.mesh.uvs)[hit]
            value, low, high = surface_texture_band(image, uv, np.zeros(len(uv)), band)
            alpha[hit] = scale * value[:, 0]
            spread[hit] = scale * np.maximum(value[:, 0] - low[:, 0], high[:, 0] - value[:, 0]) + 2.0 * EPS
    return alpha, spread


def blend_twin(scene, size, cap, opaque, shade, band=BAND, start=None):
    """The twin of a frame of ``scene`` with blended surfaces (module).

    Parameters
    ----------
    scene : glphong.Scene
    size : (int, int)
        ``(W, H)`` [px].
    cap : int
        The renderer's ``blend_layers``.
    opaque : tuple of (H, W, 3) ndarray and (H, W) bool ndarray
        ``(reference, low, high, covered)`` of the opaque surfaces (the twin of the GPU's opaque G-buffer).
    shade : callable
        ``shade(gbuffer)`` -> ``(reference, low, high, shadow_band)`` (`glphong.checks.verify.twin_and_band`).
    band : glphong.checks.tolerances.BandConstants
        For a textured alpha's filter error.
    start : tuple, optional
        `blend_hits`'s: the layers behind a transmissive surface alone.

    Returns
    -------
    BlendTwin
    """
    width, height = size
    hits = blend_hits(scene, width, height, start=start)
    samples = len(hits.count)
    values = {"reference": [], "low": [], "high": []}
    alphas, spreads = [], []
    shadow_band = np.zeros((height, width), bool)
    for layer, face in zip(hits.layers, hits.face):
        per = {name: np.zeros((samples, height, width, 3)) for name in values}
        for s in range(samples):
            gbuffer = _layer_gbuffer(scene, layer, face, s)
            if gbuffer.mask.any():
                per["reference"][s], per["low"][s], per["high"][s], uncertain = shade(gbuffer)
                shadow_band |= uncertain & gbuffer.mask
        for name in values:
            values[name].append(per[name])
        alpha, spread = _alphas(scene, layer, band)
        alphas.append(alpha)
        spreads.append(spread)
    ref_op, low_op, high_op, covered = (np.broadcast_to(a, (samples,) + a.shape) for a in opaque)
    capped = {name: composite(alphas[:cap], values[name][:cap], behind)[0]
              for name, behind in (("reference", ref_op), ("low", low_op), ("high", high_op))}
    magnitude = composite(alphas[:cap], [np.maximum(np.abs(lo), np.abs(hi)) for lo, hi in
                                         zip(values["low"][:cap], values["high"][:cap])],
                          np.maximum(np.abs(low_op), np.abs(high_op)))[0]
    layers = np.minimum(hits.count, cap)
    widen = 8.0 * (layers + 1)[..., None] * EPS * magnitude
    if any(s.any() for s in spreads[:cap]):  # a textured alpha's filter error: C is multilinear in the alphas, so
        # |dC| <= sum_k w_k da_k (|L_k| + |C behind k|) + (sum_k da_k)^2 max|C|, w_k with the alphas at their lowest
        mags = [np.maximum(np.abs(lo), np.abs(hi)) for lo, hi in zip(values["low"][:cap], values["high"][:cap])]
        behind_op = np.maximum(np.abs(low_op), np.abs(high_op))
        weight = np.ones(hits.count.shape)
        for k, (a, da) in enumerate(zip(alphas[:cap], spreads[:cap])):
            behind = composite(alphas[k + 1:cap], mags[k + 1:], behind_op)[0]
            widen = widen + (weight * da)[..., None] * (mags[k] + behind)
            weight = weight * (1.0 - np.maximum(a - da, 0.0))
        widen = widen + (sum(spreads[:cap]) ** 2)[..., None] * np.maximum(magnitude, behind_op)
    low = np.min(capped["low"] - widen, axis=0)
    high = np.max(capped["high"] + widen, axis=0)
    unchecked = hits.ambiguous
    low[unchecked], high[unchecked] = -np.inf, np.inf
    reference, cover = composite([a[0] for a in alphas[:cap]], [v[0] for v in values["reference"][:cap]], ref_op[0])
    whole = composite([a[0] for a in alphas], [v[0] for v in values["reference"]], ref_op[0])[0]
    cut = hits.count[0] > cap
    with np.errstate(divide="ignore", invalid="ignore"):
        cap_error = np.where(cut[..., None], np.abs(reference - whole) / np.abs(whole), 0.0)
    return BlendTwin(reference=reference, low=low, high=high, coverage=np.where(covered[0], 1.0, cover),
                     unchecked=unchecked, layers=hits.count[0], cut=cut, cap_error=cap_error, shadow_band=shadow_band)
