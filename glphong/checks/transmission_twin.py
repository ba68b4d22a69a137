"""The float64 twin of transmissive surfaces (glTF ``KHR_materials_transmission``, thin walls;
`glphong.gpu.transmission`, docs/transmission.md).

At each pixel whose nearest surface (the GPU's G-buffer) is transmissive, the twin adds to the surface's reflection
(the shading twin, its diffuse weighted by ``1 - t``) what the surface transmits, transmission_thin.glsl function by
function:

    L_t = gltf_transmission_weight(n.v, c, m, t, ior) * B,   w = (1 - m) t (1 - F(n.v)) c

``B`` from the twin of the background: the scene without its transmissive objects, its G-buffer drawn by the GPU and
shaded by the twin (``shade``: `glphong.checks.verify.twin_and_band`), which is the opaque surface the pixel's ray
meets next behind the thin wall (it goes straight through).  Roughness 0 (or ior 1): ``B`` is that surface's radiance
at the pixel, exactly.  Roughness ``r > 0``: ``B`` is the trilinear lookup of the background's pyramid of 2x2 box
means (`glphong.materials.gltf_transmission.background_levels`, in float64) at the pixel's centre, level of detail
``log2(W) r clamp(2 ior - 2, 0, 1)`` (`gltf_transmission_lod`): the GPU's method, whose own error against the integral
of the lobe is measured apart (benchmarks/transmission_rough.py, docs/transmission.md).

The band: ``w`` to ``(5 D + A) eps`` of ``(1 - m) t c`` (the Fresnel's slope in ``n.v`` is at most 5, ``n.v`` to ``D
eps``; the chain's rounding ``A eps``), times the background's band: at roughness 0 the pixel's low and high, above 0
the least and the greatest texel of the low and high pyramids that the lookup weights, on the two levels about the
level of detail (and the one below where float32 may round it across an integer).
"""
import dataclasses
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np

from glphong.checks.reference import incident_light, safe_normalize, shade_inputs
from glphong.checks.tolerances import BAND
from glphong.definitions.surface import _bilinear
from glphong.gpu.transmission import transmissive_objects
from glphong.materials.gltf_diffuse_transmission import gltf_diffuse_transmission_response
from glphong.materials.gltf_pbr import gltf_pbr_band
from glphong.materials.gltf_transmission import (background_levels, gltf_transmission_lod, gltf_transmission_response,
                                                 gltf_transmission_weight, gltf_volume_attenuation, gltf_volume_ray,
                                                 gltf_volume_uv)
from glphong.scene.scene import Scene
from glphong.twin.band import EPS

__all__ = ["TransmissionTwin", "opaque_scene", "transmission_twin", "transmission_check", "background_lookup"]


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
    """

    transmitted: np.ndarray
    low: np.ndarray
    high: np.ndarray
    pixels: np.ndarray
    rough: np.ndarray
    background: np.ndarray


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
    trilinear mix of the two levels about ``lod`` (the coarsest for ``lod`` beyond it) and the least and greatest texel
    it weights on the levels ``floor(lod) - 1`` (where float32 may round ``lod`` across an integer) to ``floor(lod) +
    1`` (``floor(lod)`` alone where ``lod`` is an integer: 0, the bilinear lookup of level 0)."""
    top = len(levels) - 1
    lod = np.minimum(np.asarray(lod, np.float64), top)
    d1 = np.floor(lod).astype(np.int64)
    frac = lod - d1
    value = np.zeros((len(uv), levels[0].shape[2]))
    low = np.full(value.shape, np.inf)
    high = np.full(value.shape, -np.inf)
    for k in np.unique(d1):
        at = d1 == k
        a, texels_a = _bilinear(levels[k], uv[at], "clamp")
        b, texels_b = _bilinear(levels[min(k + 1, top)], uv[at], "clamp")
        value[at] = (1.0 - frac[at])[:, None] * a + frac[at][:, None] * b
        spread = [texels_a, np.where((frac[at] > 0)[None, :, None], texels_b, texels_a)]
        near = np.abs(lod[at] - np.round(lod[at])) < 1e-4
        if k > 0 and near.any():
            spread.append(np.where(near[None, :, None], _bilinear(levels[k - 1], uv[at], "clamp")[1], texels_a))
        stack = np.concatenate(spread, axis=0)
        low[at], high[at] = stack.min(axis=0), stack.max(axis=0)
    return value, low, high


def _parameter(name, u, f, count):
    """A material parameter at the object's fragments: its surface input's value where textured, else the uniform;
    (N, 3) for an rgb one (``count`` 3), (N,) for a scalar."""
    value = (f.inputs or {}).get(name)
    value = np.asarray(u[name] if value is None else value, np.float64)
    n = len(f.n)
    return np.broadcast_to(value, (n, 3) if count == 3 else (n,))


def _bounds(name, u, f, count):
    """``(low, high)`` of a parameter (its surface input's interval where textured, else the float32 uniform)."""
    bounds = (f.input_bounds or {}).get(name)
    if bounds is None:
        value = _parameter(name, u, f, count)
        return value, value
    n = len(f.n)
    return tuple(np.broadcast_to(np.asarray(b, np.float64), (n, 3) if count == 3 else (n,)) for b in bounds)


def transmission_twin(scene, gbuffer, background, band=BAND):
    """The transmitted radiance of a frame's transmissive surfaces (module).

    Parameters
    ----------
    scene : glphong.Scene
    gbuffer : glphong.GBuffer
        The GPU's G-buffer of the whole scene (its transmissive surfaces included).
    background : tuple of (H, W, 3) float64 ndarray
        ``(reference, low, high)``: the twin of `opaque_scene` on its own G-buffer.
    band : glphong.checks.tolerances.BandConstants

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
    for selection, obj, key, u, position, f, n_valid in shade_inputs(scene, gbuffer, band=band):
        if int(gbuffer.object_index[selection][0]) not in chosen:
            continue
        rows, columns = np.nonzero(selection)
        eye = np.asarray(u["u_eye"], np.float64)
        wo_valid, wo, _ = safe_normalize(eye[:3] - position * eye[3])
        valid = n_valid & wo_valid
        n_dot_v = np.einsum("ij,ij->i", f.n, wo)
        c = _parameter("u_gltf_pbr_base_color", u, f, 3)
        m = _parameter("u_gltf_pbr_metallic", u, f, 1)
        used = obj.material.extensions()  # transmission, diffuse_transmission or both (gltf_diffuse_transmission)
        t = _parameter("u_gltf_pbr_transmission", u, f, 1) if "transmission" in used else np.zeros(len(f.n))
        r = _parameter("u_gltf_pbr_roughness", u, f, 1)
        ior = _parameter("u_gltf_pbr_ior", u, f, 1)
        weight = gltf_transmission_weight(n_dot_v, c, m, t, ior)
        # the weight's band: the Fresnel's slope in n.v (<= 5) times n.v's error, and the chain's rounding; the
        # parameters' own intervals where textured
        c_lo, c_hi = _bounds("u_gltf_pbr_base_color", u, f, 3)
        m_lo, m_hi = _bounds("u_gltf_pbr_metallic", u, f, 1)
        t_lo, t_hi = _bounds("u_gltf_pbr_transmission", u, f, 1) if "transmission" in used else (t, t)
        slack = (5.0 * band.D + band.A) * EPS
        fresnel = weight / np.maximum(c * ((1.0 - m) * t)[:, None], np.finfo(float).tiny)
        w_lo = c_lo * ((1.0 - m_hi) * t_lo)[:, None] * np.maximum(fresnel - slack, 0.0)
        w_hi = c_hi * ((1.0 - m_lo) * t_hi)[:, None] * (fresnel + slack)
        lod = gltf_transmission_lod(r.astype(np.float32), ior.astype(np.float32), np.log2(width))
        is_rough = lod > 0
        b = reference[rows, columns].copy()
        lo, hi = b_low[rows, columns].copy(), b_high[rows, columns].copy()
        volume = "volume" in obj.material.extensions()
        if (is_rough.any() or volume) and pyramids is None:  # GL row order: row 0 at the bottom
            pyramids = [background_levels(a[::-1]) for a in (reference, b_low, b_high)]
        if volume:  # KHR_materials_volume (and _dispersion): the lookup where the exit point projects
            b, lo, hi, is_rough = _through_volume(obj, u, f, position, wo, r, ior, pyramids, width)
        elif is_rough.any():
            uv = np.stack([(columns[is_rough] + 0.5) / width, (height - 1 - rows[is_rough] + 0.5) / height], axis=1)
            level = lod[is_rough].astype(np.float64)
            b[is_rough] = background_lookup(pyramids[0], uv, level)[0]
            lo[is_rough] = background_lookup(pyramids[1], uv, level)[1]
            hi[is_rough] = background_lookup(pyramids[2], uv, level)[2]
        value = np.where(valid[:, None], weight * b, 0.0)
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
        lights, lights_low, lights_high = _lights_behind(key, u, position, f.n, wo, valid, (c, m, t, r, ior),
                                                        scales, band, used, diffuse)
        out[rows, columns] = value + lights
        out_low[rows, columns] = np.where(valid[:, None], ends.min(axis=0), np.minimum(value, 0.0)) + lights_low
        out_high[rows, columns] = np.where(valid[:, None], ends.max(axis=0), np.maximum(value, 0.0)) + lights_high
        pixels[rows, columns] = True
        rough[rows, columns] = is_rough
    return TransmissionTwin(out, out_low, out_high, pixels, rough, reference)


def _lights_behind(key, u, position, n, wo, lit, parameters, scales, band, used=("transmission",), diffuse=None):
    """``(value, low, high)``, each (N, 3): what the punctual lights behind the surface send through it
    (`gltf_transmission_response` where ``used`` holds 'transmission', `gltf_diffuse_transmission_response` with
    ``diffuse = (dt, c_dt)`` where it holds 'diffuse_transmission', times E, where ``n.wi < 0``, the generated loops'
    gate).  ``scales``: ``(low, high)`` of ``(1 - m) t c``, then of ``(1 - m) (1 - t) dt c_dt``.  The diffuse's band:
    ``1 - F`` over ``v.h'``'s interval times ``n_dot_l`` to ``D eps``, the scale's and the irradiance's intervals, to
    ``A eps``.  The band: the lobe ``D V
    (n.l')`` by `glphong.materials.gltf_pbr.gltf_pbr_band` at the mirrored direction (a metal of base colour 1 is that
    lobe alone; its directions to ``D + 4`` eps: the mirror's own rounding), times ``1 - F`` over ``v.h``'s interval
    and ``scale = (low, high)`` of ``(1 - m) t c``, times the light's irradiance interval, to ``A eps``; low 0 where
    ``|n.wi| <= D eps`` (the gate may go either way)."""
    value, low, high = (np.zeros((len(position), 3)) for _ in range(3))
    c, m, t, roughness, ior = parameters
    scale = scales[0]
    tol = band.D * EPS
    wide = dataclasses.replace(band, D=band.D + 4.0)
    for valid, wi, irradiance, (e_low, e_high) in incident_light(position, key, u, band=band):
        n_dot_wi = np.einsum("ij,ij->i", n, wi)
        possible = lit & valid & (n_dot_wi < tol)
        if not possible.any():
            continue
        certain = lit & valid & (n_dot_wi < -tol)
        n_dot_l = -n_dot_wi
        gate = (lit & valid & (n_dot_wi < 0.0))[:, None]
        response = gltf_transmission_response(n, wi, wo, n_dot_l, c, m, t, roughness, ior) \
            if "transmission" in used else np.zeros_like(value)
        value += np.where(gate, response * irradiance, 0.0)
        k = np.flatnonzero(possible)
        mirrored = wi[k] + (2.0 * n_dot_l[k])[:, None] * n[k]
        lobe = SimpleNamespace(base_color=np.ones(3), metallic=np.ones(len(k)), roughness=roughness[k], ior=ior[k])
        lobe_low, lobe_high = gltf_pbr_band(n[k], mirrored, wo[k], n_dot_l[k], lobe, wide)
        half = np.sqrt(np.einsum("ij,ij->i", mirrored + wo[k], mirrored + wo[k])) / 2.0
        spread = wide.D * EPS + 3.0 * EPS
        f0 = ((ior[k] - 1.0) / (ior[k] + 1.0)) ** 2
        one_minus = [1.0 - (f0 + (1.0 - f0) * np.maximum(1.0 - half + s, 0.0) ** 5) for s in (spread, -spread)]
        rel = band.A * EPS
        if diffuse is not None:  # KHR_materials_diffuse_transmission (gltf_diffuse_transmission)
            dt, c_dt = diffuse
            value += np.where(gate, gltf_diffuse_transmission_response(n, wi, wo, n_dot_l, c_dt, m, t, dt, ior)
                              * irradiance, 0.0)
            d_lo, d_hi = scales[1]
            cos_lo, cos_hi = np.maximum(n_dot_l[k] - tol, 0.0) / np.pi, (n_dot_l[k] + tol) / np.pi
            lo = d_lo[k] * (np.maximum(one_minus[0], 0.0) * cos_lo)[:, None] * e_low[k] * (1.0 - rel)
            hi = d_hi[k] * (one_minus[1] * cos_hi)[:, None] * e_high[k] * (1.0 + rel)
            low[k] += np.where(certain[k][:, None], lo, 0.0)
            high[k] += hi
        if "transmission" not in used:
            continue
        with np.errstate(invalid="ignore", over="ignore"):
            lo = scale[0][k] * (np.maximum(one_minus[0], 0.0) * lobe_low[:, 0])[:, None] * e_low[k] * (1.0 - rel)
            hi = scale[1][k] * (one_minus[1] * lobe_high[:, 0])[:, None] * e_high[k] * (1.0 + rel)
        low[k] += np.where(certain[k][:, None], np.nan_to_num(lo, nan=0.0), 0.0)
        high[k] += np.nan_to_num(hi, nan=np.inf, posinf=np.inf)
    return value, low, high


def _through_volume(obj, u, f, position, wo, roughness, ior, pyramids, width):
    """``(B, low, high, filtered)`` of a volume's fragments (transmission_thin.glsl's ``gltf_volume_light``, per channel
    its own ior where the material disperses): the lookup of the background's pyramid where the exit point projects,
    attenuated; the band the least and greatest texel the lookup may weight (the footprints at the exit's uv moved a
    hundredth of a texel each way: float32 places it within that) times the attenuation to ``(A + 8 |y ln c|) eps``
    relative (``y = d / distance``).  ``filtered``: where the level of detail is above 0."""
    n = len(position)
    thickness = _parameter("u_gltf_pbr_thickness", u, f, 1)
    color = np.asarray(u["u_gltf_pbr_attenuation_color"], np.float64)
    distance = float(u["u_gltf_pbr_attenuation_distance"])
    scale = np.linalg.norm(np.asarray(u["u_model"], np.float64)[:3, :3], axis=0)  # GLSL's u_model[k].xyz: columns
    view_projection = np.asarray(u["u_view_projection"], np.float64)
    etas = [ior]
    if "dispersion" in obj.material.extensions():
        half = (ior - 1.0) * 0.025 * float(u["u_gltf_pbr_dispersion"])
        etas = [ior - half, ior, ior + half]
    value, low, high = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))
    filtered = np.zeros(n, bool)
    size = np.array([pyramids[0][0].shape[1], pyramids[0][0].shape[0]], np.float64)
    for k, eta in enumerate(etas):
        channels = slice(None) if len(etas) == 1 else slice(k, k + 1)
        ray = gltf_volume_ray(f.n, wo, eta, thickness, scale)
        uv = gltf_volume_uv(position + ray, view_projection)
        lod = gltf_transmission_lod(roughness.astype(np.float32), np.asarray(eta).astype(np.float32),
                                    np.log2(width)).astype(np.float64)
        filtered |= lod > 0
        attenuation = gltf_volume_attenuation(np.sqrt(np.einsum("ij,ij->i", ray, ray)), color, distance)
        with np.errstate(divide="ignore", invalid="ignore"):
            y = np.sqrt(np.einsum("ij,ij->i", ray, ray)) / distance
            slack = np.nan_to_num((16.0 + 8.0 * np.abs(y[:, None] * np.log(color))) * EPS, nan=0.0, posinf=0.0)
        sampled = background_lookup(pyramids[0], uv, lod)[0]
        ends = []
        for dx, dy in ((0.0, 0.0), (-0.01, -0.01), (0.01, -0.01), (-0.01, 0.01), (0.01, 0.01)):
            moved = uv + np.array([dx, dy]) / size
            ends += [background_lookup(pyramids[1], moved, lod)[1], background_lookup(pyramids[2], moved, lod)[2]]
        value[:, channels] = (sampled * attenuation)[:, channels]
        low[:, channels] = (np.min(ends, axis=0) * attenuation * (1.0 - slack))[:, channels]
        high[:, channels] = (np.max(ends, axis=0) * attenuation * (1.0 + slack))[:, channels]
    return value, low, high, filtered


def transmission_check(scene, renderer, gbuffer, shade, band=BAND, exact=None):
    """`transmission_twin` of a frame of ``renderer``: the background's twin from `opaque_scene`'s G-buffer drawn by
    ``renderer`` and shaded by ``shade(scene, gbuffer)`` -> ``(reference, low, high, ...)``.

    Raises
    ------
    ValueError
        ``exact=True`` (the extended lights' exact integrals are not computed through a transmissive surface), or a
        light with ``shadows=True`` (the background's twin is drawn without the transmissive objects, which the GPU's
        shadow maps hold).
    """
    name = scene.objects[transmissive_objects(scene)[0]].name
    if exact:
        raise ValueError(f"object {name!r} is transmissive (KHR_materials_transmission): verify does not compute the "
                         "exact integrals of extended lights through it (exact=True); the GPU is checked against the "
                         "twin of the lights' methods (exact=False)")
    if any(getattr(light, "shadows", False) for light in scene.lights):
        raise ValueError(f"object {name!r} is transmissive (KHR_materials_transmission) and a light has shadows=True: "
                         "verify does not twin shadows with transmissive objects yet")
    opaque = opaque_scene(scene)
    background = shade(opaque, renderer.gbuffer(opaque))[:3]
    return transmission_twin(scene, gbuffer, background, band)
