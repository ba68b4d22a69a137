"""The models 'normalized_phong_lobe' and 'normalized_blinn_lobe' and the materials `NormalizedPhong` and
`NormalizedBlinnPhong` (docs/design.md sections 1 and 9; GLSL: ``glsl/materials/normalized_phong_lobe.glsl`` and
``glsl/materials/normalized_blinn_lobe.glsl``).

The normalised, physically plausible forms of the lecture's two lobes, parameterised by albedos:

- `NormalizedPhong`, the modified Phong model of Lafortune and Willems (1994)::

      f_r = rho_d / pi + rho_s (q + 2) / (2 pi) max(v.r, 0)^q,      r = 2 (n.l) n - l

- `NormalizedBlinnPhong`, Blinn's half-vector lobe with its exact normalisation::

      f_r = rho_d / pi + rho_s c(q) max(n.h, 0)^q,      h = (l + v) / |l + v|,
      c(q) = (q + 2)(q + 4) / (8 pi (q + 2^(-q/2)))

Each is the `MaterialSum` of `Diffuse` (``rho_d / pi``) and a lobe model (`NormalizedPhongLobe`,
`NormalizedBlinnLobe`); ``rho_s = 0`` leaves the lobe out of the program.  The responses are
``f_r (n.l)`` [1/sr].  Both lobes are non-negative, isotropic and reciprocal (``v.r = 2 (n.l)(n.v) - l.v``
and ``n.h`` are symmetric in ``l`` and ``v``; Blinn's gate ``n.v > 0`` mirrors the light loop's
``n.l > 0``), for both directions above the surface, where ``f_r`` is defined: the Phong lobe, as
`PhongLobe`, is not gated on ``n.v`` (with two-sided shading a viewer is never below the surface).  The normalisations make the lobe's directional albedo exactly ``rho_s`` at normal
incidence (``(q + 2)/(2 pi) int cos^q(theta) cos(theta) d omega = 1``, and for Blinn
``int c(q) cos^q(theta/2) cos(theta) d omega = 1``); at every other incident angle it is smaller (the
lobe is cut by the horizon, and Blinn's falls like ``cos^2(theta_i)`` for large q), so the materials
conserve energy where ``rho_d + rho_s <= 1`` per channel.  ``q = 0`` makes either lobe Lambertian
(``c(0) = 1/pi``).

=========  ======  ==========  ======  ====================================================================
parameter  kind    range       unit    meaning
=========  ======  ==========  ======  ====================================================================
rho_d      rgb     [0, 1]      1       diffuse albedo (the `Diffuse` term, ``f_r = rho_d / pi``)
rho_s      rgb     [0, 1]      1       specular albedo: the lobe's directional albedo at normal incidence
q          scalar  [0, 1e7]    1       exponent (q = 0: lobe 1, the 0^0 := 1 convention; a Lambertian lobe)
fresnel    --      --          --      None (F = 1, the paper's model), SchlickFresnel(f0) or
                                       DielectricFresnel(ior): a factor F(c) on the lobe
=========  ======  ==========  ======  ====================================================================

Units: ``f_r`` and the responses in 1/sr, the albedos and ``q`` dimensionless.

Papers: E. P. Lafortune and Y. D. Willems, 1994, "Using the modified Phong reflectance model for
physically based rendering", technical report CW197, Department of Computer Science, K.U. Leuven
(the modified Phong model).  The half-vector lobe is J. F. Blinn, 1977, "Models of light reflection
for computer synthesized pictures", SIGGRAPH '77 (Computer Graphics 11(2)); its exact energy
normalisation ``c(q)`` is the closed form of the normal-incidence albedo integral (docs/design.md section 9;
derived in tests/materials/test_normalized.py; also in F. Giesen, 2009, "Derivation of Phong and
Blinn-Phong BRDF normalization factors", with the ``(q + 8)/(8 pi)`` approximation).

Fresnel (``fresnel=``; docs/design.md section 9): `NormalizedPhong` takes ``F`` at ``c = n.l`` (the Phong-type
lobe has no half vector; this is the cosine `PhongLobe` uses) and then is no longer reciprocal
(``F(n.l) != F(n.v)``: declared reciprocity is that of the paper's model, ``fresnel=None``);
`NormalizedBlinnPhong` takes it at ``c = h.l``, which equals ``h.v``, so it stays reciprocal.  ``F <= 1``
keeps energy conservation.

Where the paper and common implementations differ (glphong follows the paper, docs/design.md section 9):

- Phong normalisation: the paper's ``(q + 2)/(2 pi)`` includes the cosine of the reflection integral;
  many renderers (and importance-sampling code) use ``(q + 1)/(2 pi)``, which normalises the lobe's
  solid-angle integral instead and reflects ``(q + 1)/(q + 2)`` of ``rho_s`` at normal incidence.
- Blinn normalisation: real-time renderers widely use ``(q + 8)/(8 pi)`` (Akenine-Moeller and Haines,
  Real-Time Rendering), an approximation of ``c(q)``: too bright by up to 7.5 % (near q = 9), 2.4 % at
  q = 1, 0.2 % at q = 1000, exact only in the limit; others reuse Phong's ``(q + 2)/(2 pi)`` for
  the half-vector lobe, about 4 times too bright for large q.  glphong uses the exact ``c(q)``.
- The diffuse term is ``rho_d / pi`` (an albedo), not a BRDF value ``k_d``; many implementations also
  weight it by ``1 - F`` or ``1 - rho_s``; the paper does not (energy conservation is the condition
  ``rho_d + rho_s <= 1``), nor does glphong.
- Fresnel: the paper has none; implementations that add Schlick to a Phong lobe often take
  ``c = v.h`` or ``n.v``; glphong takes ``n.l`` for Phong (as `PhongLobe`) and ``h.l`` for Blinn.
- Blinn's lobe is 0 where ``n.v <= 0`` (and where ``|l + v| <= 2^-20``, where ``h`` is undefined);
  implementations that only clamp ``n.h`` return light toward a viewer below the surface, which is
  neither physical nor reciprocal with the light loop's ``n.l > 0`` gate.

Numerics (docs/design.md section 3): the lobes are evaluated in the chord form (``delta = |r - v|^2 / 2``,
``|h - n|^2 / 2``, then `lobe_from_delta`), stable for q up to 1e7 at and around the peak.  The
normalisation constants are formed in float32 without overflow or cancellation: ``(q + 2) / (2 pi)``,
and ``((q + 2)/(8 pi)) ((q + 4)/(q + 2^(-q/2)))`` (the denominator is at least 1; ``2^(-q/2)``
underflows to 0 for q > 252, where it is far below an ulp of q).  They are at most 1.6e6 and 4e5 for
q <= 1e7, so ``norm * lobe`` is never ``Inf * 0``; the lobe is multiplied by the constant first and by
``n.l``, ``F`` and ``rho_s`` (each at most 1) after, so a flushed partial product means a response below
FLT_MIN.  A lobe below FLT_MIN (``q ln(1 - delta) < -87``) is flushed to 0 by llvmpipe although
``norm * lobe`` might still be representable (at most ``1.6e6 FLT_MIN``, about 2e-32): documented,
and accepted by the bands.
"""
import numpy as np

from glphong.twin.functions import blinn_lobe, half_cosine, phong_delta, phong_lobe
from glphong.materials.blinn import blinn_lobe_band
from glphong.materials.diffuse import Diffuse
from glphong.definitions.fresnel import FresnelSlot, fresnel_band, fresnel_factor
from glphong.definitions.material import GlslFile, MaterialModel, MaterialSum, Param, Properties
from glphong.materials.phong import lobe_oracle
from glphong.definitions.cases import Case, generic_cases, lobe_cases
from glphong.definitions.fresnel import DielectricFresnel, SchlickFresnel, fresnel_oracle
from glphong.twin.band import EPS, FLT_MIN, lobe_band

__all__ = ["NormalizedPhongLobe", "NormalizedPhong", "NormalizedBlinnLobe", "NormalizedBlinnPhong",
           "normalized_phong_lobe_norm", "normalized_blinn_lobe_norm", "Q_MAX"]

#: the largest exponent accepted (the stability suite checks q up to this at and around the peak)
Q_MAX = 1e7
#: normalized_phong_lobe.glsl NORMALIZED_PHONG_LOBE_INV_2PI
_INV_2PI = 1.0 / (2.0 * np.pi)
#: normalized_blinn_lobe.glsl NORMALIZED_BLINN_LOBE_INV_8PI
_INV_8PI = 1.0 / (8.0 * np.pi)
#: relative error of a normalisation constant and the products of a response in float32, in eps:
#: the constant's rounding, q + 2 and q + 4, exp2 (at most 3 eps of the denominator at q = 0), the
#: division and the three products, with margin
_NORM_ULPS = 12

RHO_S = Param("rho_s", "rgb", low=0.0, high=1.0, textureable=True,
              doc="specular albedo, dimensionless: the lobe's directional albedo at normal incidence")
_Q = Param("q", "scalar", low=0.0, high=Q_MAX,
           doc="specular exponent; q = 0 gives a constant (Lambertian) lobe")


def _float_dtype(x):
    x = np.asarray(x)
    return x.dtype if x.dtype.kind == "f" else np.dtype(np.float64)


# --------------------------------------------------------------------------- normalized_phong_lobe.glsl
def normalized_phong_lobe_norm(q):
    """``(q + 2) / (2 pi)`` [1/sr] (normalized_phong_lobe.glsl), in the dtype of ``q``."""
    dtype = _float_dtype(q)
    q = np.asarray(q, dtype=dtype)
    return ((q + dtype.type(2)) * dtype.type(_INV_2PI)).astype(dtype)


# --------------------------------------------------------------------------- normalized_blinn_lobe.glsl
def normalized_blinn_lobe_norm(q):
    """``c(q) = ((q + 2) / (8 pi)) ((q + 4) / (q + 2^(-q/2)))`` [1/sr] (normalized_blinn_lobe.glsl), in the
    dtype of ``q``: the exact normalisation ``(q + 2)(q + 4) / (8 pi (q + 2^(-q/2)))``."""
    dtype = _float_dtype(q)
    q = np.asarray(q, dtype=dtype)
    with np.errstate(under="ignore"):
        tail = np.exp2(dtype.type(-0.5) * q).astype(dtype)
    return (((q + dtype.type(2)) * dtype.type(_INV_8PI)) * ((q + dtype.type(4)) / (q + tail))).astype(dtype)


# --------------------------------------------------------------------------- shared band arithmetic
def _scaled_band(p, norm, lobe_low, lobe_high, n_dot_l, f_low, f_high, constants):
    """``rho_s F (norm lobe) (n.l)`` bounds: the lobe's band times the constant widened by
    `_NORM_ULPS` eps, ``n.l`` known to ``+- D eps``, the Fresnel band; 0 below FLT_MIN (flush)."""

    tol = constants.D * EPS
    norm = np.asarray(norm, dtype=np.float64)
    s_low = (norm * (1 - _NORM_ULPS * EPS)) * lobe_low * np.maximum(n_dot_l - tol, 0.0)
    s_high = (norm * (1 + _NORM_ULPS * EPS)) * lobe_high * np.maximum(n_dot_l + tol, 0.0)
    low = p.rho_s * f_low * s_low[..., None]
    high = p.rho_s * f_high * s_high[..., None]
    return np.where(low < FLT_MIN, 0.0, low), high


class NormalizedPhongLobe(MaterialModel):
    """The lobe of the modified Phong model (Lafortune and Willems 1994):
    ``f_r = rho_s (q + 2)/(2 pi) max(v.r, 0)^q``, ``r = 2 (n.l) n - l``.

    Parameters
    ----------
    rho_s : float or (3,) array_like
        Specular albedo (the lobe's directional albedo at normal incidence), dimensionless, in [0, 1].
    q : float
        Exponent, in [0, 1e7].
    fresnel : SchlickFresnel, DielectricFresnel or None
        Fresnel factor ``F(n.l)`` multiplying the lobe (default None: ``F = 1``, the paper's model).
    """

    name = "normalized_phong_lobe"
    params = (RHO_S, _Q)
    needs = ("view",)
    glsl = GlslFile("materials/normalized_phong_lobe.glsl")
    uses = ("lobe",)
    lobe_exponent = "q"
    vanishes_with = ("rho_s",)
    fresnel_slot = FresnelSlot(cosine="n.l")
    properties = Properties(reciprocal=True, isotropic=True, energy_conserving=True,
                            condition="rho_s <= 1 (its range): the albedo is rho_s at normal incidence, less elsewhere")

    def response(self, f, wi, wo, n_dot_l, p):
        s = (normalized_phong_lobe_norm(p.q) * phong_lobe(f.n, wi, wo, p.q)) * n_dot_l
        return p.rho_s * fresnel_factor(p, n_dot_l) * s[..., None]

    def band(self, f, wi, wo, n_dot_l, p, constants):
        """The lobe band of the Phong delta (`glphong.checks.tolerances.lobe_band`, docs/design.md section 4) times the
        normalisation (widened by a few eps), ``n.l +- D eps`` and the Fresnel band at ``n.l +- D eps``;
        0 where the lower end is below FLT_MIN.

        The generic default does not fit: it neither follows the chord's q-amplified sensitivity at
        the peak of a 1e7 lobe the way `lobe_band` does, nor accepts the flush to 0 of a lobe below FLT_MIN."""

        low, high = lobe_band(phong_delta(f.n, wi, wo), p.q, 1.0, constants)
        f_low, f_high = fresnel_band(p, n_dot_l, constants.D * EPS)
        return _scaled_band(p, normalized_phong_lobe_norm(np.float64(p.q)), low, high, n_dot_l, f_low, f_high,
                            constants)

    def oracle(self, f, wi, wo, n_dot_l, p):
        """``rho_s F(n.l) (q + 2)/(2 pi) max(v.r, 0)^q (n.l)`` in mpmath, ``v.r`` from ``r = 2 (n.l) n - l``."""
        import mpmath

        v_dot_r = sum(v * (2 * n_dot_l * a - b) for v, a, b in zip(wo, f.n, wi))
        norm = (p.q + 2) / (2 * mpmath.pi)
        value = norm * lobe_oracle(v_dot_r, p.q) * n_dot_l
        return [k * F * value for k, F in zip(p.rho_s, fresnel_oracle(p, n_dot_l))]

    def pbr_roughness(self):
        """A rough pyrender roughness for comparisons: the Blinn exponent of a Phong lobe is about 4 q."""
        return float((2.0 / (4.0 * self.q + 2.0)) ** 0.25)

    @classmethod
    def stability_cases(cls):
        """Generic geometry, the exponent sweep q = 0 to 1e7 at, near and in the tail of the peak, and
        the Fresnel factor at grazing incidence at the peak (`_fresnel_cases`)."""

        return (generic_cases("normalized_phong", NormalizedPhong(0.2, 0.5, 100.0))
                + lobe_cases("normalized_phong", NormalizedPhong)
                + _fresnel_cases("normalized_phong", NormalizedPhong))


class NormalizedPhong(MaterialSum):
    """The modified Phong model (Lafortune and Willems 1994):
    ``f_r = rho_d / pi + rho_s (q + 2)/(2 pi) max(v.r, 0)^q``.

    Parameters
    ----------
    rho_d, rho_s : float or (3,) array_like
        Diffuse and specular albedos, dimensionless, in [0, 1]; energy-conserving where
        ``rho_d + rho_s <= 1``.
    q : float
        Specular exponent, in [0, 1e7].
    fresnel : SchlickFresnel, DielectricFresnel or None
        Fresnel factor ``F(n.l)`` of the lobe (default None: ``F = 1``).
    ka : float or (3,) array_like, optional
        Constant term [W/(m^2 sr)], >= 0.
    two_sided : bool, optional
    """

    name = "normalized_phong"
    terms = (Diffuse, NormalizedPhongLobe)
    properties = Properties(reciprocal=True, isotropic=True, energy_conserving=True,
                            condition="rho_d + rho_s <= 1 per channel (reciprocal with fresnel=None)")


class NormalizedBlinnLobe(MaterialModel):
    """The normalised Blinn-Phong lobe: ``f_r = rho_s c(q) max(n.h, 0)^q``, ``h = (l + v)/|l + v|``,
    ``c(q) = (q + 2)(q + 4) / (8 pi (q + 2^(-q/2)))`` (0 where ``n.v <= 0``).

    Parameters
    ----------
    rho_s : float or (3,) array_like
        Specular albedo (the lobe's directional albedo at normal incidence, exactly), in [0, 1].
    q : float
        Exponent, in [0, 1e7].
    fresnel : SchlickFresnel, DielectricFresnel or None
        Fresnel factor ``F(h.l)`` multiplying the lobe (default None: ``F = 1``).
    """

    name = "normalized_blinn_lobe"
    params = (RHO_S, _Q)
    needs = ("view",)
    glsl = GlslFile("materials/normalized_blinn_lobe.glsl")
    uses = ("lobe",)
    lobe_exponent = "q"
    vanishes_with = ("rho_s",)
    fresnel_slot = FresnelSlot(cosine="h.l")
    properties = Properties(reciprocal=True, isotropic=True, energy_conserving=True,
                            condition="rho_s <= 1 (its range): the albedo is rho_s at normal incidence, less elsewhere")

    def response(self, f, wi, wo, n_dot_l, p):
        s = (normalized_blinn_lobe_norm(p.q) * blinn_lobe(f.n, wi, wo, p.q)) * n_dot_l
        return p.rho_s * fresnel_factor(p, half_cosine(wi, wo)) * s[..., None]

    def band(self, f, wi, wo, n_dot_l, p, constants):
        """The Blinn lobe band (as `BlinnLobe.band`: the chord widening scaled by the half vector's
        conditioning ``max(1, 2/|l + v|)``, either outcome accepted near the gates ``|n.v| <= D eps`` and
        ``|l + v|`` within a factor 4 of its floor) times the normalisation, ``n.l +- D eps`` and the
        Fresnel band; 0 where the lower end is below FLT_MIN.  Model-specific for the reasons given in
        `NormalizedPhongLobe.band`."""
        low, high, f_low, f_high = blinn_lobe_band(f, wi, wo, p, constants)
        return _scaled_band(p, normalized_blinn_lobe_norm(np.float64(p.q)), low, high, n_dot_l, f_low, f_high,
                            constants)

    def oracle(self, f, wi, wo, n_dot_l, p):
        """``rho_s F(h.l) (q + 2)(q + 4) / (8 pi (q + 2^(-q/2))) max(n.h, 0)^q (n.l)`` in mpmath; 0 where
        ``n.v <= 0`` or ``l + v = 0``."""
        import mpmath

        s = [a + b for a, b in zip(wi, wo)]
        length = mpmath.sqrt(sum(x * x for x in s))
        if not (sum(a * b for a, b in zip(f.n, wo)) > 0 and length > 0):
            return [mpmath.mpf(0)] * 3
        q = p.q
        norm = (q + 2) * (q + 4) / (8 * mpmath.pi * (q + mpmath.mpf(2) ** (-q / 2)))
        value = norm * lobe_oracle(sum(a * b / length for a, b in zip(f.n, s)), q) * n_dot_l
        fresnel = fresnel_oracle(p, sum(a * b / length for a, b in zip(wi, s)))
        return [k * F * value for k, F in zip(p.rho_s, fresnel)]

    def pbr_roughness(self):
        """A rough pyrender roughness for comparisons: ``(2 / (q + 2))^(1/4)`` (Beckmann-like alpha)."""
        return float((2.0 / (self.q + 2.0)) ** 0.25)

    @classmethod
    def stability_cases(cls):
        """Generic geometry, the exponent sweep q = 0 to 1e7 at, near and in the tail of the peak, and
        the Fresnel factor at grazing incidence at the peak (`_fresnel_cases`)."""

        return (generic_cases("normalized_blinn", NormalizedBlinnPhong(0.2, 0.5, 100.0))
                + lobe_cases("normalized_blinn", NormalizedBlinnPhong)
                + _fresnel_cases("normalized_blinn", NormalizedBlinnPhong))


class NormalizedBlinnPhong(MaterialSum):
    """The normalised Blinn-Phong model: ``f_r = rho_d / pi + rho_s c(q) max(n.h, 0)^q``,
    ``c(q) = (q + 2)(q + 4) / (8 pi (q + 2^(-q/2)))`` (exact: the specular albedo at normal incidence is
    ``rho_s``).

    Parameters are those of `NormalizedPhong`; ``fresnel`` multiplies the lobe by ``F(h.l)``.
    """

    name = "normalized_blinn_phong"
    terms = (Diffuse, NormalizedBlinnLobe)
    properties = Properties(reciprocal=True, isotropic=True, energy_conserving=True,
                            condition="rho_d + rho_s <= 1 per channel")


def _fresnel_cases(label, material_class, q=1e3):
    """The lobe's peak with a Fresnel factor at grazing incidence (list of `glphong.checks.stability.Case`).

    The light at ``n.l = 1e-2`` and ``1e-4`` (a point light at 1 m delivering 1 W/m^2), the eye at its
    mirror direction (the peak of both lobes: ``v = r``, ``h = n``), ``SchlickFresnel(0.04)`` and
    ``DielectricFresnel(1.5)``: ``F`` approaches 1 there (``F(n.l)`` for Phong, ``F(h.l)`` with
    ``h.l = n.l`` at the peak for Blinn), while the normalised lobe is at its peak value ``c(q)``.

    Parameters
    ----------
    label : str
    material_class : type
        Called as ``material_class(rho_d, rho_s, q, fresnel)``.
    q : float
    """

    cases = []
    for fresnel in (SchlickFresnel(0.04), DielectricFresnel(1.5)):
        for cosine in (1e-2, 1e-4):
            s = float(np.sqrt(1.0 - cosine * cosine))
            cases.append(Case(f"{label} {fresnel!r} n.l={cosine:g} peak", "fresnel",
                              material_class(0.1, 0.8, q, fresnel), eye=(-s, 0.0, cosine),
                              lights=(("point", (s, 0.0, cosine), 4 * np.pi),),
                              note="grazing incidence at the lobe's peak: F -> 1"))
    return cases
