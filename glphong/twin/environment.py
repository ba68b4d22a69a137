"""The float64 integrals of an equirectangular radiance map (docs/design.md section 13): the twin's side of the
lecture's continuous version for an environment light, exact per texel.

Layout: a map of ``H x W`` texels, row ``i`` covering the polar angle ``theta`` in ``[pi i / H, pi (i + 1) / H]``
from +z (row 0 at the zenith), column ``j`` the azimuth ``phi`` in ``[2 pi j / W, 2 pi (j + 1) / W]`` from +x toward
+y; the direction is ``w = (sin theta cos phi, sin theta sin phi, cos theta)``.  Each texel is a constant radiance
``L_k`` [W/(m^2 sr)] over its exact solid angle.

- `texel_solid_angles`: ``Omega = (phi1 - phi0)(cos theta0 - cos theta1)``.
- `texel_moments`: ``M = integral w dw`` = ``((sin phi1 - sin phi0) T, (cos phi0 - cos phi1) T, (phi1 - phi0) S)`` with
  ``T = [theta/2 - sin(2 theta)/4]`` and ``S = [sin^2(theta)/2]`` between ``theta0`` and ``theta1``.
- `irradiance`: ``E(n) = sum_k L_k integral_texel (n.w)^+ dw``.  A texel wholly above the surface's horizon
  contributes ``L_k (n . M_k)`` exactly; one wholly below, 0.  A texel whose angular radius ``r`` (a bound on how far
  its points are from its centre) does not decide it (``|n . w_centre| <= r``) is split into 2 x 2 sub-texels, to
  ``depth`` levels; a sub-texel still undecided then contributes ``L_k max(n . M, 0)``, off by at most
  ``2 L_k Omega r`` (``n . w`` lies within ``2r`` of 0 over it; returned summed as the error bound).
"""
import numpy as np

__all__ = ["texel_edges", "texel_solid_angles", "texel_moments", "texel_directions", "irradiance"]


def texel_edges(height, width):
    """``(theta edges (H + 1,), phi edges (W + 1,))`` [rad]."""
    return np.linspace(0.0, np.pi, height + 1), np.linspace(0.0, 2.0 * np.pi, width + 1)


def _solid_angle(t0, t1, p0, p1):
    return (p1 - p0) * (np.cos(t0) - np.cos(t1))


def _moment(t0, t1, p0, p1):
    t_term = (t1 / 2 - np.sin(2 * t1) / 4) - (t0 / 2 - np.sin(2 * t0) / 4)
    s_term = (np.sin(t1) ** 2 - np.sin(t0) ** 2) / 2
    return np.stack(np.broadcast_arrays((np.sin(p1) - np.sin(p0)) * t_term, (np.cos(p0) - np.cos(p1)) * t_term,
                                        (p1 - p0) * s_term), axis=-1)


def _direction(theta, phi):
    return np.stack(np.broadcast_arrays(np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), np.cos(theta)), axis=-1)


def texel_solid_angles(height, width):
    """Each texel's exact solid angle [sr], (H, W) float64 (they sum to 4 pi)."""
    theta, phi = texel_edges(height, width)
    return _solid_angle(theta[:-1, None], theta[1:, None], phi[None, :-1], phi[None, 1:])


def texel_moments(height, width):
    """Each texel's exact moment ``integral w dw`` [sr], (H, W, 3) float64."""
    theta, phi = texel_edges(height, width)
    return _moment(theta[:-1, None], theta[1:, None], phi[None, :-1], phi[None, 1:])


def texel_directions(height, width):
    """Each texel centre's unit direction, (H, W, 3) float64."""
    theta, phi = texel_edges(height, width)
    return _direction(0.5 * (theta[:-1, None] + theta[1:, None]), 0.5 * (phi[None, :-1] + phi[None, 1:]))


def _radius(t0, t1, p0, p1):
    """A bound on the angle between a lat-long rectangle's centre and any of its points [rad]: half its polar extent
    plus half its azimuthal extent times the largest sine over it."""
    largest_sine = np.where((t0 <= np.pi / 2) & (t1 >= np.pi / 2), 1.0, np.maximum(np.sin(t0), np.sin(t1)))
    return 0.5 * (t1 - t0) + 0.5 * (p1 - p0) * largest_sine


def irradiance(radiance, normals, depth=6):
    """Irradiance ``E(n) = integral L(w) (n.w)^+ dw`` of an equirectangular map at unit normals, float64.

    Parameters
    ----------
    radiance : (H, W) or (H, W, 3) array_like
        Radiance per texel [W/(m^2 sr)] (module docstring for the layout).
    normals : (N, 3) array_like
        Unit normals.
    depth : int
        Levels of 2 x 2 splitting of the texels the horizon crosses.

    Returns
    -------
    E : (N,) or (N, 3) float64 ndarray
        [W/m^2].
    bound : (N,) or (N, 3) float64 ndarray
        A bound on ``|E - exact|`` (texels still crossed by the horizon after ``depth`` splits).
    """
    radiance = np.asarray(radiance, dtype=np.float64)
    grey = radiance.ndim == 2
    values = radiance[..., None] if grey else radiance
    height, width = values.shape[:2]
    normals = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    theta, phi = texel_edges(height, width)
    t0, t1 = np.repeat(theta[:-1], width), np.repeat(theta[1:], width)
    p0, p1 = np.tile(phi[:-1], height), np.tile(phi[1:], height)
    flat = values.reshape(-1, values.shape[-1])
    moments = _moment(t0, t1, p0, p1)
    centres = _direction(0.5 * (t0 + t1), 0.5 * (p0 + p1))
    radius = _radius(t0, t1, p0, p1)
    out = np.zeros((len(normals), flat.shape[1]))
    bound = np.zeros_like(out)
    for a in range(0, len(normals), 256):  # chunks of normals x every texel
        n = normals[a:a + 256]
        c = n @ centres.T
        out[a:a + 256] = np.where(c > radius, n @ moments.T, 0.0) @ flat
        rows, texels = np.nonzero(np.abs(c) <= radius)
        e, b = _split(n[rows], t0[texels], t1[texels], p0[texels], p1[texels], depth)
        np.add.at(out, a + rows, e[:, None] * flat[texels])
        np.add.at(bound, a + rows, b[:, None] * np.abs(flat[texels]))
    return (out[:, 0], bound[:, 0]) if grey else (out, bound)


def _split(n, t0, t1, p0, p1, depth):
    """``(integral (n.w)^+ dw, error bound)`` over lat-long rectangles (each with its own normal ``n``, (K, 3)),
    splitting, level by level, the sub-rectangles the horizon still crosses."""
    total, bound = np.zeros(len(n)), np.zeros(len(n))
    owner = np.arange(len(n))
    for _ in range(depth):
        tm, pm = 0.5 * (t0 + t1), 0.5 * (p0 + p1)
        t0, t1 = np.concatenate([t0, t0, tm, tm]), np.concatenate([tm, tm, t1, t1])
        p0, p1 = np.concatenate([p0, pm, p0, pm]), np.concatenate([pm, p1, pm, p1])
        owner, n = np.tile(owner, 4), np.tile(n, (4, 1))
        centre = np.sum(n * _direction(0.5 * (t0 + t1), 0.5 * (p0 + p1)), axis=1)
        r = _radius(t0, t1, p0, p1)
        above = centre > r
        np.add.at(total, owner[above], np.sum(n[above] * _moment(t0[above], t1[above], p0[above], p1[above]), axis=1))
        keep = np.abs(centre) <= r
        t0, t1, p0, p1, owner, n = t0[keep], t1[keep], p0[keep], p1[keep], owner[keep], n[keep]
    np.add.at(total, owner, np.maximum(np.sum(n * _moment(t0, t1, p0, p1), axis=1), 0.0))
    np.add.at(bound, owner, 2.0 * _solid_angle(t0, t1, p0, p1) * _radius(t0, t1, p0, p1))
    return total, bound
