"""The KHR_materials extensions of glTF's material that act at the surface alone, as features of `GltfPBR`
(docs/gltf_extensions.md; GLSL: ``glsl/materials/gltf_pbr.glsl`` under the structural defines ``GLTF_PBR_<NAME>``).

Each is a set of `GltfPBR` parameters; a material uses an extension where a parameter differs from the value at which
the extension changes nothing (or is textured), and only then is its code in the program (``#define
GLTF_PBR_SPECULAR``, ``GLTF_PBR_CLEARCOAT``, ``GLTF_PBR_SHEEN``, ``GLTF_PBR_ANISOTROPY``;
`GltfExtensionFeatures.extensions`).
With ``x = (1 - |v.h|)^5``, ``f0 = ((ior - 1)/(ior + 1))^2``, ``c`` the base colour, ``m`` metallic, ``D``/``V``
Appendix B's GGX and visibility::

    KHR_materials_specular   F_d = mix(min(f0 specular_color, 1) specular, specular, x)                  rgb
                             dielectric = F_d V D + (1 - max(F_d.r, F_d.g, F_d.b)) c / pi
                             f_r = mix(dielectric, (c + (1 - c) x) V D, m)     (the metal is unchanged)
    KHR_materials_clearcoat  F_c = 0.04 + 0.96 (1 - |n.v|)^5                   fresnel_coat, ior 1.5, on n.v
                             f_r' = mix(f_r, V_c D_c, clearcoat F_c),  alpha_c = clearcoat_roughness^2
    KHR_materials_sheen      f_r' = sheen_color D_s V_s + f_r max(min(1 - max3(sheen_color) E(n.v), ...(n.l)), 0)
                             under the coat (`glphong.materials.gltf_sheen`)
    KHR_materials_anisotropy D V of the base anisotropic: alpha_t = mix(alpha, 1, strength^2) along the rotated
                             tangent, alpha_b = alpha (`glphong.materials.gltf_anisotropy`; needs the tangent frame)
    KHR_materials_diffuse_transmission  the diffuse times 1 - dt in front; dt c_dt/pi (1 - max3(F(v.h'))) times the
                             layers' weights (sheen, coat) for lights behind, F the specular's or the film's
                             (`glphong.materials.gltf_diffuse_transmission`)

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
anisotropy_strength scalar [0, 1]    0       ``anisotropyStrength`` times ``anisotropyTexture.b``
anisotropy_rotation scalar radians   (0)     ``anisotropyRotation``: counter-clockwise from the tangent
anisotropy_directionrgb    [0, 1]    (1,.5)  ``anisotropyTexture``'s texel: ``2 rg - 1`` the direction in tangent space
=================== ====== ========= ======= ==========================================================================

Exact as the extensions write them, with one limit of glphong's (docs/gltf_extensions.md): the emission is not
darkened by ``1 - clearcoat F_c`` (a material with both warns).  The coat's normal (``clearcoat_normal``,
`glphong.materials.gltf_coat_normal`) is taken on the unperturbed frame, also over a base ``normal_map``.  A coat of
roughness 0 is a mirror: a delta that a point light meets with zero measure, so it only darkens the base, as the
core's roughness 0 does (`glphong.materials.gltf_pbr`).
"""
import dataclasses
import math
import warnings

import numpy as np

from glphong.definitions.cases import Case, _mirror_eye, _unit
from glphong.definitions.material_base import constant_part
from glphong.definitions.params import Param
from glphong.definitions.surface import SurfaceInput
from glphong.materials.gltf_anisotropy import ANISOTROPY_PARAMS, anisotropy_cases
from glphong.materials.gltf_diffuse_transmission import DIFFUSE_TRANSMISSION_PARAMS, diffuse_transmission_gltf_fields
from glphong.materials.gltf_iridescence import (IRIDESCENCE_PARAMS, gltf_iridescence_oracle, iridescence_cases,
                                                iridescence_gltf_fields)
from glphong.materials.gltf_coat_normal import COAT_NORMAL_PARAMS, gltf_clearcoat_geometry, uses_coat_normal
from glphong.materials.gltf_lobe import gltf_clearcoat_fresnel, gltf_pbr_specular
from glphong.materials.gltf_sheen import SHEEN_PARAMS, gltf_sheen_oracle, sheen_cases
from glphong.materials.gltf_transmission import (TRANSMISSION_PARAMS, VOLUME_EXTENSIONS, transmission_gltf_fields,
                                                 volume_extensions)
from glphong.twin.functions import microfacet_geometry

# GltfExtensionFeatures and ExtensionProperties are GltfPBR's own (a class named here would become glphong.materials')
__all__ = ["EXTENSION_PARAMS", "EXTENSIONS", "gltf_specular_fresnel", "gltf_clearcoat_fresnel",
           "gltf_clearcoat_mix", "gltf_extensions_oracle", "extension_cases",
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
EXTENSION_PARAMS = (_SPECULAR, _SPECULAR_COLOR, _CLEARCOAT, _CLEARCOAT_ROUGHNESS) + COAT_NORMAL_PARAMS + SHEEN_PARAMS \
    + ANISOTROPY_PARAMS + TRANSMISSION_PARAMS + IRIDESCENCE_PARAMS \
    + DIFFUSE_TRANSMISSION_PARAMS  # gltf_sheen, _anisotropy, _transmission, _iridescence, _diffuse_transmission
#: each extension glphong applies: its short name (the define GLTF_PBR_<NAME>), its glTF name and its parameters
EXTENSIONS = {"specular": ("KHR_materials_specular", ("specular", "specular_color")),
              "clearcoat": ("KHR_materials_clearcoat", ("clearcoat", "clearcoat_roughness")),
              "clearcoat_normal": ("KHR_materials_clearcoat", ("clearcoat_normal", "clearcoat_normal_strength")),
              "sheen": ("KHR_materials_sheen", ("sheen_color", "sheen_roughness")),
              "anisotropy": ("KHR_materials_anisotropy", ("anisotropy_strength", "anisotropy_rotation",
                                                          "anisotropy_direction")),
              "transmission": ("KHR_materials_transmission", ("transmission",)),
              "iridescence": ("KHR_materials_iridescence", tuple(q.name for q in IRIDESCENCE_PARAMS)),
              "diffuse_transmission": ("KHR_materials_diffuse_transmission",
                                       ("diffuse_transmission", "diffuse_transmission_color"))} \
    | VOLUME_EXTENSIONS  # KHR_materials_volume and _dispersion (gltf_transmission)


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


def gltf_clearcoat_mix(value, f, wi, wo, n_dot_l, p):
    """KHR_materials_clearcoat on `GltfPBR`'s twin: ``value (1 - w) + w V_c D_c (n.l)``, ``w = clearcoat F_c(n.v)``,
    ``alpha_c = clearcoat_roughness^2`` (gltf_pbr.glsl's order), the coat's lobe the base's function
    (`glphong.materials.gltf_lobe.gltf_pbr_specular`: 0 for the coat of roughness 0); value (N, 3) -> (N, 3)."""
    dtype = np.asarray(value).dtype
    alpha_c = np.asarray(p.clearcoat_roughness).astype(dtype) ** 2
    a2_c = (alpha_c * alpha_c).astype(dtype)
    with np.errstate(over="ignore", under="ignore", invalid="ignore", divide="ignore"):
        if "clearcoat_normal" in getattr(p, "extensions", ()):  # clearcoatNormalTexture: the coat's own normal
            valid, c_n_dot_l, c_n_dot_v, c_tan2, fresnel_cos = gltf_clearcoat_geometry(f, wi, wo, p, dtype)
            coat = np.where(valid, gltf_pbr_specular(a2_c, c_tan2.astype(dtype), c_n_dot_l, c_n_dot_v),
                            dtype.type(0)).astype(dtype)
        else:  # the shading normal: the base's geometry; roughness 0: a delta, 0 for a point light
            _, n_dot_v, _, _, tan2 = microfacet_geometry(f.n, wi, wo, n_dot_l)
            coat = gltf_pbr_specular(a2_c, tan2.astype(dtype), np.asarray(n_dot_l).astype(dtype), n_dot_v)
            fresnel_cos = n_dot_v.astype(dtype)
        weight = (np.asarray(p.clearcoat).astype(dtype) * gltf_clearcoat_fresnel(fresnel_cos)).astype(dtype)
        return (value * (dtype.type(1) - weight)[..., None] + (weight * coat)[..., None]).astype(dtype)


class ExtensionProperties:
    """`GltfPBR`'s ``properties``: the core's `Properties` read from the class, and from an instance with a coat the
    same with ``reciprocal=False`` (the coat's Fresnel is on ``n.v`` alone, as the extension writes it), with the
    anisotropy or a coat normal ``isotropic=False``."""

    def __init__(self, core):
        self.core = core

    def __get__(self, material, cls=None):
        used = () if material is None else material.extensions()
        changed = {"reciprocal": False} if "clearcoat" in used else {}
        if "anisotropy" in used or "clearcoat_normal" in used:  # a lobe not symmetric about n
            changed["isotropic"] = False
        return dataclasses.replace(self.core, **changed) if changed else self.core


class ExtensionNeeds:
    """`GltfPBR`'s ``needs``: the core's read from the class (what its GLSL reads outside the structural defines), and
    from an instance also what the code under its structural defines reads (the class's ``structural_needs``: the
    anisotropy's tangent frame), so that a mesh without tangents serves every glTF material but an anisotropic one."""

    def __init__(self, core):
        self.core = tuple(core)

    def __get__(self, material, cls=None):
        if material is None:
            return self.core
        defines = {f"{material.name.upper()}_{name}" for name, _ in material.structural_defines()}
        extra = tuple(n for define, needs in type(material).structural_needs.items() if define in defines for n in needs)
        return tuple(dict.fromkeys(self.core + extra))


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
        ``sheen_color`` is not 0, anisotropy where ``anisotropy_strength`` is not 0 (tuple of str).  Found once
        and kept (a material is immutable; the frame's draw asks it of every object)."""
        found = self.__dict__.get("_extensions_used")
        if found is None:
            found = self._extensions_used()
            object.__setattr__(self, "_extensions_used", found)
        return found

    def _extensions_used(self):
        def differs(name, neutral):
            value = getattr(self, name)
            return isinstance(value, SurfaceInput) and value.texture is not None or \
                bool(np.any(np.asarray(constant_part(value), np.float64) != neutral))

        out = []
        if differs("specular", 1.0) or differs("specular_color", 1.0):
            out.append("specular")
        if np.any(constant_part(self.clearcoat)):
            out += ["clearcoat", "clearcoat_normal"] if uses_coat_normal(self) else ["clearcoat"]  # gltf_coat_normal
        if np.any(constant_part(self.sheen_color)):  # sheenColorFactor 0 disables the layer, textured or not
            out.append("sheen")
        if np.any(constant_part(self.anisotropy_strength)):  # anisotropyStrength 0 (the default): isotropic
            out.append("anisotropy")
        if np.any(constant_part(self.transmission)):  # transmissionFactor 0 (the default): opaque (gltf_transmission)
            out += ["transmission", *volume_extensions(self)]  # and KHR_materials_volume, _dispersion in it
        if np.any(constant_part(self.iridescence)):  # iridescenceFactor 0 (the default): no film (gltf_iridescence)
            out.append("iridescence")
        if np.any(constant_part(self.diffuse_transmission)):  # diffuseTransmissionFactor 0 (the default): opaque
            out.append("diffuse_transmission")  # (gltf_diffuse_transmission)
        return tuple(out)

    def defines(self):
        """``GLTF_PBR_<NAME>`` for each extension used: its code is in the program only then."""
        return tuple((name.upper(), "1") for name in self.extensions())

    @classmethod
    def uniform_guard(cls, name):
        """KHR_materials_transmission's, _volume's (_dispersion's with them: the volume's code reads it) and
        _diffuse_transmission's uniforms are declared only in the programs that use the extension (its
        ``GLTF_PBR_<NAME>``); every other parameter's in every program."""
        for extension, define in (("transmission", "TRANSMISSION"), ("volume", "VOLUME"), ("dispersion", "VOLUME"),
                                  ("diffuse_transmission", "DIFFUSE_TRANSMISSION")):
            if name in EXTENSIONS[extension][1]:
                return f"GLTF_PBR_{define}"
        return super().uniform_guard(name)

    def library_uses(self, uber=False):
        """`MaterialModel.library_uses`, and the library chunk ``normal_map`` (its ``surface_normal``, the coat
        normal's formula) where the coat has its own normal, ``fresnel`` (``fresnel_schlick``) where it transmits."""
        extra = ("normal_map",) if "clearcoat_normal" in self.extensions() else ()
        if {"transmission", "diffuse_transmission"} & set(self.extensions()):  # their Schlick (transmission_thin.glsl)
            extra += ("fresnel",)
        return tuple(dict.fromkeys(super().library_uses(uber) + extra))

    def active_params(self):
        """The uniforms this instance's programs read: the extensions' only where used."""
        unused = {q for name, (_, params) in EXTENSIONS.items() if name not in self.extensions() for q in params}
        return tuple(q for q in super().active_params() if q.name not in unused)

    def structure(self):
        """Beside the uniforms, the twin reads ``p.extensions``: the extensions used (`extensions`)."""
        return super().structure() | {"extensions": self.extensions()}


def gltf_extensions_oracle(base_color, metallic, roughness, ior, extensions, p, n_dot_l, n_dot_v, n_dot_h, v_dot_h,
                           layer=None, coat=None):
    """The response of a `GltfPBR` with extensions in mpmath, straight from the extensions' text: Appendix B's ``D``
    and ``V`` (``(n.h)^2 (alpha^2 - 1) + 1``; ``layer``, the base's ``V D``, where given: the anisotropy's,
    `glphong.materials.gltf_anisotropy.gltf_anisotropy_oracle`), ``fresnel_mix`` with ``f0_color`` and ``weight``
    (specular), then ``mix(material, clearcoat_brdf, clearcoat F_c)`` (clearcoat), times ``n.l``; the coat's lobe times
    ``n_c.l`` on its own normal where ``coat = (n_c.l, n_c.v, n_c.h)`` is given (`gltf_coat_normal.coat_normal_oracle`);
    a list of 3 mpmath numbers."""
    import mpmath  # noqa: PLC0415 - the stability suite's, kept out of import time

    def d_and_v(alpha, n_dot_l=n_dot_l, n_dot_v=n_dot_v, n_dot_h=n_dot_h):
        a2 = alpha * alpha
        denominator = n_dot_h * n_dot_h * (a2 - 1) + 1
        if denominator == 0:
            return mpmath.mpf(0)
        d = a2 / (mpmath.pi * denominator * denominator)
        return d / (2 * (n_dot_v * mpmath.sqrt(a2 + (1 - a2) * n_dot_l ** 2)
                         + n_dot_l * mpmath.sqrt(a2 + (1 - a2) * n_dot_v ** 2)))

    layer = d_and_v(roughness * roughness) if layer is None else layer
    x = (1 - v_dot_h) ** 5
    f0 = ((ior - 1) / (ior + 1)) ** 2
    weight, color = (p.specular, p.specular_color) if "specular" in extensions else (1, [1, 1, 1])
    fr = [weight * (min(f0 * k, 1) + (1 - min(f0 * k, 1)) * x) for k in color]
    fm = [c + (1 - c) * x for c in base_color]
    if "iridescence" in extensions:  # KHR_materials_iridescence: F = mix(F, F_iridescence, iridescence)
        fr, fm = gltf_iridescence_oracle(fr, base_color, x, [weight * min(f0 * k, 1) for k in color], p, v_dot_h)
    out = []
    for c, f, g in zip(base_color, fr, fm):
        keep = (1 - p.diffuse_transmission if "diffuse_transmission" in extensions else 1) \
            * (1 - p.transmission if "transmission" in extensions else 1)  # light in front: (1 - dt)(1 - t)
        dielectric = (1 - max(fr)) * c / mpmath.pi * keep + f * layer
        metal = g * layer
        out.append((1 - metallic) * dielectric + metallic * metal)
    if "sheen" in extensions:  # KHR_materials_sheen, under the coat (gltf_sheen)
        out = gltf_sheen_oracle(out, p, n_dot_l, n_dot_v, n_dot_h)
    if "clearcoat" in extensions:  # on the coat's own normal where given (its clampedDot in the Fresnel)
        c_l, c_v, c_h = (n_dot_l, n_dot_v, n_dot_h) if coat is None else coat
        w = p.clearcoat * (mpmath.mpf("0.04") + (1 - mpmath.mpf("0.04")) * (1 - max(c_v, 0)) ** 5)
        lobe = d_and_v(p.clearcoat_roughness ** 2, c_l, c_v, c_h) * c_l if c_l > 0 and c_v > 0 else 0
        return [(1 - w) * o * n_dot_l + w * lobe for o in out]
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
    for texel, scale, theta_h in (((0.7, 0.4, 0.9), 1.0, 0.0), ((0.7, 0.4, 0.9), 1.0, 0.3), ((0.1, 0.5, 0.6), 3.0, 0.2),
                                  ((0.5, 0.5, 1.0), 0.0, 0.1)):  # tilted, far (n_c.v or n_c.l <= 0), texel unperturbed
        cases.append(Case(f"gltf_pbr clearcoat normal {texel} scale={scale:g} theta_h={theta_h:g}", "gltf clearcoat",
                          cls((0.8, 0.5, 0.2), 0.2, 0.5, clearcoat=1.0, clearcoat_roughness=0.2,
                              clearcoat_normal=texel, clearcoat_normal_strength=scale),
                          eye=_mirror_eye(30.0, 2 * theta_h), lights=light, note="the coat on its own normal"))
    return cases + sheen_cases(cls) + anisotropy_cases(cls) + iridescence_cases(cls)


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
        normal = material.clearcoat_normal
        if isinstance(normal, SurfaceInput) and normal.texture is not None and np.all(np.asarray(normal.scale) == 1.0):
            fields["clearcoatNormalTexture"] = {"index": texture_index(normal.texture),
                                                "scale": float(material.clearcoat_normal_strength)}
        out["KHR_materials_clearcoat"] = fields
    if "sheen" in used:
        fields = {"sheenColorFactor": [float(c) for c in np.broadcast_to(constant_part(material.sheen_color), 3)],
                  "sheenRoughnessFactor": float(constant_part(material.sheen_roughness))}
        textured("sheen_color", "sheenColorTexture", fields)
        out["KHR_materials_sheen"] = fields
    if "anisotropy" in used:
        direction, strength = material.anisotropy_direction, material.anisotropy_strength
        rotation = float(material.anisotropy_rotation)
        if not isinstance(direction, SurfaceInput):  # a constant direction: its angle joins the rotation (the file's
            dx, dy = 2.0 * np.broadcast_to(np.asarray(direction, np.float64), 3)[:2] - 1.0  # direction, the tangent)
            rotation += math.atan2(dy, dx)  # atan2(0, 0) = 0: a zero direction takes the tangent, as the shader
        fields = {"anisotropyStrength": float(constant_part(material.anisotropy_strength)),
                  "anisotropyRotation": rotation}
        if isinstance(direction, SurfaceInput) and isinstance(strength, SurfaceInput) and direction.texture is not None \
                and direction.texture is strength.texture and strength.channel == "b" and \
                np.all(np.asarray(direction.scale) == 1.0):
            # the file's one texture: rg the direction, b the strength (as the loader makes them); other pairs are
            # kept by glphong's extras only
            fields["anisotropyTexture"] = {"index": texture_index(direction.texture)}
        out["KHR_materials_anisotropy"] = fields
    return out | transmission_gltf_fields(material, texture_index) \
        | iridescence_gltf_fields(material, texture_index) \
        | diffuse_transmission_gltf_fields(material, texture_index)  # _transmission, _iridescence, ...: their modules
