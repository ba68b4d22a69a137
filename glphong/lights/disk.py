"""The area light 'disk': a one-sided uniform disk (docs/design.md section 13; GLSL: ``glsl/lights/disk.glsl``).

Lambert's irradiance is its rim's contour integral in closed form, the horizon included (an arc and a chord; module
docstring of disk.glsl); every other term is summed over ``samples^2`` cells of equal area.  Its power is
``pi L pi R^2``; far away it is a point of intensity ``L pi R^2 cos(theta_l)``.
"""
import numpy as np

from glphong.lights.extended import CENTER, RADIANCE, RADIUS, SAMPLES, ExtendedLight, extended_cases
from glphong.definitions.light import GlslFile, Param
from glphong.twin.area import area_angle
from glphong.twin.band import EPS
from glphong.twin.functions import dot as _dot, perpendiculars, safe_normalize
from glphong.twin.quadrature import disk_integral

__all__ = ["DiskLight"]


def disk_atan2(y, x):
    """``atan2(y, x)`` in ``(-pi, pi]`` (disk.glsl)."""
    return np.where(y >= 0, area_angle(np.abs(y), x), -area_angle(np.abs(y), x))


def disk_log1p_over(z):
    """``log(1 + z) / z``, 1 at ``z = 0`` (disk.glsl's Kahan form; exact here)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(z != 0, np.log1p(z) / np.where(z != 0, z, 1.0), 1.0)


def disk_angle_over(y, x):
    """``atan2(y, x) / y``, ``1/x`` at ``y = 0`` (disk.glsl)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(y != 0, disk_atan2(y, x) / np.where(y != 0, y, 1.0), 1.0 / x)


class DiskLight(ExtendedLight):
    """A one-sided uniform disk light, emitting toward the side its ``normal`` points to.

    ``E(n) = L integral (n.w)^+ dw`` over the disk as seen from ``x``, exactly (its rim's contour integral, the
    horizon included); every other term summed over ``samples^2`` cells of equal area.  Its power is
    ``pi L pi R^2``; far away it is a point of intensity ``L pi R^2 cos(theta_l)``.

    Parameters
    ----------
    center : (3,) array_like
        Its centre [m].
    normal : (3,) array_like
        The direction it emits toward (normalised).
    radius : float
        Its radius [m], > 0.
    radiance : float or (3,) array_like
        ``L`` [W/(m^2 sr)].
    samples : int
        Cells per side of the sampled method, 1 to 64 (default 4).
    """

    name = "disk"
    loop_order = 7
    params = (CENTER, Param("normal", "direction", low=-np.inf, doc="the side it emits to"), RADIUS, RADIANCE, SAMPLES)
    glsl = GlslFile("lights/disk.glsl")
    uses = ("angle", "area")
    integrals = ("irradiance",)
    exact_integrals = ("irradiance",)

    def power(self):
        """``pi L pi R^2`` [W] (3,)."""
        return np.pi ** 2 * self.radius ** 2 * np.asarray(self.radiance)

    # ---- the twin (disk.glsl, function by function)
    @staticmethod
    def _rim(x, n, p):
        """The contour integral's parts: ``(front, value, magnitude)``, (N,) each: ``-(1/2) (I + chord)`` and the sum
        of its terms' magnitudes (for the band)."""
        big_n, radius = p.normal / np.linalg.norm(p.normal), p.radius  # unit to the last bit: the rim is a circle
        c = p.center - x
        e1, e2 = perpendiculars(big_n)
        cp = np.stack([_dot(c, e1), _dot(c, e2)], axis=-1)
        big_a = _dot(c, c) + radius * radius
        lcp = np.linalg.norm(cp, axis=-1)
        rho = 2 * radius * lcp
        with np.errstate(divide="ignore", invalid="ignore"):
            g = np.where((rho > 0)[:, None], cp / lcp[:, None], np.array([1.0, 0.0]))
            gp = np.stack([-g[:, 1], g[:, 0]], axis=-1)
            alpha = radius * _dot(n, np.cross(c, e2))
            beta = -radius * _dot(n, np.cross(c, e1))
            a = alpha * g[:, 0] + beta * g[:, 1]
            b = beta * g[:, 0] - alpha * g[:, 1]
            gam = radius * radius * _dot(n, big_n)
            s = np.sqrt(np.maximum((big_a - rho) * (big_a + rho), 0.0))
            k = (big_a - rho) / s
            km1 = -rho * (s + big_a - rho) / (s * (s + big_a))
            np_ = np.stack([_dot(n, e1), _dot(n, e2)], axis=-1)
            kappa = radius * np.linalg.norm(np_, axis=-1)
            h = _dot(n, c)
            whole = a * (-2 * np.pi * rho / (s * (s + big_a))) + gam * (2 * np.pi / s)
            whole_terms = np.abs(a * (2 * np.pi * rho / (s * (s + big_a)))) + np.abs(gam * (2 * np.pi / s))
            cb = np.clip(-h / kappa, -1.0, 1.0)
            sb = np.sqrt(np.maximum(1 - cb * cb, 0.0))
            nh = np_ / np.linalg.norm(np_, axis=-1, keepdims=True)
            nq = np.stack([-nh[:, 1], nh[:, 0]], axis=-1)
            u0 = cb[:, None] * nh - sb[:, None] * nq
            u1 = cb[:, None] * nh + sb[:, None] * nq
            x0, y0 = np.sum(u0 * g, axis=-1), np.sum(u0 * gp, axis=-1)
            x1, y1 = np.sum(u1 * g, axis=-1), np.sum(u1 * gp, axis=-1)
            t0, t1 = disk_atan2(y0, x0), disk_atan2(y1, x1)
            wraps = t1 < t0
            dt = t1 - t0 + np.where(wraps, 2 * np.pi, 0.0)
            big_j = (2 / s) * (disk_atan2(k * y1, 1 + x1) - disk_atan2(k * y0, 1 + x0) + np.where(wraps, np.pi, 0.0))
            scale = -(s + big_a - rho) / (s * (s + big_a))
            d1 = disk_angle_over(km1 * (1 + x1) * y1, (1 + x1) ** 2 + k * y1 * y1) * scale * (1 + x1) * y1
            d0 = disk_angle_over(km1 * (1 + x0) * y0, (1 + x0) ** 2 + k * y0 * y0) * scale * (1 + x0) * y0
            big_k = -dt * rho / (s * (s + big_a)) - (2 * big_a / s) * (d1 - d0)
            w = (x1 - x0) / (big_a + rho * x0)
            big_l = -w * disk_log1p_over(rho * w)
            reached = h > -kappa
            arc = np.where(reached, a * big_k + b * big_l + gam * big_j, 0.0)
            arc_terms = np.abs(a * big_k) + np.abs(b * big_l) + np.abs(gam * big_j) + np.abs(a * dt * rho / (s * (s + big_a)))
            p0 = c + radius * (u0[:, :1] * e1 + u0[:, 1:] * e2)
            p1 = c + radius * (u1[:, :1] * e1 + u1[:, 1:] * e2)
            m = np.cross(p1, p0 - p1)
            lm = np.linalg.norm(m, axis=-1)
            chord = np.where(reached & (lm > 0), area_angle(lm, _dot(p1, p0)) * (_dot(n, m) / lm), 0.0)
            total = np.where(h >= kappa, whole, arc + chord)
            terms = np.where(h >= kappa, whole_terms, np.where(reached, arc_terms + np.abs(chord), 0.0))
        front = _dot(x - p.center, big_n) > 0
        return front, np.nan_to_num(np.maximum(-0.5 * total, 0.0)), np.nan_to_num(0.5 * terms)

    def irradiance(self, x, n, p):
        front, value, _ = self._rim(x, n, p)
        return np.where(front[:, None], p.radiance * value[:, None], 0.0)

    def irradiance_band(self, x, n, p, constants):
        """The generic sensitivity band plus ``32 eps`` of the magnitudes of the contour integral's terms."""
        low, high = super().irradiance_band(x, n, p, constants)
        front, _, terms = self._rim(x, n, p)
        slack = p.radiance * np.where(front, 32 * EPS * terms, 0.0)[:, None]
        return np.maximum(low - slack, 0.0), high + slack

    def sample(self, x, n, k, p):
        m = int(p.samples)
        a, b = k // m, k - (k // m) * m
        big_n = p.normal / np.linalg.norm(p.normal)
        e1, e2 = perpendiculars(big_n)
        r = p.radius * np.sqrt((a + 0.5) / m)
        phi = 2 * np.pi * (b + 0.5) / m
        y = (p.center - x) + r * (np.cos(phi) * e1 + np.sin(phi) * e2)
        valid, wi, d = safe_normalize(y)
        cos_l = -_dot(big_n, wi)
        with np.errstate(divide="ignore", invalid="ignore"):
            irradiance = p.radiance * (((cos_l * (np.pi * p.radius * p.radius / (m * m))) / d) / d)[:, None]
        return valid & (k < m * m) & (cos_l > 0), wi, irradiance

    def exact(self, x, n, p, integrand, clip=()):
        return disk_integral(x, n, np.asarray(p.center, np.float64), np.asarray(p.normal, np.float64), float(p.radius),
                             p.radiance, integrand, clip=clip)

    @classmethod
    def stability_cases(cls):
        up = (0.0, 0.0, 1.0)
        overhead = cls((0.0, 0.0, 1.0), (0.0, 0.0, -1.0), 0.5, 2.0)
        return extended_cases("disk", (
            ("overhead", overhead, up),
            ("on its axis, tilted", cls((0.0, 0.0, 1.0), (0.3, 0.0, -1.0), 0.5, 2.0), up),
            ("straddling the horizon", overhead, (np.sin(1.3), 0.0, np.cos(1.3))),
            ("touching the surface (its rim on the plane)", cls((0.0, 0.6, 0.5), (0.0, -1.0, 0.0), 0.5, 2.0), up),
            ("edge-on (the point in its plane)", cls((2.0, 0.0, 0.0), (0.0, 0.0, 1.0), 0.5, 2.0), up)))
