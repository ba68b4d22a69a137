"""Materials: frozen, validated parameters of the lecture's reflectance models.

Each material names its BRDF family (which GLSL chunk and numpy twin evaluate its
lobe) and hands the renderer its uniforms as float32, the exact values the twin
then shades with.  Coefficients are RGB; a scalar broadcasts to all channels.

Units: ``kd`` and ``ks`` are BRDF values [1/sr] (an albedo rho gives kd = rho/pi);
``ka`` is an emitted-like ambient radiance [W/(m^2 sr)]; ``q`` is dimensionless.
"""
from dataclasses import dataclass, field

import numpy as np

from . import _validate

__all__ = ["Material", "Lambert", "Phong", "BlinnPhong"]


@dataclass(frozen=True)
class Material:
    """Base of all materials: the diffuse and ambient part of DESIGN E6.

    Parameters
    ----------
    kd : float or (3,) array_like
        Diffuse BRDF value k_d [1/sr], >= 0.
    ka : float or (3,) array_like
        Ambient term k_a [W/(m^2 sr)], >= 0.  Default 0.
    two_sided : bool
        Shade back faces with the normal flipped toward the viewer (default True).
    """

    family = "lambert"
    kd: tuple
    ka: tuple = field(default=(0.0, 0.0, 0.0), kw_only=True)
    two_sided: bool = field(default=True, kw_only=True)

    def __post_init__(self):
        object.__setattr__(self, "kd", _validate.rgb("kd", self.kd))
        object.__setattr__(self, "ka", _validate.rgb("ka", self.ka))
        if not isinstance(self.two_sided, (bool, np.bool_)):
            raise TypeError(f"two_sided must be a bool, True or False (got {self.two_sided!r})")
        object.__setattr__(self, "two_sided", bool(self.two_sided))

    @property
    def has_specular(self):
        """True when the material has a non-zero specular lobe."""
        return False

    def uniform_values(self, key):
        """The material's uniforms for a program ``key``, as float32 arrays.

        Parameters
        ----------
        key : glphong.key.ProgramKey

        Returns
        -------
        dict of str to numpy.ndarray
            Only the uniforms the keyed program declares.
        """
        f32 = lambda v: np.asarray(v, dtype=np.float32)  # noqa: E731
        values = {}
        if key.has_ka:
            values["u_ka"] = f32(self.ka)
        if key.has_diffuse or key.has_kd_la:
            values["u_kd"] = f32(self.kd)
        if key.has_specular:
            values["u_ks"] = f32(self.ks)
            values["u_q"] = f32(self.q)
        return values


@dataclass(frozen=True)
class Lambert(Material):
    """Ideal diffuse reflector (DESIGN E3): ``L = k_a + k_d L_a + sum_j k_d (n.l_j) E_j``."""


@dataclass(frozen=True)
class _Glossy(Material):
    ks: tuple
    q: float

    def __post_init__(self):
        super().__post_init__()
        object.__setattr__(self, "ks", _validate.rgb("ks", self.ks))
        object.__setattr__(self, "q", _validate.scalar("q", self.q))

    @property
    def has_specular(self):
        return any(c > 0.0 for c in self.ks)


@dataclass(frozen=True)
class Phong(_Glossy):
    """The Phong model (DESIGN E4, E6): ``k_d (n.l) + k_s max(v.r, 0)^q`` per light, plus ambient.

    Parameters
    ----------
    kd, ks : float or (3,) array_like
        Diffuse and specular coefficients [1/sr], >= 0.
    q : float
        Specular exponent, finite, >= 0 (q = 0 gives a constant lobe of 1).
    ka : float or (3,) array_like, optional
        Ambient term [W/(m^2 sr)], >= 0.
    """

    family = "phong"


@dataclass(frozen=True)
class BlinnPhong(_Glossy):
    """The Blinn-Torrance variation (DESIGN E5, E6): ``k_d (n.l) + k_s max(n.h, 0)^q`` per light.

    Parameters are those of `Phong`; the lobe uses the half vector ``h = (l + v)/|l + v|``.
    """

    family = "blinn"
