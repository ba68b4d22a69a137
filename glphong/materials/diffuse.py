"""The model 'diffuse': Lambert's law by its albedo (docs/design.md section 9; GLSL: ``glsl/materials/diffuse.glsl``).

``f_r = rho_d / pi`` [1/sr]; response ``rho_d (n.l) / pi``; answers the ambient light with
``(rho_d / pi) L_a`` (the same as `Lambert` with ``kd = rho_d / pi``).  Non-negative, reciprocal,
isotropic; its directional albedo is ``rho_d`` at every incident angle, so it conserves energy when
``rho_d <= 1`` (the range).  It is the diffuse term of `NormalizedPhong`, `NormalizedBlinnPhong`,
`CookTorrance`, `Ward` and `Lafortune`, whose ``rho_d`` it is.

=========  ======  ==========  ======  =============================================
parameter  kind    range       unit    meaning
=========  ======  ==========  ======  =============================================
rho_d      rgb     [0, 1]      1       diffuse albedo (kd = rho_d / pi)
=========  ======  ==========  ======  =============================================
"""
import numpy as np

from glphong.definitions.material import GlslFile, Integral, MaterialModel, Param, Properties
from glphong.definitions.cases import generic_cases
from glphong.twin.band import EPS

__all__ = ["Diffuse", "diffuse", "RHO_D"]

#: the albedo parameter shared by the models with a diffuse term
RHO_D = Param("rho_d", "rgb", low=0.0, high=1.0, textureable=True, doc="diffuse albedo, dimensionless (f_r = rho_d / pi)")


def diffuse(rho_d, n_dot_l):
    """``rho_d (n.l) / pi`` (diffuse.glsl): rho_d (3,), n_dot_l (...) -> (..., 3) [1/sr]."""
    return rho_d * (np.asarray(n_dot_l) / np.pi)[..., None]


class Diffuse(MaterialModel):
    """Ideal diffuse reflector of albedo ``rho_d``: ``f_r = rho_d / pi``.

    Parameters
    ----------
    rho_d : float or (3,) array_like
        Diffuse albedo, dimensionless, in [0, 1].
    ka : float or (3,) array_like, optional
        Constant term k_a [W/(m^2 sr)], >= 0.
    two_sided : bool, optional
    """

    name = "diffuse"
    params = (RHO_D,)
    glsl = GlslFile("materials/diffuse.glsl")
    ambient = "rho_d"
    ambient_scale = 1.0 / np.pi
    vanishes_with = ("rho_d",)
    properties = Properties(reciprocal=True, isotropic=True, energy_conserving=True, condition="rho_d <= 1")

    def response(self, f, wi, wo, n_dot_l, p):
        return diffuse(p.rho_d, n_dot_l)

    def integral_form(self):
        """``(rho_d / pi) E(n)`` under an extended light (docs/design.md section 13)."""
        return Integral("irradiance", "rho_d", factor=1.0 / np.pi)

    def band(self, f, wi, wo, n_dot_l, p, constants):
        """``rho_d / pi [max(n.l - D eps, 0), n.l + D eps]`` widened by 2 eps (the constant and the product)."""

        tol = constants.D * EPS
        return (diffuse(p.rho_d, np.maximum(n_dot_l - tol, 0.0)) * (1 - 2 * EPS),
                diffuse(p.rho_d, np.maximum(n_dot_l + tol, 0.0)) * (1 + 2 * EPS))

    def pbr_base_color(self):
        """The albedo ``rho_d`` (RGB), a metallic-roughness base colour for comparisons with pyrender."""
        return tuple(self.rho_d)

    def oracle(self, f, wi, wo, n_dot_l, p):
        import mpmath

        return [k * n_dot_l / mpmath.pi for k in p.rho_d]

    @classmethod
    def stability_cases(cls):
        return generic_cases("diffuse", cls(0.6))
