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
from glphong.definitions.material import MaterialModel, Param, Properties, constant_part
from glphong.definitions.params import GlslFile
from glphong.definitions.surface import SurfaceInput
from glphong.twin.band import EPS
from glphong.twin.functions import microfacet_geometry, microfacet_ggx

__all__ = ["GltfPBR", "gltf_pbr_ggx", "gltf_pbr_visibility_cos"]

_FLT_MAX = float(np.finfo(np.float32).max)
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


def gltf_pbr_visibility_cos(n_dot_l, n_dot_v, a2):
    """``V (n.l) = n.l / (2 (n.v r_l + n.l r_v))``, ``r_x = sqrt((n.x)^2 + a2 (1 - (n.x)^2))`` (gltf_pbr.glsl)."""
    n_dot_l = np.asarray(n_dot_l)
    dtype = np.result_type(n_dot_l, n_dot_v)
    n_dot_l, n_dot_v, a2 = n_dot_l.astype(dtype), np.asarray(n_dot_v).astype(dtype), np.asarray(a2).astype(dtype)
    one = dtype.type(1)
    r_l = np.sqrt(n_dot_l * n_dot_l + a2 * (one - n_dot_l * n_dot_l))
    r_v = np.sqrt(n_dot_v * n_dot_v + a2 * (one - n_dot_v * n_dot_v))
    with np.errstate(divide="ignore", invalid="ignore"):
        return (n_dot_l / (dtype.type(2) * (n_dot_v * r_l + n_dot_l * r_v))).astype(dtype)


class GltfPBR(MaterialModel):
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
    """

    name = "gltf_pbr"
    params = (_BASE_COLOR, _METALLIC, _ROUGHNESS, _EMISSIVE, _OCCLUSION, _IOR)
    needs = ("view",)
    ambient = "base_color"
    ambient_scale = 1.0 / np.pi
    emission = "emissive"
    occluded_by = "occlusion"
    glsl = GlslFile("materials/gltf_pbr.glsl")
    uses = ("microfacet",)
    vanishes_with = ()
    properties = Properties(reciprocal=True, isotropic=True, energy_conserving=False, non_negative=True,
                            condition="never in general: the Fresnel mix of a light dielectric exceeds 1 at oblique "
                                      "incidence (module docstring)")

    def gltf_fields(self, texture_index):
        """glTF's fields as the file writes them: the factors as they are, the metallic-roughness texture where
        metallic and roughness read one image's blue and green, the emissive factor (its strength above 1 as
        ``KHR_materials_emissive_strength``) and texture (`MaterialModel.gltf_fields`)."""
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
        return pbr, out

    def _parts(self, f, wi, wo, n_dot_l, p):
        """``(valid, diffuse (N, 3), fresnel (N, 3), specular (N,), tan2, a2, v_dot_h)``: the response is ``diffuse +
        fresnel * specular`` where valid, ``specular = D V (n.l)`` (gltf_pbr.glsl's order)."""
        valid, n_dot_v, _, v_dot_h, tan2 = microfacet_geometry(f.n, wi, wo, n_dot_l)
        dtype = tan2.dtype
        n_dot_l = np.asarray(n_dot_l).astype(dtype)
        roughness = np.asarray(p.roughness).astype(dtype)  # a constant, or (N,) where textured
        alpha = roughness * roughness
        a2 = alpha * alpha
        with np.errstate(over="ignore", under="ignore", invalid="ignore"):
            specular = np.minimum(gltf_pbr_ggx(tan2, a2) * gltf_pbr_visibility_cos(n_dot_l, n_dot_v, a2),
                                  dtype.type(_FLT_MAX)).astype(dtype)
            x1 = np.maximum(dtype.type(1) - v_dot_h, dtype.type(0))
            x = ((x1 * x1) * (x1 * x1) * x1).astype(dtype)
            c = np.asarray(p.base_color, dtype)
            ior = np.asarray(p.ior).astype(dtype)
            r = ((ior - dtype.type(1)) / (ior + dtype.type(1))).astype(dtype)
            f0 = (r * r).astype(dtype)
            fd = (f0 + (dtype.type(1) - f0) * x).astype(dtype)
            m = np.asarray(p.metallic).astype(dtype)[..., None]
            diffuse = (c * (dtype.type(1 / np.pi) * n_dot_l)[..., None]) * (dtype.type(1) - fd)[..., None] \
                * (dtype.type(1) - m)
            fresnel = fd[..., None] * (dtype.type(1) - m) + (c + (dtype.type(1) - c) * x[..., None]) * m
        return valid, diffuse, fresnel, specular, tan2, a2, v_dot_h

    def response(self, f, wi, wo, n_dot_l, p):
        valid, diffuse, fresnel, specular, _, _, _ = self._parts(f, wi, wo, n_dot_l, p)
        dtype = specular.dtype
        with np.errstate(over="ignore", invalid="ignore"):
            value = diffuse + fresnel * specular[..., None]
        return np.where(valid[..., None], value, dtype.type(0)).astype(dtype)

    def band(self, f, wi, wo, n_dot_l, p, constants):
        """The generic band, widened by D over the half vector's angular uncertainty: ``theta_h`` is known to
        ``delta = 2 D eps / (v.h)`` (l, v and n rounded to float32, h from their sum), and D falls monotonically
        with ``theta_h``, so the specular part lies between its values at ``theta_h + delta`` and at
        ``max(theta_h - delta, 0)``.  What matters where the lobe (``alpha = roughness^2`` rad wide) is narrower
        than float32 resolves directions: roughness below about 3e-4, off the exact peak."""
        low, high = super().band(f, wi, wo, n_dot_l, p, constants)
        valid, _, fresnel, specular, tan2, a2, v_dot_h = self._parts(f, wi, wo, n_dot_l, p)
        theta = np.arctan(np.sqrt(tan2))
        delta = 2 * constants.D * EPS / np.maximum(v_dot_h, 1e-30)

        def ggx(t):
            with np.errstate(over="ignore"):
                return gltf_pbr_ggx(np.tan(np.clip(t, 0.0, np.pi / 2)) ** 2, a2)

        d = gltf_pbr_ggx(tan2, a2)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            ratio_high = np.where(d > 0, ggx(theta - delta) / d, 1.0)
            ratio_low = np.where(d > 0, ggx(theta + delta) / d, 1.0)
            part = np.where(valid, specular, 0.0)[..., None] * fresnel
            high = high + np.nan_to_num(part * np.maximum(ratio_high - 1, 0.0)[..., None], posinf=_FLT_MAX)
            low = low - np.nan_to_num(part * np.maximum(1 - ratio_low, 0.0)[..., None])
        return low, high

    def oracle(self, f, wi, wo, n_dot_l, p):
        """Appendix B in mpmath, as the specification writes it: ``h`` from ``l + v``, ``D`` with the denominator
        ``(n.h)^2 (alpha^2 - 1) + 1``, ``V`` with its ``|n.l|``, then times ``n.l``; 0 where ``n.v <= 0`` or
        ``l = -v``, and where roughness is 0 at the exact mirror direction (the delta, module docstring)."""
        import mpmath  # noqa: PLC0415 - the stability suite's, kept out of import time

        dot, n_dot_v, h = oracle_half_vector(f, wi, wo, n_dot_l)
        if h is None:
            return [mpmath.mpf(0)] * 3
        n_dot_h, v_dot_h = dot(f.n, h), abs(dot(wo, h))
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
        return _stability_cases()


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
