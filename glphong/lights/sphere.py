"""The area light 'sphere': a uniform spherical emitter (docs/design.md section 13; GLSL: ``glsl/lights/sphere.glsl``).

Seen from ``x`` at distance ``d > R`` the sphere is a cone of directions of half-angle ``sigma``, ``sin(sigma) =
R/d``, of uniform radiance ``L``.  Lambert's irradiance is the cone's exact integral, the surface's horizon included
(Snyder 1996; Lagarde and de Rousiers 2014); every other term is summed over ``samples^2`` equal-solid-angle cells
of the cone.  Its intensity is ``pi R^2 L`` in every direction and its power ``4 pi^2 R^2 L``: at fixed power it
tends to a `PointLight` of that power as ``R -> 0`` (tested).
"""
import numpy as np

from glphong.lights.extended import CENTER, RADIANCE, RADIUS, SAMPLES, ExtendedLight, extended_cases
from glphong.definitions.light import GlslFile
from glphong.twin.area import area_angle
from glphong.twin.band import EPS
from glphong.twin.functions import atan2_first_quadrant, dot as _dot, perpendiculars, safe_normalize
from glphong.twin.quadrature import sphere_integral

__all__ = ["SphereLight"]


class SphereLight(ExtendedLight):
    """A uniform spherical light.

    Seen from ``x`` at distance ``d > R`` it is a cone of directions of half-angle ``sigma``, ``sin(sigma) = R/d``,
    of radiance ``L``: ``E(n) = L integral (n.w)^+ dw`` over the cone, exactly (the horizon included); every other
    term summed over ``samples^2`` cells of equal solid angle.  Its intensity is ``pi R^2 L`` in every direction,
    its power ``4 pi^2 R^2 L``.

    Parameters
    ----------
    center : (3,) array_like
        Its centre [m].
    radius : float
        Its radius [m], > 0.
    radiance : float or (3,) array_like
        ``L`` [W/(m^2 sr)] leaving its surface (`from_power` for a power).
    samples : int
        Cells per side of the sampled method, 1 to 64 (default 4).
    """

    name = "sphere"
    loop_order = 6
    params = (CENTER, RADIUS, RADIANCE, SAMPLES)
    glsl = GlslFile("lights/sphere.glsl")
    uses = ("angle", "area")
    integrals = ("irradiance",)
    exact_integrals = ("irradiance",)

    @classmethod
    def from_power(cls, center, radius, power, samples=4):
        """The sphere of ``power`` [W] (scalar or RGB): ``L = Phi / (4 pi^2 R^2)``."""
        return cls(center, radius, np.asarray(power, dtype=np.float64) / (4 * np.pi ** 2 * radius ** 2), samples)

    def power(self):
        """``4 pi^2 R^2 L`` [W] (3,)."""
        return 4 * np.pi ** 2 * self.radius ** 2 * np.asarray(self.radiance)

    # ---- the twin (sphere.glsl, function by function)
    @staticmethod
    def _cap(x, n, p):
        """The cap integral's parts: ``(reached, F, terms, t, dF/dt bound)``, (N,) each."""
        valid, wc, d = safe_normalize(p.center - x)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = p.radius / d
            s2 = ratio * ratio
            c = _dot(n, wc)
            st = np.sqrt(np.maximum(1 - c * c, 0.0))
            big_x = np.sqrt(np.maximum(1 / s2 - 1, 0.0))
            y = np.clip(-big_x * c / np.maximum(st, 1e-30), -1.0, 1.0)
            t = np.sqrt(np.maximum(1 - y * y, 0.0))
            s = st * t
            parts = (c * area_angle(t, y) * s2, -big_x * s * s2, atan2_first_quadrant(s, big_x))
            above = c * c >= s2
            f = np.where(above, np.pi * s2 * np.maximum(c, 0.0), sum(parts))
            terms = np.where(above, np.pi * s2 * np.abs(c), sum(np.abs(a) for a in parts))
            slope = np.where(above, 0.0, np.abs(c) * s2 + big_x * st * s2 + st / big_x)
        return valid & (ratio < 1), np.maximum(f, 0.0), terms, t, np.nan_to_num(slope)

    def irradiance(self, x, n, p):
        reached, f, _, _, _ = self._cap(x, n, p)
        return np.where(reached[:, None], p.radiance * f[:, None], 0.0)

    def irradiance_band(self, x, n, p, constants):
        """The generic sensitivity band plus the formula's own float32 rounding: ``16 eps`` of the magnitudes of its
        terms, and where the cone straddles the horizon the error of ``t = sqrt(1 - y^2)`` (``4 eps / t``, which near
        the tangent configuration reaches ``sqrt(eps)``) times the bound ``|c| s^2 + X sin(theta) s^2 +
        sin(theta)/X`` of ``|dF/dt|``."""
        low, high = super().irradiance_band(x, n, p, constants)
        reached, _, terms, t, slope = self._cap(x, n, p)
        slack = 16 * EPS * terms + 4 * EPS / np.maximum(t, np.sqrt(4 * EPS)) * slope
        slack = p.radiance * np.where(reached, slack, 0.0)[:, None]
        return np.maximum(low - slack, 0.0), high + slack

    def sample(self, x, n, k, p):
        m = int(p.samples)
        a, b = k // m, k - (k // m) * m
        valid, wc, d = safe_normalize(p.center - x)
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = p.radius / d
            s2 = ratio * ratio
            versine = s2 / (1 + np.sqrt(np.maximum(1 - s2, 0.0)))
        v = (a + 0.5) / m * versine
        st = np.sqrt(np.maximum(v * (2 - v), 0.0))
        phi = 2 * np.pi * (b + 0.5) / m
        e1, e2 = perpendiculars(wc)
        wi = wc * (1 - v)[:, None] + (e1 * np.cos(phi) + e2 * np.sin(phi)) * st[:, None]
        irradiance = p.radiance * (2 * np.pi * versine / (m * m))[:, None]
        return valid & (ratio < 1) & (k < m * m), wi, irradiance

    @classmethod
    def stability_cases(cls):
        up = (0.0, 0.0, 1.0)
        return extended_cases("sphere", (
            ("overhead", cls((0.0, 0.0, 1.0), 0.3, 2.0), up),
            ("straddling the horizon", cls((1.0, 0.0, 0.1), 0.3, 2.0), up),
            ("half below the horizon", cls((1.0, 0.0, 0.0), 0.3, 2.0), up),
            ("touching (1e-6 of its radius away)", cls((0.0, 0.0, 0.3 * (1 + 1e-6)), 0.3, 2.0), up),
            ("1e-4 m at 1 m (a point)", cls((0.3, 0.0, 1.0), 1e-4, 2.0e8), up)))

    def exact(self, x, n, p, integrand, clip=()):
        return sphere_integral(x, n, np.asarray(p.center, np.float64), float(p.radius), p.radiance, integrand, clip=clip)
