"""The model 'lambert': ideal diffuse reflection (docs/design.md E3; GLSL: ``glsl/materials/lambert.glsl``).

``f_r = k_d`` [1/sr] (an albedo rho gives ``k_d = rho / pi``); response ``k_d (n.l)``; answers the
ambient light with ``k_d L_a``.  Non-negative, reciprocal, isotropic; energy-conserving when
``pi k_d <= 1`` per channel (its albedo is ``pi k_d`` at every incident angle).

=========  ======  ==========  ======  =============================================
parameter  kind    range       unit    meaning
=========  ======  ==========  ======  =============================================
kd         rgb     >= 0        1/sr    diffuse BRDF value k_d
=========  ======  ==========  ======  =============================================
"""
import numpy as np

from glphong.definitions.material import GlslFile, Integral, MaterialModel, Param, Properties
from glphong.definitions.cases import generic_cases
from glphong.twin.band import EPS

__all__ = ["Lambert", "lambert"]


def lambert(kd, n_dot_l):
    """``kd (n.l)`` (lambert.glsl): kd (3,) [1/sr], n_dot_l (...) -> (..., 3)."""
    return kd * np.asarray(n_dot_l)[..., None]


class Lambert(MaterialModel):
    """Ideal diffuse reflector (docs/design.md E3): ``L = k_a + k_d L_a + sum_j k_d (n.l_j) E_j``.

    Parameters
    ----------
    kd : float or (3,) array_like
        Diffuse BRDF value k_d [1/sr], >= 0.
    ka : float or (3,) array_like, optional
        Constant term k_a [W/(m^2 sr)], >= 0.  Default 0.
    two_sided : bool, optional
        Shade back faces with the normal flipped toward the viewer (default True).
    """

    name = "lambert"
    params = (Param("kd", "rgb", low=0.0, unit="1/sr", textureable=True, doc="diffuse BRDF value; an albedo rho is kd = rho/pi"),)
    glsl = GlslFile("materials/lambert.glsl")
    ambient = "kd"
    vanishes_with = ("kd",)
    in_uber = True  # the lecture's models: every uber-shader holds them
    properties = Properties(reciprocal=True, isotropic=True, energy_conserving=True, condition="pi kd <= 1")

    def response(self, f, wi, wo, n_dot_l, p):
        return lambert(p.kd, n_dot_l)

    def integral_form(self):
        """``k_d E(n)`` under an extended light (docs/design.md section 13)."""
        return Integral("irradiance", "kd")

    def band(self, f, wi, wo, n_dot_l, p, constants):
        """``k_d [max(n.l - D eps, 0), n.l + D eps]``: the dot product's absolute error (docs/design.md section 4)."""

        tol = constants.D * EPS
        return lambert(p.kd, np.maximum(n_dot_l - tol, 0.0)), lambert(p.kd, np.maximum(n_dot_l + tol, 0.0))

    def pbr_base_color(self):
        """The albedo ``pi k_d`` (RGB), a metallic-roughness base colour for comparisons with pyrender."""
        return tuple(np.pi * c for c in self.kd)

    def oracle(self, f, wi, wo, n_dot_l, p):
        return [k * n_dot_l for k in p.kd]

    @classmethod
    def stability_cases(cls):
        return generic_cases("lambert", cls(0.2))
