"""The model 'blinn_lobe' and the material `BlinnPhong` (docs/design.md E5, E6; GLSL: ``glsl/materials/blinn_lobe.glsl``).

The lobe's response is ``k_s max(n.h, 0)^q`` with ``h = (l + v)/|l + v|`` (0 where ``n.v <= 0``
or ``l + v`` is below a floor), so its BRDF is ``k_s (n.h)^q / (n.l)``: non-negative, not
reciprocal, isotropic, not energy-conserving.  `BlinnPhong` is ``Lambert + BlinnLobe``.  Evaluated
in the chord form of docs/design.md section 3: ``delta = |h - n|^2 / 2``.  `blinn_delta`, `blinn_lobe`,
`half_cosine` and `BLINN_HALF_FLOOR` are library functions (GLSL in ``glsl/lobe.glsl``, twins in
`glphong.reference`), shared with `glphong.materials.NormalizedBlinnLobe`; re-exported here.

=========  ======  ==========  ======  =============================================
parameter  kind    range       unit    meaning
=========  ======  ==========  ======  =============================================
ks         rgb     >= 0        1/sr    specular coefficient k_s
q          scalar  >= 0        1       exponent (q = 0: lobe 1 where h is defined)
=========  ======  ==========  ======  =============================================
"""
import numpy as np

from glphong.twin.functions import BLINN_HALF_FLOOR, blinn_delta, blinn_lobe, half_cosine
from glphong.definitions.fresnel import FresnelSlot, fresnel_band, fresnel_factor
from glphong.materials.lambert import Lambert
from glphong.definitions.material import GlslFile, MaterialModel, MaterialSum, Properties
from glphong.materials.phong import _KS, _Q, lobe_oracle
from glphong.twin.functions import dot as _dot
from glphong.definitions.cases import generic_cases, lobe_cases
from glphong.definitions.fresnel import fresnel_oracle
from glphong.twin.band import EPS, lobe_band
from glphong.twin.functions import safe_normalize

__all__ = ["BlinnLobe", "BlinnPhong", "blinn_delta", "blinn_lobe", "half_cosine", "BLINN_HALF_FLOOR", "blinn_lobe_band"]


def blinn_lobe_band(f, wi, wo, p, constants):
    """Band of the Blinn lobe ``max(n.h, 0)^q`` and of its Fresnel factor ``F(h.l)``.

    The lobe band of the Blinn delta (`glphong.checks.tolerances.lobe_band`), its chord widening scaled by the
    half vector's conditioning ``max(1, 2/|l + v|)``; near the gates (``|n.v| <= D eps``, ``|l + v|``
    within a factor 4 of its floor) either outcome is accepted; the Fresnel band at ``h.l`` known to
    ``4 D eps max(1, 2/|l + v|)``.

    Returns
    -------
    low, high : (N,) ndarray
        The lobe's interval.
    f_low, f_high : (N, 3) ndarray
        The Fresnel factor's interval.
    """

    tol = constants.D * EPS
    ok_h, h_dir, h_len = safe_normalize(wi + wo)
    delta = 0.5 * _dot(h_dir - f.n, h_dir - f.n)
    scale = np.maximum(1.0, 2.0 / np.maximum(h_len, BLINN_HALF_FLOOR))
    low, high = lobe_band(delta, p.q, scale, constants)
    n_dot_v = _dot(f.n, wo)
    certain = ok_h & (n_dot_v > tol) & (h_len > 4 * BLINN_HALF_FLOOR)
    possible = ok_h & (n_dot_v > -tol) & (h_len > BLINN_HALF_FLOOR / 4)
    low = np.where(certain, low, 0.0)
    high = np.where(possible, np.where(certain, high, 1.0), 0.0)
    f_low, f_high = fresnel_band(p, half_cosine(wi, wo), 4 * tol * scale)
    return low, high, f_low, f_high


class BlinnLobe(MaterialModel):
    """The Blinn-Torrance lobe alone: response ``k_s max(n.h, 0)^q``.

    Parameters are those of `glphong.materials.PhongLobe`; ``fresnel`` multiplies the lobe by
    ``F(h.l)``.
    """

    name = "blinn_lobe"
    params = (_KS, _Q)
    needs = ("view",)
    glsl = GlslFile("materials/blinn_lobe.glsl")
    uses = ("lobe",)
    lobe_exponent = "q"
    vanishes_with = ("ks",)
    in_uber = True  # the lecture's models: every uber-shader holds them
    fresnel_slot = FresnelSlot(cosine="h.l")
    properties = Properties(reciprocal=False, isotropic=True, energy_conserving=False,
                            condition="never: the albedo grows without bound at grazing incidence")

    def response(self, f, wi, wo, n_dot_l, p):
        return p.ks * fresnel_factor(p, half_cosine(wi, wo)) * blinn_lobe(f.n, wi, wo, p.q)[..., None]

    def band(self, f, wi, wo, n_dot_l, p, constants):
        """``k_s`` times `blinn_lobe_band` (the lobe's and the Fresnel factor's intervals)."""
        low, high, f_low, f_high = blinn_lobe_band(f, wi, wo, p, constants)
        return p.ks * f_low * low[..., None], p.ks * f_high * high[..., None]

    def oracle(self, f, wi, wo, n_dot_l, p):
        import mpmath

        s = [a + b for a, b in zip(wi, wo)]
        length = mpmath.sqrt(sum(x * x for x in s))
        if not (sum(a * b for a, b in zip(f.n, wo)) > 0 and length > 0):
            return [mpmath.mpf(0)] * 3

        lobe = lobe_oracle(sum(a * b / length for a, b in zip(f.n, s)), p.q)
        fresnel = fresnel_oracle(p, sum(a * b / length for a, b in zip(wi, s)))
        return [k * F * lobe for k, F in zip(p.ks, fresnel)]

    def pbr_roughness(self):
        """A rough pyrender roughness for comparisons: ``(2 / (q + 2))^(1/4)`` (Beckmann-like alpha)."""
        return float((2.0 / (self.q + 2.0)) ** 0.25)

    @classmethod
    def stability_cases(cls):
        return generic_cases("blinn", BlinnPhong(0.2, 0.5, 100.0)) + lobe_cases("blinn", BlinnPhong)


class BlinnPhong(MaterialSum):
    """The Blinn-Torrance variation (docs/design.md E5, E6): ``k_d (n.l) + k_s max(n.h, 0)^q`` per light.

    Parameters are those of `Phong`; the lobe uses the half vector ``h = (l + v)/|l + v|``.
    """

    name = "blinn_phong"
    terms = (Lambert, BlinnLobe)
