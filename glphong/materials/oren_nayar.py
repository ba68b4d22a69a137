"""The model 'oren_nayar': rough diffuse reflection (docs/design.md section 9; GLSL: ``glsl/materials/oren_nayar.glsl``).

Oren, M. and Nayar, S. K. (1994), "Generalization of Lambert's reflectance model", Proceedings of
SIGGRAPH 94 (Computer Graphics, Annual Conference Series), pp. 239-246.  The surface is a collection
of long symmetric V-cavities whose Lambertian facets have slopes normally distributed about the
mean surface with standard deviation ``sigma`` [rad]; the model accounts for masking, shadowing and
one inter-reflection between facets.  With ``s2 = sigma^2``, ``alpha = max(theta_i, theta_o)``,
``beta = min(theta_i, theta_o)`` and ``c = cos(phi_o - phi_i)``, the BRDF [1/sr] is

- ``form="full"`` (the paper's functional approximation of its model, with the inter-reflection
  component):
  ``rho/pi (C1 + c C2 tan(beta) + (1 - |c|) C3 tan((alpha + beta)/2))
  + 0.17 rho^2/pi s2/(s2 + 0.13) (1 - c (2 beta/pi)^2)``, with
  ``C1 = 1 - 0.5 s2/(s2 + 0.33)``, ``C2 = 0.45 s2/(s2 + 0.09) sin(alpha)`` where ``c >= 0`` and
  ``0.45 s2/(s2 + 0.09) (sin(alpha) - (2 beta/pi)^3)`` where ``c < 0``,
  ``C3 = 0.125 s2/(s2 + 0.09) (4 alpha beta/pi^2)^2``.  The inter-reflection term is quadratic in
  ``rho``: the response is not linear in the albedo.
- ``form="qualitative"`` (the paper's simpler model, without inter-reflection):
  ``rho/pi (A + B max(0, c) sin(alpha) tan(beta))``, ``A = 1 - 0.5 s2/(s2 + 0.33)``,
  ``B = 0.45 s2/(s2 + 0.09)``.

``sigma = 0`` is Lambert's ``rho/pi`` exactly (the same float32 operations as `Diffuse`).  Where
``theta_i = 0`` or ``theta_o = 0`` the azimuth is undefined and the value is its limit: ``beta = 0``
removes every ``c`` term (``c`` is taken as 0 there).  The response is ``f_r (n.l)`` where
``n.l > 0``, and exactly 0 where ``n.v <= 0``.  Where light and view both graze with ``c > 0``,
``f_r`` diverges like ``1/(n.l)`` (``tan(beta)`` does; the paper's model is meant for
``theta < pi/2``), but the response ``f_r (n.l)`` has a finite limit, and the formulation evaluates
it bounded (``tan(beta) (n.l) <= 1``, ``tan((alpha + beta)/2) (n.l) <= 2``): see the GLSL header.

The ambient light ``L_a`` is answered with ``(rho/pi) L_a`` (``ambient = "rho"``,
``ambient_scale = 1/pi``): Lambert's answer for the same albedo.  That is an approximation: under
uniform light an Oren-Nayar surface reflects its directional albedo, which depends on the
direction and on sigma (measured for ``rho = 1``: 0.96 to 1.05 at ``sigma = 0.3`` in the full form,
0.72 to 0.89 at ``sigma = pi/2``), and the full form's inter-reflection part is quadratic in rho.

Properties: reciprocal (``alpha``, ``beta``, ``|c|`` and the case split on ``sign(c)`` are
symmetric in ``l`` and ``v``), isotropic (only ``phi_o - phi_i`` enters), not energy-conserving:
by Gauss quadrature (``rho = 1``, see the tests) the directional albedo is below 1 at normal
incidence for ``sigma > 0`` (0.962 full, 0.893 qualitative at ``sigma = 0.3``) and rises toward
grazing incidence to above 1, at most 1.051 (full form, ``sigma`` about 0.3, ``theta_i -> 90``
deg) and 1.015 (qualitative, ``sigma`` about 0.2).  The qualitative form is non-negative; the
full form is not for large roughness: at forward scattering (``c = -1``) with both directions
grazing, ``c C2 tan(beta)`` tends to ``-0.45 s2/(s2 + 0.09) 6/pi``, which exceeds ``C1`` for
``sigma > 0.664`` rad as ``rho -> 0`` (the ``rho^2`` term moves the bound up with the albedo:
0.953 rad at ``rho = 0.5``, 1.448 at ``rho = 0.8``, none at ``rho = 1``).  glphong follows the
paper and does not clamp; ``non_negative`` is declared False.

The slope deviation's range is ``[0, pi/2]`` rad: facet slopes are angles in ``[0, pi/2)``, and a
Gaussian of that width is already far from the physical picture; the formulas are a functional
approximation of the paper's numerically evaluated V-cavity model, so large sigma stretches them
(the full form's sign change above 0.664 rad is one sign of it).  All of ``[0, pi/2]`` evaluates
finite and stable.

=========  ======  =============  ======  ============================================================
parameter  kind    range          unit    meaning
=========  ======  =============  ======  ============================================================
rho        rgb     [0, 1]         1       albedo of the facets (the Lambert albedo at sigma = 0)
sigma      scalar  [0, pi/2]      rad     standard deviation of the facet slope angle (0: Lambert)
form       choice  'full' (0) or  --      the full model with inter-reflection, or the qualitative one
                   'qualitative'
                   (1)
=========  ======  =============  ======  ============================================================

Units: ``f_r`` and the response in 1/sr; ``rho`` dimensionless; ``sigma`` in radians.  No Fresnel
factor (the facets are Lambertian).

Where common implementations differ from the paper (glphong follows the paper, docs/design.md section 9):

- pbrt-v3's ``OrenNayar`` (and the many renderers that port it) implements only the qualitative
  form and takes ``sigma`` in degrees; glphong takes radians and offers both forms
  (``form="full"`` is the default).
- Mitsuba 0.x ``roughdiffuse`` takes a Beckmann-style RMS slope ``alpha`` and uses
  ``sigma = alpha / sqrt(2)``; glphong's ``sigma`` is the paper's.  Its full form is the paper's,
  like glphong's.
- Many shaders give only the qualitative form and compute ``theta = acos(n.l)`` and
  ``tan(beta)`` directly, which lose precision near the normal (acos) and overflow where both
  directions graze (tan); glphong evaluates the same function in a stable form (GLSL header).
  The ``s/t`` form (``s = l.v - (n.l)(n.v)``, ``t = max(n.l, n.v)``) some use is the same
  qualitative function, not a different model.
- Many shaders use 0.57 instead of 0.33 in ``A`` (a variant that folds inter-reflection into
  the qualitative form), some rescale by ``1/A``, some drop the full form's inter-reflection term;
  glphong uses the paper's constants and terms unchanged.
"""
import numpy as np

from glphong.twin.functions import atan2_first_quadrant
from glphong.definitions.material import Choice, GlslFile, MaterialModel, Param, Properties
from glphong.definitions.cases import Case, generic_cases
from glphong.twin.band import EPS
from glphong.twin.functions import dot as _dot, safe_normalize

__all__ = ["OrenNayar", "oren_nayar_tangential", "oren_nayar_cos_phi", "oren_nayar_tan_beta",
           "oren_nayar_full", "oren_nayar_qualitative", "RHO", "SIGMA"]

#: the facets' albedo
RHO = Param("rho", "rgb", low=0.0, high=1.0, textureable=True,
            doc="albedo of the Lambertian facets, dimensionless (sigma = 0: f_r = rho/pi)")
#: the roughness
SIGMA = Param("sigma", "scalar", low=0.0, high=np.pi / 2, unit="rad",
              doc="standard deviation of the facet slope angle [rad]; 0 is Lambert")
FORM = Choice("form", ("full", "qualitative"), default="full",
              doc="'full': the paper's model with inter-reflection; 'qualitative': its simpler model")

_TWO_OVER_PI = 2.0 / np.pi


def oren_nayar_tangential(n, w):
    """``sin(theta) = |w - (n.w) n|`` (clamped to 1) and the unit tangential direction (0 where it
    vanishes), by `safe_normalize` (oren_nayar.glsl): (..., 3) -> ((...), (..., 3))."""

    _, direction, length = safe_normalize(w - _dot(n, w)[..., None] * n)
    return np.minimum(length, 1).astype(direction.dtype), direction


def oren_nayar_cos_phi(dir_i, dir_o):
    """``(c, 1 - c, 1 - |c|)``, ``c = cos(phi_o - phi_i)`` from the unit tangential directions, the
    differences as chords ``|dir_i -+ dir_o|^2 / 2``; ``(0, 1, 1)`` where either direction is 0
    (oren_nayar.glsl)."""
    defined = (_dot(dir_i, dir_i) > 0) & (_dot(dir_o, dir_o) > 0)
    d = dir_i - dir_o
    s = dir_i + dir_o
    minus = 0.5 * _dot(d, d)
    plus = 0.5 * _dot(s, s)
    one = np.ones_like(minus)
    c = np.where(defined, np.clip(_dot(dir_i, dir_o), -1, 1), 0).astype(minus.dtype)
    return c, np.where(defined, minus, one), np.where(defined, np.minimum(minus, plus), one)


def oren_nayar_tan_beta(cos_i, sin_i, cos_o, sin_o):
    """``(tan(beta) cos_i, sin(alpha), cos(alpha))`` (oren_nayar.glsl): ``tan(beta) cos_i`` is ``sin_i``
    where ``theta_i <= theta_o``, else ``sin_o (cos_i / cos_o)``, at most 1."""
    light_is_beta = sin_i * cos_o <= sin_o * cos_i
    sin_alpha = np.where(light_is_beta, sin_o, sin_i)
    cos_alpha = np.where(light_is_beta, cos_o, cos_i)
    with np.errstate(divide="ignore", invalid="ignore"):
        other = sin_o * (cos_i / np.maximum(cos_o, cos_i))
    return np.where(light_is_beta, sin_i, other), sin_alpha, cos_alpha


def oren_nayar_full(cos_i, sin_i, cos_o, sin_o, c, one_minus_c, one_minus_abs_c, s2):
    """The full model's ``f_r cos_i`` without its albedo factors (oren_nayar.glsl): (..., 2), the single
    scattering part (times ``rho/pi`` in the response) and the inter-reflection part (times ``rho^2/pi``).

    Stable form: ``g = 1 - 2 theta/pi = (2/pi) atan2(cos, sin)``; ``sin(alpha) - (2 beta/pi)^3 =
    g_b (3 - 3 g_b + g_b^2) - cos(alpha)^2/(1 + sin(alpha))``; ``1 - c (2 beta/pi)^2 = (1 - c) + c g_b (2 - g_b)``."""
    first, signed, third, inter = _full_parts(cos_i, sin_i, cos_o, sin_o, c, one_minus_c, one_minus_abs_c, s2)
    return np.stack([first + signed + third, inter], axis=-1)


def _full_parts(cos_i, sin_i, cos_o, sin_o, c, one_minus_c, one_minus_abs_c, s2):
    """`oren_nayar_full`'s summands: ``C1 cos_i``, ``c C2 tan(beta) cos_i``, ``(1 - |c|) C3
    tan((alpha + beta)/2) cos_i`` and the inter-reflection part; all but the second are non-negative."""
    tan_beta, sin_alpha, cos_alpha = oren_nayar_tan_beta(cos_i, sin_i, cos_o, sin_o)
    tan_half = (sin_i + sin_o) * (cos_i / (cos_i + cos_o))
    g_i = _TWO_OVER_PI * atan2_first_quadrant(cos_i, sin_i)
    g_o = _TWO_OVER_PI * atan2_first_quadrant(cos_o, sin_o)
    g_b = np.maximum(g_i, g_o)
    g_a = np.minimum(g_i, g_o)
    k = s2 / (s2 + 0.09)
    c1 = 1.0 - 0.5 * s2 / (s2 + 0.33)
    drop = g_b * (3.0 - 3.0 * g_b + g_b * g_b) - cos_alpha * cos_alpha / (1.0 + sin_alpha)
    c2 = 0.45 * k * np.where(c >= 0, sin_alpha, drop)
    ab = (1.0 - g_a) * (1.0 - g_b)
    c3 = 0.125 * k * (ab * ab)
    inter = 0.17 * s2 / (s2 + 0.13) * (one_minus_c + c * (g_b * (2.0 - g_b))) * cos_i
    return c1 * cos_i, c * c2 * tan_beta, one_minus_abs_c * c3 * tan_half, inter


def oren_nayar_qualitative(cos_i, sin_i, cos_o, sin_o, c, s2):
    """The qualitative model's ``f_r cos_i`` without ``rho/pi`` (oren_nayar.glsl):
    ``A cos_i + B max(c, 0) sin(alpha) tan(beta) cos_i``."""
    tan_beta, sin_alpha, _ = oren_nayar_tan_beta(cos_i, sin_i, cos_o, sin_o)
    a = 1.0 - 0.5 * s2 / (s2 + 0.33)
    b = 0.45 * s2 / (s2 + 0.09)
    return a * cos_i + b * np.maximum(c, 0) * sin_alpha * tan_beta


class OrenNayar(MaterialModel):
    """Oren and Nayar's rough diffuse reflector (SIGGRAPH 94): Lambertian V-cavity facets of slope
    deviation ``sigma``.

    With ``s2 = sigma^2``, ``alpha = max(theta_i, theta_o)``, ``beta = min(theta_i, theta_o)`` and
    ``c = cos(phi_o - phi_i)``, in 1/sr::

        full:        rho/pi (C1 + c C2 tan(beta) + (1 - |c|) C3 tan((alpha + beta)/2))
                     + 0.17 rho^2/pi s2/(s2 + 0.13) (1 - c (2 beta/pi)^2)
        qualitative: rho/pi (A + B max(0, c) sin(alpha) tan(beta))

        C1 = A = 1 - 0.5 s2/(s2 + 0.33),  B = 0.45 s2/(s2 + 0.09),  C3 = 0.125 s2/(s2 + 0.09) (4 alpha beta/pi^2)^2
        C2 = B sin(alpha) where c >= 0,  B (sin(alpha) - (2 beta/pi)^3) where c < 0

    Parameters
    ----------
    rho : float or (3,) array_like
        Albedo of the facets, dimensionless, in [0, 1].
    sigma : float
        Standard deviation of the facet slope angle [rad], in [0, pi/2]; 0 is Lambert ``rho/pi``.
    form : {'full', 'qualitative'}
        ``'full'`` (default): the paper's model with its inter-reflection term (quadratic in rho);
        ``'qualitative'``: ``rho/pi (A + B max(0, c) sin(alpha) tan(beta))``.
    ka : float or (3,) array_like, optional
        Constant term k_a [W/(m^2 sr)], >= 0.
    two_sided : bool, optional

    Notes
    -----
    The ambient light is answered with ``(rho/pi) L_a``, Lambert's answer for the same albedo (an
    approximation).  The full form can be negative for ``sigma > 0.664`` rad at forward-scattering
    grazing geometry (the paper's approximation; not clamped).
    """

    name = "oren_nayar"
    params = (RHO, SIGMA)
    choices = (FORM,)
    needs = ("view",)
    glsl = GlslFile("materials/oren_nayar.glsl")
    uses = ("angle",)
    ambient = "rho"
    ambient_scale = 1.0 / np.pi
    vanishes_with = ("rho",)
    properties = Properties(
        reciprocal=True, isotropic=True, energy_conserving=False, non_negative=False,
        condition="not exactly: the directional albedo (rho = 1, by quadrature) is below 1 at normal incidence "
                  "for sigma > 0 and rises above 1 toward grazing incidence, measured at most 1.051 (full form, "
                  "sigma ~ 0.3, theta_i -> 90 deg) and 1.015 (qualitative, sigma ~ 0.2); non-negative: the "
                  "qualitative form always, the full form for sigma <= 0.664 rad (above, f_r < 0 at forward-"
                  "scattering grazing geometry as rho -> 0; the rho^2 term moves the bound to 0.953 rad at rho = 0.5)")

    @staticmethod
    def _geometry(f, wi, wo):
        """``(n.v, sin_i, cos_o, sin_o, c, 1 - c, 1 - |c|)`` as the GLSL response forms them."""
        n_dot_v = _dot(f.n, wo)
        sin_i, dir_i = oren_nayar_tangential(f.n, wi)
        sin_o, dir_o = oren_nayar_tangential(f.n, wo)
        # below the surface: a finite stand-in (grazing view), selected away at the end
        sin_o = np.where(n_dot_v > 0, sin_o, 1).astype(sin_o.dtype)
        cos_o = np.maximum(n_dot_v, 0)
        return (n_dot_v, sin_i, cos_o, sin_o) + oren_nayar_cos_phi(dir_i, dir_o)

    def response(self, f, wi, wo, n_dot_l, p):
        n_dot_v, sin_i, cos_o, sin_o, c, one_minus_c, one_minus_abs_c = self._geometry(f, wi, wo)
        s2 = p.sigma * p.sigma
        if p.form == "qualitative":
            k = np.stack([oren_nayar_qualitative(n_dot_l, sin_i, cos_o, sin_o, c, s2),
                          np.zeros_like(sin_i)], axis=-1)
        else:
            k = oren_nayar_full(n_dot_l, sin_i, cos_o, sin_o, c, one_minus_c, one_minus_abs_c, s2)
        # rho (k / pi): at sigma = 0 exactly Diffuse's rho_d (n.l / pi) (the GLSL multiplies by the
        # float32 1/pi, as diffuse.glsl does)
        value = p.rho * (k[..., :1] / np.pi) + p.rho * p.rho * (k[..., 1:] / np.pi)
        return np.where((n_dot_v > 0)[..., None], value, 0).astype(value.dtype)

    def band(self, f, wi, wo, n_dot_l, p, constants):
        """The generic band (`MaterialModel.band`: the twin's sensitivity to a few ulps of its inputs),
        widened by ``A eps`` times the sum of the magnitudes of the full form's summands.

        Rounding in float32 errs relative to the summands, not to their sum; the full form's
        ``c C2 tan(beta)`` is negative where ``c < 0`` and cancels ``C1`` at forward-scattering
        grazing geometry for large sigma (the response crosses 0 above sigma = 0.664 rad), where
        a band relative to the result alone is too narrow.  The qualitative form's summands are
        non-negative: the widening is then ``A eps`` of the value, inside the generic band's own."""

        low, high = super().band(f, wi, wo, n_dot_l, p, constants)
        n_dot_l = np.maximum(n_dot_l, np.finfo(np.float64).tiny)
        n_dot_v, sin_i, cos_o, sin_o, c, one_minus_c, one_minus_abs_c = self._geometry(f, wi, wo)
        s2 = p.sigma * p.sigma
        if p.form == "qualitative":
            single = oren_nayar_qualitative(n_dot_l, sin_i, cos_o, sin_o, c, s2)
            inter = np.zeros_like(single)
        else:
            first, signed, third, inter = _full_parts(n_dot_l, sin_i, cos_o, sin_o, c, one_minus_c,
                                                      one_minus_abs_c, s2)
            single = first + np.abs(signed) + third
        magnitude = (p.rho * single[..., None] + p.rho * p.rho * np.abs(inter)[..., None]) / np.pi
        widen = np.where((n_dot_v > 0)[..., None], constants.A * EPS * magnitude, 0.0)
        return low - widen, high + widen

    def oracle(self, f, wi, wo, n_dot_l, p):
        """The paper's formula in mpmath, textbook: ``theta = acos(n.w)``, the azimuth difference from the
        tangential projections (taken as c = 0 where one vanishes: the limit), ``tan`` of the angles."""
        import mpmath

        dot = lambda a, b: sum(x * y for x, y in zip(a, b))  # noqa: E731
        n = f.n
        n_dot_v = dot(n, wo)
        if not n_dot_v > 0:
            return [mpmath.mpf(0)] * 3
        theta_i = mpmath.acos(min(n_dot_l, mpmath.mpf(1)))
        theta_o = mpmath.acos(min(n_dot_v, mpmath.mpf(1)))
        pi_ = [a - n_dot_l * b for a, b in zip(wi, n)]
        po = [a - n_dot_v * b for a, b in zip(wo, n)]
        norm = mpmath.sqrt(dot(pi_, pi_)) * mpmath.sqrt(dot(po, po))
        c = dot(pi_, po) / norm if norm > 0 else mpmath.mpf(0)
        c = max(min(c, mpmath.mpf(1)), mpmath.mpf(-1))
        alpha, beta = max(theta_i, theta_o), min(theta_i, theta_o)
        s2 = p.sigma * p.sigma
        pi = mpmath.pi
        if p.form == "qualitative":
            a = 1 - s2 / (2 * (s2 + mpmath.mpf("0.33")))
            b = mpmath.mpf("0.45") * s2 / (s2 + mpmath.mpf("0.09"))
            single, inter = a + b * max(c, 0) * mpmath.sin(alpha) * mpmath.tan(beta), mpmath.mpf(0)
        else:
            c1 = 1 - s2 / (2 * (s2 + mpmath.mpf("0.33")))
            k = s2 / (s2 + mpmath.mpf("0.09"))
            if c >= 0:
                c2 = mpmath.mpf("0.45") * k * mpmath.sin(alpha)
            else:
                c2 = mpmath.mpf("0.45") * k * (mpmath.sin(alpha) - (2 * beta / pi) ** 3)
            c3 = mpmath.mpf("0.125") * k * (4 * alpha * beta / pi ** 2) ** 2
            single = c1 + c * c2 * mpmath.tan(beta) + (1 - abs(c)) * c3 * mpmath.tan((alpha + beta) / 2)
            inter = mpmath.mpf("0.17") * s2 / (s2 + mpmath.mpf("0.13")) * (1 - c * (2 * beta / pi) ** 2)
        return [(r / pi * single + r * r / pi * inter) * n_dot_l for r in p.rho]

    def pbr_base_color(self):
        """The albedo ``rho`` (RGB), a metallic-roughness base colour for comparisons with pyrender."""
        return tuple(self.rho)

    @classmethod
    def stability_cases(cls):
        """The generic geometry for both forms, and the model's own limits: l = n and v = n (undefined
        azimuth), l and v near n, both grazing in retro (c = 1), forward (c = -1) and crossed (c = 0)
        azimuth, grazing light under a steep view and the reverse, and sigma at 0 and pi/2."""

        e_one = 4 * np.pi  # a point light at 1 m: E = 1 W/m^2

        def unit(theta, phi=0.0):
            return (float(np.sin(theta) * np.cos(phi)), float(np.sin(theta) * np.sin(phi)), float(np.cos(theta)))

        def grazing(cosine, phi=0.0):
            s = float(np.sqrt(1.0 - cosine * cosine))
            return (s * float(np.cos(phi)), s * float(np.sin(phi)), float(cosine))

        def light_from(w):  # a directional light toward the surface from direction w
            return (("directional", tuple(-x for x in w), 1.0),)

        group = "oren_nayar"
        full, qualitative = cls(0.6, 0.5), cls(0.6, 0.5, form="qualitative")
        cases = generic_cases("oren_nayar full", full) + generic_cases("oren_nayar qualitative", qualitative)
        for label, m in (("full", full), ("qualitative", qualitative)):
            cases += [
                Case(f"oren_nayar {label} l = n, v at 50 deg", group, m, eye=unit(np.radians(50.0), 1.0),
                     lights=(("point", (0.0, 0.0, 1.0), e_one),),
                     note="azimuth of l undefined: beta = 0 removes every c term"),
                Case(f"oren_nayar {label} v = n, l at 50 deg", group, m, eye=(0.0, 0.0, 1.0),
                     lights=(("point", unit(np.radians(50.0), 2.0), e_one),), note="azimuth of v undefined"),
                Case(f"oren_nayar {label} l = v = n", group, m, eye=(0.0, 0.0, 1.0),
                     lights=(("point", (0.0, 0.0, 1.0), e_one),)),
                Case(f"oren_nayar {label} l 1e-6 rad off n", group, m, eye=unit(np.radians(40.0), 3.0),
                     lights=light_from(unit(1e-6, 0.5)), note="acos(n.l) resolves no angle below 3.5e-4 in float32"),
                Case(f"oren_nayar {label} v 1e-4 rad off n", group, m, eye=unit(1e-4, 0.5),
                     lights=light_from(unit(np.radians(60.0), 2.5))),
                Case(f"oren_nayar {label} l 1e-3 rad off n, v opposite", group, m, eye=unit(np.radians(70.0), np.pi),
                     lights=light_from(unit(1e-3)), note="c = -1 with beta = 1e-3"),
                Case(f"oren_nayar {label} grazing light n.l=1e-5, v at 10 deg", group, m,
                     eye=unit(np.radians(10.0), 0.3), lights=light_from(grazing(1e-5)),
                     note="theta_i = alpha, tan(beta) moderate"),
                Case(f"oren_nayar {label} grazing view n.v=1e-6, l at 30 deg retro", group, m,
                     eye=grazing(1e-6), lights=light_from(unit(np.radians(30.0)))),
            ]
            for cosine in (1e-2, 1e-4, 1e-6):
                for where, phi_o in (("retro c=1", 0.0), ("forward c=-1", np.pi), ("crossed c=0", np.pi / 2)):
                    if phi_o == 0.0:
                        note = "tan(beta) -> inf; f_r (n.l) bounded"
                    elif label == "full":
                        note = "textbook sin(alpha) - (2 beta/pi)^3, 1 - (2 beta/pi)^2, 1 - |c| cancel"
                    else:
                        note = "max(0, c) = 0: A (n.l) only"
                    cases.append(Case(f"oren_nayar {label} both grazing n.l=n.v={cosine:g} {where}", group, m,
                                      eye=grazing(cosine, phi_o), lights=light_from(grazing(cosine)), note=note))
        for sigma in (0.0, np.pi / 2):
            for form in ("full", "qualitative"):
                m = cls(0.9, sigma, form=form)
                cases.append(Case(f"oren_nayar {form} sigma={sigma:.4g} l = v at 60 deg", group, m,
                                  eye=unit(np.radians(60.0), 0.7), lights=light_from(unit(np.radians(60.0), 0.7)),
                                  note="Lambert rho/pi" if sigma == 0 else "the roughest surface: retro-reflection"))
                cases.append(Case(f"oren_nayar {form} sigma={sigma:.4g} both grazing 1e-5 retro", group, m,
                                  eye=grazing(1e-5, 0.2), lights=light_from(grazing(1e-5, 0.2))))
        return cases
