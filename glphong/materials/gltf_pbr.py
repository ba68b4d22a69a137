"""The model 'gltf_pbr' and the material `GltfPBR`: glTF 2.0's metallic-roughness material exactly as the
specification's Appendix B writes it (docs/design.md section 9; GLSL: ``glsl/materials/gltf_pbr.glsl``)::

    alpha = roughness^2,  x = (1 - |v.h|)^5
    D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2)                                   GGX
    V = 1 / (2 (|n.v| sqrt(alpha^2 + (1 - alpha^2)(n.l)^2) + |n.l| sqrt(alpha^2 + (1 - alpha^2)(n.v)^2)))
    metal = (c + (1 - c) x) V D
    dielectric = mix(c / pi, V D, f0 + (1 - f0) x),  f0 = ((ior - 1)/(ior + 1))^2 = 0.04 for ior 1.5
    f_r = mix(dielectric, metal, metallic)                                              [1/sr]

=========== ====== ======= ======================================================================
parameter   kind   range   meaning
=========== ====== ======= ======================================================================
base_color  rgb    [0, 1]  ``baseColorFactor``: the diffuse colour of a dielectric, ``f0`` of a metal
metallic    scalar [0, 1]  ``metallicFactor``: mixes the dielectric (0) and the metal (1)
roughness   scalar [0, 1]  ``roughnessFactor``: ``alpha = roughness^2``
=========== ====== ======= ======================================================================

Numerics (float32, branchless, never NaN or Inf; see the GLSL header): the half-vector geometry is the library chunk
``microfacet.glsl`` (`glphong.twin.functions.microfacet_geometry`, shared with Cook-Torrance: ``tan^2(theta_h)`` from
the chord), and D (``microfacet_ggx``, shared with Cook-Torrance's GGX option) is divided through by ``(n.h)^4``: ``D = (alpha^2 r) r / pi``, ``r = 1 + (1 - alpha^2)/(alpha^2 +
tan^2)``, a sum of positive terms (at the peak ``alpha^2 + tan^2 = alpha^2``: 1e-16 at roughness 1e-4), ``r`` saturated;
``V (n.l)`` is formed with the response's ``n.l`` cancelled against V's.  Roughness 0 is a mirror: D is a delta
at ``h = n`` that a point light meets with zero measure, so the program reflects 0 there (and everywhere else
the specification's D is 0 too); no NaN.

Properties: non-negative, reciprocal (D, V and the Fresnel factor of ``|v.h| = |l.h|`` are symmetric in l and v),
isotropic.  Energy: not conserved, as the specification says of its Fresnel mix.  Directional albedo with base colour 1
(`glphong.analysis.albedo`, error estimates below 1e-5 up to 85 degrees):

========== ============ ====== ====== ====== ======
roughness  metallic     0 deg  60 deg 85 deg 89 deg
========== ============ ====== ====== ====== ======
0.05       0 dielectric 1.000  1.025  1.586  1.84
0.3        0            1.000  1.025  1.294  1.359
1          0            0.972  0.976  0.995  1.010
0.3        1 metal      0.991  0.975  0.886  0.958
1          1            0.307  0.451  0.780  0.929
========== ============ ====== ====== ====== ======

The dielectric gains energy at oblique incidence (the diffuse part is weighted by ``1 - F(v.h)`` per direction, not
by the albedo the specular part takes); the metal loses it as roughness grows (single scattering only).
"""
import numpy as np

from glphong.definitions.cases import Case, _mirror_eye, _unit, generic_cases
from glphong.materials.cook_torrance import oracle_half_vector
from glphong.materials.gltf_anisotropy import (gltf_anisotropy_frame, gltf_anisotropy_ggx,  # noqa: F401
                                               gltf_anisotropy_layer, gltf_anisotropy_oracle, gltf_anisotropy_specular,
                                               gltf_anisotropy_visibility_cos)  # the GLSL chunk's twins, by its name
from glphong.materials.gltf_extensions import (EXTENSION_PARAMS, ExtensionNeeds, ExtensionProperties,  # noqa: F401
                                               GltfExtensionFeatures, extension_cases, extension_gltf_fields,
                                               gltf_clearcoat_fresnel, gltf_clearcoat_mix, gltf_extensions_oracle,
                                               gltf_specular_fresnel)
from glphong.materials.gltf_iridescence import (gltf_iridescence_fresnel, gltf_iridescence_parts,  # noqa: F401
                                                gltf_iridescence_sensitivity)  # the GLSL chunk's twins, by its name
from glphong.materials.gltf_coat_normal import coat_normal_oracle, gltf_clearcoat_normal  # noqa: F401
from glphong.materials.gltf_lobe import gltf_pbr_specular, gltf_pbr_visibility_cos  # noqa: F401
from glphong.materials.gltf_sheen import (gltf_sheen_albedo, gltf_sheen_distribution, gltf_sheen_l,  # noqa: F401
                                          gltf_sheen_lambda, gltf_sheen_mix,
                                          gltf_sheen_scaling)  # the GLSL chunk's twins, by its name
from glphong.materials.gltf_transmission import (gltf_transmission_background,  # noqa: F401
                                                 gltf_transmission_fresnel, gltf_transmission_layers,
                                                 gltf_transmission_lod, gltf_transmission_radiance,
                                                 gltf_transmission_response, gltf_transmission_sample,
                                                 gltf_transmission_weight, gltf_volume_attenuation,
                                                 gltf_volume_diffuse_attenuation, gltf_volume_exit,
                                                 gltf_volume_exit_attenuation, gltf_volume_light, gltf_volume_ray,
                                                 gltf_volume_uv)  # transmission_thin.glsl's twins
from glphong.materials.gltf_transmission_cases import transmission_stability_cases  # docs/transmission.md
from glphong.materials.gltf_diffuse_transmission import gltf_diffuse_transmission_response  # noqa: F401,E402
from glphong.definitions.material import MaterialModel, Param, Properties, constant_part
from glphong.definitions.params import GlslFile
from glphong.definitions.surface import SurfaceInput
from glphong.twin.band import EPS, FLT_MAX, FLT_MIN
from glphong.twin.functions import dot as _dot, microfacet_geometry, microfacet_ggx

__all__ = ["GltfPBR", "gltf_pbr_band", "gltf_pbr_ggx", "gltf_pbr_visibility_cos", "gltf_pbr_specular"]

_INV_PI = 1.0 / np.pi
_BASE_COLOR = Param("base_color", "rgb", low=0.0, high=1.0, default=1.0, unit="", textureable=True,
                    doc="baseColorFactor: a dielectric's diffuse colour, a metal's f0")
_METALLIC = Param("metallic", "scalar", low=0.0, high=1.0, default=1.0, unit="", textureable=True,
                  doc="metallicFactor")
_ROUGHNESS = Param("roughness", "scalar", low=0.0, high=1.0, default=1.0, unit="", textureable=True,
                   doc="roughnessFactor (alpha = roughness^2)")
_EMISSIVE = Param("emissive", "rgb", low=0.0, default=0.0, unit="W/(m^2 sr)", textureable=True,
                  doc="emissiveFactor (times KHR_materials_emissive_strength): radiance emitted")
_OCCLUSION = Param("occlusion", "scalar", low=0.0, high=1.0, default=1.0, unit="", textureable=True,
                   doc="the occlusion texture's 1 + strength (R - 1): scales the ambient answer only")
_IOR = Param("ior", "scalar", low=1.0, high=1e4, default=1.5, unit="",
             doc="KHR_materials_ior: the dielectric's f0 = ((ior - 1)/(ior + 1))^2 (1.5: 0.04, the core's)")


#: GGX D, the library chunk microfacet.glsl's (`glphong.twin.functions.microfacet_ggx`); this name is kept
gltf_pbr_ggx = microfacet_ggx


#: the parameters `gltf_pbr_band` bounds (emissive and occlusion: outside the response)
_CORE_PARAMS = ("base_color", "metallic", "roughness", "emissive", "occlusion", "ior")
#: KHR_materials_specular's, _clearcoat's and _sheen's defaults, at which the response is the core formula
_CORE_AT = {"specular": 1.0, "specular_color": 1.0, "clearcoat": 0.0, "sheen_color": 0.0, "transmission": 0.0,
            "anisotropy_strength": 0.0, "iridescence": 0.0, "diffuse_transmission": 0.0}
#: parameters that change nothing where no extension is used
_UNUSED_ALONE = ("extensions", "clearcoat_roughness", "sheen_roughness", "anisotropy_rotation", "anisotropy_direction",
                 "clearcoat_normal", "clearcoat_normal_strength",
                 "iridescence_ior", "iridescence_thickness_minimum", "iridescence_thickness_maximum",
                 "iridescence_thickness_mix", "thickness", "attenuation_distance", "attenuation_color", "dispersion",
                 "diffuse_transmission_color")


def _interval(value, rel):
    """``value (1 -+ rel)``: the float32 rounding of a chain of operations on non-negative factors."""
    return value * (1.0 - rel), value * (1.0 + rel)


def _float32(value):
    """A parameter as the GPU holds it: rounded to float32 (a float32 uniform is itself), as float64."""
    return np.asarray(value, dtype=np.float64).astype(np.float32).astype(np.float64)


def gltf_pbr_band(n, wi, wo, n_dot_l, p, constants):
    """Interval ``(low, high)``, each (N, 3), of the float32 ``gltf_pbr_response``: the formula of gltf_pbr.glsl over
    the box of its float32 inputs, one evaluation, each factor bounded by its monotonicity (docs/speed.md, "Verify
    against the render").

    The inputs: ``n.l`` and ``n.v`` to ``D eps`` (`glphong.twin.band.BandConstants`), ``v.h = |l + v|/2`` to ``D eps``
    (l and v each to ``D eps``) and ``2 eps`` of its length; the half vector's angle from n, ``theta_h``, to
    ``2 D eps / (v.h)`` (the direction of ``l + v``, and n's) plus ``2 C eps (1 + c)`` (its chord ``c = |h - n|``
    formed in float32, `glphong.twin.band.lobe_band`'s rule); the parameters as the float32 uniforms hold them
    (a textured value's own interval is `glphong.checks.tolerances`'s), ``a2 = roughness^4`` to ``4 eps`` (two
    products), ``1 - metallic`` and ``1 - base_color`` to ``eps``.  Then, all factors non-negative: ``tan2 =
    sin^2(theta_h) / (n.h)^2`` with ``n.h = (n.l + n.v)/|l + v|`` at its ends; GGX ``D`` falls with ``tan2`` (``a2 <=
    1``) and moves by at most the relative change of ``a2`` (``|d ln D / d ln a2| = |tan2 - a2|/(tan2 + a2) <= 1``);
    ``V (n.l)`` rises with ``n.l`` and falls with ``n.v`` and ``a2``; ``x = (1 - v.h)^5`` falls with ``v.h``; the
    products and sums of non-negative intervals bound the rest.  Each chain of float32 operations (D, V, x, f0, fd,
    the two parts, the sum) is widened by ``A eps`` relative, at least twice its operations' rounding.  Where the
    GPU's gate ``n.v > 0``, ``n.l > 0`` is uncertain the low end is 0; where ``n.v <= -D eps`` the GPU returns 0.
    Checked against the formula run in float32 and on both GPUs (tests/materials/test_gltf_pbr.py).

    Parameters
    ----------
    n, wi, wo : (N, 3) float64 ndarray
        Unit normal, directions toward the light and the viewer.
    n_dot_l : (N,) float64 ndarray
        As the caller's gate computed it; the band covers ``(0, n.l + D eps]``.
    p : ParamValues
        ``base_color`` (3,) or (N, 3), ``metallic``, ``roughness``, ``ior`` scalars or (N,).
    constants : glphong.twin.band.BandConstants

    Returns
    -------
    low, high : (N, 3) float64 ndarray
    """
    de, rel = constants.D * EPS, constants.A * EPS
    nl = np.asarray(n_dot_l, dtype=np.float64)
    nv = _dot(n, wo)
    s = wi + wo
    length = np.sqrt(_dot(s, s))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        e = s / length[:, None] - n
        chord = np.sqrt(_dot(e, e))
        theta = 2.0 * np.arcsin(np.minimum(0.5 * chord, 1.0))
        spread = 4.0 * de / length + 2.0 * constants.C * EPS * (1.0 + chord)
        nl_lo, nl_hi = np.maximum(nl - de, 0.0), nl + de
        nv_lo, nv_hi = np.maximum(nv - de, np.finfo(np.float64).tiny), nv + de
        # tan^2(theta_h) = sin^2 / (n.h)^2, n.h = (n.l + n.v)/|l + v| with |l + v| to 2 D eps and 2 eps of itself
        sin2_lo = np.sin(np.maximum(theta - spread, 0.0)) ** 2
        sin2_hi = np.where(theta + spread < 0.5 * np.pi, np.sin(theta + spread) ** 2, 1.0)
        nh_lo = (nl_lo + nv_lo) / ((length + 2.0 * de) * (1.0 + 2.0 * EPS))
        nh_hi = (nl_hi + nv_hi) / np.maximum((length - 2.0 * de) * (1.0 - 2.0 * EPS), 0.0)
        tan2_lo = sin2_lo / (nh_hi * nh_hi) * (1.0 - rel)
        tan2_hi = sin2_hi / (nh_lo * nh_lo) * (1.0 + rel)
        a2 = _float32(p.roughness) ** 4
        a2_lo, a2_hi = _interval(a2, 4.0 * EPS)  # two float32 products of the float32 roughness
        a2_lo = np.where(a2_lo < 2.0 * FLT_MIN, 0.0, a2_lo)  # float32 may flush alpha^2
        # D (its rounding and a2's within 2 A eps) times V (n.l) (its rounding within A eps), and their product
        d_lo = microfacet_ggx(tan2_hi, a2_lo)
        d_hi = microfacet_ggx(tan2_lo, a2)
        spec_lo = np.minimum(d_lo * gltf_pbr_visibility_cos(nl_lo, nv_hi, a2_hi)
                             * ((1.0 - 2.0 * rel) * (1.0 - rel) * (1.0 - EPS)), FLT_MAX)
        spec_hi = np.where(d_hi > 0, np.minimum(d_hi * gltf_pbr_visibility_cos(nl_hi, nv_lo, a2_lo)
                                                * ((1.0 + 2.0 * rel) * (1.0 + rel) * (1.0 + EPS)), FLT_MAX), 0.0)
        # v.h = |l + v|/2 to D eps (and 2 eps of |l + v|, 1 of 1 - v.h); x = max(1 - v.h, 0)^5
        x1_lo = np.maximum(1.0 - 0.5 * length - (de + 3.0 * EPS), 0.0)
        x1_hi = np.maximum(1.0 - 0.5 * length + (de + 3.0 * EPS), 0.0)
        x_lo, x_hi = x1_lo ** 5 * (1.0 - rel), x1_hi ** 5 * (1.0 + rel)
        ior = _float32(p.ior)
        f0_lo, f0_hi = _interval(((ior - 1.0) / (ior + 1.0)) ** 2, rel)
        fd_lo = (f0_lo + np.maximum(1.0 - f0_hi, 0.0) * x_lo) * (1.0 - rel)
        fd_hi = np.minimum((f0_hi + (1.0 - f0_lo) * x_hi) * (1.0 + rel), 1.0 + rel)
        m = _float32(p.metallic)
        om_lo, om_hi = _interval(1.0 - m, EPS)  # one float32 difference (exact for m >= 1/2)
        c = _float32(p.base_color)
        # the two parts, each a chain widened by A eps, and their sum by A eps more; the diffuse part c times
        # (n.l/pi)(1 - fd)(1 - m), the specular part the Fresnel factor fd (1 - m) + (c + (1 - c) x) m times spec
        shrink, grow = (1.0 - rel) ** 2, (1.0 + rel) ** 2
        diffuse_lo = (_INV_PI * shrink) * nl_lo * np.maximum(1.0 - fd_hi, 0.0) * om_lo
        diffuse_hi = (_INV_PI * grow) * nl_hi * (1.0 - fd_lo) * om_hi
        # diffuse c + [fd (1 - m) + (c + (1 - c) x) m] spec = c (diffuse + m spec) + (1 - c) m (x spec) + fd (1 - m) spec
        spec_lo, spec_hi = spec_lo * shrink, spec_hi * grow
        m3 = m[..., None]
        low = c * (diffuse_lo + m * spec_lo)[..., None] + ((1.0 - c) * (1.0 - EPS) * m3) * (x_lo * spec_lo)[..., None] \
            + (fd_lo * om_lo * spec_lo)[..., None]
        high = c * (diffuse_hi + m * spec_hi)[..., None] + ((1.0 - c) * (1.0 + EPS) * m3) * (x_hi * spec_hi)[..., None] \
            + (fd_hi * om_hi * spec_hi)[..., None]
    np.nan_to_num(low, copy=False, nan=0.0)
    np.nan_to_num(high, copy=False, nan=np.inf)
    low[~((nl - de > 0) & (nv - de > 0))] = 0.0  # the GPU's gate n.l > 0, n.v > 0 uncertain: it may return 0
    high[~(nv + de > 0)] = 0.0  # n.v <= -D eps: the GPU returns 0
    return low, high


class GltfPBR(GltfExtensionFeatures, MaterialModel):
    """glTF 2.0's metallic-roughness material, as the specification's Appendix B writes it:
    ``f_r = mix(dielectric, metal, metallic)`` [1/sr].

    With ``alpha = roughness^2``, ``x = (1 - |v.h|)^5`` and ``c`` the base colour (the module docstring has the
    numerics)::

        D = alpha^2 / (pi ((n.h)^2 (alpha^2 - 1) + 1)^2)                                   GGX
        V = 1 / (2 (|n.v| sqrt(alpha^2 + (1 - alpha^2)(n.l)^2) + |n.l| sqrt(alpha^2 + (1 - alpha^2)(n.v)^2)))
        metal = (c + (1 - c) x) V D
        dielectric = mix(c / pi, V D, f0 + (1 - f0) x),  f0 = ((ior - 1)/(ior + 1))^2

    ``emissive`` is radiance added whatever the lights; ``occlusion`` multiplies the answers to the ambient and the
    environment light only.

    Parameters
    ----------
    base_color : float or (3,) array_like or glphong.definitions.surface.SurfaceInput
        ``baseColorFactor`` (linear RGB) in [0, 1]; times the base-colour texture and ``COLOR_0`` where given
        (`glphong.Texture`, sRGB).
    metallic : float or SurfaceInput
        ``metallicFactor`` in [0, 1]; times the metallic-roughness texture's blue channel where given
        (``glphong.Texture(image, metallic, srgb=False, channel='b')``).
    roughness : float or SurfaceInput
        ``roughnessFactor`` in [0, 1]; times that texture's green channel (``channel='g'``); ``alpha = roughness^2``.
    emissive : float or (3,) array_like or SurfaceInput
        ``emissiveFactor`` times ``KHR_materials_emissive_strength`` [W/(m^2 sr)], >= 0: radiance the surface emits
        whatever the lights; times the emissive texture (sRGB) where given.
    occlusion : float or SurfaceInput
        In [0, 1]: multiplies the answer to the ambient light ``base_color / pi L_a`` and the reflection of an
        environment light, never a point, spot, directional or area light's; glTF's ``1 + strength (R - 1)`` of its
        occlusion texture.
    ior : float
        ``KHR_materials_ior``, in [1, 1e4]: the dielectric's Fresnel ``f0 = ((ior - 1)/(ior + 1))^2`` (the core
        specification's 1.5 gives 0.04).
    specular, specular_color : float or SurfaceInput, float or (3,) array_like or SurfaceInput
        ``KHR_materials_specular`` (default 1 and 1: the core): the dielectric's Fresnel ``F_d = mix(min(f0
        specular_color, 1) specular, specular, x)`` and its diffuse weight ``1 - max(F_d)``
        (`glphong.materials.gltf_extensions`, docs/gltf_extensions.md).
    clearcoat, clearcoat_roughness : float or SurfaceInput
        ``KHR_materials_clearcoat`` (default 0: no coat): ``mix(f_r, V_c D_c, clearcoat F_c(n.v))``, ``alpha_c =
        clearcoat_roughness^2``; the coat takes the shading normal, or its own where given:
    clearcoat_normal, clearcoat_normal_strength : (3,) or SurfaceInput, float
        ``clearcoatNormalTexture`` (its texel, linear; default (0.5, 0.5, 1): the unperturbed normal) and its
        ``scale``: the coat's normal on the unperturbed frame, the interpolated normal's, also over a ``normal_map``
        (which perturbs the base alone: the coat of a normal-mapped material keeps the unperturbed normal unless given
        its own); needs the tangent frame (`glphong.materials.gltf_coat_normal`).
    sheen_color, sheen_roughness : float or (3,) array_like or SurfaceInput, float or SurfaceInput
        ``KHR_materials_sheen`` (default 0: no sheen), under the coat: ``sheen_color D_s V_s + f_r max(min(1 -
        max3(sheen_color) E(n.v), 1 - max3(sheen_color) E(n.l)), 0)``, Charlie ``D_s`` with ``alpha_g =
        sheen_roughness^2`` (`glphong.materials.gltf_sheen`).
    anisotropy_strength, anisotropy_rotation, anisotropy_direction : float or SurfaceInput, float, (3,) or SurfaceInput
        ``KHR_materials_anisotropy`` (default 0: isotropic): the base's GGX ``D`` and ``V`` anisotropic with ``alpha_t
        = mix(alpha, 1, strength^2)`` along the direction ``2 anisotropy_direction.rg - 1`` (the anisotropy
        texture's texel, default (1, 0.5): the tangent) rotated by ``anisotropy_rotation`` [rad] in the tangent
        frame, ``alpha_b = alpha`` across it; the strength times the texture's blue channel.  Needs the mesh's
        tangent frame (`glphong.materials.gltf_anisotropy`).
    iridescence, iridescence_ior : float or SurfaceInput, float
        ``KHR_materials_iridescence`` (default 0: no film): the thin film's Fresnel ``F_irid`` (film ior default 1.3)
        mixed into the dielectric's and the metal's Fresnel by ``iridescence`` (`glphong.materials.gltf_iridescence`).
    iridescence_thickness_minimum, iridescence_thickness_maximum, iridescence_thickness_mix : float, float, float or SurfaceInput
        The film's thickness ``mix(minimum, maximum, mix)`` [nm] (defaults 100, 400 and 1: 400 nm).
    diffuse_transmission, diffuse_transmission_color : float or SurfaceInput, float or (3,) array_like or SurfaceInput
        ``KHR_materials_diffuse_transmission`` (default 0 and 1: opaque): the diffuse times ``1 - dt`` for lights in
        front, and ``dt diffuse_transmission_color / pi (1 - max3(F))`` (F the specular's or the film's), times the
        sheen's and the coat's weights, for point, spot and directional lights behind the
        surface (`glphong.materials.gltf_diffuse_transmission`; drawn as glphong draws transmissive surfaces).
    """

    name = "gltf_pbr"
    params = (_BASE_COLOR, _METALLIC, _ROUGHNESS, _EMISSIVE, _OCCLUSION, _IOR) + EXTENSION_PARAMS  # gltf_extensions
    needs = ExtensionNeeds(("view",))  # an instance with the anisotropy needs "tangent" too (structural_needs)
    #: what the code under a structural define reads beside `needs` (the definition check accepts it there); a coat
    #: normal reads the frame before a base normal map ('unperturbed', gltf_coat_normal)
    structural_needs = {"GLTF_PBR_ANISOTROPY": ("tangent",), "GLTF_PBR_CLEARCOAT_NORMAL": ("tangent", "unperturbed")}
    #: a light behind the surface: the transmission's BTDF (transmission_thin.glsl) and the diffuse transmission's
    behind_responses = (("TRANSMISSION", "gltf_transmission_response", "through"),
                        ("DIFFUSE_TRANSMISSION", "gltf_diffuse_transmission_response", "diffuse_through"))
    #: a light behind a volume (transmission_thin.glsl, the Sample Viewer's): the BTDF's seen from the exit point and
    #: attenuated along the ray, the diffuse transmission's attenuated over the thickness
    behind_exits = (("VOLUME", "through", "gltf_volume_exit", "gltf_volume_exit_attenuation"),
                    ("VOLUME", "diffuse_through", None, "gltf_volume_diffuse_attenuation"))
    ambient = "base_color"
    ambient_scale = 1.0 / np.pi
    emission = "emissive"
    occluded_by = "occlusion"
    glsl = GlslFile("materials/gltf_pbr.glsl", before=("materials/gltf_iridescence.glsl",))  # under its define
    uses = ("microfacet",)
    vanishes_with = ()
    properties = ExtensionProperties(Properties(  # a coat is not reciprocal (gltf_extensions)
        reciprocal=True, isotropic=True, energy_conserving=False, non_negative=True,
        condition="never in general: the Fresnel mix of a light dielectric exceeds 1 at oblique incidence (module "
                  "docstring)"))

    def gltf_fields(self, texture_index):
        """glTF's fields as the file writes them: the factors as they are, the metallic-roughness texture where
        metallic and roughness read one image's blue and green, the emissive factor (its strength above 1 as
        ``KHR_materials_emissive_strength``) and texture, the occlusion texture (its red channel at strength 1), an
        ior other than 1.5 as ``KHR_materials_ior`` (`MaterialModel.gltf_fields`)."""
        pbr = {"baseColorFactor": [float(c) for c in np.broadcast_to(constant_part(self.base_color), 3)] + [1.0],
               "metallicFactor": float(constant_part(self.metallic)), "roughnessFactor": float(constant_part(self.roughness))}
        if isinstance(self.base_color, SurfaceInput) and self.base_color.texture is not None:
            pbr["baseColorTexture"] = {"index": texture_index(self.base_color.texture)}
        m, r = self.metallic, self.roughness
        if isinstance(m, SurfaceInput) and isinstance(r, SurfaceInput) and m.texture is r.texture and \
                m.texture is not None and (m.channel, r.channel) == ("b", "g"):
            pbr["metallicRoughnessTexture"] = {"index": texture_index(m.texture)}
        out = {}
        emissive = np.broadcast_to(np.asarray(constant_part(self.emissive), np.float64), 3)
        if emissive.max() > 0:
            out["emissiveFactor"] = [float(c) for c in emissive / max(emissive.max(), 1.0)]
            if emissive.max() > 1.0:
                out["extensions"] = {"KHR_materials_emissive_strength": {"emissiveStrength": float(emissive.max())}}
            if isinstance(self.emissive, SurfaceInput) and self.emissive.texture is not None:
                out["emissiveTexture"] = {"index": texture_index(self.emissive.texture)}
        # occlusionTexture.r at strength 1 (a loaded strength is folded into its values), linear data as glTF reads it
        occlusion = self.occlusion
        if isinstance(occlusion, SurfaceInput) and occlusion.texture is not None and not occlusion.vertex_colors \
                and occlusion.channel == "r" and float(occlusion.scale) == 1.0 \
                and occlusion.texture.encoding == "linear8":
            out["occlusionTexture"] = {"index": texture_index(occlusion.texture)}
        extensions = extension_gltf_fields(self, texture_index)  # KHR_materials_specular, _clearcoat (gltf_extensions)
        if float(constant_part(self.ior)) != 1.5:  # KHR_materials_ior (1.5: the core's f0 = 0.04, its default)
            extensions = {"KHR_materials_ior": {"ior": float(constant_part(self.ior))}} | (extensions or {})
        if extensions:
            out["extensions"] = out.get("extensions", {}) | extensions
        return pbr, out

    def _parts(self, f, wi, wo, n_dot_l, p):
        """``(valid, diffuse (N, 3), fresnel (N, 3), specular (N,), tan2, a2, v_dot_h)``: the response is ``diffuse +
        fresnel * specular`` where valid, ``specular = D V (n.l)`` (gltf_pbr.glsl's order)."""
        valid, n_dot_v, n_dot_h, v_dot_h, tan2 = microfacet_geometry(f.n, wi, wo, n_dot_l)
        dtype = tan2.dtype
        n_dot_l = np.asarray(n_dot_l).astype(dtype)
        roughness = np.asarray(p.roughness).astype(dtype)  # a constant, or (N,) where textured
        alpha = roughness * roughness
        a2 = alpha * alpha
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            if "anisotropy" in getattr(p, "extensions", ()):  # KHR_materials_anisotropy (gltf_anisotropy)
                specular = gltf_anisotropy_layer(f, wi, wo, n_dot_l, n_dot_v, n_dot_h, v_dot_h, alpha, p)
            else:  # roughness 0: D is a delta (0 for a point light), 0 (gltf_lobe)
                specular = gltf_pbr_specular(a2, tan2, n_dot_l, n_dot_v)
            x1 = np.maximum(dtype.type(1) - v_dot_h, dtype.type(0))
            x = ((x1 * x1) * (x1 * x1) * x1).astype(dtype)
            c = np.asarray(p.base_color, dtype)
            ior = np.asarray(p.ior).astype(dtype)
            r = ((ior - dtype.type(1)) / (ior + dtype.type(1))).astype(dtype)
            f0 = (r * r).astype(dtype)
            m = np.asarray(p.metallic).astype(dtype)[..., None]
            extensions = getattr(p, "extensions", ())
            if "specular" in extensions:  # KHR_materials_specular: an rgb F_d, the diffuse by 1 - max(F_d)
                fd = gltf_specular_fresnel(f0, p.specular, p.specular_color, x)
                fd_max = np.max(fd, axis=-1)
            else:
                fd_max = (f0 + (dtype.type(1) - f0) * x).astype(dtype)
                fd = fd_max[..., None]
            fresnel = fd * (dtype.type(1) - m) + (c + (dtype.type(1) - c) * x[..., None]) * m
            if "iridescence" in extensions:  # KHR_materials_iridescence (gltf_iridescence)
                film_f0 = gltf_specular_fresnel(f0, p.specular, p.specular_color, dtype.type(0)) \
                    if "specular" in extensions else np.broadcast_to(f0[..., None], np.shape(f0) + (3,))
                fd_max, fresnel = gltf_iridescence_parts(c, m, x, film_f0, fd, v_dot_h, p)
            # mix(dielectric, metal, m) = (c/pi)(n.l)(1 - fd)(1 - m) + [fd (1 - m) + (c + (1 - c) x) m] V D (n.l)
            diffuse = (c * (dtype.type(1 / np.pi) * n_dot_l)[..., None]) * (dtype.type(1) - fd_max)[..., None] \
                * (dtype.type(1) - m)
            if "transmission" in extensions:  # KHR_materials_transmission: 1 - t (gltf_transmission)
                diffuse = diffuse * (dtype.type(1) - np.asarray(p.transmission).astype(dtype))[..., None]
            if "diffuse_transmission" in extensions:  # KHR_materials_diffuse_transmission: 1 - dt in front
                diffuse = diffuse * (dtype.type(1) - np.asarray(p.diffuse_transmission).astype(dtype))[..., None]
        return valid, diffuse, fresnel, specular, tan2, a2, v_dot_h

    def response(self, f, wi, wo, n_dot_l, p):
        valid, diffuse, fresnel, specular, _, _, _ = self._parts(f, wi, wo, n_dot_l, p)
        dtype = specular.dtype
        with np.errstate(over="ignore", invalid="ignore"):
            value = diffuse + fresnel * specular[..., None]
        if "sheen" in getattr(p, "extensions", ()):  # KHR_materials_sheen, under the coat (gltf_sheen)
            value = gltf_sheen_mix(value, f, wi, wo, n_dot_l, p)
        if "clearcoat" in getattr(p, "extensions", ()):  # KHR_materials_clearcoat (gltf_extensions)
            value = gltf_clearcoat_mix(value, f, wi, wo, n_dot_l, p)
        return np.where(valid[..., None], value, dtype.type(0)).astype(dtype)

    def band(self, f, wi, wo, n_dot_l, p, constants):
        """The derived band (`gltf_pbr_band`): the response over the box of float32 inputs, factor by factor; the
        generic band (`MaterialModel.band`) where a parameter the derived band does not know is present, unless it is
        at the value where the core formula holds (`_CORE_AT`: glTF's extensions at their defaults)."""
        for name, value in p.__dict__.items():
            if name in _CORE_PARAMS or (name in _CORE_AT and np.all(np.asarray(value) == _CORE_AT[name])) or \
                    (name in _UNUSED_ALONE and not getattr(p, "extensions", ())):
                continue
            return super().band(f, wi, wo, n_dot_l, p, constants)
        return gltf_pbr_band(f.n, wi, wo, n_dot_l, p, constants)

    def oracle(self, f, wi, wo, n_dot_l, p):
        """Appendix B in mpmath, as the specification writes it: ``h`` from ``l + v``, ``D`` with the denominator
        ``(n.h)^2 (alpha^2 - 1) + 1``, ``V`` with its ``|n.l|``, then times ``n.l``; 0 where ``n.v <= 0`` or
        ``l = -v``, and where roughness is 0 at the exact mirror direction (the delta, module docstring)."""
        import mpmath  # noqa: PLC0415 - the stability suite's, kept out of import time

        dot, n_dot_v, h = oracle_half_vector(f, wi, wo, n_dot_l)
        if h is None:
            return [mpmath.mpf(0)] * 3
        n_dot_h, v_dot_h = dot(f.n, h), abs(dot(wo, h))
        if getattr(p, "extensions", ()):  # the extensions' own formulas (gltf_extensions, gltf_anisotropy)
            layer = gltf_anisotropy_oracle(f, wi, wo, h, p) if "anisotropy" in p.extensions else None
            coat = coat_normal_oracle(f, wi, wo, p) if "clearcoat_normal" in p.extensions else None
            return gltf_extensions_oracle(p.base_color, p.metallic, p.roughness, p.ior, p.extensions, p, n_dot_l,
                                          n_dot_v, n_dot_h, v_dot_h, layer, coat)
        alpha = p.roughness * p.roughness
        a2 = alpha * alpha
        denominator = n_dot_h * n_dot_h * (a2 - 1) + 1
        if denominator == 0:
            return [mpmath.mpf(0)] * 3
        d = a2 / (mpmath.pi * denominator * denominator)
        v = 1 / (2 * (abs(n_dot_v) * mpmath.sqrt(a2 + (1 - a2) * n_dot_l ** 2)
                      + abs(n_dot_l) * mpmath.sqrt(a2 + (1 - a2) * n_dot_v ** 2)))
        x = (1 - v_dot_h) ** 5
        out = []
        for c in p.base_color:
            metal = (c + (1 - c) * x) * v * d
            f0 = ((p.ior - 1) / (p.ior + 1)) ** 2
            fd = f0 + (1 - f0) * x
            dielectric = (c / mpmath.pi) * (1 - fd) + v * d * fd
            out.append(((1 - p.metallic) * dielectric + p.metallic * metal) * n_dot_l)
        return out

    def pbr_roughness(self):
        """pyrender's roughness: the same parameter."""
        return float(self.roughness)

    @classmethod
    def stability_cases(cls):
        return _stability_cases() + extension_cases(cls) + transmission_stability_cases(cls)


def _stability_cases():
    """Generic geometry plus the glTF extremes: roughness from 0 to 1 (1e-4 included) at the peak and off it, for a
    dielectric and a metal; grazing light and view; a black and a white base colour."""
    e_one = 4 * np.pi  # a point light at 1 m: E = 1 W/m^2
    light = _unit(30.0)
    cases = generic_cases("gltf_pbr", GltfPBR(0.5, 0.0, 0.5)) + generic_cases("gltf_pbr metal", GltfPBR(0.9, 1.0, 0.3))
    for metallic in (0.0, 1.0):
        for roughness in (1e-4, 1e-2, 0.1, 0.5, 1.0):
            offsets = (("peak", 0.0), ("near", 0.5 * roughness ** 2), ("tail", 3.0 * roughness ** 2))
            for where, theta_h in offsets if roughness < 0.5 else (("peak", 0.0), ("theta_h=0.5", 0.5)):
                cases.append(Case(f"gltf_pbr metallic={metallic:g} roughness={roughness:g} {where}", "gltf peak",
                                  GltfPBR((0.8, 0.5, 0.2), metallic, roughness), eye=_mirror_eye(30.0, 2 * theta_h),
                                  lights=(("point", light, e_one),), note=f"theta_h = {theta_h:.3g} rad"))
    cases.append(Case("gltf_pbr roughness=0 off the mirror", "gltf peak", GltfPBR(0.8, 0.0, 0.0),
                      eye=_mirror_eye(30.0, 0.2), lights=(("point", light, e_one),), note="D = 0: the diffuse part only"))
    for nv in (1e-3, 1e-8, 1e-20):
        cases.append(Case(f"gltf_pbr grazing view n.v={nv:g}", "gltf grazing", GltfPBR(0.5, 0.5, 0.3),
                          eye=(-float(np.sqrt(1.0 - nv * nv)), 0.0, nv), lights=(("point", _unit(40.0), e_one),),
                          note="V (n.l) <= 1/(2 r_v): finite"))
    for color in (0.0, 1.0):
        cases.append(Case(f"gltf_pbr base colour {color:g}", "gltf colour", GltfPBR(color, 0.3, 0.4),
                          eye=_mirror_eye(30.0, 0.3), lights=(("point", light, e_one),)))
    return cases
