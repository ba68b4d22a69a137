"""The model 'phong_lobe' and the material `Phong` (docs/design.md E4, E6; GLSL: ``glsl/materials/phong_lobe.glsl``).

The lobe's response is the lecture's ``k_s max(v.r, 0)^q`` with ``r = 2 (n.l) n - l``, so its BRDF
is ``k_s (v.r)^q / (n.l)``: non-negative with the clamp, not reciprocal, isotropic, not
energy-conserving (its albedo grows without bound at grazing incidence).  `Phong` is the sum
``Lambert + PhongLobe``: ``k_d (n.l) + k_s (v.r)^q`` per light.  Evaluated in the chord form of
docs/design.md section 3: ``delta = |r - v|^2 / 2``, ``lobe = (1 - delta)^q`` by `lobe_from_delta`, stable
for q up to FLT_MAX.  `phong_delta` and `phong_lobe` are library functions (GLSL in ``glsl/lobe.glsl``,
twins in `glphong.reference`), shared with `glphong.materials.NormalizedPhongLobe`; re-exported here.

=========  ======  ==========  ======  =============================================
parameter  kind    range       unit    meaning
=========  ======  ==========  ======  =============================================
ks         rgb     >= 0        1/sr    specular coefficient k_s
q          scalar  >= 0        1       exponent (q = 0: lobe 1, the 0^0 := 1 convention)
=========  ======  ==========  ======  =============================================
"""

from glphong.twin.functions import phong_delta, phong_lobe
from glphong.definitions.fresnel import FresnelSlot, fresnel_band, fresnel_factor
from glphong.materials.lambert import Lambert
from glphong.definitions.material import GlslFile, Integral, MaterialModel, MaterialSum, Param, Properties
from glphong.definitions.cases import generic_cases, lobe_cases
from glphong.definitions.fresnel import fresnel_oracle
from glphong.twin.band import EPS, lobe_band

__all__ = ["PhongLobe", "Phong", "phong_delta", "phong_lobe"]

#: the largest integer exponent whose lobe an extended light integrates exactly: Arvo's recurrence takes up to q/2
#: steps per edge (fewer where its tail bound stops it), and llvmpipe ends a loop after 65535 iterations of one
#: invocation (measured: q = 40000 under a square came out 6 % low), so 10 edges x 5000 steps stay clear of it;
#: beyond, the lobe is sampled (docs/design.md section 13)
LOBE_MAX_Q = 10000

_KS = Param("ks", "rgb", low=0.0, unit="1/sr", textureable=True, doc="specular coefficient")
_Q = Param("q", "scalar", low=0.0, doc="specular exponent; q = 0 gives a constant lobe of 1")


def lobe_oracle(cosine, q):
    """``max(c, 0)^q`` with ``0^0 := 1``, in mpmath (for the stability oracle)."""
    import mpmath

    return mpmath.mpf(1) if q == 0 else max(cosine, 0) ** q


class PhongLobe(MaterialModel):
    """The Phong lobe alone: response ``k_s max(v.r, 0)^q``, ``r = 2 (n.l) n - l``.

    Parameters
    ----------
    ks : float or (3,) array_like
        Specular coefficient [1/sr], >= 0.
    q : float
        Exponent, finite, >= 0.
    fresnel : SchlickFresnel, DielectricFresnel or None
        Fresnel factor ``F(n.l)`` multiplying the lobe (default None: ``F = 1``, the lecture's lobe).
    """

    name = "phong_lobe"
    params = (_KS, _Q)
    needs = ("view",)
    glsl = GlslFile("materials/phong_lobe.glsl")
    uses = ("lobe",)
    lobe_exponent = "q"
    vanishes_with = ("ks",)
    in_uber = True  # the lecture's models: every uber-shader holds them
    fresnel_slot = FresnelSlot(cosine="n.l")
    properties = Properties(reciprocal=False, isotropic=True, energy_conserving=False,
                            condition="never: the albedo grows without bound at grazing incidence")

    def response(self, f, wi, wo, n_dot_l, p):
        return p.ks * fresnel_factor(p, n_dot_l) * phong_lobe(f.n, wi, wo, p.q)[..., None]

    def integral_form(self):
        """``k_s integral max(r_v . w, 0)^q L(w) [n.w > 0] dw`` under an extended light where there is no Fresnel factor
        (the lobe is then zonal about ``r_v``; docs/design.md section 13): form 'lobe' for an integer ``q`` up to
        `LOBE_MAX_Q` (what Arvo's edge recurrences take), 'lobe_real' for any other ``q`` (what the environment
        light's harmonics take); None with a Fresnel factor (sampled)."""
        if self.fresnel is None:
            integer = float(self.q).is_integer() and self.q <= LOBE_MAX_Q
            return Integral("lobe" if integer else "lobe_real", "ks", exponent="q")
        return None

    def band(self, f, wi, wo, n_dot_l, p, constants):
        """``k_s`` times `glphong.checks.tolerances.lobe_band` of the Phong delta (docs/design.md section 4), times the
        Fresnel band at ``n.l +- D eps``."""

        low, high = lobe_band(phong_delta(f.n, wi, wo), p.q, 1.0, constants)
        f_low, f_high = fresnel_band(p, n_dot_l, constants.D * EPS)
        return p.ks * f_low * low[..., None], p.ks * f_high * high[..., None]

    def oracle(self, f, wi, wo, n_dot_l, p):
        c = sum(v * (2 * n_dot_l * a - b) for v, a, b in zip(wo, f.n, wi))
        lobe = lobe_oracle(c, p.q)
        return [k * F * lobe for k, F in zip(p.ks, fresnel_oracle(p, n_dot_l))]

    def pbr_roughness(self):
        """A rough pyrender roughness for comparisons: the Blinn exponent of a Phong lobe is about 4 q."""
        return float((2.0 / (4.0 * self.q + 2.0)) ** 0.25)

    @classmethod
    def stability_cases(cls):
        return generic_cases("phong", Phong(0.2, 0.5, 100.0)) + lobe_cases("phong", Phong)


class Phong(MaterialSum):
    """The Phong model (docs/design.md E4, E6): ``k_d (n.l) + k_s max(v.r, 0)^q`` per light, plus ambient.

    Parameters
    ----------
    kd, ks : float or (3,) array_like
        Diffuse and specular coefficients [1/sr], >= 0.
    q : float
        Specular exponent, finite, >= 0 (q = 0 gives a constant lobe of 1).
    fresnel : SchlickFresnel, DielectricFresnel or None
        Fresnel factor ``F(n.l)`` of the lobe (default None: ``F = 1``).
    ka : float or (3,) array_like, optional
        Constant term [W/(m^2 sr)], >= 0.
    two_sided : bool, optional
    """

    name = "phong"
    terms = (Lambert, PhongLobe)
