"""The KHR_materials extensions of glTF's material that act at the surface alone, as features of `GltfPBR`
(docs/gltf_extensions.md; GLSL: ``glsl/materials/gltf_pbr.glsl`` under the structural defines ``GLTF_PBR_<NAME>``).

Each is a set of `GltfPBR` parameters; a material uses an extension where a parameter differs from the value at which
the extension changes nothing (or is textured), and only then is its code in the program (``#define
GLTF_PBR_SPECULAR``, ``GLTF_PBR_CLEARCOAT``, ``GLTF_PBR_SHEEN``; `GltfExtensionFeatures.extensions`).
With ``x = (1 - |v.h|)^5``, ``f0 = ((ior - 1)/(ior + 1))^2``, ``c`` the base colour, ``m`` metallic, ``D``/``V``
Appendix B's GGX and visibility::

    KHR_materials_specular   F_d = mix(min(f0 specular_color, 1) specular, specular, x)                  rgb
                             dielectric = F_d V D + (1 - max(F_d.r, F_d.g, F_d.b)) c / pi
                             f_r = mix(dielectric, (c + (1 - c) x) V D, m)     (the metal is unchanged)
    KHR_materials_clearcoat  F_c = 0.04 + 0.96 (1 - |n.v|)^5                   fresnel_coat, ior 1.5, on n.v
                             f_r' = mix(f_r, V_c D_c, clearcoat F_c),  alpha_c = clearcoat_roughness^2
    KHR_materials_sheen      f_r' = sheen_color D_s V_s + f_r max(min(1 - max3(sheen_color) E(n.v), ...(n.l)), 0)
                             under the coat (`glphong.materials.gltf_sheen`)

=================== ====== ========= ======= ==========================================================================
parameter           kind   range     neutral meaning
=================== ====== ========= ======= ==========================================================================
specular            scalar [0, 1]    1       ``specularFactor`` times ``specularTexture.a``: the dielectric's specular
                                             strength (``dielectric_f90``), and its ``f0``'s factor
specular_color      rgb    [0, inf)  1       ``specularColorFactor`` times ``specularColorTexture`` (sRGB): ``f0``'s
                                             colour (the product ``f0 specular_color`` is clamped at 1)
clearcoat           scalar [0, 1]    0       ``clearcoatFactor`` times ``clearcoatTexture.r``: the coat's weight
clearcoat_roughness scalar [0, 1]    0       ``clearcoatRoughnessFactor`` times ``clearcoatRoughnessTexture.g``
sheen_color         rgb    [0, 1]    0       ``sheenColorFactor`` times ``sheenColorTexture`` (sRGB)
sheen_roughness     scalar [0, 1]    0       ``sheenRoughnessFactor`` times ``sheenRoughnessTexture.a``
=================== ====== ========= ======= ==========================================================================

Exact as the extensions write them, with two limits of glphong's (docs/gltf_extensions.md): the coat's normal is the
material's shading normal (its ``normal_map``; the specification's coat takes ``clearcoatNormalTexture``, or the
unperturbed normal where there is none), and the emission is not darkened by ``1 - clearcoat F_c`` (a material with
both warns).  A coat of roughness 0 is a mirror: a delta that a point light meets with zero measure, so it only darkens
the base, as the core's roughness 0 does (`glphong.materials.gltf_pbr`).
"""
import dataclasses
import warnings

import numpy as np

from glphong.definitions.cases import Case, _mirror_eye, _unit
from glphong.definitions.material_base import constant_part
from glphong.definitions.params import Param
from glphong.definitions.surface import SurfaceInput
from glphong.materials.gltf_sheen import SHEEN_PARAMS, gltf_sheen_oracle, sheen_cases
from glphong.twin.band import FLT_MAX
from glphong.twin.functions import microfacet_geometry, microfacet_ggx

# GltfExtensionFeatures and ExtensionProperties are GltfPBR's own (a class named here would become glphong.materials')
__all__ = ["EXTENSION_PARAMS", "EXTENSIONS", "gltf_specular_fresnel", "gltf_clearcoat_fresnel",
           "gltf_specular_parts", "gltf_clearcoat_mix", "gltf_extensions_oracle", "extension_cases",
           "extension_gltf_fields"]

_SPECULAR = Param("specular", "scalar", low=0.0, high=1.0, default=1.0, unit="", textureable=True,
                  doc="KHR_materials_specular specularFactor (times specularTexture.a): the dielectric's f90 and f0 factor")
_SPECULAR_COLOR = Param("specular_color", "rgb", low=0.0, default=1.0, unit="", textureable=True,
                        doc="KHR_materials_specular specularColorFactor (times specularColorTexture, sRGB): f0's colour")
_CLEARCOAT = Param("clearcoat", "scalar", low=0.0, high=1.0, default=0.0, unit="", textureable=True,
                   doc="KHR_materials_clearcoat clearcoatFactor (times clearcoatTexture.r): the coat's weight")
_CLEARCOAT_ROUGHNESS = Param("clearcoat_roughness", "scalar", low=0.0, high=1.0, default=0.0, unit="", textureable=True,
                             doc="KHR_materials_clearcoatRoughnessFactor (times clearcoatRoughnessTexture.g): "
                                 "alpha_c = clearcoat_roughness^2")

#: the extensions' parameters, appended to `GltfPBR`'s
EXTENSION_PARAMS = (_SPECULAR, _SPECULAR_COLOR, _CLEARCOAT, _CLEARCOAT_ROUGHNESS) + SHEEN_PARAMS  # gltf_sheen
#: each extension glphong applies: its short name (the define GLTF_PBR_<NAME>), its glTF name and its parameters
EXTENSIONS = {"specular": ("KHR_materials_specular", ("specular", "specular_color")),
              "clearcoat": ("KHR_materials_clearcoat", ("clearcoat", "clearcoat_roughness")),
              "sheen": ("KHR_materials_sheen", ("sheen_color", "sheen_roughness"))}
#: the coat's f0: ((1 - 1.5)/(1 + 1.5))^2, fresnel_coat's fixed ior 1.5
CLEARCOAT_F0 = 0.04


def gltf_specular_fresnel(f0, specular, specular_color, x):
    """KHR_materials_specular's dielectric Fresnel factor ``F_d = d0 + (specular - d0) x``, ``d0 = min(f0
    specular_color, 1) specular`` (gltf_pbr.glsl).  f0, specular, x (...) or (); specular_color (..., 3) or (3,)
    -> (..., 3), dimensionless."""
    x = np.asarray(x)
    dtype = x.dtype if x.dtype.kind == "f" else np.float64
    one = dtype.type(1)
    f0 = np.asarray(f0).astype(dtype)[..., None]
    specular = np.asarray(specular).astype(dtype)[..., None]
    dielectric_f0 = (np.minimum(f0 * np.asarray(specular_color).astype(dtype), one) * specular).astype(dtype)
    return (dielectric_f0 + (specular - dielectric_f0) * x.astype(dtype)[..., None]).astype(dtype)


def gltf_clearcoat_fresnel(n_dot_v):
    """KHR_materials_clearcoat's ``F_c = 0.04 + 0.96 (1 - n.v)^5`` (gltf_pbr.glsl; fresnel_coat with ior 1.5, on n.v).
    (...) -> (...), dimensionless."""
    n_dot_v = np.asarray(n_dot_v)
    dtype = n_dot_v.dtype if n_dot_v.dtype.kind == "f" else np.float64
    y1 = np.maximum(dtype.type(1) - n_dot_v.astype(dtype), dtype.type(0))
    y = ((y1 * y1) * (y1 * y1) * y1).astype(dtype)
    return (dtype.type(CLEARCOAT_F0) + dtype.type(1 - CLEARCOAT_F0) * y).astype(dtype)


def gltf_specular_parts(c, m, n_dot_l, x, f0, p):
    """``(diffuse, fresnel)``, each (N, 3), of `GltfPBR`'s twin with KHR_materials_specular, in gltf_pbr.glsl's order:
    ``diffuse = c (n.l)/pi (1 - max F_d)(1 - m)``, ``fresnel = F_d (1 - m) + (c + (1 - c) x) m``."""
    dtype = np.asarray(x).dtype
    one = dtype.type(1)
    fd = gltf_specular_fresnel(f0, p.specular, p.specular_color, x)
    fd_max = np.max(fd, axis=-1)
    diffuse = (c * (dtype.type(1 / np.pi) * n_dot_l)[..., None]) * (one - fd_max)[..., None] * (one - m)
    fresnel = fd * (one - m) + (c + (one - c) * x[..., None]) * m
    return diffuse.astype(dtype), fresnel.astype(dtype)


def gltf_clearcoat_mix(value, f, wi, wo, n_dot_l, p, gltf_pbr_visibility_cos):
    """KHR_materials_clearcoat on `GltfPBR`'s twin: ``value (1 - w) + w V_c D_c (n.l)``, ``w = clearcoat F_c(n.v)``,
    ``alpha_c = clearcoat_roughness^2`` (gltf_pbr.glsl's order), 0 for the coat of roughness 0; value (N, 3) -> (N, 3).
    ``gltf_pbr_visibility_cos`` is `glphong.materials.gltf_pbr.gltf_pbr_visibility_cos` (which imports this module)."""
    dtype = np.asarray(value).dtype
    _, n_dot_v, _, _, tan2 = microfacet_geometry(f.n, wi, wo, n_dot_l)
    n_dot_l = np.asarray(n_dot_l).astype(dtype)
    alpha_c = np.asarray(p.clearcoat_roughness).astype(dtype) ** 2
    a2_c = (alpha_c * alpha_c).astype(dtype)
    with np.errstate(over="ignore", under="ignore", invalid="ignore", divide="ignore"):
        coat = np.minimum(microfacet_ggx(tan2.astype(dtype), a2_c) * gltf_pbr_visibility_cos(n_dot_l, n_dot_v, a2_c),
                          dtype.type(FLT_MAX))
        coat = np.where(a2_c > 0, coat, dtype.type(0)).astype(dtype)  # roughness 0: a delta, 0 for a point light
        weight = (np.asarray(p.clearcoat).astype(dtype) * gltf_clearcoat_fresnel(n_dot_v.astype(dtype))).astype(dtype)
        return (value * (dtype.type(1) - weight)[..., None] + (weight * coat)[..., None]).astype(dtype)


class ExtensionProperties:
    """`GltfPBR`'s ``properties``: the core's `Properties` read from the class, and from an instance with a coat the
    same with ``reciprocal=False`` (the coat's Fresnel is on ``n.v`` alone, as the extension writes it)."""

    def __init__(self, core):
        self.core = core

    def __get__(self, material, cls=None):
        if material is None or "clearcoat" not in material.extensions():
            return self.core
        return dataclasses.replace(self.core, reciprocal=False)


class GltfExtensionFeatures:
    """What `GltfPBR` adds for its extensions (a mixin before `MaterialModel`): which it uses, its structural defines,
    the uniforms its programs read, and what its twin reads (``p.extensions``)."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        if "clearcoat" in self.extensions() and np.any(constant_part(self.emissive)):
            warnings.warn("KHR_materials_clearcoat with an emission: glphong does not darken the emission by the "
                          "coat's 1 - clearcoat F_c(n.v) (F_c = 0.04 at normal view, 1 at grazing): the emission is "
                          "drawn as it is (docs/gltf_extensions.md)", stacklevel=3)

    def extensions(self):
        """The extensions this material uses, by short name (`EXTENSIONS`): specular where ``specular`` or
        ``specular_color`` is not 1 or is textured, clearcoat where ``clearcoat`` is not 0, sheen where
        ``sheen_color`` is not 0 (tuple of str)."""
        def differs(name, neutral):
            value = getattr(self, name)
            return isinstance(value, SurfaceInput) and value.texture is not None or \
                bool(np.any(np.asarray(constant_part(value), np.float64) != neutral))

        out = []
        if differs("specular", 1.0) or differs("specular_color", 1.0):
            out.append("specular")
        if np.any(constant_part(self.clearcoat)):
            out.append("clearcoat")
        if np.any(constant_part(self.sheen_color)):  # sheenColorFactor 0 disables the layer, textured or not
            out.append("sheen")
        return tuple(out)

    def defines(self):
        """``GLTF_PBR_<NAME>`` for each extension used: its code is in the program only then."""
        return tuple((name.upper(), "1") for name in self.extensions())

    def active_params(self):
        """The uniforms this instance's programs read: the extensions' only where used."""
        unused = {q for name, (_, params) in EXTENSIONS.items() if name not in self.extensions() for q in params}
        return tuple(q for q in super().active_params() if q.name not in unused)

    def structure(self):
        """Beside the uniforms, the twin reads ``p.extensions``: the extensions used (`extensions`)."""
        return super().structure() | {"extensions": self.extensions()}


def gltf_extensions_oracle(base_color, metallic, roughness, ior, extensions, p, n_dot_l, n_dot_v, n_dot_h, v_dot_h):
    """The response of a `GltfPBR` with extensions in mpmath, straight from the extensions' text: Appendix B's ``D``
    and ``V`` (``(n.h)^2 (alpha^2 - 1) + 1``), ``fresnel_mix`` with ``f0_color`` and ``weight`` (specular), then
    ``mix(material, clearcoat_brdf, clearcoat F_c)`` (clearcoat), times ``n.l``; a list of 3 mpmath numbers."""
    import mpmath  # noqa: PLC0415 - the stability suite's, kept out of import time

    def d_and_v(alpha):
        a2 = alpha * alpha
        denominator = n_dot_h * n_dot_h * (a2 - 1) + 1
        if denominator == 0:
            return mpmath.mpf(0)
        d = a2 / (mpmath.pi * denominator * denominator)
        return d / (2 * (n_dot_v * mpmath.sqrt(a2 + (1 - a2) * n_dot_l ** 2)
                         + n_dot_l * mpmath.sqrt(a2 + (1 - a2) * n_dot_v ** 2)))

    layer = d_and_v(roughness * roughness)
    x = (1 - v_dot_h) ** 5
    f0 = ((ior - 1) / (ior + 1)) ** 2
    weight, color = (p.specular, p.specular_color) if "specular" in extensions else (1, [1, 1, 1])
    fr = [min(f0 * k, 1) + (1 - min(f0 * k, 1)) * x for k in color]
    out = []
    for c, f in zip(base_color, fr):
        dielectric = (1 - weight * max(fr)) * c / mpmath.pi + weight * f * layer
        metal = (c + (1 - c) * x) * layer
        out.append((1 - metallic) * dielectric + metallic * metal)
    if "sheen" in extensions:  # KHR_materials_sheen, under the coat (gltf_sheen)
        out = gltf_sheen_oracle(out, p, n_dot_l, n_dot_v, n_dot_h)
    if "clearcoat" in extensions:
        w = p.clearcoat * (mpmath.mpf("0.04") + (1 - mpmath.mpf("0.04")) * (1 - n_dot_v) ** 5)
        coat = d_and_v(p.clearcoat_roughness ** 2)
        out = [(1 - w) * o + w * coat for o in out]
    return [o * n_dot_l for o in out]


def extension_cases(cls):
    """Stability cases of the extensions on `GltfPBR` ``cls``: specular 0 and 1, a coloured f0 clamped at 1; clearcoat
    0.5 and 1 at roughness 0, 1e-2 and 1, at the coat's peak, in its tail, and at grazing view (F_c -> 1)."""
    e_one = 4 * np.pi  # a point light at 1 m: E = 1 W/m^2
    light = (("point", _unit(30.0), e_one),)
    cases = []
    for specular, color in ((0.0, 1.0), (1.0, (0.2, 1.0, 30.0)), (0.5, (2.0, 0.5, 0.0)), (1.0, 0.0)):
        for theta_h in (0.0, 0.3):
            cases.append(Case(f"gltf_pbr specular={specular:g} color={color} theta_h={theta_h:g}", "gltf specular",
                              cls((0.8, 0.5, 0.2), 0.3, 0.3, specular=specular, specular_color=color),
                              eye=_mirror_eye(30.0, 2 * theta_h), lights=light))
    for clearcoat in (0.5, 1.0):
        for roughness in (0.0, 1e-2, 0.3, 1.0):
            for where, theta_h in (("peak", 0.0), ("tail", 3.0 * max(roughness, 0.05) ** 2)):
                cases.append(Case(f"gltf_pbr clearcoat={clearcoat:g} roughness={roughness:g} {where}", "gltf clearcoat",
                                  cls((0.8, 0.5, 0.2), 0.0, 0.5, clearcoat=clearcoat, clearcoat_roughness=roughness),
                                  eye=_mirror_eye(30.0, 2 * theta_h), lights=light, note=f"theta_h = {theta_h:.3g} rad"))
    for nv in (1e-3, 1e-8, 1e-20):
        cases.append(Case(f"gltf_pbr clearcoat grazing view n.v={nv:g}", "gltf clearcoat",
                          cls(0.5, 0.5, 0.3, clearcoat=1.0, clearcoat_roughness=0.1, specular=0.5),
                          eye=(-float(np.sqrt(1.0 - nv * nv)), 0.0, nv), lights=(("point", _unit(40.0), e_one),),
                          note="F_c -> 1: the coat alone"))
    return cases + sheen_cases(cls)


def extension_gltf_fields(material, texture_index):
    """The ``extensions`` entries of a `GltfPBR`'s glTF material for the extensions it uses (dict), with their
    textures where the file's channel is the one glphong reads (``specularTexture``'s alpha is not written: glphong
    holds it as a grey image, and its own ``extras`` keep it)."""
    out = {}
    used = material.extensions()

    def textured(name, key, fields, channel=None):
        value = getattr(material, name)
        if isinstance(value, SurfaceInput) and value.texture is not None and (channel is None or value.channel == channel):
            fields[key] = {"index": texture_index(value.texture)}

    if "specular" in used:
        fields = {"specularFactor": float(constant_part(material.specular)),
                  "specularColorFactor": [float(c) for c in np.broadcast_to(constant_part(material.specular_color), 3)]}
        textured("specular_color", "specularColorTexture", fields)
        out["KHR_materials_specular"] = fields
    if "clearcoat" in used:
        fields = {"clearcoatFactor": float(constant_part(material.clearcoat)),
                  "clearcoatRoughnessFactor": float(constant_part(material.clearcoat_roughness))}
        textured("clearcoat", "clearcoatTexture", fields, "r")
        textured("clearcoat_roughness", "clearcoatRoughnessTexture", fields, "g")
        out["KHR_materials_clearcoat"] = fields
    if "sheen" in used:
        fields = {"sheenColorFactor": [float(c) for c in np.broadcast_to(constant_part(material.sheen_color), 3)],
                  "sheenRoughnessFactor": float(constant_part(material.sheen_roughness))}
        textured("sheen_color", "sheenColorTexture", fields)
        out["KHR_materials_sheen"] = fields
    return out
