"""The kind 'point': an isotropic point source given by its power (docs/design.md E1, section 11; GLSL:
``glsl/lights/point.glsl``).

``E = Phi / (4 pi d^2)`` at distance ``d``, times KHR_lights_punctual's window
``clamp(1 - (d/range)^4, 0, 1)`` where a ``range`` is given (pyrender ignores range).
"""
import numpy as np

from glphong.core import validate as _validate
from glphong.core.radiometry import point_intensity, power_from_intensity
from glphong.definitions.light import (ExactIrradiance, GlslFile, LightModel, Param, gltf_entry, mp, mp32, mp_range_window,
                                  mp_toward)
from glphong.twin.functions import point_irradiance, range_window, safe_normalize

__all__ = ["PointLight", "POSITION", "RANGE", "WithRange"]

_MAX_POWER = 4.0 * np.pi * _validate.FLT_MAX
#: a light's position, shared by the positional kinds
POSITION = Param("position", "vec3", low=-np.inf, unit="m", doc="world-space position")
#: KHR_lights_punctual's range, shared by point and spot lights
RANGE = Param("range", "scalar", low=0.0, low_inclusive=False, optional=True, unit="m",
              doc="distance where the light's window reaches 0; None: no window")


def with_range(irradiance, d, p):
    """``irradiance`` times `range_window` where the kind's chunk has the window (``p.defines['RANGE']``) and
    the light has a range (its uniform > 0): the tail of point.glsl and spot.glsl."""
    if not p.defines.get("RANGE"):
        return irradiance
    return np.where(p.range > 0, irradiance * range_window(d, np.where(p.range > 0, p.range, 1))[..., None], irradiance)


def range_defines(lights):
    """``(('RANGE', '1'),)`` where one of ``lights`` has a range, else none: the window is left out."""
    return (("RANGE", "1"),) if any(light.range is not None for light in lights) else ()


class WithRange:
    """What a light kind with KHR_lights_punctual's ``range`` (the `RANGE` param) shares: the window's structural
    define (``<KIND>_RANGE`` where one of the scene's lights of the kind has a range) and its uniform, 0 for none."""

    optional_code = (("RANGE", "range window clamp(1 - (d/range)^4, 0, 1) and its uniform"),)
    conditional_uniforms = {"range": "RANGE"}

    @classmethod
    def structural_defines(cls, lights):
        return range_defines(lights)

    def uniform_value(self, name):
        if name == "range":
            return 0.0 if self.range is None else self.range
        return getattr(self, name)


class PointLight(WithRange, LightModel):
    """Isotropic point source given by its power (docs/design.md E1): ``E = Phi / (4 pi d^2)`` at distance ``d``.

    Times KHR_lights_punctual's window ``clamp(1 - (d/range)^4, 0, 1)`` where a ``range`` is given.

    Parameters
    ----------
    position : (3,) array_like
        World-space position [m].
    power : float or (3,) array_like
        Radiant flux Phi_s [W] per RGB channel, >= 0 (at most 4 pi FLT_MAX so that the
        intensity Phi / (4 pi) [W/sr] is representable in float32).
    range : float or None
        KHR_lights_punctual's range [m] (> 0): ``E`` is multiplied by ``clamp(1 - (d/range)^4, 0, 1)``;
        None (default): no window.
    shadows : bool
        Cast shadows (a cube shadow map around the light; default False).
    """

    name = "point"
    loop_order = 0  # the shader loops over the kinds in this order (point, unattenuated, directional, spot, ...)
    params = (POSITION, Param("power", "rgb", low=0.0, high=_MAX_POWER, unit="W", doc="radiant flux Phi"), RANGE)
    uniforms = (POSITION, Param("intensity", "rgb", low=0.0, unit="W/sr", doc="Phi / (4 pi)"), RANGE)
    glsl = GlslFile("lights/point.glsl")
    shadow_map = "cube"
    uses = ("lights",)
    numerics_bounds = {"light": "position", "falloff": "intensity"}
    in_uber = True
    gltf_type = "point"
    pyrender_type = "PointLight"

    @property
    def intensity(self):
        """Radiant intensity ``I = Phi / (4 pi)`` [W/sr], (3,) float64 (pyrender's point intensity)."""
        return point_intensity(np.asarray(self.power))

    def uniform_value(self, name):
        return self.intensity if name == "intensity" else super().uniform_value(name)

    def incident(self, x, p):
        valid, wi, d = safe_normalize(p.position - x)
        with np.errstate(divide="ignore", invalid="ignore"):
            return valid, wi, with_range(point_irradiance(p.intensity, d), d, p)

    @classmethod
    def stability_cases(cls):
        """None of its own: the suite's groups 'distance', 'power' and 'normals' are point lights."""
        return ()

    def oracle(self, x):
        wi, d = mp_toward(mp32(self.position), x)
        if wi is None:
            return None
        return wi, [phi / (4 * mp().pi * d * d) * mp_range_window(d, self.range) for phi in mp32(self.power)]

    def band(self, x, p, constants):
        """The twin's value: ``(I / d) / d`` is two quotients, inside the term's ``A eps``; the window (where
        present) is the generic band."""
        if p.defines.get("RANGE"):
            return LightModel.band(self, x, p, constants)
        return ExactIrradiance.band(self, x, p, constants)

    def band_given(self, x, p, constants, incident):
        """`band` with ``incident`` = ``self.incident(x, p)`` in hand (`LightModel.band_given`)."""
        if p.defines.get("RANGE"):
            return self.generic_band(x, p, constants, incident[2])
        return ExactIrradiance.band_given(self, x, p, constants, incident)

    @classmethod
    def from_gltf(cls, value, entry, pose):
        return cls(tuple(pose[:3, 3]), tuple(power_from_intensity(value)), range=entry.get("range"))

    def to_gltf(self):
        extra = {} if self.range is None else {"range": self.range}
        pose = np.eye(4)
        pose[:3, 3] = self.position
        return gltf_entry("point", self.intensity, **extra), pose

    @classmethod
    def from_pyrender(cls, value, light, pose):
        return cls(pose[:3, 3], power_from_intensity(value))

    def to_pyrender(self, pyrender):
        entry, pose = self.to_gltf()  # pyrender ignores range
        return pyrender.PointLight(color=entry["color"], intensity=entry["intensity"]), pose
