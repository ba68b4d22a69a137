"""The float64 twin of transmissive surfaces (glTF ``KHR_materials_transmission``, thin walls;
`glphong.gpu.transmission`, docs/transmission.md).

At each pixel whose nearest surface (the GPU's G-buffer) is transmissive, the twin adds to the surface's reflection
(the shading twin, its diffuse weighted by ``1 - t``) what the surface transmits, transmission_thin.glsl function by
function:

    L_t = gltf_transmission_radiance(...) = gltf_transmission_weight(n.v, c, m, t, ior) * B * keep,
    w = (1 - m) t (1 - max3(F(n.v))) c,  keep = gltf_transmission_layers(n.v, n.v) (the sheen's and the coat's)

(`glphong.materials.gltf_transmission`'s twins compute the value, this module the band).

``B`` from the twin of the background: the scene without its transmissive objects, its G-buffer drawn by the GPU and
shaded by the twin in the whole scene (``shade``: `glphong.checks.verify.twin_and_band`; `in_scene`: the GPU's opaque
pass draws with the whole scene's shadow maps, whose casters include the transmissive objects), which is the opaque
surface the pixel's ray meets next behind the thin wall (it goes straight through).  Roughness 0 (or ior 1): ``B`` is
that surface's radiance at the pixel, exactly.  Roughness ``r > 0``: ``B`` is the trilinear lookup of the background's
pyramid of 2x2 box means (`glphong.materials.gltf_transmission.background_levels`, in float64) at the pixel's centre,
level of detail ``log2(W) r clamp(2 ior - 2, 0, 1)`` (`gltf_transmission_lod`): the GPU's method, whose own error
against the integral of the lobe is measured apart (benchmarks/transmission_rough.py, docs/transmission.md).

The band: ``w`` to ``(5 D + A) eps`` of ``(1 - m) t c`` (the Fresnel's slope in ``n.v`` is at most 5, ``n.v`` to ``D
eps``; the chain's rounding ``A eps``; the specular's interval where textured), times ``keep``'s interval
(`_layers_bounds`), times the background's band: at roughness 0 the pixel's low and high, above 0
the least and the greatest texel of the low and high pyramids that the lookup weights, on the two levels about the
level of detail (and the one below where float32 may round it across an integer).
"""
import dataclasses
from dataclasses import dataclass
from functools import partial
from types import SimpleNamespace

import numpy as np

from glphong.checks.reference import incident_light, safe_normalize, shade_inputs
from glphong.checks.transmission_extended import extended_behind
from glphong.checks.tolerances import BAND
from glphong.checks.transmission_lights import (_attenuation_slack, _bounds, _coat_cosines, _coat_normal, _film,
                                                _layers_bounds, _lights_behind, _one_minus_fresnel, _parameter)
from glphong.definitions.surface import _bilinear
from glphong.gpu.transmission import transmissive_objects
from glphong.materials.gltf_transmission import (background_levels, gltf_transmission_lod,
                                                 gltf_transmission_radiance, gltf_transmission_sample,
                                                 gltf_dispersion_iors, gltf_volume_attenuation, gltf_volume_ray,
                                                 gltf_volume_uv)
from glphong.scene.scene import Scene
from glphong.twin.band import EPS

__all__ = ["TransmissionTwin", "opaque_scene", "in_scene", "transmission_twin", "transmission_check",
           "background_lookup", "background_texel_bounds"]


@dataclass(frozen=True)
class TransmissionTwin:
    """What the twin added for the transmissive surfaces of a frame.

    Attributes
    ----------
    transmitted, low, high : (H, W, 3) float64 ndarray
        ``L_t`` and its band (0 where the nearest surface is not transmissive).
    pixels : (H, W) bool ndarray
        The pixels whose nearest surface is transmissive.
    rough : (H, W) bool ndarray
        Those seen through a filtered lookup (level of detail above 0): the GPU is checked against the twin of the
        method, whose error against the lobe's integral is docs/transmission.md's, not this report's.
    background : (H, W, 3) float64 ndarray
        The twin of the background (the scene without its transmissive objects).
    background_blend : glphong.checks.blend_twin.BlendTwin or None
        Where that scene has blended surfaces: the twin of their composite over it, which is the background
        (`glphong.checks.transmission_blend`).
    shadow_band : (H, W) bool ndarray or None
        Where a light has ``shadows=True``: the transmissive pixels whose background pixel (the same pixel) has a
        shadowing light's visibility uncertain (`glphong.checks.verify.twin_and_band`'s shadow band; the background's
        band holds it between 0 and 1, and the lookups of rough surfaces and volumes read that band too).
    """

    transmitted: np.ndarray
    low: np.ndarray
    high: np.ndarray
    pixels: np.ndarray
    rough: np.ndarray
    background: np.ndarray
    background_blend: object = None
    shadow_band: np.ndarray = None


def opaque_scene(scene):
    """The scene without its transmissive objects (the same camera, lights and ambient light; the other objects in
    order, with their poses, names, ids and categories)."""
    out = Scene(scene.camera, scene.lights, scene.ambient)
    chosen = set(transmissive_objects(scene))
    for i, obj in enumerate(scene.objects):
        if i not in chosen:
            out.add(obj.mesh, obj.material, obj.pose, name=obj.name, casts_shadow=obj.casts_shadow,
                    instance_id=obj.instance_id, category=obj.category)
    return out


def background_lookup(levels, uv, lod):
    """``textureLod`` of a pyramid ``levels`` (GL row order, clamped to the edge, GL_LINEAR_MIPMAP_LINEAR) at ``uv``
    (N, 2) and level of detail ``lod`` (N,) > 0: ``(value, low_texel, high_texel)``, each (N, C), the value the
    trilinear mix of the two levels about ``lod`` (the coarsest for ``lod`` beyond it, `gltf_transmission_sample`) and
    `background_texel_bounds`."""
    return (gltf_transmission_sample(levels, uv, lod), *background_texel_bounds(levels, uv, lod))


def background_texel_bounds(levels, uv, lod):
    """The least and greatest texel a lookup of `background_lookup` weights, each (N, C): on the levels ``floor(lod)
    - 1`` (where float32 may round ``lod`` across an integer) to ``floor(lod) + 1`` (``floor(lod)`` alone where
    ``lod`` is an integer: 0, the bilinear lookup of level 0); the band's ends need these alone."""
    top = len(levels) - 1
    lod = np.minimum(np.asarray(lod, np.float64), top)
    d1 = np.floor(lod).astype(np.int64)
    frac = lod - d1
    shape = (len(uv), levels[0].shape[2])
    low = np.full(shape, np.inf)
    high = np.full(shape, -np.inf)
    for k in np.unique(d1):
        at = d1 == k
        texels_a = _bilinear(levels[k], uv[at], "clamp")[1]
        texels_b = _bilinear(levels[min(k + 1, top)], uv[at], "clamp")[1]
        spread = [texels_a, np.where((frac[at] > 0)[None, :, None], texels_b, texels_a)]
        near = np.abs(lod[at] - np.round(lod[at])) < 1e-4
        if k > 0 and near.any():
            spread.append(np.where(near[None, :, None], _bilinear(levels[k - 1], uv[at], "clamp")[1], texels_a))
        stack = np.concatenate(spread, axis=0)
        low[at], high[at] = stack.min(axis=0), stack.max(axis=0)
    return low, high


def transmission_twin(scene, gbuffer, background, band=BAND, shadows=None):
    """The transmitted radiance of a frame's transmissive surfaces (module).

    Parameters
    ----------
    scene : glphong.Scene
    gbuffer : glphong.GBuffer
        The GPU's G-buffer of the whole scene (its transmissive surfaces included).
    background : tuple of (H, W, 3) float64 ndarray
        ``(reference, low, high)``: the twin of `opaque_scene`'s G-buffer, shaded in ``scene`` (`in_scene`).
    band : glphong.checks.tolerances.BandConstants
    shadows : (int, int), optional
        The renderer's shadow settings (`glphong.Renderer.shadow_settings`), where a light has ``shadows=True``: the
        lights behind the surface take each shadowed light's ray-cast visibility at the surface (`_visible`).

    Returns
    -------
    TransmissionTwin
    """
    height, width = gbuffer.mask.shape
    reference, b_low, b_high = (np.asarray(a, np.float64) for a in background)
    out = np.zeros((height, width, 3))
    out_low, out_high = np.zeros_like(out), np.zeros_like(out)
    pixels = np.zeros((height, width), bool)
    rough = np.zeros((height, width), bool)
    chosen = set(transmissive_objects(scene))
    pyramids = None
    tol = band.D * EPS
    for selection, obj, key, u, position, f, n_valid in shade_inputs(scene, gbuffer, band=band, shadows=shadows):
        if int(gbuffer.object_index[selection][0]) not in chosen:
            continue
        rows, columns = np.nonzero(selection)
        eye = np.asarray(u["u_eye"], np.float64)
        wo_valid, wo, _ = safe_normalize(eye[:3] - position * eye[3])
        valid = n_valid & wo_valid
        n_dot_v = np.einsum("ij,ij->i", f.n, wo)
        used = obj.material.extensions()  # transmission, diffuse_transmission or both (gltf_diffuse_transmission)
        p = _material(u, f, used)
        if pyramids is None:  # GL row order: row 0 at the bottom
            pyramids = [background_levels(reference[::-1])]
        fragcoord = np.stack([columns + 0.5, height - 1 - rows + 0.5], axis=1)
        volume = _volume(obj, u, f) if "volume" in used else None
        value = gltf_transmission_radiance(pyramids[0], fragcoord, position, f.n, wo, valid, p, volume)
        # the weight's band: the Fresnel's slope in n.v (<= 5) times n.v's error, and the chain's rounding; the
        # parameters' own intervals where textured (F grows with specular and specular_color)
        c_lo, c_hi = _bounds("u_gltf_pbr_base_color", u, f, 3)
        m_lo, m_hi = _bounds("u_gltf_pbr_metallic", u, f, 1)
        t_lo, t_hi = _bounds("u_gltf_pbr_transmission", u, f, 1) if "transmission" in used else (p.t, p.t)
        slack = (5.0 * band.D + band.A) * EPS
        fr_lo, fr_hi = _one_minus_fresnel(u, f, used, p.ior, n_dot_v, n_dot_v, tol)
        w_lo = c_lo * ((1.0 - m_hi) * t_lo)[:, None] * np.maximum(fr_lo - slack, 0.0)[:, None]
        w_hi = c_hi * ((1.0 - m_lo) * t_hi)[:, None] * (fr_hi + slack)[:, None]
        keep_lo, keep_hi = _layers_bounds(u, f, used, np.maximum(n_dot_v, 0.0), np.maximum(n_dot_v, 0.0), tol,
                                          _coat_cosines(u, f, used, wo))
        w_lo, w_hi = w_lo * keep_lo[:, None], w_hi * keep_hi[:, None]
        lod = gltf_transmission_lod(p.r.astype(np.float32), p.ior.astype(np.float32), np.log2(width))
        is_rough = lod > 0
        lo, hi = b_low[rows, columns].copy(), b_high[rows, columns].copy()
        if (is_rough.any() or volume) and len(pyramids) == 1:
            pyramids += [background_levels(a[::-1]) for a in (b_low, b_high)]
        if volume:  # KHR_materials_volume (and _dispersion): the lookup where the exit point projects
            lo, hi, is_rough = _through_volume(volume, f, position, wo, p.r, p.ior, pyramids, width)
        elif is_rough.any():
            uv = fragcoord[is_rough] / np.array([width, height])
            level = lod[is_rough].astype(np.float64)
            lo[is_rough] = background_texel_bounds(pyramids[1], uv, level)[0]
            hi[is_rough] = background_texel_bounds(pyramids[2], uv, level)[1]
        ends = np.stack([w_lo * lo, w_lo * hi, w_hi * lo, w_hi * hi])
        scales = [(c_lo * ((1.0 - m_hi) * t_lo)[:, None], c_hi * ((1.0 - m_lo) * t_hi)[:, None])]
        diffuse = None
        if "diffuse_transmission" in used:  # (1 - m) (1 - t) dt c_dt and its interval
            dt, c_dt = (_parameter(f"u_gltf_pbr_diffuse_transmission{s}", u, f, k) for s, k in (("", 1), ("_color", 3)))
            (dt_lo, dt_hi), (cd_lo, cd_hi) = (_bounds(f"u_gltf_pbr_diffuse_transmission{s}", u, f, k)
                                              for s, k in (("", 1), ("_color", 3)))
            diffuse = (dt, c_dt)
            scales.append((cd_lo * ((1.0 - m_hi) * (1.0 - t_hi) * dt_lo)[:, None],
                           cd_hi * ((1.0 - m_lo) * (1.0 - t_lo) * dt_hi)[:, None]))
        behind = partial(_lights_behind, key, u, f, position, wo, valid, p, scales, band, used, diffuse, volume)
        lights, lights_low, lights_high = (a + b for a, b in zip(behind(_visible(key, u, band, f.visibility)),
                                                                 extended_behind(behind, key, u, f, band)))
        out[rows, columns] = value + lights
        out_low[rows, columns] = np.where(valid[:, None], ends.min(axis=0), np.minimum(value, 0.0)) + lights_low
        out_high[rows, columns] = np.where(valid[:, None], ends.max(axis=0), np.maximum(value, 0.0)) + lights_high
        pixels[rows, columns] = True
        rough[rows, columns] = is_rough
    return TransmissionTwin(out, out_low, out_high, pixels, rough, reference)


def _visible(key, u, band, visibility):
    """The punctual lights at points ``x`` (N, 3), `incident_light`'s ``(valid, wi, E, (E_low, E_high))`` each, every
    shadowed light's ``E`` and interval times its visibility at the fragments (``f.visibility``: the exact value, its
    low and high): the generated loops' ``irradiance *= V(position)``, which the responses behind the surface and a
    volume's exit point (``x`` moved) take as they are (`glphong.shaders.generated.lights_chunk`)."""
    def incident(x):
        lights = incident_light(x, key, u, band=band)
        for i, v in enumerate(visibility or ()):
            if v is not None:
                valid, wi, e, (e_low, e_high) = lights[i]
                lights[i] = (valid, wi, e * v[0][:, None], (e_low * v[1][:, None], e_high * v[2][:, None]))
        return lights
    return incident


def _material(u, f, used):
    """The transmissive material's parameters at the fragments, as `gltf_transmission_radiance` reads them: ``c``,
    ``m``, ``t`` (0 without KHR_materials_transmission), ``r``, ``ior``; ``specular`` ``(specular, specular_color)``
    with KHR_materials_specular; ``layers``, `gltf_transmission_layers`' keywords for the sheen and the coat."""
    n = len(f.n)
    layers = {}
    if "sheen" in used:
        layers |= {"sheen_color": _parameter("u_gltf_pbr_sheen_color", u, f, 3),
                   "sheen_roughness": _parameter("u_gltf_pbr_sheen_roughness", u, f, 1)}
    if "clearcoat" in used:
        layers["clearcoat"] = _parameter("u_gltf_pbr_clearcoat", u, f, 1)
    if "clearcoat_normal" in used:  # the coat's own normal, on the unperturbed frame (gltf_coat_normal)
        layers["coat_normal"] = _coat_normal(u, f, _parameter("u_gltf_pbr_clearcoat_normal", u, f, 3))
    specular = (_parameter("u_gltf_pbr_specular", u, f, 1), _parameter("u_gltf_pbr_specular_color", u, f, 3)) \
        if "specular" in used else None
    film = _film(u, f, _parameter("u_gltf_pbr_iridescence", u, f, 1),
                 _parameter("u_gltf_pbr_iridescence_thickness_mix", u, f, 1)) if "iridescence" in used else None
    return SimpleNamespace(c=_parameter("u_gltf_pbr_base_color", u, f, 3), m=_parameter("u_gltf_pbr_metallic", u, f, 1),
                           t=_parameter("u_gltf_pbr_transmission", u, f, 1) if "transmission" in used else np.zeros(n),
                           r=_parameter("u_gltf_pbr_roughness", u, f, 1), ior=_parameter("u_gltf_pbr_ior", u, f, 1),
                           specular=specular, layers=layers, film=film)


def _volume(obj, u, f):
    """KHR_materials_volume's (and _dispersion's) inputs of `gltf_transmission_radiance` for ``obj``'s fragments."""
    return {"thickness": _parameter("u_gltf_pbr_thickness", u, f, 1),
            "scale": np.linalg.norm(np.asarray(u["u_model"], np.float64)[:3, :3], axis=0),  # GLSL's u_model[k].xyz
            "view_projection": np.asarray(u["u_view_projection"], np.float64),
            "color": np.asarray(u["u_gltf_pbr_attenuation_color"], np.float64),
            "distance": float(u["u_gltf_pbr_attenuation_distance"]),
            "dispersion": float(u["u_gltf_pbr_dispersion"]) if "dispersion" in obj.material.extensions() else 0.0}


def _through_volume(volume, f, position, wo, roughness, ior, pyramids, width):
    """``(low, high, filtered)`` of a volume's fragments' ``B`` (``volume``: `_volume`'s; transmission_thin.glsl's
    ``gltf_volume_light``, `glphong.materials.gltf_transmission.gltf_volume_light`, per channel its own ior where the material disperses):
    the least and greatest texel the lookup may weight (the footprints at the exit's uv moved a hundredth of a texel
    each way: float32 places it within that) times the attenuation to ``(A + 8 |y ln c|) eps`` relative (``y = d /
    distance``).  ``filtered``: where the level of detail is above 0."""
    n = len(position)
    color, distance = volume["color"], volume["distance"]
    etas = gltf_dispersion_iors(ior, volume["dispersion"]) if volume["dispersion"] else [ior]
    low, high = np.zeros((n, 3)), np.zeros((n, 3))
    filtered = np.zeros(n, bool)
    size = np.array([pyramids[0][0].shape[1], pyramids[0][0].shape[0]], np.float64)
    for k, eta in enumerate(etas):
        channels = slice(None) if len(etas) == 1 else slice(k, k + 1)
        ray = gltf_volume_ray(f.n, wo, eta, volume["thickness"], volume["scale"])
        uv = gltf_volume_uv(position + ray, volume["view_projection"])
        lod = gltf_transmission_lod(roughness.astype(np.float32), np.asarray(eta).astype(np.float32),
                                    np.log2(width)).astype(np.float64)
        filtered |= lod > 0
        attenuation = gltf_volume_attenuation(np.sqrt(np.einsum("ij,ij->i", ray, ray)), color, distance)
        slack = _attenuation_slack(np.sqrt(np.einsum("ij,ij->i", ray, ray)), color, distance)
        ends = []
        for dx, dy in ((0.0, 0.0), (-0.01, -0.01), (0.01, -0.01), (-0.01, 0.01), (0.01, 0.01)):
            moved = uv + np.array([dx, dy]) / size
            ends += [background_texel_bounds(pyramids[1], moved, lod)[0],
                     background_texel_bounds(pyramids[2], moved, lod)[1]]
        low[:, channels] = (np.min(ends, axis=0) * attenuation * (1.0 - slack))[:, channels]
        high[:, channels] = (np.max(ends, axis=0) * attenuation * (1.0 + slack))[:, channels]
    return low, high, filtered


def in_scene(scene, gbuffer):
    """`opaque_scene`'s G-buffer ``gbuffer`` with its object indices those of the same objects in ``scene`` (-1 where
    not covered): shaded in ``scene``, its surfaces take the programs, uniforms and shadow maps (every caster of
    ``scene``, its transmissive objects included, and their frusta from its bounds) that the GPU's opaque pass draws
    them with."""
    chosen = set(transmissive_objects(scene))
    kept = np.array([i for i in range(len(scene.objects)) if i not in chosen] + [-1])
    return dataclasses.replace(gbuffer, object_index=kept[gbuffer.object_index])


def transmission_check(scene, renderer, gbuffer, shade, band=BAND, exact=None, blend=None):
    """`transmission_twin` of a frame of ``renderer``: the background's twin from `opaque_scene`'s G-buffer drawn by
    ``renderer`` and shaded in ``scene`` (`in_scene`) by ``shade(scene, gbuffer)`` -> ``(reference, low, high,
    shadow_band)``; where the scene has blended surfaces, ``blend(opaque, (reference, low, high, covered))`` -> the
    `glphong.checks.blend_twin.BlendTwin` of their composite over it, which is then the background
    (`glphong.checks.transmission_blend`).  Where a light has ``shadows=True``, the GPU's maps hold every caster, the
    transmissive objects included (`glphong.gpu.renderer.Renderer._shadow_values`): the background's visibility is
    theirs (`in_scene`), and the lights behind the surface take the visibility at it (``renderer.shadow_settings``
    to `transmission_twin`); the blended layers of the background are shaded in the whole scene too (``blend``:
    `glphong.checks.transmission_blend.layers_behind`).

    Raises
    ------
    ValueError
        ``exact=True`` (the extended lights' exact integrals are not computed through a transmissive surface).
    """
    obj = scene.objects[transmissive_objects(scene)[0]]
    name, used = obj.name, obj.material.extensions()
    named = " and ".join(f"KHR_materials_{e}" for e in ("transmission", "diffuse_transmission") if e in used)
    if exact:
        raise ValueError(f"object {name!r} is transmissive ({named}): verify does not compute the exact integrals of "
                         "extended lights with it (exact=True); the GPU is checked against the twin of the lights' "
                         "methods, behind the surface too (exact=False; their error: docs/transmission.md, Lights)")
    shadowed = any(getattr(light, "shadows", False) for light in scene.lights)
    opaque = opaque_scene(scene)
    opaque_gbuffer = renderer.gbuffer(opaque)
    shaded = shade(scene, in_scene(scene, opaque_gbuffer))  # the GPU's opaque pass: the whole scene's maps
    shadows = renderer.shadow_settings if shadowed else None
    if blend is None:
        twin = transmission_twin(scene, gbuffer, shaded[:3], band, shadows)
    else:
        behind = blend(opaque, (*shaded[:3], opaque_gbuffer.mask))
        twin = dataclasses.replace(transmission_twin(scene, gbuffer, (behind.reference, behind.low, behind.high), band,
                                                     shadows), background_blend=behind)
    return dataclasses.replace(twin, shadow_band=twin.pixels & shaded[3]) if shadowed else twin
