"""KHR_materials_transmission on `glphong.GltfPBR` (docs/transmission.md; GLSL: ``glsl/transmission_thin.glsl`` and
the diffuse weight in ``glsl/materials/gltf_pbr.glsl``, both under the structural define ``GLTF_PBR_TRANSMISSION``).

The extension's dielectric is ``fresnel_mix(ior, base = mix(diffuse_brdf(c), specular_btdf(alpha) c, t), layer =
specular_brdf(alpha))``, ``t`` the transmission.  glphong draws its thin-walled form (no ``KHR_materials_volume``):

- a light on the viewer's side (``n.l > 0``) meets no BTDF (it is 0 there), so the reflection is the core material's
  with its diffuse weighted by ``1 - t`` (gltf_pbr.glsl and `glphong.materials.gltf_pbr`'s twin);
- what lies behind the surface is seen through it, from the opaque scene drawn first (the background ``B``):

      L_t = (1 - m) t (1 - F(n.v)) c B,   F(n.v) = f0 + (1 - f0) (1 - n.v)^5,  f0 = ((ior - 1)/(ior + 1))^2
      (times the layers' weight, below)

  For roughness 0 the BTDF is a delta on the straight-through ray (a thin wall does not bend it), ``B`` is the
  radiance of the next opaque surface along the pixel's own ray, and ``L_t`` is the specification's exactly.  For
  roughness ``r > 0``, ``B`` is a filtered lookup of the background image at the pixel, level of detail ``lod =
  log2(W) r clamp(2 ior - 2, 0, 1)`` (``W`` the image's width: the glTF Sample Viewer's rule), trilinear over a
  pyramid of 2x2 box means (`background_levels`); its error against the float64 integral of the lobe is measured
  (docs/transmission.md), not bounded.

``F`` is the library's Schlick (`glphong.twin.functions.fresnel_schlick`, fresnel.glsl); with KHR_materials_specular
the dielectric's ``F = specular fresnel_schlick(min(f0 specular_color, 1), c)`` (rgb) and the light let through is
weighted by ``1 - max3(F)``, as ``fresnel_mix`` weights its base (`gltf_transmission_fresnel`).  A sheen and a coat
over the base weight the light it lets through as they weight the base: ``max(min(1 - max3(sheen_color) E(n.v), 1 -
max3(sheen_color) E(|n.l|)), 0) (1 - clearcoat F_c(max(n_c.v, 0)))`` (`gltf_transmission_layers`; ``n_c`` the coat's
own normal where it has one, on the unperturbed frame, else ``n``).  A film (KHR_materials_iridescence) replaces the
dielectric's ``F`` by ``F' = mix(F, F_iridescence, iridescence)`` (`_film`), so the light let through takes ``1 -
max3(F')``.

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
from glphong.definitions.surface import _bilinear
from glphong.materials.gltf_iridescence import gltf_iridescence_fresnel
from glphong.materials.gltf_lobe import gltf_clearcoat_fresnel, gltf_pbr_specular
from glphong.materials.gltf_sheen import gltf_sheen_scaling
from glphong.twin.band import FLT_MAX
from glphong.twin.functions import fresnel_schlick, microfacet_geometry

__all__ = ["TRANSMISSION_PARAMS", "VOLUME_EXTENSIONS", "volume_extensions",
           "gltf_transmission_fresnel", "gltf_transmission_layers", "gltf_transmission_weight", "gltf_transmission_lod",
           "gltf_transmission_sample", "gltf_transmission_background", "gltf_volume_ray", "gltf_volume_uv",
           "gltf_volume_attenuation", "gltf_dispersion_iors", "gltf_volume_light", "gltf_volume_exit", "gltf_volume_exit_attenuation",
           "gltf_volume_diffuse_attenuation", "gltf_transmission_response", "gltf_transmission_radiance",
           "background_levels", "transmissive"]

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


def _film(fresnel, f0, c, film, specular=None, specular_color=None):
    """KHR_materials_iridescence over the dielectric's Fresnel ``fresnel`` (in transmission_thin.glsl's
    ``gltf_transmission_fresnel``): ``mix(F, F_iridescence(1, iridescence_ior, film_f0, thickness, clamp(c, 0, 1)),
    iridescence)``, ``film_f0 = min(f0 specular_color, 1) specular`` (``f0`` without KHR_materials_specular),
    `glphong.materials.gltf_iridescence.gltf_iridescence_fresnel`.

    Parameters
    ----------
    fresnel : (N, 3) ndarray
    f0 : (N,) ndarray or float
        ``((ior - 1)/(ior + 1))^2``.
    c : (N,) ndarray
        The cosine (the arithmetic follows its dtype).
    film : mapping
        ``iridescence`` and ``iridescence_ior`` ((N,) or floats) and ``thickness`` [nm] (``mix(thickness_minimum,
        thickness_maximum, thickness_mix)``).
    specular, specular_color : optional
        KHR_materials_specular's (`gltf_transmission_fresnel`).

    Returns
    -------
    (N, 3) ndarray, dimensionless
    """
    c = np.asarray(c)
    dtype = c.dtype if c.dtype.kind == "f" else np.dtype(np.float64)
    one = dtype.type(1)
    f0 = np.asarray(f0).astype(dtype)[..., None]
    if specular_color is None:
        film_f0 = np.broadcast_to(f0, c.shape + (3,))
    else:
        film_f0 = np.minimum(f0 * np.asarray(specular_color).astype(dtype), one) * \
            np.asarray(specular).astype(dtype)[..., None]
    irid = gltf_iridescence_fresnel(one, np.asarray(film["iridescence_ior"]).astype(dtype), film_f0.astype(dtype),
                                    np.asarray(film["thickness"]).astype(dtype), np.clip(c, 0, 1).astype(dtype))
    w = np.asarray(film["iridescence"]).astype(dtype)[..., None]
    return (np.asarray(fresnel).astype(dtype) * (one - w) + irid * w).astype(dtype)


def gltf_transmission_fresnel(ior, c, specular=None, specular_color=None, film=None):
    """The dielectric's Fresnel factor on the cosine ``c`` (transmission_thin.glsl's ``gltf_transmission_fresnel``):
    `glphong.twin.functions.fresnel_schlick` of ``f0 = ((ior - 1)/(ior + 1))^2`` (grey), or with KHR_materials_specular
    ``specular fresnel_schlick(min(f0 specular_color, 1), c)`` (= ``mix(min(f0 specular_color, 1) specular, specular,
    x)``, the specification's ``F`` of ``fresnel_mix``); with KHR_materials_iridescence ``film`` (`_film`'s mapping)
    the film's ``F'`` over it.

    Parameters
    ----------
    ior : (N,) ndarray or float
    c : (N,) ndarray
        The cosine (float32 or float64: the arithmetic follows it).
    specular : (N,) ndarray or float, optional
    specular_color : (N, 3) or (3,) ndarray, optional
        KHR_materials_specular's weight and colour; ``None``: the core's grey Fresnel.

    Returns
    -------
    (N, 3) ndarray, dimensionless
    """
    c = np.asarray(c)
    dtype = c.dtype if c.dtype.kind == "f" else np.float64
    one = dtype.type(1)
    ior = np.asarray(ior).astype(dtype)
    r = ((ior - one) / (ior + one)).astype(dtype)
    f0 = (r * r).astype(dtype)[..., None]
    if specular_color is None:
        fresnel = np.broadcast_to(fresnel_schlick(f0, c.astype(dtype)), c.shape + (3,)).astype(dtype)
    else:
        fresnel = (np.asarray(specular).astype(dtype)[..., None]
                   * fresnel_schlick(np.minimum(f0 * np.asarray(specular_color).astype(dtype), one), c.astype(dtype)))
    if film is None:
        return fresnel.astype(dtype)
    return _film(fresnel, f0[..., 0], c, film, specular, specular_color)


def gltf_transmission_layers(n_dot_v, n_dot_l, sheen_color=None, sheen_roughness=0.0, clearcoat=None,
                             coat_n_dot_v=None):
    """What the layers over the base leave of the light it lets through (transmission_thin.glsl's
    ``gltf_transmission_layers``): KHR_materials_sheen's albedo scaling
    `glphong.materials.gltf_sheen.gltf_sheen_scaling` ``(n.v, n_dot_l)``, times KHR_materials_clearcoat's ``1 -
    clearcoat F_c(n_c.v)`` on the coat's normal ``n_c`` (``n`` itself without a coat normal; the GLSL forms ``max(n_c.v,
    0)`` from the frame, the twin's callers with `_coat_cosine`); 1 without them.

    Parameters
    ----------
    n_dot_v, n_dot_l : (N,) ndarray
        The view's cosine and the light's ``|n.l|`` (behind the surface: ``-n.wi``; the background seen straight
        through: ``n.v``).
    sheen_color : (N, 3) or (3,) ndarray, optional
    sheen_roughness : (N,) ndarray or float
    clearcoat : (N,) ndarray or float, optional
    coat_n_dot_v : (N,) ndarray, optional
        ``max(n_c.v, 0)`` on the coat's own normal (`glphong.materials.gltf_coat_normal.gltf_clearcoat_normal`);
        None: ``n_dot_v``.

    Returns
    -------
    (N,) float64 ndarray, dimensionless, in [0, 1]
    """
    n_dot_v = np.asarray(n_dot_v, np.float64)
    keep = np.ones(n_dot_v.shape)
    if sheen_color is not None:
        keep = gltf_sheen_scaling(n_dot_v, np.asarray(n_dot_l, np.float64), sheen_color, sheen_roughness)
    if clearcoat is not None:
        cosine = n_dot_v if coat_n_dot_v is None else np.asarray(coat_n_dot_v, np.float64)
        keep = keep * (1.0 - np.asarray(clearcoat, np.float64) * gltf_clearcoat_fresnel(cosine))
    return keep


def _coat_cosine(layers, wo):
    """`gltf_transmission_layers`' keywords from ``layers`` (as `gltf_transmission_radiance` takes them): a
    ``coat_normal`` (N, 3), the coat's own normal, becomes ``coat_n_dot_v = max(n_c.v, 0)`` (transmission_thin.glsl
    forms it in ``gltf_transmission_layers``)."""
    layers = dict(layers or {})
    coat_normal = layers.pop("coat_normal", None)
    if coat_normal is not None:
        layers["coat_n_dot_v"] = np.maximum(np.einsum("ij,ij->i", np.asarray(coat_normal, np.float64),
                                                      np.asarray(wo, np.float64)), 0.0)
    return layers


def gltf_transmission_weight(n_dot_v, c, m, t, ior, specular=None, specular_color=None, film=None):
    """The weight of the background, ``(1 - m) t (1 - max3(F(n.v))) c``, `gltf_transmission_fresnel` (its Schlick
    clamps ``n.v`` to [0, 1]; transmission_thin.glsl's ``gltf_transmission_weight``).

    Parameters
    ----------
    n_dot_v : (N,) ndarray
        The shading normal against the view (float32 or float64: the arithmetic follows it).
    c : (N, 3) or (3,) ndarray
        Base colour.
    m, t, ior : (N,) ndarray or float
        Metallic, transmission, index of refraction.
    specular, specular_color : optional
        KHR_materials_specular's (`gltf_transmission_fresnel`).
    film : mapping, optional
        KHR_materials_iridescence's (`_film`).

    Returns
    -------
    (N, 3) ndarray, dimensionless
    """
    n_dot_v = np.asarray(n_dot_v)
    dtype = n_dot_v.dtype if n_dot_v.dtype.kind == "f" else np.float64
    one = dtype.type(1)
    fresnel = np.max(gltf_transmission_fresnel(ior, n_dot_v.astype(dtype), specular, specular_color, film), axis=-1)
    scale = ((one - np.asarray(m).astype(dtype)) * np.asarray(t).astype(dtype) * (one - fresnel)).astype(dtype)
    return (np.asarray(c).astype(dtype) * scale[..., None]).astype(dtype)


def gltf_transmission_lod(roughness, ior, levels):
    """``lod = levels r clamp(2 ior - 2, 0, 1)`` (transmission_thin.glsl; the Sample Viewer's ``applyIorToRoughness``
    times ``log2`` of the background's width, ``levels``); (N,) -> (N,)."""
    roughness = np.asarray(roughness)
    dtype = roughness.dtype if roughness.dtype.kind == "f" else np.float64
    ior = np.asarray(ior).astype(dtype)
    return (dtype.type(levels) * roughness * np.clip(dtype.type(2) * ior - dtype.type(2), 0, 1)).astype(dtype)


def gltf_transmission_sample(levels, uv, lod):
    """``textureLod`` of the background's pyramid ``levels`` (`background_levels`, GL row order) at ``uv`` (N, 2) and
    level of detail ``lod`` (N,) >= 0, GL_LINEAR_MIPMAP_LINEAR clamped to the edge (transmission_thin.glsl's
    ``gltf_transmission_sample``): the linear mix of the bilinear lookups of the two levels about ``lod`` (the coarsest
    beyond it; level 0 alone at ``lod = 0``); (N, C) float64."""
    top = len(levels) - 1
    lod = np.minimum(np.asarray(lod, np.float64), top)
    d1 = np.floor(lod).astype(np.int64)
    frac = lod - d1
    value = np.zeros((len(uv), levels[0].shape[2]))
    for k in np.unique(d1):
        at = d1 == k
        a = _bilinear(levels[k], uv[at], "clamp")[0]
        b = _bilinear(levels[min(k + 1, top)], uv[at], "clamp")[0]
        value[at] = (1.0 - frac[at])[:, None] * a + frac[at][:, None] * b
    return value


def gltf_transmission_background(levels, fragcoord, lod):
    """``B`` of a thin wall (transmission_thin.glsl's ``gltf_transmission_background``): the background's texel at the
    pixel (``texelFetch``) where ``lod`` is 0, `gltf_transmission_sample` at the pixel's centre above.  ``fragcoord``
    (N, 2): the pixels' centres in window coordinates (``gl_FragCoord.xy``, y up), ``lod`` (N,); (N, C) float64."""
    fragcoord = np.asarray(fragcoord, np.float64)
    size = np.array([levels[0].shape[1], levels[0].shape[0]], np.float64)
    pixel = np.floor(fragcoord).astype(np.int64)
    out = np.asarray(levels[0], np.float64)[pixel[:, 1], pixel[:, 0]].copy()
    rough = np.asarray(lod) > 0
    out[rough] = gltf_transmission_sample(levels, fragcoord[rough] / size, np.asarray(lod)[rough])
    return out


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
    distance) and where ``d <= 0`` (no path); d (N,), color (3,) or (N, 3), distance scalar -> (N, 3)."""
    d = np.asarray(d, np.float64)
    if float(distance) >= FLT_MAX:
        return np.ones(d.shape + (3,))
    with np.errstate(divide="ignore"):  # d <= 0: no path, 1 (GLSL's pow(0, 0) is undefined: transmission_thin.glsl)
        return np.where((d <= 0.0)[..., None], 1.0, np.asarray(color, np.float64) ** (d / float(distance))[..., None])


def gltf_dispersion_iors(ior, dispersion):
    """KHR_materials_dispersion's iors of the red, green and blue channels (transmission_thin.glsl's
    ``gltf_transmission_radiance`` forms them inline): ``max(ior - h, 1)``, ``ior``, ``ior + h`` with ``h = (ior - 1)
    0.025 dispersion`` (half of ``n_F - n_C = (n_d - 1)/V_d``, ``dispersion = 20/V_d``), the red kept at 1 or above
    (below it a grazing view has no refracted ray).  ior (N,) or float; dispersion float -> a tuple of three."""
    half = (np.asarray(ior, np.float64) - 1.0) * 0.025 * float(dispersion)
    return np.maximum(ior - half, 1.0), ior, ior + half


def gltf_volume_light(levels, x, n, wo, eta, roughness, thickness, scale, view_projection, color, distance):
    """``B`` through a volume (transmission_thin.glsl's ``gltf_volume_light``): `gltf_transmission_sample` where the
    exit point ``x + gltf_volume_ray(n, wo, eta, thickness, scale)`` projects (`gltf_volume_uv`), at
    `gltf_transmission_lod` of ``roughness`` and ``eta`` (formed in float32, as the GPU forms it; ``levels``' width
    gives ``log2 W``), times `gltf_volume_attenuation` over the ray's length.  x, n, wo (N, 3); eta, roughness,
    thickness (N,) or floats; scale (3,); view_projection (4, 4); color (3,), distance float -> (N, C) float64."""
    ray = gltf_volume_ray(n, wo, eta, thickness, scale)
    uv = gltf_volume_uv(np.asarray(x, np.float64) + ray, view_projection)
    lod = gltf_transmission_lod(np.asarray(roughness).astype(np.float32), np.asarray(eta).astype(np.float32),
                                np.log2(levels[0].shape[1])).astype(np.float64)
    lod = np.broadcast_to(lod, (len(uv),))
    length = np.sqrt(np.einsum("ij,ij->i", ray, ray))
    return gltf_transmission_sample(levels, uv, lod) * gltf_volume_attenuation(length, color, distance)


def gltf_volume_exit(n, wo, ior, thickness, scale):
    """Where a point, spot or directional light behind a volume is seen from: ``x + gltf_volume_exit(...)``,
    `gltf_volume_ray` at the material's ``ior`` (no dispersion; transmission_thin.glsl's ``gltf_volume_exit``, the
    Sample Viewer's ``transmissionRay``).  n, wo (N, 3); ior, thickness (N,) or floats; scale (3,) -> (N, 3) [m]."""
    return gltf_volume_ray(n, wo, ior, thickness, scale)


def gltf_volume_exit_attenuation(n, wo, ior, thickness, scale, color, distance):
    """What the volume leaves of a light behind it along `gltf_volume_exit`: `gltf_volume_attenuation` over its
    length (transmission_thin.glsl's ``gltf_volume_exit_attenuation``); arguments as `gltf_volume_exit`'s, color
    (3,), distance float -> (N, 3)."""
    ray = gltf_volume_exit(n, wo, ior, thickness, scale)
    return gltf_volume_attenuation(np.sqrt(np.einsum("ij,ij->i", ray, ray)), color, distance)


def gltf_volume_diffuse_attenuation(thickness, scale, color, distance):
    """What the volume leaves of the diffusely transmitted light (transmission_thin.glsl's
    ``gltf_volume_diffuse_attenuation``, the Sample Viewer's ``diffuseTransmissionThickness``):
    `gltf_volume_attenuation` over ``thickness (s_x + s_y + s_z) / 3``, the path not refracted.  thickness (N,),
    scale (3,), color (3,), distance float -> (N, 3)."""
    return gltf_volume_attenuation(np.asarray(thickness, np.float64) * np.mean(np.asarray(scale, np.float64)), color,
                                   distance)


def gltf_transmission_response(n, wi, wo, n_dot_l, c, m, t, roughness, ior, specular=None, layers=None, film=None):
    """The BTDF of a punctual light behind a thin wall times ``n_dot_l = -n.wi > 0`` (transmission_thin.glsl's
    ``gltf_transmission_response``): ``(1 - m) t c (1 - max3(F(v.h'))) D V (n.l')`` with the light mirrored through
    the surface, ``l' = wi + 2 n_dot_l n``, ``h' = normalize(l' + v)``, ``F`` `gltf_transmission_fresnel`, ``D V
    (n.l')`` `gltf_pbr_specular` (0 for roughness 0), times `gltf_transmission_layers` ``(n.v, n_dot_l)``.  n, wi, wo
    (N, 3); n_dot_l, m, t, roughness, ior (N,) or scalars; c (N, 3) or (3,); ``specular``: ``(specular,
    specular_color)`` (KHR_materials_specular) or None; ``layers``: `gltf_transmission_layers`' keywords (the coat's
    own normal as ``coat_normal`` (N, 3)) or None; ``film``: KHR_materials_iridescence's (`_film`) or
    None -> (N, 3) [1/sr], float64."""
    n_dot_l = np.asarray(n_dot_l, np.float64)
    mirrored = wi + (2.0 * n_dot_l)[:, None] * n
    valid, n_dot_v, _, v_dot_h, tan2 = microfacet_geometry(n, mirrored, wo, n_dot_l)
    alpha = np.asarray(roughness, np.float64) ** 2
    lobe = gltf_pbr_specular(alpha * alpha, tan2, n_dot_l, n_dot_v)
    specular, specular_color = specular or (None, None)
    fresnel = np.max(gltf_transmission_fresnel(ior, v_dot_h, specular, specular_color, film), axis=-1)
    value = np.asarray(c, np.float64) * ((1.0 - np.asarray(m)) * np.asarray(t) * (1.0 - fresnel) * lobe)[:, None]
    keep = gltf_transmission_layers(n_dot_v, n_dot_l, **_coat_cosine(layers, wo))
    return np.where(valid[:, None], value * keep[:, None], 0.0)


def gltf_transmission_radiance(levels, fragcoord, x, n, wo, valid, p, volume=None):
    """``L_t``, what a transmissive surface shows of what lies behind it (transmission_thin.glsl's
    ``gltf_transmission_radiance``): ``gltf_transmission_weight(n.v) B gltf_transmission_layers(n.v, n.v)``, ``B``
    `gltf_transmission_background` at ``gltf_transmission_lod(r, ior)`` (formed in float32), or through a volume
    `gltf_volume_light` (per channel its own ior, ``ior -+ (ior - 1) 0.025 dispersion``, the red kept at 1 or above,
    where it disperses); 0 where
    not ``valid``.

    Parameters
    ----------
    levels : list of (h, w, C) ndarray
        The background's pyramid (`background_levels`, GL row order).
    fragcoord : (N, 2) ndarray
        The pixels' centres in window coordinates.
    x, n, wo : (N, 3) ndarray
        Position [m], unit normal, unit direction toward the viewer.
    valid : (N,) bool ndarray
    p : namespace
        Per fragment: ``c`` (N, 3), ``m``, ``t``, ``r``, ``ior`` (N,), ``specular`` (as `gltf_transmission_response`'s),
        ``film`` (`_film`'s mapping; absent or None: no film)
        and ``layers`` (`gltf_transmission_layers`' keywords, the coat's own normal as ``coat_normal`` (N, 3)), each
        possibly None.
    volume : dict, optional
        KHR_materials_volume's ``thickness`` (N,), ``scale`` (3,), ``view_projection`` (4, 4), ``color`` (3,),
        ``distance``, and ``dispersion`` (0 or None: none).

    Returns
    -------
    (N, 3) float64 ndarray [W/(m^2 sr)] (the background's unit)
    """
    n_dot_v = np.einsum("ij,ij->i", n, wo)
    if volume is None:
        lod = gltf_transmission_lod(np.asarray(p.r).astype(np.float32), np.asarray(p.ior).astype(np.float32),
                                    np.log2(levels[0].shape[1])).astype(np.float64)
        behind = gltf_transmission_background(levels, fragcoord, np.broadcast_to(lod, (len(n),)))
    else:
        def light(eta):
            return gltf_volume_light(levels, x, n, wo, eta, p.r, volume["thickness"], volume["scale"],
                                     volume["view_projection"], volume["color"], volume["distance"])

        if volume.get("dispersion"):  # KHR_materials_dispersion: each channel its own ior
            behind = np.stack([light(eta)[:, k] for k, eta in
                               enumerate(gltf_dispersion_iors(p.ior, float(volume["dispersion"])))], 1)
        else:
            behind = light(p.ior)
    weight = gltf_transmission_weight(n_dot_v, p.c, p.m, p.t, p.ior, *(p.specular or (None, None)),
                                      getattr(p, "film", None))
    keep = gltf_transmission_layers(np.maximum(n_dot_v, 0.0), np.maximum(n_dot_v, 0.0), **_coat_cosine(p.layers, wo))
    return np.where(np.asarray(valid)[:, None], weight * behind * keep[:, None], 0.0)
