"""The kind 'spot': KHR_lights_punctual's spot light (docs/design.md section 11; GLSL: ``glsl/lights/spot.glsl``).

A point source of intensity ``I`` [W/sr] along its axis, with the specification's angular falloff
``f = clamp(cos(theta) s + o, 0, 1)^2``, ``s = 1 / max(0.001, cos(inner) - cos(outer))``,
``o = -cos(outer) s``, so ``E = f I / d^2`` at distance ``d`` (times the range window, where given).
pyrender's ``SpotLight`` has the same falloff and ignores range.
"""
import numpy as np

from glphong.core.radiometry import point_intensity
from glphong.definitions.light import GlslFile, LightModel, Param, gltf_entry, mp, mp32, mp_dot, mp_range_window, mp_toward, pose_pointing
from glphong.lights.point import POSITION, RANGE, WithRange, with_range
from glphong.definitions.cases import Case
from glphong.materials.phong import Phong
from glphong.twin.band import EPS
from glphong.twin.functions import FLT_MAX, safe_normalize

__all__ = ["SpotLight", "spot_falloff"]

_AXIS = Param("direction", "direction", low=-1.0, high=1.0, doc="the axis: the direction the light points in")
_INTENSITY = Param("intensity", "rgb", low=0.0, unit="W/sr", doc="radiant intensity along the axis")
_INNER = Param("inner_cone_angle", "scalar", low=0.0, high=np.pi / 2, default=0.0, unit="rad",
               doc="angle from the axis where the falloff starts")
_OUTER = Param("outer_cone_angle", "scalar", low=0.0, high=np.pi / 2, low_inclusive=False, default=np.pi / 4,
               unit="rad", doc="angle from the axis where the light ends")


def spot_falloff(cos_theta, inner_cone_angle, outer_cone_angle):
    """KHR_lights_punctual's angular falloff as the specification writes it (float64, for tests and files):
    ``clamp(cos(theta) s + o, 0, 1)^2`` with ``s = 1 / max(0.001, cos(inner) - cos(outer))``, ``o = -cos(outer) s``."""
    s = 1.0 / max(0.001, np.cos(inner_cone_angle) - np.cos(outer_cone_angle))
    return np.clip(np.asarray(cos_theta) * s - np.cos(outer_cone_angle) * s, 0.0, 1.0) ** 2


class SpotLight(WithRange, LightModel):
    """A spot light: a point source whose light is confined to a cone (KHR_lights_punctual).

    ``E = f I / d^2`` at distance ``d``, ``theta`` the angle from the axis, with the specification's falloff
    ``f = clamp(cos(theta) s + o, 0, 1)^2``, ``s = 1 / max(0.001, cos(inner) - cos(outer))``, ``o = -cos(outer) s``;
    times the window ``clamp(1 - (d/range)^4, 0, 1)`` where a ``range`` is given.

    Parameters
    ----------
    position : (3,) array_like
        World-space position [m].
    direction : (3,) array_like
        The axis, the direction the light points in (any non-zero length; stored normalised).
    intensity : float or (3,) array_like
        Radiant intensity along the axis [W/sr], >= 0 (an isotropic source of power ``Phi`` has ``Phi / (4 pi)``).
    inner_cone_angle, outer_cone_angle : float
        Angles from the axis [rad], ``0 <= inner <= outer <= pi/2``, ``outer > 0`` (defaults 0 and pi/4): full
        intensity inside ``inner``, none beyond ``outer``, the specification's falloff between (``inner = outer``,
        which the specification excludes but files carry, is its hard edge smoothed over a cosine of 0.001).
    range : float or None
        KHR_lights_punctual's range [m] (> 0): ``E`` times ``clamp(1 - (d/range)^4, 0, 1)``; None: no window.
    shadows : bool
        Cast shadows (a cube shadow map around the light; default False).
    """

    name = "spot"
    loop_order = 3
    params = (POSITION, _AXIS, _INTENSITY, _INNER, _OUTER, RANGE)
    uniforms = (POSITION, Param("axis", "direction", low=-1.0, high=1.0, doc="unit axis"), _INTENSITY,
                Param("versin_outer", "scalar", low=0.0, high=1.0, doc="1 - cos(outer) = 2 sin^2(outer/2)"),
                Param("scale", "scalar", low=1.0, high=1000.0, doc="s = 1 / max(0.001, cos(inner) - cos(outer))"),
                RANGE)
    glsl = GlslFile("lights/spot.glsl")
    shadow_map = "cube"
    uses = ("lights",)
    numerics_bounds = {"light": "position"}
    gltf_type = "spot"
    pyrender_type = "SpotLight"

    def check(self):
        if self.inner_cone_angle > self.outer_cone_angle:
            raise ValueError(f"inner_cone_angle ({self.inner_cone_angle!r}) must be at most outer_cone_angle "
                             f"({self.outer_cone_angle!r})")

    def uniform_value(self, name):
        if name == "axis":
            return self.direction
        if name == "versin_outer":
            return 2.0 * np.sin(0.5 * self.outer_cone_angle) ** 2
        if name == "scale":  # cos(inner) - cos(outer) = 2 (sin^2(outer/2) - sin^2(inner/2)), without cancellation
            half = 0.5 * np.array([self.outer_cone_angle, self.inner_cone_angle])
            gap = 2.0 * (np.sin(half[0]) - np.sin(half[1])) * (np.sin(half[0]) + np.sin(half[1]))
            return 1.0 / max(0.001, gap)
        return super().uniform_value(name)

    def incident(self, x, p):
        valid, wi, d = safe_normalize(p.position - x)
        chord = -wi - p.axis
        delta = 0.5 * np.sum(chord * chord, axis=-1)
        g = np.clip((p.versin_outer - delta) * p.scale, 0.0, 1.0)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
            g_d = (g / d)[..., None]
            irradiance = np.minimum((p.intensity * g_d) * g_d, FLT_MAX)
            return valid, wi, with_range(irradiance, d, p)

    def band(self, x, p, constants):
        """Derived from the chord form: the chord ``-wi - a`` within ``C eps`` of its length (wi's normalisation),
        so ``delta`` within ``C eps |chord| + A eps delta``; ``g`` from the ends of that interval, times
        ``(1 -+ A eps)``; ``d`` within ``(1 -+ D eps)``; ``E`` from the ends of both (and the range window from
        the ends of ``d``)."""
        valid, wi, d = safe_normalize(p.position - x)
        chord = -wi - p.axis
        length = np.sqrt(np.sum(chord * chord, axis=-1))
        delta = 0.5 * length * length
        spread = constants.C * EPS * length + constants.A * EPS * delta
        a = constants.A * EPS
        g_lo = np.clip((p.versin_outer - delta - spread) * p.scale * (1 - a), 0.0, 1.0)
        g_hi = np.clip((p.versin_outer - delta + spread) * p.scale * (1 + a), 0.0, 1.0)
        d_lo, d_hi = d * (1 - constants.D * EPS), d * (1 + constants.D * EPS)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
            low = np.minimum(p.intensity * ((g_lo / d_hi) ** 2)[..., None], FLT_MAX) * (1 - a)
            high = np.minimum(p.intensity * ((g_hi / d_lo) ** 2)[..., None], FLT_MAX) * (1 + a)
            return with_range(low, d_hi, p), with_range(high, d_lo, p)

    def oracle(self, x):
        """The specification's formula as it writes it, ``clamp(cos(theta) s + o, 0, 1)^2 I / d^2``, in mpmath from
        the float32 position, axis and intensity and the float64 angles."""
        wi, d = mp_toward(mp32(self.position), x)
        if wi is None:
            return None
        axis = mp32(self.direction)
        mpmath = mp()
        axis = [c / mpmath.sqrt(mp_dot(axis, axis)) for c in axis]
        cos_theta = -mp_dot(wi, axis)
        cos_outer = mpmath.cos(mpmath.mpf(self.outer_cone_angle))
        s = 1 / max(mpmath.mpf("0.001"), mpmath.cos(mpmath.mpf(self.inner_cone_angle)) - cos_outer)
        falloff = min(max(cos_theta * s - cos_outer * s, 0), 1) ** 2
        return wi, [i * falloff / (d * d) * mp_range_window(d, self.range) for i in mp32(self.intensity)]

    @classmethod
    def stability_cases(cls):
        """The cone's edge (``cos(theta) = cos(outer)``, just inside and outside), the inner edge, ``inner = outer``,
        cones of 1e-6 rad and of pi/2, ``d -> range`` and the distances a `PointLight` is stable at."""
        material = Phong(0.3, 0.4, 20.0)
        out = []
        down = (0.0, 0.0, -1.0)

        def case(label, light, group="spot light", in_range=True, note="", normal=(0.0, 0.0, 1.0)):
            out.append(Case(f"spot {label}", group, material, normal=normal, eye=(0.3, 0.2, 2.0), lights=(light,),
                            in_range=in_range, note=note))

        outer, inner = np.radians(30.0), np.radians(20.0)
        for label, angle in (("on the outer edge", outer), ("1e-4 rad inside the outer edge", outer - 1e-4),
                             ("1e-4 rad outside the outer edge", outer + 1e-4), ("on the inner edge", inner),
                             ("halfway in the falloff", 0.5 * (inner + outer)), ("on the axis", 0.0)):
            # the light 1 m above the origin, tilted so that the origin is `angle` off its axis
            case(label, cls((0.0, 0.0, 1.0), (np.sin(angle), 0.0, -np.cos(angle)), 1.0, inner, outer))
        case("inner = outer, 1e-5 rad inside", cls((0.0, 0.0, 1.0), (np.sin(outer - 1e-5), 0.0, -np.cos(outer - 1e-5)),
                                                     1.0, outer, outer))
        for cone in (1e-6, np.pi / 2):
            for label, angle in (("on the axis", 0.0), ("at half the cone", 0.5 * cone)):
                case(f"cone {cone:.3g} rad, {label}", cls((0.0, 0.0, 1.0), (np.sin(angle), 0.0, -np.cos(angle)), 1.0,
                                                          0.0, cone))
        case("cone pi/2, grazing 89.9 deg", cls((0.0, 0.0, 1.0), (np.sin(np.radians(89.9)), 0.0, -np.cos(np.radians(89.9))),
                                                1.0, 0.0, np.pi / 2))
        for fraction in (0.5, 0.999, 0.999999, 1.0, 1.001):
            case(f"d = {fraction:g} range", cls((0.0, 0.0, 1.0), down, 1.0, 0.0, np.pi / 4, range=1.0 / fraction),
                 group="spot range")
        for d in (1e-18, 1e-3, 1e3, 1e19):
            case(f"distance {d:g}, E = 1 W/m^2", cls((0.0, 0.0, d), down, d * d, 0.0, np.pi / 4), group="spot distance")
        return tuple(out)

    @classmethod
    def from_gltf(cls, value, entry, pose):
        spot = entry.get("spot", {})
        return cls(tuple(pose[:3, 3]), tuple(-pose[:3, 2]), tuple(value), spot.get("innerConeAngle", 0.0),
                   spot.get("outerConeAngle", np.pi / 4), range=entry.get("range"))

    def to_gltf(self):
        extra = {"spot": {"innerConeAngle": self.inner_cone_angle, "outerConeAngle": self.outer_cone_angle}}
        if self.range is not None:
            extra["range"] = self.range
        return gltf_entry("spot", self.intensity, **extra), pose_pointing(self.direction, self.position)

    @classmethod
    def from_pyrender(cls, value, light, pose):
        return cls(pose[:3, 3], -pose[:3, 2], value, light.innerConeAngle, light.outerConeAngle)

    def to_pyrender(self, pyrender):
        entry, pose = self.to_gltf()
        return pyrender.SpotLight(color=entry["color"], intensity=entry["intensity"],
                                  innerConeAngle=self.inner_cone_angle, outerConeAngle=self.outer_cone_angle), pose

    @classmethod
    def from_power(cls, position, direction, power, **kwargs):
        """A spot light whose axis intensity is that of an isotropic source of power ``power`` [W]:
        ``I = Phi / (4 pi)`` (the lecture's point light, confined to a cone)."""
        return cls(position, direction, point_intensity(np.asarray(power, dtype=np.float64)), **kwargs)
