"""The model 'cook_torrance_lobe' and the material `CookTorrance` (docs/design.md section 9; GLSL:
``glsl/materials/cook_torrance_lobe.glsl``).

Cook and Torrance 1982, "A Reflectance Model for Computer Graphics", ACM Transactions on Graphics
1(1), 7-24.  `CookTorrance` is the sum ``Diffuse + CookTorranceLobe``::

    f_r = rho_d / pi + F(h.l) D G / (4 (n.l)(n.v))          form="microfacet" (default)
    f_r = rho_d / pi + F(h.l) D' G / (pi (n.l)(n.v))        form="1982", D' = pi D (the paper's)

    D  = exp(-tan^2(theta_h) / m^2) / (pi m^2 cos^4(theta_h))        Beckmann, normalised:
                                                                    int D (n.h) dw_h = 1
    G  = min(1, 2 (n.h)(n.v) / (v.h), 2 (n.h)(n.l) / (v.h))         Torrance-Sparrow (V-cavity) masking
    h  = (l + v) / |l + v|,  cos(theta_h) = n.h,  h.l = v.h

All ``f_r`` in 1/sr; the response (what the GLSL and the twin return) is ``f_r (n.l)``.

**The two forms differ by exactly 4**, not by 4/pi: ``D' G / (pi (n.l)(n.v)) = pi D G / (pi (n.l)(n.v))
= D G / ((n.l)(n.v)) = 4 D G / (4 (n.l)(n.v))``, so ``f_r(1982) = 4 f_r(microfacet)`` for every pair of
directions (the paper's D' is un-normalised, ``int D' (n.h) dw_h = pi``, and its 1/pi cancels it; the
factor 4/pi would appear only if the normalised D were put into the paper's formula).  In float32 the
two programs differ only in the constant ``1/pi`` against ``1/(4 pi)``, a power of two apart: the
responses are in the ratio 4 to the last bit, except where one of them is flushed or saturated.  The
microfacet form has ``1/4 = |d w_h / d w_o| (v.h)`` from the half-vector Jacobian (Torrance and
Sparrow 1967, Walter et al. 2007); the paper's ``1/pi`` comes from its reflectance normalisation.

=========  ======  ===========  ======  =================================================================
parameter  kind    range        unit    meaning
=========  ======  ===========  ======  =================================================================
rho_d      rgb     [0, 1]       1       diffuse albedo (the `Diffuse` term, f_r = rho_d / pi)
m          scalar  [1e-3, 10]   1       rms slope of the microfacets (Beckmann); small m: a sharp lobe
fresnel    --      see below    --      F(h.l); default ``SchlickFresnel(0.04)``
form       choice  "microfacet" --      "microfacet": F D G / (4 (n.l)(n.v)); "1982": F D' G / (pi (n.l)(n.v))
                   or "1982"
=========  ======  ===========  ======  =================================================================

The Fresnel factor uses ``c = h.l`` (``= v.h``, the paper's ``c = V.H``): `SchlickFresnel` ``(f0)``,
`DielectricFresnel` ``(ior)`` (the paper's own, exact unpolarised formula) or None (``F = 1``).  The
lobe has no scale parameter: F sets its strength (``f0`` is its normal-incidence reflectance), so
it never vanishes from a program (``vanishes_with`` is empty).

The range of m: m -> 0 makes D a delta (its width is m radians).  float32 knows the angle of h to a
few eps (about 5e-7 rad, with the rounding of the unit vectors), and D's relative sensitivity to that
angle is about ``2 tan(theta_h) / m^2``: at m = 1e-3 the relative error within three decades of the peak
measured at most 5e-4 against the closed form, and it grows as about 4e-7/m (1.2e-3 at m = 3e-4,
5e-3 at 1e-4, 4 % at 1e-5: the lobe is then a few float32 angles wide).  1e-3 is therefore the smallest m
glphong accepts: the smallest, to a factor 2, that keeps the float32 response within 1e-3 of the exact
value over three decades around the peak (the Blinn equivalent is q = 2/m^2 - 2 = 2e6).  The upper
end, 10, is a nearly flat distribution (``tan^2(theta_h)/m^2`` is exponentially distributed over D's
projected mass, so m = 1 already puts 37 % of it beyond 45 degrees, m = 10 99 %).

Numerics (float32, branchless, never NaN or Inf from valid input; see the GLSL header):

- ``1/((n.l)(n.v))`` is never formed: the response's n.l cancels, and ``G / (n.v) = min(min(1, k (n.l))
  / (n.v), k)``, ``k = 2 (n.h)/(v.h)``, is at most ``4 / (n.l + n.v)`` (bounded at grazing view, where
  the masking term takes over); the product before F saturates at FLT_MAX.
- ``tan^2(theta_h) = delta (2 - delta) / (n.h)^2`` from the chord ``delta = |h - n|^2 / 2`` (no
  ``1 - (n.h)^2`` cancellation at the peak), ``n.h = (n.l + n.v)/|l + v|`` and ``v.h = h.l = |l + v|/2``
  (symmetric in l and v, no cancellation of ``dot(v, h)`` as l -> -v).
- ``1/cos^4 = (1 + tan^2)^2``; tan^2 is clamped at ``104 m^2`` (where exp(-104) rounds to 0) and D is 0
  beyond; ``exp(-x)`` is formed as ``exp(-x/2)^2`` around the other factor, so D is flushed only where
  it is itself below FLT_MIN (then the whole term is; its band accepts 0 there).
- Schlick's ``(1 - c)^5`` clamps ``c`` into [0, 1] (``|l + v|/2`` may round above 1 at ``l = v``).

Where the paper and common implementations differ, and what glphong follows:

- the normalisation (see above): the paper's ``F D' G / (pi (n.l)(n.v))`` is ``form="1982"``; the
  microfacet ``F D G / (4 (n.l)(n.v))`` of Walter et al. 2007 and most real-time code is the default.
  The paper's form is kept exactly as written, so it is 4 times brighter and its specular albedo
  exceeds 1 (with F = 1 up to 4.0, at m = 0.05 and normal incidence).
- the paper weights ``R = s R_s + d R_d`` with ``s + d = 1``; here ``rho_d`` is ``d R_d``'s albedo and F
  (f0) sets the specular strength; the terms are not coupled (no ``1 - F`` on the diffuse term), as
  in the paper.
- the paper allows a weighted sum of Beckmann distributions with several slopes m_j; glphong takes one
  m (a sum of two `CookTorranceLobe` terms cannot share one material, their uniforms would clash).
- the paper's Fresnel is the exact dielectric one with ``c = V.H``; the default here is Schlick's
  approximation with ``f0 = 0.04`` on the same cosine (``fresnel=DielectricFresnel(ior)`` for the
  paper's).
- D is Beckmann's (the paper's first choice; the Gaussian ``c exp(-(alpha/m)^2)`` it mentions is not
  offered); G is the paper's V-cavity min(), not the Smith masking of later implementations.
- the paper does not say what happens below the horizon; glphong gates on ``n.l > 0`` (docs/design.md section 1)
  and on ``n.v > 0`` (a one-sided surface seen from behind reflects nothing toward the viewer).

Properties: non-negative, reciprocal (D, G and F(h.l) are symmetric in l and v), isotropic.  The
microfacet form conserves energy for F <= 1: its specular directional albedo is at most max F (with
F = 1, by quadrature: 1.0000 for m = 0.05 at normal incidence, 0.94 at 85 degrees; 0.45 to 0.97 for
m = 1), so `CookTorrance` conserves energy when ``rho_d + max F <= 1``; the 1982 form does not.
"""
import numpy as np

from glphong.materials.diffuse import Diffuse
from glphong.definitions.fresnel import DielectricFresnel, FresnelSlot, SchlickFresnel, fresnel_factor
from glphong.definitions.material import Choice, GlslFile, MaterialModel, MaterialSum, Param, Properties
from glphong.definitions.cases import Case, _mirror_eye, _unit, generic_cases
from glphong.definitions.fresnel import fresnel_oracle
from glphong.twin.functions import microfacet_geometry, microfacet_ggx

__all__ = ["CookTorranceLobe", "CookTorrance", "cook_torrance_geometry", "cook_torrance_beckmann",
           "cook_torrance_masking", "COOK_TORRANCE_EXP_LIMIT", "COOK_TORRANCE_FORM_RATIO"]

#: the half-vector geometry, now the library chunk microfacet.glsl shared with `GltfPBR` (this name is kept)
cook_torrance_geometry = microfacet_geometry

#: cook_torrance_lobe.glsl COOK_TORRANCE_EXP_LIMIT: tan^2(theta_h) / m^2 at which D is set to 0
COOK_TORRANCE_EXP_LIMIT = 104.0
#: f_r(form="1982") / f_r(form="microfacet"): exactly 4 (D' = pi D cancels the paper's 1/pi)
COOK_TORRANCE_FORM_RATIO = 4.0
#: the constant of each form's response: F D' (G / n.v) times it (D' = pi D)
_SCALE = {"microfacet": 0.25 / np.pi, "1982": 1.0 / np.pi}
_FLT_MAX = float(np.finfo(np.float32).max)
_FLT_MIN = float(np.finfo(np.float32).tiny)

_M = Param("m", "scalar", low=1e-3, high=10.0, unit="",
           doc="rms slope of the microfacets (Beckmann), GGX's alpha; float32 resolves the peak down to 1e-3")
_DISTRIBUTION = Choice("distribution", ("beckmann", "ggx"), default="beckmann",
                       doc="the microfacet distribution D: the paper's Beckmann (slope m), or GGX (Trowbridge-Reitz) "
                           "with alpha = m; the masking stays Cook-Torrance's")
_FORM = Choice("form", ("microfacet", "1982"), default="microfacet",
               doc="'microfacet': F D G / (4 (n.l)(n.v)); '1982': the paper's F D' G / (pi (n.l)(n.v)), "
                   "D' = pi D, exactly 4 times the microfacet form")


def cook_torrance_beckmann(tan2, m):
    """The paper's un-normalised Beckmann distribution ``D' = pi D = exp(-tan2/m^2) / (m^2 cos^4)``
    (cook_torrance_lobe.glsl), evaluated as ``(exp(-x/2) (1 + t)^2 / m^2) exp(-x/2)``, ``t = min(tan2,
    104 m^2)``, ``x = t / m^2``; 0 where ``tan2 >= 104 m^2``.  tan2 (...) >= 0 (may be inf) -> (...)."""
    tan2 = np.asarray(tan2)
    dtype = tan2.dtype if tan2.dtype.kind == "f" else np.float64
    tan2 = tan2.astype(dtype)
    m = np.asarray(m, dtype)
    m2 = m * m
    limit = dtype.type(COOK_TORRANCE_EXP_LIMIT) * m2
    t = np.minimum(tan2, limit)
    sec2 = dtype.type(1) + t
    root = np.exp(dtype.type(-0.5) * (t / m2)).astype(dtype)
    with np.errstate(under="ignore"):
        value = ((root * ((sec2 * sec2) / m2)) * root).astype(dtype)
    return np.where(tan2 < limit, value, dtype.type(0)).astype(dtype)


def _distribution(tan2, m, distribution):
    """``D' = pi D`` of cook_torrance_lobe.glsl: Beckmann's (`cook_torrance_beckmann`), or ``pi`` times GGX's with
    ``alpha = m`` (`glphong.twin.functions.microfacet_ggx`)."""
    if distribution == "ggx":
        tan2 = np.asarray(tan2)
        m = tan2.dtype.type(m)
        return (tan2.dtype.type(np.pi) * microfacet_ggx(tan2, m * m)).astype(tan2.dtype)
    return cook_torrance_beckmann(tan2, m)


def cook_torrance_masking(n_dot_l, n_dot_v, n_dot_h, h_dot_l):
    """``G / (n.v)`` (cook_torrance_lobe.glsl): ``min(min(1, k (n.l)) / (n.v), k)``, ``k = 2 (n.h)/(v.h)``,
    each step at most FLT_MAX; the arguments as `cook_torrance_geometry` returns them, (...) -> (...)."""
    n_dot_h = np.asarray(n_dot_h)
    dtype = n_dot_h.dtype
    big = dtype.type(_FLT_MAX)
    with np.errstate(divide="ignore", over="ignore"):
        k = np.minimum((dtype.type(2) * n_dot_h) / h_dot_l, big)
        shadowing = np.minimum(dtype.type(1), k * n_dot_l)
        return np.minimum(np.minimum(shadowing / n_dot_v, k), big).astype(dtype)


def oracle_half_vector(f, wi, wo, n_dot_l):
    """For the microfacet models' mpmath oracles: ``(dot, n.v, h)`` with ``h = (l + v)/|l + v|`` straight from the
    textbook, ``h`` None where ``n.l <= 0``, ``n.v <= 0`` or ``l = -v`` (the response is 0 there)."""
    import mpmath  # noqa: PLC0415 - the stability suite's, kept out of import time

    dot = lambda a, b: sum(x * y for x, y in zip(a, b))  # noqa: E731
    n_dot_v = dot(f.n, wo)
    s = [a + b for a, b in zip(wi, wo)]
    length = mpmath.sqrt(dot(s, s))
    if not (n_dot_l > 0 and n_dot_v > 0 and length > 0):
        return dot, n_dot_v, None
    return dot, n_dot_v, [x / length for x in s]


class CookTorranceLobe(MaterialModel):
    """The Cook-Torrance specular term alone: ``f_r = F(h.l) D G / (4 (n.l)(n.v))`` (form="microfacet")
    or the paper's ``F(h.l) D' G / (pi (n.l)(n.v))`` (form="1982", exactly 4 times as large).

    With ``h = (l + v)/|l + v|`` and ``cos(theta_h) = n.h``::

        D  = exp(-tan^2(theta_h) / m^2) / (pi m^2 cos^4(theta_h))     Beckmann (distribution="beckmann"), D' = pi D
        G  = min(1, 2 (n.h)(n.v) / (v.h), 2 (n.h)(n.l) / (v.h))      Torrance-Sparrow masking

    [1/sr]; ``distribution="ggx"`` puts GGX's ``D`` with ``alpha = m`` in place of Beckmann's.

    Parameters
    ----------
    m : float
        rms slope of the microfacets, dimensionless, in [1e-3, 10].
    fresnel : SchlickFresnel, DielectricFresnel or None
        The Fresnel factor ``F(h.l)`` (default ``SchlickFresnel(0.04)``; None: ``F = 1``).
    form : {'microfacet', '1982'}
    distribution : {'beckmann', 'ggx'}
        The paper's Beckmann distribution of slope ``m``, or GGX with ``alpha = m`` (the masking stays the paper's).
    """

    name = "cook_torrance_lobe"
    params = (_M,)
    needs = ("view",)
    glsl = GlslFile("materials/cook_torrance_lobe.glsl")
    uses = ("microfacet",)
    vanishes_with = ()
    choices = (_FORM, _DISTRIBUTION)
    fresnel_slot = FresnelSlot(cosine="h.l", default=SchlickFresnel(0.04))
    properties = Properties(reciprocal=True, isotropic=True, energy_conserving=True,
                            condition="form='microfacet' and F <= 1 (the specular albedo is at most max F); "
                                      "form='1982' is 4 times as large and exceeds 1")

    def response(self, f, wi, wo, n_dot_l, p):
        valid, n_dot_v, n_dot_h, h_dot_l, tan2 = cook_torrance_geometry(f.n, wi, wo, n_dot_l)
        dtype = tan2.dtype
        d = _distribution(tan2, p.m, p.distribution)
        g = cook_torrance_masking(np.asarray(n_dot_l).astype(dtype), n_dot_v, n_dot_h, h_dot_l)
        with np.errstate(over="ignore", under="ignore"):
            s = np.minimum(d * (g * dtype.type(_SCALE[p.form])), dtype.type(_FLT_MAX)).astype(dtype)
        value = fresnel_factor(p, h_dot_l) * s[..., None]
        return np.where(valid[..., None], value, dtype.type(0)).astype(dtype)

    def band(self, f, wi, wo, n_dot_l, p, constants):
        """The generic band (`MaterialModel.band`: the twin's sensitivity to a few ulps of its inputs),
        with its lower end at 0 where the twin's ``D'`` is below ``2 FLT_MIN``: float32 flushes D' there
        before ``G / (n.v)`` multiplies it (only at grazing view far in D's tail can the product be
        representable)."""
        low, high = super().band(f, wi, wo, n_dot_l, p, constants)
        n_dot_l = np.maximum(n_dot_l, np.finfo(np.float64).tiny)
        _, _, _, _, tan2 = cook_torrance_geometry(f.n, wi, wo, n_dot_l)
        flushed = _distribution(tan2, p.m, p.distribution) < 2 * _FLT_MIN
        return np.where(flushed[..., None], np.minimum(low, 0.0), low), high

    def oracle(self, f, wi, wo, n_dot_l, p):
        """The paper's formulas in mpmath, straight from the textbook (h from l + v, tan^2 from 1 - cos^2,
        cos^4 in the denominator, 1/((n.l)(n.v)) formed): 0 where n.v <= 0 or l = -v."""
        import mpmath

        dot, n_dot_v, h = oracle_half_vector(f, wi, wo, n_dot_l)
        if h is None:
            return [mpmath.mpf(0)] * 3
        n_dot_h = dot(f.n, h)
        v_dot_h = dot(wo, h)
        cos2 = n_dot_h * n_dot_h
        tan2 = (1 - cos2) / cos2
        m2 = p.m * p.m
        if p.distribution == "ggx":  # GGX with alpha = m, as Walter et al. write it
            d = m2 / (mpmath.pi * (cos2 * (m2 - 1) + 1) ** 2)
        else:
            d = mpmath.exp(-tan2 / m2) / (mpmath.pi * m2 * cos2 * cos2)
        g = min(mpmath.mpf(1), 2 * n_dot_h * n_dot_v / v_dot_h, 2 * n_dot_h * n_dot_l / v_dot_h)
        if p.form == "1982":
            f_r = [F * (mpmath.pi * d) * g / (mpmath.pi * n_dot_l * n_dot_v) for F in fresnel_oracle(p, dot(h, wi))]
        else:
            f_r = [F * d * g / (4 * n_dot_l * n_dot_v) for F in fresnel_oracle(p, dot(h, wi))]
        return [x * n_dot_l for x in f_r]

    def pbr_roughness(self):
        """A rough pyrender roughness for comparisons: ``sqrt(m)`` (alpha = m), at most 1."""
        return float(min(np.sqrt(self.m), 1.0))

    @classmethod
    def stability_cases(cls):
        return _stability_cases()


class CookTorrance(MaterialSum):
    """Cook and Torrance 1982: ``rho_d / pi + F(h.l) D G / (4 (n.l)(n.v))`` (form="microfacet") or the
    paper's ``rho_d / pi + F(h.l) D' G / (pi (n.l)(n.v))``, ``D' = pi D`` (form="1982", whose specular
    term is exactly 4 times the microfacet one).

    Parameters
    ----------
    rho_d : float or (3,) array_like
        Diffuse albedo, dimensionless, in [0, 1].
    m : float
        rms slope of the microfacets (Beckmann), dimensionless, in [1e-3, 10].
    fresnel : SchlickFresnel, DielectricFresnel or None
        ``F(h.l)`` of the specular term (default ``SchlickFresnel(0.04)``; None: ``F = 1``).
    form : {'microfacet', '1982'}
    distribution : {'beckmann', 'ggx'}
        Beckmann (the paper's), or GGX with ``alpha = m``.
    ka : float or (3,) array_like, optional
        Constant term [W/(m^2 sr)], >= 0.
    two_sided : bool, optional
    """

    name = "cook_torrance"
    terms = (Diffuse, CookTorranceLobe)
    properties = Properties(reciprocal=True, isotropic=True, energy_conserving=True,
                            condition="form='microfacet' and rho_d + max F <= 1 (the terms are not coupled)")


def _stability_cases():
    """Generic geometry plus the extremes of Cook-Torrance: grazing view (1/((n.l)(n.v))), grazing half
    vectors (Beckmann's tan^2 and exp), small m at the peak, v.h near 0, Schlick at c rounding above 1."""

    e_one = 4 * np.pi  # a point light at 1 m: E = 1 W/m^2
    light = _unit(30.0)
    cases = generic_cases("cook_torrance", CookTorrance(0.2, 0.3)) + \
        generic_cases("cook_torrance 1982 m=0.05", CookTorrance(0.2, 0.05, form="1982"))

    def toward(l):  # a point light at the unit vector l (E = 1 W/m^2): its direction is formed from the
        # float32 position in the twin and the oracle alike (a directional light's is normalised first)
        return (("point", tuple(float(x) for x in l), e_one),)

    def mirrored(c):  # l and v at n.l = n.v = c, opposite azimuths: h = n exactly, v.h = c
        s = float(np.sqrt(1.0 - c * c))
        return dict(eye=(-s, 0.0, c), lights=toward((s, 0.0, c)))

    spec = lambda m, form="microfacet", fresnel=SchlickFresnel(0.04): CookTorrance(0.0, m, fresnel, form)  # noqa: E731
    # grazing view: G/(n.v) -> 2 (n.h)/(v.h), the product (n.l)(n.v) never formed
    for nv in (1e-3, 1e-8, 1e-20, 1e-30):
        cases.append(Case(f"cook_torrance grazing view n.v={nv:g}", "cook-torrance grazing", spec(0.3),
                          eye=(-float(np.sqrt(1.0 - nv * nv)), 0.0, nv), lights=(("point", _unit(40.0), e_one),),
                          note="G/(n.v) -> 2 (n.h)/(v.h) as n.v -> 0: finite"))
    for c, m in ((1e-10, 0.3), (1e-20, 0.3), (1e-20, 1e-3)):
        cases.append(Case(f"cook_torrance mirrored grazing n.l=n.v={c:g} m={m:g}", "cook-torrance grazing", spec(m),
                          note="(n.l)(n.v) below FLT_MIN; the response F D/(4 n.v) is representable", **mirrored(c)))
    cases.append(Case("cook_torrance mirrored grazing n.l=n.v=1e-36 m=1e-3", "cook-torrance grazing", spec(1e-3),
                      in_range=False, note="F D/(4 n.v) = 8e40 exceeds FLT_MAX: saturates at FLT_MAX, never Inf",
                      **mirrored(1e-36)))
    cases.append(Case("cook_torrance 1982 mirrored grazing n.l=n.v=1e-20", "cook-torrance grazing", spec(0.3, "1982"),
                      **mirrored(1e-20)))
    # grazing half vectors: tan^2 from the chord, exp(-x) underflowing cleanly
    for nh, m in ((0.5, 0.3), (0.3, 1.0), (0.1, 3.0), (0.03, 10.0), (0.0105, 10.0), (0.1, 1.0), (1e-3, 10.0)):
        # l = cos(a) h + sin(a) s, v = cos(a) h - sin(a) s with s = +y perpendicular to h: the half vector is h
        theta_h = float(np.arccos(nh))
        h = np.array([np.sin(theta_h), 0.0, nh])
        s = np.array([0.0, 1.0, 0.0])
        a = 0.3
        l, v = np.cos(a) * h + np.sin(a) * s, np.cos(a) * h - np.sin(a) * s
        x = (1 - nh * nh) / (nh * nh) / (m * m)
        note = f"tan^2/m^2 = {x:.3g}" + ("" if x < 87 else ": exp(-x) below FLT_MIN" if x < 104 else ": D = 0")
        cases.append(Case(f"cook_torrance grazing h n.h={nh:g} m={m:g}", "cook-torrance tan2", spec(m),
                          eye=tuple(map(float, v)), lights=toward(l), note=note))
    for c in (1e-19, 1e-25):
        cases.append(Case(f"cook_torrance l, v grazing and crossed n.l=n.v={c:g}", "cook-torrance tan2", spec(10.0),
                          eye=(0.0, 1.0, c), lights=toward((1.0, 0.0, c)),
                          note="n.h = 1.4 n.l: (n.h)^2 underflows for 1e-25 (tan^2 = Inf, D = 0, no Inf * 0)"))
    # small m at and around the peak (the lobe is m radians wide; the mirror eye turned by 2 theta_h turns h
    # by theta_h); wide lobes at fixed angles
    for m in (1e-3, 1e-2, 0.1, 1.0, 10.0):
        offsets = ((("peak", 0.0), ("near", 0.7 * m), ("tail", 3.0 * m)) if m < 1 else
                   (("peak", 0.0), ("theta_h=0.25", 0.25), ("theta_h=0.5", 0.5)))
        for where, theta_h in offsets:
            cases.append(Case(f"cook_torrance m={m:g} {where}", "cook-torrance peak", CookTorrance(0.1, m),
                              eye=_mirror_eye(30.0, 2 * theta_h), lights=(("point", light, e_one),),
                              note=f"theta_h = {theta_h:.3g} rad"))
    cases.append(Case("cook_torrance 1982 m=1e-3 peak", "cook-torrance peak", CookTorrance(0.1, 1e-3, form="1982"),
                      eye=_mirror_eye(30.0, 0.0), lights=(("point", light, e_one),)))
    # the GGX option: its peak (a2 + tan2 = a2: 1e-12 at m = 1e-3), its long tail, grazing view
    for m in (1e-3, 0.05, 0.5, 10.0):
        for where, theta_h in (("peak", 0.0), ("tail", min(30.0 * m, 1.2))):
            cases.append(Case(f"cook_torrance ggx m={m:g} {where}", "cook-torrance ggx",
                              CookTorrance(0.1, m, distribution="ggx"), eye=_mirror_eye(30.0, 2 * theta_h),
                              lights=(("point", light, e_one),), note=f"theta_h = {theta_h:.3g} rad"))
    for nv in (1e-3, 1e-20):
        cases.append(Case(f"cook_torrance ggx grazing view n.v={nv:g}", "cook-torrance ggx",
                          CookTorrance(0.0, 0.3, distribution="ggx"), eye=(-float(np.sqrt(1.0 - nv * nv)), 0.0, nv),
                          lights=(("point", _unit(40.0), e_one),)))
    # v.h near 0: l almost opposite to v, both grazing (l = -v itself is not lit: n.v < 0 there)
    for c, gap in ((1e-2, 1e-3), (1e-4, 1e-5), (1e-6, 1e-7)):
        r = float(np.sqrt(1.0 - c * c))
        l = (r, 0.0, c)
        v = (-r * float(np.cos(gap)), r * float(np.sin(gap)), c)
        v_dot_h = float(np.hypot(r * gap, 2 * c)) / 2
        cases.append(Case(f"cook_torrance l almost -v, v.h={v_dot_h:.3g}", "cook-torrance v.h", spec(0.3),
                          eye=v, lights=toward(l),
                          note="v.h = |l + v|/2, no cancellation; G = 1 there"))
    # Schlick's (1 - c)^5 where c = |l + v|/2 rounds above 1 (l = v)
    for angle in (0.0, 10.0, 60.0):
        u = _unit(angle, 30.0)
        cases.append(Case(f"cook_torrance l = v at {angle:g} deg (c = 1)", "cook-torrance fresnel", spec(0.3),
                          eye=u, lights=toward(u),
                          note="h.l may round above 1: clamped, F = f0"))
    cases.append(Case("cook_torrance l = v = n, dielectric F", "cook-torrance fresnel",
                      CookTorrance(0.0, 0.3, DielectricFresnel(1.5)), eye=_unit(0.0),
                      lights=toward(_unit(0.0)), note="h.l = 1: F = ((ior-1)/(ior+1))^2"))
    return cases

