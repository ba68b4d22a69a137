"""Lights: where light comes from and how much (docs/design.md E1, E2, section 2).

Kinds and the irradiance ``E`` [W/m^2] each delivers at a surface point:

- `PointLight` (E1): power Phi [W] radiated uniformly, ``E = Phi / (4 pi d^2)``.
- `UnattenuatedPointLight` (E2, the lecture's assignment variant): a position and a
  value ``L_i`` used as ``E`` directly, with no distance falloff.
- `DirectionalLight`: a constant direction and irradiance ``E`` (a light at infinity).
- `AmbientLight`: the ambient ``L_a`` of the term ``k_d L_a``.

Each kind packs its lights into the float32 uniform arrays the shader reads; the
numpy twin reads the very same arrays.
"""
from dataclasses import dataclass

import numpy as np

from glphong.core import validate as _validate
from glphong.core.radiometry import point_intensity

__all__ = ["PointLight", "UnattenuatedPointLight", "DirectionalLight", "AmbientLight", "LIGHT_KINDS"]

_MAX_POWER = 4.0 * np.pi * _validate.FLT_MAX


@dataclass(frozen=True)
class PointLight:
    """Isotropic point source given by its power (docs/design.md E1).

    Parameters
    ----------
    position : (3,) array_like
        World-space position [m].
    power : float or (3,) array_like
        Radiant flux Phi_s [W] per RGB channel, >= 0 (at most 4 pi FLT_MAX so that the
        intensity Phi / (4 pi) [W/sr] is representable in float32).
    """

    position: tuple
    power: tuple

    kind = "point"

    def __post_init__(self):
        object.__setattr__(self, "position", _validate.vec3("position", self.position))
        object.__setattr__(self, "power", _validate.rgb("power", self.power, high=_MAX_POWER))

    @property
    def intensity(self):
        """Radiant intensity ``I = Phi / (4 pi)`` [W/sr], (3,) float64 (pyrender's point intensity)."""
        return point_intensity(np.asarray(self.power))

    def uniform_row(self):
        """``(position, intensity)`` as the shader's uniform arrays hold them."""
        return self.position, self.intensity


@dataclass(frozen=True)
class UnattenuatedPointLight:
    """A positional light of value ``L_i`` with no distance falloff (docs/design.md E2).

    Parameters
    ----------
    position : (3,) array_like
        World-space position [m].
    radiance : float or (3,) array_like
        The lecture's ``L_i``, used as the irradiance ``E`` [W/m^2] at every distance, >= 0.
    """

    position: tuple
    radiance: tuple

    kind = "unattenuated"

    def __post_init__(self):
        object.__setattr__(self, "position", _validate.vec3("position", self.position))
        object.__setattr__(self, "radiance", _validate.rgb("radiance", self.radiance))

    def uniform_row(self):
        """``(position, radiance)`` as the shader's uniform arrays hold them."""
        return self.position, self.radiance


@dataclass(frozen=True)
class DirectionalLight:
    """A light at infinity: constant direction and irradiance.

    Parameters
    ----------
    direction : (3,) array_like
        Direction the light travels in (from the light toward the scene), any non-zero length.
    irradiance : float or (3,) array_like
        Irradiance ``E`` [W/m^2] on a surface facing the light, >= 0.
    """

    direction: tuple
    irradiance: tuple

    kind = "directional"

    def __post_init__(self):
        d = np.asarray(_validate.vec3("direction", self.direction, nonzero=True))
        d = d / np.max(np.abs(d))
        object.__setattr__(self, "direction", tuple(float(c) for c in d / np.linalg.norm(d)))
        object.__setattr__(self, "irradiance", _validate.rgb("irradiance", self.irradiance))

    def uniform_row(self):
        """``(unit vector toward the light, irradiance)`` as the shader's uniform arrays hold them."""
        return tuple(-c for c in self.direction), self.irradiance


@dataclass(frozen=True)
class AmbientLight:
    """Ambient illumination ``L_a`` [W/m^2] of the term ``k_d L_a`` (docs/design.md E6).

    Parameters
    ----------
    radiance : float or (3,) array_like
        ``L_a`` per RGB channel, >= 0.
    """

    radiance: tuple

    def __post_init__(self):
        object.__setattr__(self, "radiance", _validate.rgb("radiance", self.radiance))


#: light kind -> (class, uniform name of the position/direction array, uniform name of the value array)
LIGHT_KINDS = {
    "point": (PointLight, "u_point_position", "u_point_intensity"),
    "unattenuated": (UnattenuatedPointLight, "u_unattenuated_position", "u_unattenuated_radiance"),
    "directional": (DirectionalLight, "u_directional_direction", "u_directional_irradiance"),
}
