"""The model 'ashikhmin_shirley': the anisotropic Phong BRDF (docs/design.md section 9; GLSL:
``glsl/materials/ashikhmin_shirley.glsl``).

Ashikhmin and Shirley 2000, "An anisotropic Phong BRDF model", Journal of Graphics Tools 5(2),
pp. 25-32.  In the local frame ``(t, b, n)`` with ``h = (l + v)/|l + v|``::

    f_r = f_s + f_d                                                          [1/sr]
    f_s = sqrt((nu + 1)(nv + 1)) / (8 pi) (n.h)^e F(v.h) / ((v.h) max(n.l, n.v))
    e   = (nu (h.t)^2 + nv (h.b)^2) / (1 - (n.h)^2)
    F(u) = rho_s + (1 - rho_s)(1 - u)^5                                      (Schlick 1994)
    f_d = 28 rho_d / (23 pi) (1 - rho_s) (1 - (1 - n.l/2)^5) (1 - (1 - n.v/2)^5)

The response is ``f_r (n.l)``; 0 where ``n.v <= 0`` (nothing is reflected toward a viewer below
the surface).  Both parts are one model, because the diffuse part depends on ``rho_s`` (the energy
the specular layer takes).  The Fresnel factor is built in (Schlick's, with ``f0 = rho_s``), at the
cosine ``u = v.h = l.h`` (the paper's ``k.h``, the same for both directions): the model has no
``fresnel=`` argument.  It needs the view and the tangent frame (``needs = ('view', 'tangent')``):
``t`` is the mesh tangent made orthogonal to n, ``b = sign(w) n x t``.

=========  ======  ==========  ======  =====================================================
parameter  kind    range       unit    meaning
=========  ======  ==========  ======  =====================================================
rho_d      rgb     [0, 1]      1       diffuse reflectance of the substrate (under the layer)
rho_s      rgb     [0, 1]      1       specular reflectance at normal incidence (Schlick f0)
nu         scalar  [0, 1e6]    1       Phong exponent along t (larger: narrower along t)
nv         scalar  [0, 1e6]    1       Phong exponent along b (larger: narrower along b)
=========  ======  ==========  ======  =====================================================

``nu = nv = q`` is isotropic (the exponent is ``q`` for every ``h``), with a Blinn-Phong-like lobe
``(q + 1)/(8 pi) (n.h)^q``.  A brushed metal has ``nu >> nv`` or the reverse: the highlight is
stretched along the direction of the smaller exponent.

Properties (checked in tests/materials/test_ashikhmin_shirley.py): non-negative; reciprocal (``h``,
``v.h = l.h`` and ``max(n.l, n.v)`` are symmetric, and so is the diffuse product); anisotropic
unless ``nu = nv``.  Energy: the paper shows the model is nearly, not exactly, energy conserving.
Quadrature of this implementation (float64): with ``F = 1`` (``rho_s = 1``) the specular albedo at
normal incidence is ``(q + 1) 2 (1 - 2^(-(q+3)/2))/(q + 3) - (1 - 2^(-(q+1)/2))`` for ``nu = nv = q``,
about ``(q - 1)/(q + 3)`` (0.996 at q = 1000, 0.999996 at 1e6), and decreases toward grazing to
about 1/2; the diffuse albedo is ``rho_d (1 - rho_s)(1 - (1 - n.l/2)^5)`` (28/23 normalises it);
the total albedo over ``rho_d = 1``, ``rho_s`` in [0, 1], ``nu, nv`` in [0, 1e6] and incidence 0 to
89.9 degrees stayed below 1 (largest 0.999996).  Declared ``energy_conserving=True`` on that
numerical evidence (no proof).

Ambient light: the model answers ``L_a`` with ``(rho_d / pi) L_a`` (``ambient = 'rho_d'``,
``ambient_scale = 1/pi``, the convention of `Diffuse`).  That is an approximation: the exact
answer to a uniform ``L_a`` would be the directional albedo of ``f_d + f_s`` at ``v`` (it has the
factor ``1 - rho_s``, a view dependence and the specular part); glphong keeps the ambient term a
constant times a parameter.

Stable evaluation (docs/design.md section 3): the exponent as the weighted mean
``e = (nu (h.t)^2 + nv (h.b)^2) / ((h.t)^2 + (h.b)^2)`` (``1 - (n.h)^2 = (h.t)^2 + (h.b)^2``: never 0/0
as ``n.h`` rounds to 1; h.t and h.b scaled by the larger of them first; positive terms only, so e is
good to a few ulp, where ``mix(nu, nv, w)`` would carry an absolute error ``nu eps``, 2% in ``(n.h)^e``
at nu = 1e6; ``(nu + nv)/2`` at ``h = n`` exactly, where ``(n.h)^e = 1`` for any e);
``(n.h)^e`` by `lobe_from_delta` with ``delta = |h - n|^2 / 2``; ``v.h = |l + v| / 2`` (exact for
unit vectors, and good to eps absolute, where ``dot(v, h)`` of vectors that are unit only to eps is
off by ``(|v|^2 - |l|^2) / (2 |l + v|)``, as large as v.h itself near ``|l + v| = 1e-4``); ``h`` is
undefined, and ``f_s = 0``, where ``|l + v| <= 2^-20`` (`ASHIKHMIN_SHIRLEY_HALF_FLOOR`, as Blinn's), so
``1/(v.h) <= 2^21`` and the response is at most about 8e10; ``n.l / max(n.l, n.v)`` formed as a ratio in (0, 1];
``1 - (1 - c/2)^5 = y (1 + m + m^2 + m^3 + m^4)``, ``y = c/2``, ``m = 1 - y``, without cancellation.

Where the paper and common implementations differ (glphong follows the paper):

- pbrt's ``FresnelBlend`` (Pharr, Jakob and Humphreys, pbrt-v3) keeps the paper's diffuse term and
  its specular denominator ``4 (h.l) max(n.l, n.v)`` but replaces the paper's anisotropic Phong
  distribution by a microfacet distribution (Beckmann or Trowbridge-Reitz, from a roughness alpha);
  glphong uses the paper's ``(nu + 1)(nv + 1)`` normalised ``(n.h)^e`` with exponents.
- Real-time ports often clamp ``1 - (n.h)^2`` from below (e.g. ``max(1 - (n.h)^2, 1e-4)``), which
  changes the exponent, and so the peak, of sharp lobes; glphong evaluates the exact weighted mean.
- Some ports write the exponent with the azimuth of h, ``nu cos^2(phi_h) + nv sin^2(phi_h)``: the
  same function (glphong's form needs no trigonometry and no atan2).
- Some ports replace ``(1 - rho_s)`` in the diffuse term by ``(1 - F)``, or the Fresnel cosine
  ``v.h`` by ``n.v``, or ``max(n.l, n.v)`` by ``n.l + n.v``; glphong keeps the paper's
  ``(1 - rho_s)``, ``F(v.h)`` and ``max``.
- The paper's model is one-sided (``n.l, n.v > 0``); pbrt takes absolute cosines.  glphong gates
  ``n.l > 0`` (the light loop) and ``n.v > 0`` (a select) and leaves two-sided shading to the
  renderer, which flips n toward the viewer.
"""
import numpy as np

from glphong.definitions.material import GlslFile, MaterialModel, Param, Properties
from glphong.materials.phong import lobe_oracle
from glphong.twin.functions import dot as _dot
from glphong.definitions.cases import Case, generic_cases
from glphong.twin.band import EPS, FLT_MIN
from glphong.twin.functions import fresnel_schlick, lobe_from_delta, safe_normalize

__all__ = ["AshikhminShirley", "ashikhmin_shirley_norm", "ashikhmin_shirley_exponent",
           "ashikhmin_shirley_diffuse_factor", "ashikhmin_shirley_diffuse", "ashikhmin_shirley_half",
           "ashikhmin_shirley_lobe", "ashikhmin_shirley_specular", "ASHIKHMIN_SHIRLEY_HALF_FLOOR"]

#: ashikhmin_shirley.glsl ASHIKHMIN_SHIRLEY_HALF_FLOOR = 2^-20: |l + v| at or below it gives f_s = 0
ASHIKHMIN_SHIRLEY_HALF_FLOOR = 2.0 ** -20
_INV_8PI = 1.0 / (8.0 * np.pi)
_DIFFUSE_NORM = 28.0 / (23.0 * np.pi)
_EXPONENT_MAX = 1e6

_RHO_D = Param("rho_d", "rgb", low=0.0, high=1.0, textureable=True,
               doc="diffuse reflectance of the substrate, dimensionless (f_d = 28 rho_d/(23 pi) (1 - rho_s) ...)")
_RHO_S = Param("rho_s", "rgb", low=0.0, high=1.0, textureable=True,
               doc="specular reflectance at normal incidence, dimensionless (Schlick's f0)")
_NU = Param("nu", "scalar", low=0.0, high=_EXPONENT_MAX, doc="Phong exponent along the tangent t")
_NV = Param("nv", "scalar", low=0.0, high=_EXPONENT_MAX, doc="Phong exponent along the bitangent b")


def ashikhmin_shirley_norm(nu, nv):
    """``sqrt((nu + 1)(nv + 1)) / (8 pi)`` [1/sr] (ashikhmin_shirley.glsl)."""
    return np.sqrt((nu + 1) * (nv + 1)) * _INV_8PI


def ashikhmin_shirley_exponent(h_t, h_b, nu, nv):
    """The exponent ``e = (nu (h.t)^2 + nv (h.b)^2) / ((h.t)^2 + (h.b)^2)`` (ashikhmin_shirley.glsl):
    h_t, h_b (...) -> (...), as ``(nu a^2 + nv c^2) / (a^2 + c^2)`` with ``a, c = h.t, h.b`` divided by
    ``max(|h.t|, |h.b|)``; ``(nu + nv)/2`` where both are 0."""
    h_t, h_b = np.asarray(h_t), np.asarray(h_b)
    m = np.maximum(np.abs(h_t), np.abs(h_b))
    ok = m > 0
    safe = np.where(ok, m, 1).astype(m.dtype)
    a = h_t / safe
    c = h_b / safe
    a2, c2 = a * a, c * c
    with np.errstate(invalid="ignore", divide="ignore"):
        e = (nu * a2 + nv * c2) / (a2 + c2)
    return np.where(ok, e, 0.5 * (nu + nv)).astype(m.dtype)


def ashikhmin_shirley_diffuse_factor(c):
    """``1 - (1 - c/2)^5`` as ``y (1 + m + m^2 + m^3 + m^4)``, ``y = c/2``, ``m = 1 - y``, c clamped to
    [0, 1] (ashikhmin_shirley.glsl)."""
    y = 0.5 * np.clip(np.asarray(c), 0, 1)
    m = 1 - y
    return y * (1 + m * (1 + m * (1 + m * (1 + m))))


def ashikhmin_shirley_diffuse(n_dot_l, n_dot_v, rho_d, rho_s):
    """``f_d (n.l)`` [1/sr] (ashikhmin_shirley.glsl): n_dot_l, n_dot_v (...), rho_d, rho_s (3,) -> (..., 3)."""
    k = _DIFFUSE_NORM * (rho_d * (1 - rho_s))
    n_dot_l = np.asarray(n_dot_l)
    return ((k * n_dot_l[..., None]) * ashikhmin_shirley_diffuse_factor(n_dot_l)[..., None]) \
        * ashikhmin_shirley_diffuse_factor(n_dot_v)[..., None]


def ashikhmin_shirley_half(wi, wo):
    """The half vector (the head of ashikhmin_shirley_specular).

    Returns
    -------
    valid : (...) bool ndarray
        ``l + v`` normalises and ``|l + v| > ASHIKHMIN_SHIRLEY_HALF_FLOOR``.
    h : (..., 3) ndarray
    h_len : (...) ndarray
        ``|l + v|`` (``v.h = |l + v| / 2``).
    """

    ok, h, h_len = safe_normalize(wi + wo)
    return ok & (h_len > ASHIKHMIN_SHIRLEY_HALF_FLOOR), h, h_len


def ashikhmin_shirley_lobe(f, h, nu, nv):
    """``(n.h)^e``: lobe.glsl's ``lobe_from_delta(delta, e)`` with ``delta = |h - n|^2 / 2`` and the
    per-point exponent of `ashikhmin_shirley_exponent` (the lobe of ashikhmin_shirley_specular): (...).

    1 where ``e = 0``, 0 where ``delta >= 1``, else ``exp(max(e ln(1 - delta), -104))``.
    """

    d = h - f.n
    delta = 0.5 * _dot(d, d)
    return lobe_from_delta(delta, ashikhmin_shirley_exponent(_dot(h, f.t), _dot(h, f.b), nu, nv))


def ashikhmin_shirley_specular(f, wi, wo, n_dot_l, n_dot_v, rho_s, nu, nv):
    """``f_s (n.l)`` [1/sr] (ashikhmin_shirley.glsl): 0 where `ashikhmin_shirley_half` is not valid.

    ``C (n.h)^e F(v.h) (n.l / max(n.l, n.v)) / (v.h)``, ``v.h = |l + v| / 2``; (..., 3).
    """

    valid, h, h_len = ashikhmin_shirley_half(wi, wo)
    lobe = ashikhmin_shirley_lobe(f, h, nu, nv)
    v_dot_h = 0.5 * np.maximum(h_len, ASHIKHMIN_SHIRLEY_HALF_FLOOR)
    ratio = n_dot_l / np.maximum(n_dot_l, n_dot_v)
    scale = ashikhmin_shirley_norm(nu, nv) * (ratio / v_dot_h)
    F = fresnel_schlick(rho_s, v_dot_h)
    return np.where(valid[..., None], F * (scale * lobe)[..., None], 0).astype(F.dtype)


class AshikhminShirley(MaterialModel):
    """The anisotropic Phong BRDF of Ashikhmin and Shirley 2000: a glossy Schlick-Fresnel layer over a
    diffuse substrate, ``f_r = f_s + f_d`` [1/sr], 0 where ``n.v <= 0``.

    In the frame ``(t, b, n)`` with ``h = (l + v)/|l + v|`` (the module docstring has the stable evaluation)::

        f_s  = sqrt((nu + 1)(nv + 1)) / (8 pi) (n.h)^e F(v.h) / ((v.h) max(n.l, n.v))
        e    = (nu (h.t)^2 + nv (h.b)^2) / (1 - (n.h)^2)
        F(u) = rho_s + (1 - rho_s)(1 - u)^5
        f_d  = 28 rho_d / (23 pi) (1 - rho_s) (1 - (1 - n.l/2)^5) (1 - (1 - n.v/2)^5)

    Parameters
    ----------
    rho_d : float or (3,) array_like
        Diffuse reflectance of the substrate, dimensionless, in [0, 1].
    rho_s : float or (3,) array_like
        Specular reflectance at normal incidence (Schlick's f0), dimensionless, in [0, 1].
    nu, nv : float
        Phong exponents along the tangent t and the bitangent b, in [0, 1e6]; ``nu = nv`` is isotropic.
    ka : float or (3,) array_like, optional
        Constant term k_a [W/(m^2 sr)], >= 0.
    two_sided : bool, optional
    """

    name = "ashikhmin_shirley"
    params = (_RHO_D, _RHO_S, _NU, _NV)
    needs = ("view", "tangent")
    glsl = GlslFile("materials/ashikhmin_shirley.glsl")
    uses = ("lobe", "fresnel")
    ambient = "rho_d"
    ambient_scale = 1.0 / np.pi
    # no parameter scales the whole term: rho_s = 0 leaves the Fresnel part (1 - v.h)^5 of f_s, and
    # rho_d = 0 leaves f_s
    vanishes_with = ()
    properties = Properties(reciprocal=True, isotropic=False, energy_conserving=True,
                            condition="rho_d, rho_s in [0, 1] (the ranges); numerical evidence, not a proof: "
                                      "quadrature of the total albedo stayed <= 0.999996 (the paper: nearly "
                                      "energy conserving); isotropic where nu = nv")

    def response(self, f, wi, wo, n_dot_l, p):
        n_dot_v = _dot(f.n, wo)
        value = ashikhmin_shirley_diffuse(n_dot_l, n_dot_v, p.rho_d, p.rho_s) \
            + ashikhmin_shirley_specular(f, wi, wo, n_dot_l, n_dot_v, p.rho_s, p.nu, p.nv)
        return np.where((n_dot_v > 0)[..., None], value, 0).astype(value.dtype)

    def band(self, f, wi, wo, n_dot_l, p, constants):
        """The generic band (`MaterialModel.band`: the twin's sensitivity to a few ulps of its inputs),
        reaching down to the diffuse part's lower bound where the lobe ``(n.h)^e`` is below 2 FLT_MIN:
        float32 may flush the lobe to 0 before it is scaled by ``C / (v.h)`` (up to 8e10), so the
        specular part may vanish where the product is still representable."""

        low, high = super().band(f, wi, wo, n_dot_l, p, constants)
        tol = constants.D * EPS
        _, h, _ = ashikhmin_shirley_half(wi, wo)
        lobe = ashikhmin_shirley_lobe(f, h, p.nu, p.nv)
        n_dot_v = _dot(f.n, wo)
        diffuse_low = ashikhmin_shirley_diffuse(np.maximum(n_dot_l - tol, 0.0), np.maximum(n_dot_v - tol, 0.0),
                                                p.rho_d, p.rho_s) * (1 - constants.A * EPS)
        flush = (lobe < 2 * FLT_MIN)[..., None]
        return np.where(flush, np.minimum(low, diffuse_low), low), high

    def oracle(self, f, wi, wo, n_dot_l, p):
        """The paper's formula in mpmath, unstabilised: ``e`` from ``1 - (n.h)^2`` (``(nu + nv)/2`` where it
        is 0: h = n, where ``(n.h)^e = 1`` for any e), ``F`` and ``f_d`` as written; 0 where ``n.v <= 0``;
        ``f_s = 0`` where ``l + v = 0`` (h undefined)."""
        import mpmath

        dot = lambda a, b: sum(x * y for x, y in zip(a, b))  # noqa: E731
        n_dot_v = dot(f.n, wo)
        if not n_dot_v > 0:
            return [mpmath.mpf(0)] * 3
        pi = mpmath.pi
        nl, nv_ = n_dot_l, n_dot_v
        g = lambda c: 1 - (1 - c / 2) ** 5  # noqa: E731
        diffuse = [28 * rd / (23 * pi) * (1 - rs) * g(nl) * g(nv_) * nl for rd, rs in zip(p.rho_d, p.rho_s)]
        s = [a + b for a, b in zip(wi, wo)]
        length = mpmath.sqrt(dot(s, s))
        if length == 0:
            return diffuse
        h = [x / length for x in s]
        t, b = f.t, f.b
        if t is None:  # the tangent was parallel to n: the shader's fallback basis (Duff et al. 2017)
            n = f.n
            sign = 1 if n[2] >= 0 else -1
            a = -1 / (sign + n[2])
            t = [1 + sign * n[0] * n[0] * a, sign * n[0] * n[1] * a, -sign * n[0]]
            b = [n[1] * t[2] - n[2] * t[1], n[2] * t[0] - n[0] * t[2], n[0] * t[1] - n[1] * t[0]]
        n_dot_h, h_t, h_b, v_dot_h = dot(f.n, h), dot(t, h), dot(b, h), dot(wo, h)
        one_minus = 1 - n_dot_h ** 2
        e = (p.nu * h_t ** 2 + p.nv * h_b ** 2) / one_minus if one_minus > 0 else (p.nu + p.nv) / 2
        lobe = lobe_oracle(n_dot_h, e)
        norm = mpmath.sqrt((p.nu + 1) * (p.nv + 1)) / (8 * pi)
        u = min(max(v_dot_h, mpmath.mpf(0)), mpmath.mpf(1))
        fresnel = [rs + (1 - rs) * (1 - u) ** 5 for rs in p.rho_s]
        specular = [norm * lobe * F / (v_dot_h * max(nl, nv_)) * nl for F in fresnel]
        return [d + s_ for d, s_ in zip(diffuse, specular)]

    @classmethod
    def stability_cases(cls):
        """glphong's generic geometry, and the model's extremes: the exponent at, near (n.h rounding
        to 1) and off the peak for nu, nv up to 1e6 along t, b and the diagonal; Schlick's cosine
        rounding above 1 (l = v); v.h -> 0 (l, v grazing and nearly opposite); max(n.l, n.v) at
        grazing; n.v <= 0; rho_s = 0 and 1, rho_d = 0."""

        e_one = 4 * np.pi  # a point light at 1 m: E = 1 W/m^2
        light = _unit(30.0, 0.0)
        lights = (("point", light, e_one),)
        cases = generic_cases("ashikhmin_shirley", cls(0.4, 0.05, 100.0, 10.0))
        cases += generic_cases("ashikhmin_shirley nu=nv=0", cls(0.4, 0.3, 0.0, 0.0))
        for nu, nv in ((0.0, 0.0), (1.0, 1.0), (100.0, 10.0), (1e3, 1e3), (1e4, 1e2), (1e6, 1e6), (1e6, 0.0),
                       (0.0, 1e6)):
            material = cls(0.0, 0.9, nu, nv)
            cases.append(Case(f"as nu={nu:g} nv={nv:g} peak h = n", "as exponent", material,
                              eye=_mirror_eye(30.0, 0.0, 0.0), lights=lights,
                              note="h.t = h.b = 0: e = (nu + nv)/2, (n.h)^e = 1"))
            for along, azimuth in (("t", 0.0), ("b", 90.0)):
                e = nu if along == "t" else nv
                width = 1.0 / np.sqrt(max(e, 1.0))  # h tilted by at most 0.45 rad: v stays above the surface
                for where, offset in (("near", min(0.7 * width, 0.3)), ("tail", min(3.0 * width, 0.45))):
                    cases.append(Case(f"as nu={nu:g} nv={nv:g} {where} along {along}", "as exponent", material,
                                      eye=_mirror_eye(30.0, offset, azimuth), lights=lights))
        for azimuth in (0.0, 90.0, 45.0):
            cases.append(Case(f"as nu=1e6 nv=1e4 n.h rounds to 1, azimuth {azimuth:g}", "as exponent",
                              cls(0.0, 0.9, 1e6, 1e4), eye=_mirror_eye(30.0, 2e-4, azimuth), lights=lights,
                              note="1 - n.h = 2e-8 < eps/2: the textbook e is 0/0 or garbage"))
        cases.append(Case("as nu=1e6 nv=1e6 far tail (lobe below FLT_MIN)", "as exponent", cls(0.0, 1.0, 1e6, 1e6),
                          eye=_mirror_eye(30.0, 0.05, 0.0), lights=lights, in_range=False,
                          note="result ~1e-543, below FLT_MIN: 0 (the twin's lobe stops at exp(-104))"))
        for theta in (0.0, 40.0, 85.0):
            cases.append(Case(f"as l = v at {theta:g} deg", "as fresnel", cls(0.3, 0.5, 50.0, 5.0),
                              eye=_unit(theta, 30.0), lights=(("point", _unit(theta, 30.0), e_one),),
                              note="v.h = |l + v|/2 may round above 1: F = rho_s"))
        grazing = lambda c, azimuth: (float(np.sqrt(1 - c * c) * np.cos(np.radians(azimuth))),  # noqa: E731
                                      float(np.sqrt(1 - c * c) * np.sin(np.radians(azimuth))), float(c))
        toward = lambda c: (("directional", tuple(-x for x in grazing(c, 0.0)), 1.0),)  # noqa: E731
        for nu in (0.0, 100.0):
            material = cls(0.2, 0.5, nu, nu)
            for c in (1e-3, 1e-5):
                cases.append(Case(f"as nu=nv={nu:g} l, v grazing mirrored n.l=n.v={c:g}", "as grazing", material,
                                  eye=grazing(c, 180.0), lights=toward(c),
                                  note="h = n, v.h = n.l: f_s = C F / (n.l)^2, the response C F / n.l"))
            cases.append(Case(f"as nu=nv={nu:g} l, v nearly opposite |l + v| = 1e-5", "as grazing", material,
                              eye=(-1.0, 1e-5, 1e-6), lights=(("directional", (-1.0, 0.0, -1e-6), 1.0),),
                              note="v.h = 5e-6: 1/(v.h) large, bounded"))
        for label, c_l, c_v in (("n.l=1e-6, n.v=0.6", 1e-6, 0.6), ("n.v=1e-6, n.l=0.6", 0.6, 1e-6),
                                ("n.l=1e-4, n.v=1e-3", 1e-4, 1e-3)):
            cases.append(Case(f"as max(n.l, n.v) {label}", "as grazing", cls(0.3, 0.2, 20.0, 200.0),
                              eye=grazing(c_v, 150.0), lights=toward(c_l)))
        for label, eye in (("n.v=0", (-1.0, 0.2, 0.0)), ("n.v=-1e-3", grazing(-1e-3, 180.0)),
                           ("n.v=-0.5", _unit(120.0, 180.0))):
            cases.append(Case(f"as view below the surface {label}", "as behind", cls(0.5, 0.3, 10.0, 10.0), eye=eye,
                              lights=lights, note="n.v <= 0: 0, the diffuse part too"))
        for rho_d, rho_s in ((0.8, 0.0), (0.8, 1.0), (0.0, 0.0), ((1.0, 0.5, 0.0), (0.0, 0.5, 1.0))):
            cases.append(Case(f"as rho_d={_short(rho_d)} rho_s={_short(rho_s)}", "as coefficients",
                              cls(rho_d, rho_s, 300.0, 30.0), eye=_mirror_eye(30.0, 0.02, 20.0), lights=lights,
                              note="rho_s = 1: no diffuse part; rho_s = 0: F = (1 - v.h)^5"))
        return cases


def _short(x):
    return f"{x:g}" if np.isscalar(x) else "(" + ",".join(f"{c:g}" for c in x) + ")"


def _unit(theta_deg, azimuth_deg):
    """Unit vector at polar angle ``theta_deg`` from +z and azimuth ``azimuth_deg`` from +x (tuple)."""
    t, a = np.radians(theta_deg), np.radians(azimuth_deg)
    return (float(np.sin(t) * np.cos(a)), float(np.sin(t) * np.sin(a)), float(np.cos(t)))


def _mirror_eye(light_deg, offset, azimuth_deg):
    """The eye at the mirror direction of a light ``light_deg`` off +z (azimuth 0), so that ``h = n``,
    then turned so that h moves by about ``offset`` rad toward the azimuth ``azimuth_deg`` (0: along
    t = +x, 90: along b = +y for the default tangent), keeping ``l`` fixed."""
    l = np.array(_unit(light_deg, 0.0))
    a = np.radians(azimuth_deg)
    h = np.array([np.sin(offset) * np.cos(a), np.sin(offset) * np.sin(a), np.cos(offset)])
    v = 2 * np.dot(h, l) * h - l
    return tuple(float(c) for c in v / np.linalg.norm(v))
