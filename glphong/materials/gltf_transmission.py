"""KHR_materials_transmission on `glphong.GltfPBR` (docs/transmission.md; GLSL: ``glsl/transmission_thin.glsl`` and
the diffuse weight in ``glsl/materials/gltf_pbr.glsl``, both under the structural define ``GLTF_PBR_TRANSMISSION``).

The extension's dielectric is ``fresnel_mix(ior, base = mix(diffuse_brdf(c), specular_btdf(alpha) c, t), layer =
specular_brdf(alpha))``, ``t`` the transmission.  glphong draws its thin-walled form (no ``KHR_materials_volume``):

- a light on the viewer's side (``n.l > 0``) meets no BTDF (it is 0 there), so the reflection is the core material's
  with its diffuse weighted by ``1 - t`` (gltf_pbr.glsl and `glphong.materials.gltf_pbr`'s twin);
- what lies behind the surface is seen through it, from the opaque scene drawn first (the background ``B``):

      L_t = (1 - m) t (1 - F(n.v)) c B,   F(n.v) = f0 + (1 - f0) (1 - n.v)^5,  f0 = ((ior - 1)/(ior + 1))^2

  For roughness 0 the BTDF is a delta on the straight-through ray (a thin wall does not bend it), ``B`` is the
  radiance of the next opaque surface along the pixel's own ray, and ``L_t`` is the specification's exactly.  For
  roughness ``r > 0``, ``B`` is a filtered lookup of the background image at the pixel, level of detail ``lod =
  log2(W) r clamp(2 ior - 2, 0, 1)`` (``W`` the image's width: the glTF Sample Viewer's rule), trilinear over a
  pyramid of 2x2 box means (`background_levels`); its error against the float64 integral of the lobe is measured
  (docs/transmission.md), not bounded.

=================== ====== ========= ======= ==========================================================================
parameter           kind   range     neutral meaning
=================== ====== ========= ======= ==========================================================================
transmission        scalar [0, 1]    0       ``transmissionFactor`` times ``transmissionTexture.r``: the dielectric's
                                             share transmitted
=================== ====== ========= ======= ==========================================================================
"""
import numpy as np

from glphong.definitions.material_base import constant_part
from glphong.definitions.params import Param
from glphong.materials.gltf_lobe import gltf_pbr_specular
from glphong.twin.band import FLT_MAX
from glphong.twin.functions import microfacet_geometry

__all__ = ["TRANSMISSION_PARAMS", "VOLUME_EXTENSIONS", "volume_extensions", "gltf_transmission_weight", "gltf_volume_ray",
           "gltf_volume_uv", "gltf_volume_attenuation", "gltf_transmission_response", "gltf_transmission_lod", "background_levels",
           "transmissive"]

_TRANSMISSION = Param("transmission", "scalar", low=0.0, high=1.0, default=0.0, unit="", textureable=True,
                      doc="KHR_materials_transmission transmissionFactor (times transmissionTexture.r): the "
                          "dielectric's share transmitted (thin walls)")
_THICKNESS = Param("thickness", "scalar", low=0.0, default=0.0, unit="m (the mesh's own units)", textureable=True,
                   doc="KHR_materials_volume thicknessFactor (times thicknessTexture.g): the volume's thickness in the "
                       "mesh's frame; 0: thin walls")
_ATTENUATION_DISTANCE = Param("attenuation_distance", "scalar", low=0.0, low_inclusive=False, default=float(FLT_MAX),
                              unit="m", doc="KHR_materials_volume attenuationDistance: the distance over which light "
                                            "keeps attenuation_color of itself; FLT_MAX (the default): no attenuation "
                                            "(the specification's +Infinity)")
_ATTENUATION_COLOR = Param("attenuation_color", "rgb", low=0.0, high=1.0, default=1.0, unit="",
                           doc="KHR_materials_volume attenuationColor (linear): the transmittance over "
                               "attenuation_distance")
_DISPERSION = Param("dispersion", "scalar", low=0.0, high=1e4, default=0.0, unit="",
                    doc="KHR_materials_dispersion dispersion = 20 / V_d (the Abbe number): the spread of the volume's "
                        "ior per channel; 0: none")
#: the extensions' parameters, appended to `GltfPBR`'s (`glphong.materials.gltf_extensions`): transmission, volume
#: and dispersion
TRANSMISSION_PARAMS = (_TRANSMISSION, _THICKNESS, _ATTENUATION_DISTANCE, _ATTENUATION_COLOR, _DISPERSION)
#: KHR_materials_volume's parameters and KHR_materials_dispersion's, by glphong's short names of the extensions
VOLUME_EXTENSIONS = {"volume": ("KHR_materials_volume", ("thickness", "attenuation_distance", "attenuation_color")),
                     "dispersion": ("KHR_materials_dispersion", ("dispersion",))}


def transmissive(material):
    """Whether ``material`` transmits (a `GltfPBR` using KHR_materials_transmission or _diffuse_transmission: both
    are drawn over the opaque scene, their lights behind the surface added by the same loops)."""
    extensions = getattr(material, "extensions", None)
    return callable(extensions) and bool({"transmission", "diffuse_transmission"} & set(extensions()))


def volume_extensions(material):
    """The volume extensions ``material`` (a transmissive `GltfPBR`) uses: 'volume' where ``thickness`` is above 0,
    'dispersion' where it has a volume and ``dispersion`` is above 0 (tuple of str; neither changes a thin wall)."""
    if not np.any(constant_part(material.thickness)):
        return ()
    return ("volume",) + (("dispersion",) if float(material.dispersion) > 0.0 else ())


def gltf_transmission_weight(n_dot_v, c, m, t, ior):
    """The weight of the background, ``(1 - m) t (1 - F(n.v)) c``, ``F = f0 + (1 - f0) (1 - max(n.v, 0))^5``
    (transmission_thin.glsl's ``gltf_transmission_weight``).

    Parameters
    ----------
    n_dot_v : (N,) ndarray
        The shading normal against the view (float32 or float64: the arithmetic follows it).
    c : (N, 3) or (3,) ndarray
        Base colour.
    m, t, ior : (N,) ndarray or float
        Metallic, transmission, index of refraction.

    Returns
    -------
    (N, 3) ndarray, dimensionless
    """
    n_dot_v = np.asarray(n_dot_v)
    dtype = n_dot_v.dtype if n_dot_v.dtype.kind == "f" else np.float64
    one = dtype.type(1)
    ior = np.asarray(ior).astype(dtype)
    r = ((ior - one) / (ior + one)).astype(dtype)
    f0 = (r * r).astype(dtype)
    y1 = (one - np.maximum(n_dot_v.astype(dtype), dtype.type(0))).astype(dtype)
    y = ((y1 * y1) * (y1 * y1) * y1).astype(dtype)
    fresnel = (f0 + (one - f0) * y).astype(dtype)
    scale = ((one - np.asarray(m).astype(dtype)) * np.asarray(t).astype(dtype) * (one - fresnel)).astype(dtype)
    return (np.asarray(c).astype(dtype) * scale[..., None]).astype(dtype)


def gltf_transmission_lod(roughness, ior, levels):
    """``lod = levels r clamp(2 ior - 2, 0, 1)`` (transmission_thin.glsl; the Sample Viewer's ``applyIorToRoughness``
    times ``log2`` of the background's width, ``levels``); (N,) -> (N,)."""
    roughness = np.asarray(roughness)
    dtype = roughness.dtype if roughness.dtype.kind == "f" else np.float64
    ior = np.asarray(ior).astype(dtype)
    return (dtype.type(levels) * roughness * np.clip(dtype.type(2) * ior - dtype.type(2), 0, 1)).astype(dtype)


def background_levels(image, dtype=np.float64):
    """The pyramid of 2x2 box means of ``image`` (H, W, C): level ``k + 1`` is ``floor(w_k / 2) x floor(h_k / 2)``
    (at least 1), each texel the mean of the 2x2 block at ``(2i, 2j)`` of level ``k`` (the block clamped at the edge
    where level ``k`` is 1 wide), down to 1 x 1; the GPU's background mipmap (`glphong.gpu.transmission`), computed in
    ``dtype``.  Returns a list of (h_k, w_k, C) arrays in the input's row order (the GPU's: row 0 at the bottom)."""
    levels = [np.asarray(image, dtype)]
    while levels[-1].shape[0] > 1 or levels[-1].shape[1] > 1:
        top = levels[-1]
        h, w = top.shape[:2]
        rows = np.minimum(np.arange(2 * max(h // 2, 1)), h - 1)
        cols = np.minimum(np.arange(2 * max(w // 2, 1)), w - 1)
        block = top[rows][:, cols]
        quarter = np.dtype(dtype).type(0.25)
        levels.append(((block[0::2, 0::2] + block[0::2, 1::2]) + (block[1::2, 0::2] + block[1::2, 1::2])) * quarter)
    return levels


def _factor_and_texture(value, factor_key, texture_key, channel, texture_index):
    """A textureable parameter as glTF writes it: ``{factor_key: scale}`` and, where it reads a texture's ``channel``,
    ``{texture_key: {"index": ...}}``."""
    texture = getattr(value, "texture", None)
    fields = {factor_key: float(constant_part(value))}
    if texture is not None and value.channel == channel:
        fields[texture_key] = {"index": texture_index(texture)}
    return fields


def transmission_gltf_fields(material, texture_index):
    """The ``KHR_materials_transmission`` entry of a `GltfPBR`'s glTF material where it transmits, and
    ``KHR_materials_volume`` and ``KHR_materials_dispersion`` where it uses them (dict, empty otherwise): the factors,
    and the textures where the parameter reads the channel glTF gives it (``transmissionTexture.r``,
    ``thicknessTexture.g``); an attenuation distance of FLT_MAX is left out (the specification's +Infinity)."""
    if "transmission" not in material.extensions():
        return {}
    out = {"KHR_materials_transmission": _factor_and_texture(material.transmission, "transmissionFactor",
                                                             "transmissionTexture", "r", texture_index)}
    used = volume_extensions(material)
    if "volume" in used:
        volume = _factor_and_texture(material.thickness, "thicknessFactor", "thicknessTexture", "g", texture_index)
        volume["attenuationColor"] = [float(c) for c in np.broadcast_to(material.attenuation_color, 3)]
        if float(material.attenuation_distance) < FLT_MAX:
            volume["attenuationDistance"] = float(material.attenuation_distance)
        out["KHR_materials_volume"] = volume
    if "dispersion" in used:
        out["KHR_materials_dispersion"] = {"dispersion": float(material.dispersion)}
    return out


def gltf_volume_ray(n, wo, eta, thickness, scale):
    """KHR_materials_volume's ray through the volume, ``normalize(refract(-wo, n, 1/eta)) thickness s`` (GLSL's
    ``refract``: 0 where ``k = 1 - (1/eta)^2 (1 - (n.i)^2) < 0``; transmission_thin.glsl's ``gltf_volume_ray``).

    Parameters
    ----------
    n, wo : (N, 3) ndarray
        Unit normal and direction toward the viewer.
    eta, thickness : (N,) ndarray or float
        The index of refraction and the thickness [the mesh's units].
    scale : (3,) ndarray
        The lengths of the pose's three columns (the node's scale per axis).

    Returns
    -------
    (N, 3) ndarray [m]
    """
    i = -np.asarray(wo, np.float64)
    ratio = 1.0 / np.asarray(eta, np.float64)
    d = np.einsum("ij,ij->i", n, i)
    k = 1.0 - ratio * ratio * (1.0 - d * d)
    with np.errstate(invalid="ignore", divide="ignore"):
        r = np.where((k < 0.0)[:, None], 0.0, ratio[..., None] * i - (ratio * d + np.sqrt(np.maximum(k, 0.0)))[:, None] * n)
        r = r / np.sqrt(np.einsum("ij,ij->i", r, r))[:, None]
    return r * np.asarray(thickness, np.float64)[..., None] * np.asarray(scale, np.float64)


def gltf_volume_uv(p, view_projection):
    """Where the points ``p`` (N, 3) project: ``((P p).xy / (P p).w + 1) / 2`` with ``P`` = ``view_projection`` (4, 4),
    texture coordinates of the background (GL's: v up); (N, 2)."""
    clip = np.asarray(p, np.float64) @ np.asarray(view_projection)[:, :3].T + np.asarray(view_projection)[:, 3]
    return (clip[:, :2] / clip[:, 3:4] + 1.0) * 0.5


def gltf_volume_attenuation(d, color, distance):
    """Beer-Lambert, ``color^(d / distance)`` per channel, 1 where ``distance >= FLT_MAX`` (the specification's infinite
    distance); d (N,), color (3,) or (N, 3), distance scalar -> (N, 3)."""
    d = np.asarray(d, np.float64)
    if float(distance) >= FLT_MAX:
        return np.ones(d.shape + (3,))
    with np.errstate(divide="ignore"):
        return np.asarray(color, np.float64) ** (d / float(distance))[..., None]


def gltf_transmission_response(n, wi, wo, n_dot_l, c, m, t, roughness, ior):
    """The BTDF of a punctual light behind a thin wall times ``n_dot_l = -n.wi > 0`` (transmission_thin.glsl's
    ``gltf_transmission_response``): ``(1 - m) t c (1 - F(v.h')) D V (n.l')`` with the light mirrored through the
    surface, ``l' = wi + 2 n_dot_l n``, ``h' = normalize(l' + v)``, ``D V (n.l')`` `gltf_pbr_specular` (0 for roughness
    0).  n, wi, wo (N, 3); n_dot_l, m, t, roughness, ior (N,) or scalars; c (N, 3) or (3,) -> (N, 3) [1/sr], float64."""
    n_dot_l = np.asarray(n_dot_l, np.float64)
    mirrored = wi + (2.0 * n_dot_l)[:, None] * n
    valid, n_dot_v, _, v_dot_h, tan2 = microfacet_geometry(n, mirrored, wo, n_dot_l)
    alpha = np.asarray(roughness, np.float64) ** 2
    lobe = gltf_pbr_specular(alpha * alpha, tan2, n_dot_l, n_dot_v)
    ior = np.asarray(ior, np.float64)
    f0 = ((ior - 1.0) / (ior + 1.0)) ** 2
    fresnel = f0 + (1.0 - f0) * np.maximum(1.0 - v_dot_h, 0.0) ** 5
    value = np.asarray(c, np.float64) * ((1.0 - np.asarray(m)) * np.asarray(t) * (1.0 - fresnel) * lobe)[:, None]
    return np.where(valid[:, None], value, 0.0)
