"""The bounds of a transmissive `GltfPBR`'s parameters and what the punctual lights behind it send through it, for
`glphong.checks.transmission_twin` (glTF ``KHR_materials_transmission``, ``_diffuse_transmission``, ``_volume``;
docs/transmission.md): the parameters at the fragments and their intervals (`_parameter`, `_bounds`), ``1 - max3(F)``
and the layers' weight over them (`_one_minus_fresnel`, `_layers_bounds`), and the lights behind the surface with
their band (`_lights_behind`), seen from a volume's exit point where the material has one (`_exit_light`).
"""
import dataclasses
from types import SimpleNamespace

import numpy as np

from glphong.checks.reference import incident_light
from glphong.materials.gltf_coat_normal import gltf_clearcoat_normal
from glphong.materials.gltf_diffuse_transmission import gltf_diffuse_transmission_response
from glphong.materials.gltf_pbr import gltf_pbr_band
from glphong.materials.gltf_transmission import (gltf_transmission_fresnel, gltf_transmission_layers,
                                                 gltf_transmission_response, gltf_volume_diffuse_attenuation,
                                                 gltf_volume_exit, gltf_volume_exit_attenuation)
from glphong.twin.band import EPS


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


def _coat_normal(u, f, texel):
    """``n_c`` (N, 3) of the texel ``texel`` (N, 3) (`gltf_clearcoat_normal`, in float64)."""
    scale = _parameter("u_gltf_pbr_clearcoat_normal_strength", u, f, 1)
    return gltf_clearcoat_normal(f, SimpleNamespace(clearcoat_normal=texel, clearcoat_normal_strength=scale[0]),
                                 np.dtype(np.float64))


def _coat_cosines(u, f, used, wo):
    """``(low, high)`` of the coat's cosine ``max(n_c.v, 0)`` (N,) each, over the corners of the coat normal's texel
    interval where textured; None without a coat normal."""
    if "clearcoat_normal" not in used:
        return None
    lo, hi = _bounds("u_gltf_pbr_clearcoat_normal", u, f, 3)
    texels = [np.stack([(lo, hi)[i][:, k] for k, i in enumerate(index)], axis=1) for index in np.ndindex(2, 2, 2)]
    cosines = [np.maximum(np.einsum("ij,ij->i", _coat_normal(u, f, texel), wo), 0.0) for texel in texels]
    return np.min(cosines, axis=0), np.max(cosines, axis=0)


def _one_minus_fresnel(u, f, used, ior, cos_low, cos_high, spread=0.0):
    """``(low, high)`` of ``1 - max3(F)`` (`gltf_transmission_fresnel`), (N,) each: at ``cos_low`` with the greatest
    specular and specular colour (F grows with both, falls with the cosine), at ``cos_high`` with the least; with the
    film, `_one_minus_film` (``spread``: its cosine's own tolerance)."""
    if "iridescence" in used:
        return _one_minus_film(u, f, used, ior, cos_low, cos_high, spread)
    if "specular" not in used:
        return tuple(1.0 - gltf_transmission_fresnel(ior, c)[:, 0] for c in (cos_low, cos_high))
    (s_lo, s_hi), (k_lo, k_hi) = (_bounds(name, u, f, k) for name, k in (("u_gltf_pbr_specular", 1),
                                                                         ("u_gltf_pbr_specular_color", 3)))
    return (1.0 - np.max(gltf_transmission_fresnel(ior, cos_low, s_hi, k_hi), axis=-1),
            1.0 - np.max(gltf_transmission_fresnel(ior, cos_high, s_lo, k_lo), axis=-1))


#: the float32 film's error, absolute in ``1 - max3(F')`` per unit ``iridescence`` (KHR_materials_iridescence over
#: transmission): gltf_iridescence_fresnel's float32 chain (phases to 40 rad, the sensitivity's sums cancelling) moves
#: max3(F_iridescence) by at most 3.2e-6 (the twin in float32 against float64, 10^5 random cosines, thicknesses to
#: 1200 nm, film iors 1 to 2.3, base f0s), taken about 4 times (docs/transmission.md, "Layers over transmission")
FILM_SLACK = 1.2e-5


def _film(u, f, iridescence, thickness_mix):
    """`gltf_transmission_fresnel`'s ``film`` mapping at the weight ``iridescence`` and ``thickness_mix`` (N,):
    ``thickness = mix(minimum, maximum, thickness_mix)`` [nm] as gltf_transmission_fresnel forms it."""
    low, high = (float(u[f"u_gltf_pbr_iridescence_thickness_{end}"]) for end in ("minimum", "maximum"))
    return {"iridescence": iridescence, "iridescence_ior": _parameter("u_gltf_pbr_iridescence_ior", u, f, 1),
            "thickness": low * (1.0 - thickness_mix) + high * thickness_mix}


def _one_minus_film(u, f, used, ior, cos_low, cos_high, spread):
    """``(low, high)`` of ``1 - max3(F')`` with KHR_materials_iridescence's film (`gltf_transmission_fresnel`), (N,)
    each.  F' is not monotone in the cosine, the thickness or the film's base (the specular's, per channel), so the
    band is first-order, as `glphong.definitions.material.MaterialModel.band`'s: the value at the parameters and the
    cosine's middle, plus and minus twice the sum of its largest moves when each input alone goes to either end of its
    interval (the cosine's moved ``spread`` each way; a textured parameter's interval, each channel of an rgb one
    apart), widened by `FILM_SLACK` times the greatest weight."""
    names = [("u_gltf_pbr_iridescence", 1), ("u_gltf_pbr_iridescence_thickness_mix", 1)]
    if "specular" in used:
        names += [("u_gltf_pbr_specular", 1), ("u_gltf_pbr_specular_color", 3)]
    values = [np.array(_parameter(name, u, f, k)) for name, k in names]
    boxes = [_bounds(name, u, f, k) for name, k in names]

    def one_minus(c, inputs):
        specular = inputs[2:] if "specular" in used else (None, None)
        return 1.0 - np.max(gltf_transmission_fresnel(ior, c, *specular, _film(u, f, inputs[0], inputs[1])), axis=-1)

    middle = 0.5 * (cos_low + cos_high)
    value = one_minus(middle, values)
    move = np.maximum(np.abs(one_minus(cos_low - spread, values) - value),
                      np.abs(one_minus(cos_high + spread, values) - value))
    for i, (low, high) in enumerate(boxes):
        for channel in range(values[i].shape[1]) if values[i].ndim == 2 else (None,):
            ends = []
            for end in (low, high):
                moved = list(values)
                moved[i] = values[i].copy()
                if channel is None:
                    moved[i] = np.asarray(end, np.float64).copy()
                else:
                    moved[i][:, channel] = np.asarray(end, np.float64)[:, channel]
                ends.append(np.abs(one_minus(middle, moved) - value))
            move = move + np.maximum(*ends)
    margin = 2.0 * move + FILM_SLACK * boxes[0][1]
    return value - margin, value + margin


def _layers_bounds(u, f, used, n_dot_v, n_dot_l, tol, coat=None):
    """``(low, high)`` of `gltf_transmission_layers` (N,): the least and greatest over the corners of the sheen's and
    the coat's parameter intervals and of the cosines moved ``tol`` each way (the coat's own cosine's interval
    ``coat``, `_coat_cosines`, moved ``16 tol``: n_c's rounding), to ``8 eps`` relative (the table's lookup and the
    products' rounding)."""
    if "sheen" not in used and "clearcoat" not in used:
        return np.ones(len(n_dot_v)), np.ones(len(n_dot_v))
    boxes = [[{}]]
    if "sheen" in used:
        colors, roughs = _bounds("u_gltf_pbr_sheen_color", u, f, 3), _bounds("u_gltf_pbr_sheen_roughness", u, f, 1)
        boxes.append([{"sheen_color": c, "sheen_roughness": r} for c in colors for r in roughs])
    if "clearcoat" in used:
        cosines = [{}] if coat is None else [{"coat_n_dot_v": np.clip(coat[0] - 16.0 * tol, 0.0, 1.0)},
                                             {"coat_n_dot_v": np.clip(coat[1] + 16.0 * tol, 0.0, 1.0)}]
        boxes.append([{"clearcoat": c} | k for c in _bounds("u_gltf_pbr_clearcoat", u, f, 1) for k in cosines])
    corners = [{}]
    for box in boxes:
        corners = [a | b for a in corners for b in box]
    values = [gltf_transmission_layers(np.clip(n_dot_v + dv, 0.0, 1.0), np.clip(n_dot_l + dl, 0.0, 1.0), **corner)
              for corner in corners for dv in (-tol, tol) for dl in (-tol, tol)]
    return np.min(values, axis=0) * (1.0 - 8.0 * EPS), np.max(values, axis=0) * (1.0 + 8.0 * EPS)


def _lights_behind(key, u, f, position, wo, lit, p, scales, band, used=("transmission",), diffuse=None, volume=None,
                   incident=None):
    """``(value, low, high)``, each (N, 3): what the punctual lights behind the surface send through it
    (`gltf_transmission_response` where ``used`` holds 'transmission', `gltf_diffuse_transmission_response` with
    ``diffuse = (dt, c_dt)`` where it holds 'diffuse_transmission', times E, where ``n.wi < 0``, the generated loops'
    gate); ``p`` the material (`_material`).  ``scales``: ``(low, high)`` of ``(1 - m) t c``, then of ``(1 - m) (1 -
    t) dt c_dt``.  The diffuse's band: ``1 - F`` over ``v.h'``'s interval times ``n_dot_l`` to ``D eps``, the scale's
    and the irradiance's intervals, to ``A eps``.  The band: the lobe ``D V (n.l')`` by
    `glphong.materials.gltf_pbr.gltf_pbr_band` at the mirrored direction (a metal of base colour 1 is that lobe alone;
    its directions to ``D + 4`` eps: the mirror's own rounding), times ``1 - max3(F)`` over ``v.h``'s interval (and
    the specular's, `_one_minus_fresnel`), times the layers' interval (`_layers_bounds` at ``n.v`` and ``n_dot_l``),
    and ``scale = (low, high)`` of ``(1 - m) t c``, times the light's irradiance interval, to ``A eps``; low 0 where
    ``|n.wi| <= D eps`` (the gate may go either way) (`_behind_part`).

    ``volume`` (`_volume`'s mapping; KHR_materials_volume, the generated loops' exits): the transmission's light is
    seen from the exit point ``x' = x + gltf_volume_exit(n, wo, ior, thickness, scale)`` (its ``valid'``, ``wi'``,
    ``E'`` there, gated on ``n.wi' < 0``: `_exit_light`) and multiplied by `gltf_volume_exit_attenuation`; the
    diffuse transmission's by `gltf_volume_diffuse_attenuation`; each attenuation to `_attenuation_slack`.
    ``incident(x)``: the lights at points x (N, 3), `incident_light`'s (valid, wi, E, (E_low, E_high)) each (default:
    the punctual lights, `incident_light` with ``band``)."""
    incident = incident or (lambda x: incident_light(x, key, u, band=band))
    n = len(position)
    value, low, high = (np.zeros((n, 3)) for _ in range(3))
    n_dot_v = np.einsum("ij,ij->i", f.n, wo)
    coat = _coat_cosines(u, f, used, wo)
    lights = list(incident(position))
    none = (np.ones((n, 3)), 0.0)
    exits, through, diffused = [(light, np.zeros(n)) for light in lights], none, none
    if volume is not None:
        args = (f.n, wo, p.ior, volume["thickness"], volume["scale"])
        color, distance = volume["color"], volume["distance"]
        ray = gltf_volume_exit(*args)
        exits = _exit_light(incident, position, ray, band)
        through = (gltf_volume_exit_attenuation(*args, color, distance),
                   _attenuation_slack(np.sqrt(np.einsum("ij,ij->i", ray, ray)), color, distance,
                                      band.D + 8.0))  # |ray| from n and wo to D eps (a scale per axis turns it)
        depth = np.broadcast_to(np.asarray(volume["thickness"], np.float64) * np.mean(volume["scale"]), (n,))
        diffused = (gltf_volume_diffuse_attenuation(volume["thickness"], volume["scale"], color, distance),
                    _attenuation_slack(depth, color, distance))
    for light, (exit, turn) in zip(lights, exits):
        parts = [_behind_part(u, f, used, wo, n_dot_v, coat, light, lit, p, band, np.zeros(n), diffused, scales[1],
                              diffuse)] if diffuse is not None else []
        if "transmission" in used:
            parts.append(_behind_part(u, f, used, wo, n_dot_v, coat, exit, lit, p, band, turn, through, scales[0]))
        for part in parts:
            value += part[0]
            low += part[1]
            high += part[2]
    return value, low, high


def _behind_part(u, f, used, wo, n_dot_v, coat, light, lit, p, band, turn, attenuation, scale, diffuse=None):
    """One light's part through one behind response for `_lights_behind`: ``(value, low, high)``, each (N, 3).
    ``light``: ``(valid, wi, E, (E_low, E_high))`` as `incident_light` gives it; ``turn`` (N,) how far the GPU's
    ``wi`` may turn beyond the band's ``D eps`` (radians; 0 but at an exit point, `_exit_light`): the gate's and
    ``n.l``'s tolerance and the lobe's directions widen by it; ``attenuation``: ``(a, slack)``, the volume's factor
    (N, 3) and its relative error (1 and 0 without a volume); ``scale``: the weight's ``(low, high)``; ``diffuse``:
    ``(dt, c_dt)`` for the diffuse transmission's response (no lobe), None for the transmission's BTDF."""
    n = f.n
    valid, wi, irradiance, (e_low, e_high) = light
    out = [np.zeros((len(n), 3)) for _ in range(3)]
    tol = band.D * EPS + turn
    n_dot_wi = np.einsum("ij,ij->i", n, wi)
    possible = lit & valid & (n_dot_wi < tol)
    if not possible.any():
        return out
    certain = lit & valid & (n_dot_wi < -tol) & (n_dot_v > band.D * EPS)  # the response is 0 where n.v <= 0 (GLSL)
    n_dot_l = -n_dot_wi
    gate = (lit & valid & (n_dot_wi < 0.0))[:, None]
    a, slack = attenuation
    if diffuse is None:
        response = gltf_transmission_response(n, wi, wo, n_dot_l, p.c, p.m, p.t, p.r, p.ior, p.specular, p.layers,
                                              p.film)
    else:
        response = gltf_diffuse_transmission_response(n, wi, wo, n_dot_l, diffuse[1], p.m, p.t, diffuse[0], p.ior,
                                                      p.specular, p.layers, p.film)
    out[0] += np.where(gate, response * irradiance * a, 0.0)
    k = np.flatnonzero(possible)
    wide = dataclasses.replace(band, D=band.D + 4.0 + float(np.ceil(np.max(turn, initial=0.0) / EPS)))
    mirrored = wi[k] + (2.0 * n_dot_l[k])[:, None] * n[k]
    half = np.sqrt(np.einsum("ij,ij->i", mirrored + wo[k], mirrored + wo[k])) / 2.0
    spread = wide.D * EPS + 3.0 * EPS
    rel = band.A * EPS
    cancel = band.A * EPS  # 1 - F where F -> 1 (ior far above 1): F's own rounding, absolute, as the weight's slack
    if "specular" in used or "iridescence" in used:  # over the specular's interval too; the film's F'
        sub = SimpleNamespace(n=n[k], inputs={q: v[k] for q, v in (f.inputs or {}).items()},
                              input_bounds={q: tuple(b[k] for b in v) for q, v in (f.input_bounds or {}).items()})
        one_minus = list(_one_minus_fresnel(u, sub, used, p.ior[k], half - spread, half + spread))
    else:
        one_minus = [1.0 - gltf_transmission_fresnel(p.ior[k], c)[:, 0] for c in (half - spread, half + spread)]
    keep_lo, keep_hi = _layers_bounds(u, f, used, np.maximum(n_dot_v, 0.0), n_dot_l, tol, coat)
    if diffuse is None:
        lobe = SimpleNamespace(base_color=np.ones(3), metallic=np.ones(len(k)), roughness=p.r[k], ior=p.ior[k])
        lobe_low, lobe_high = (b[:, 0] for b in gltf_pbr_band(n[k], mirrored, wo[k], n_dot_l[k], lobe, wide))
    else:  # n_dot_l / pi
        lobe_low, lobe_high = np.maximum(n_dot_l[k] - tol[k], 0.0) / np.pi, (n_dot_l[k] + tol[k]) / np.pi
    a_lo, a_hi = a[k] * (1.0 - slack[k] if np.ndim(slack) else 1.0 - slack), \
        a[k] * (1.0 + slack[k] if np.ndim(slack) else 1.0 + slack)
    with np.errstate(invalid="ignore", over="ignore"):
        lo = scale[0][k] * (np.maximum(one_minus[0] - cancel, 0.0) * lobe_low * keep_lo[k])[:, None] * e_low[k] \
            * a_lo * (1.0 - rel)
        hi = scale[1][k] * ((one_minus[1] + cancel) * lobe_high * keep_hi[k])[:, None] * e_high[k] * a_hi * (1.0 + rel)
    out[1][k] += np.where(certain[k][:, None], np.nan_to_num(lo, nan=0.0), 0.0)
    out[2][k] += np.nan_to_num(hi, nan=np.inf, posinf=np.inf)
    return out


def _exit_light(incident, position, ray, band):
    """Each light seen from the exit points ``x' = position + ray`` (N, 3) (the generated loops' second incident call):
    ``[((valid, wi, E, (E_low, E_high)), turn), ...]`` in `incident_light`'s order.  The GPU forms ``x + ray`` in
    float32 from its own ``x`` (to ``D eps |x_i|`` per axis, as the band assumes of every point) and ``ray`` (its
    direction from ``n`` and ``wo`` to ``D eps`` each, then refract, normalize and the scale's product: within ``(D + 8)
    eps |ray|`` of it); the light's band at ``x'`` covers ``D eps |x'_i|`` (the sum's rounding among it) only, so each
    axis ``i`` is also moved by ``delta_i = D eps |x_i| + (D + 8) eps |ray|`` both ways and ``E`` widened by the sum
    over the axes of its largest move (first order: ``delta`` is a few ulps of the scene's lengths; for a point light
    ``|dE/E| ~ 2 delta / distance``, 0 for a directional one), ``turn`` the same sum of ``wi``'s moves (radians)."""
    exit = np.asarray(position, np.float64) + ray
    lights = list(incident(exit))
    length = np.sqrt(np.einsum("ij,ij->i", ray, ray))
    delta = band.D * EPS * np.abs(position) + ((band.D + 8.0) * EPS * length)[:, None]
    moves = []
    for axis in range(3):
        step = np.zeros_like(exit)
        step[:, axis] = delta[:, axis]
        moves.append([list(incident(exit + sign * step)) for sign in (-1.0, 1.0)])
    out = []
    for index, (valid, wi, e, (e_low, e_high)) in enumerate(lights):
        widen, turn = np.zeros_like(e_low), np.zeros(len(exit))
        for pair in moves:
            with np.errstate(invalid="ignore"):
                widen += np.nan_to_num(np.max([np.abs(moved[index][2] - e) for moved in pair], axis=0), nan=np.inf)
                turn += np.nan_to_num(np.max([np.linalg.norm(moved[index][1] - wi, axis=1) for moved in pair], axis=0),
                                      nan=np.pi)
        out.append(((valid, wi, e, (np.maximum(e_low - widen, 0.0), e_high + widen)), turn))
    return out


def _attenuation_slack(d, color, distance, path=8.0):
    """The relative error (N, 3) of the GPU's `gltf_volume_attenuation` ``color^y``, ``y = d / distance``, over a path
    ``d`` (N,) it forms in float32 to ``path`` eps relative: ``(16 + path |y ln color|) eps`` (pow's rounding, and
    ``y``'s error scaled by ``|d color^y / dy| / color^y = |ln color|``); 0 where ``distance`` is infinite or the
    colour 0.  ``path``: 8 by default (`_through_volume`'s, unchanged; the diffuse path ``thickness mean(s)``, a few
    roundings); the lights' exit ray takes ``D + 8`` (its direction from ``n`` and ``wo`` to ``D eps``, which a scale
    differing per axis turns into its length)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        y = np.asarray(d, np.float64) / distance
        return np.nan_to_num((16.0 + path * np.abs(y[:, None] * np.log(color))) * EPS, nan=0.0, posinf=0.0)
