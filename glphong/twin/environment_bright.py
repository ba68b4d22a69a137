"""The bright blocks of an environment map (docs/design.md section 13): a small bright source (a sun) taken out of the
map and integrated apart, the twin's side of ``glsl/lights/environment.glsl``'s ``ENVIRONMENT_BRIGHT`` functions.

The map is split exactly, texel by texel and channel by channel, at a threshold ``T`` [W/(m^2 sr)]::

    L = min(L, T) + max(L - T, 0)

The residual ``min(L, T)`` goes to the irradiance cube map and the harmonics as the whole map did; the excess
``max(L - T, 0)`` (non-zero on the texels above ``T``, the bright texels) is cut into at most ``K`` blocks
(`bright_blocks`): each bright texel split into ``2^l x 2^l`` equal lat-long rectangles while they fit in ``K`` and
are wider than `SMALLEST` in ``theta``, or, where the bright texels are more than ``K``, the map's ``2^m x 2^m``
tiles that hold them.  A block ``b`` carries, from the exact per-rectangle integrals of
`glphong.twin.environment` (its moments ``M = integral w dw`` and solid angles):

- ``moment[b, c] = sum_t X_tc M_t`` (C, 3), the exact first moment of channel ``c`` of its excess ``X``: where the
  whole block is above a surface's horizon its irradiance is exactly ``n . moment``;
- ``length[b, c] = |moment[b, c]|``, ``power[b, c] = sum_t X_tc Omega_t`` [W/m^2];
- ``direction[b]``, the unit vector of ``sum_c moment[b, c]`` (its centroid), and ``radius[b] = sqrt(Omega_b / pi)``
  [rad], the radius of the flat disc of its solid angle (bright texels only).

The shader integrates each block as that disc about its centroid (`environment_segment`, the part above the horizon
a chord of the disc): Lambert ``max(n . moment + length (e - c), 0)`` with ``c = n . direction``, exactly ``n .
moment`` where the disc is wholly above (``c >= radius``, ``e = c``) and ``~0`` where wholly below (``e = 0``); the
Phong lobe by the midpoint rule, ``power max(r . direction, 0)^q f`` with ``f`` the disc's part above the horizon
(relative error about ``q h^2 / 12`` at the lobe's peak for a block ``h`` rad wide: 1.3e-3 for ``q = 100`` and a
texel of a 256 x 512 map).
"""
import numpy as np

from glphong.twin.environment import _moment, _solid_angle, texel_edges, texel_solid_angles
from glphong.twin.functions import atan2_first_quadrant

__all__ = ["SMALLEST", "BRIGHT_FACTOR", "BRIGHT_SOLID_ANGLE", "bright_threshold", "bright_blocks",
           "environment_segment", "environment_bright_irradiance", "environment_bright_peak", "environment_bright_lobe"]

#: a block narrower than this in ``theta`` [rad] is not split further (the midpoint rule's error about 1e-4 of the
#: lobe's peak at ``q = 100``)
SMALLEST = 0.004
#: the automatic threshold: this many times the map's median radiance (by solid angle) ...
BRIGHT_FACTOR = 8.0
#: ... raised where needed so that the texels above it cover at most this solid angle [sr] (a cap of 16 degrees)
BRIGHT_SOLID_ANGLE = 0.25


def bright_threshold(radiance, factor=BRIGHT_FACTOR, solid_angle=BRIGHT_SOLID_ANGLE):
    """The automatic threshold ``T`` [W/(m^2 sr)] of a map (H, W, C): ``factor`` times the median over the sphere
    (by solid angle) of each texel's largest channel, or, where the texels above that cover more than
    ``solid_angle`` sr, the smallest radiance above which they cover at most that (the brightest part of a large
    bright region is then extracted, the rest stays in the residual)."""
    values = np.asarray(radiance, dtype=np.float64)
    peak = values.reshape(values.shape[0], values.shape[1], -1).max(axis=-1).reshape(-1)
    omega = texel_solid_angles(values.shape[0], values.shape[1]).reshape(-1)
    order = np.argsort(peak, kind="stable")
    cumulative = np.cumsum(omega[order])
    median = peak[order][np.searchsorted(cumulative, 0.5 * cumulative[-1])]
    threshold = factor * median
    above = cumulative[-1] - cumulative                     # solid angle strictly after each sorted texel
    fits = np.flatnonzero(above <= solid_angle)
    return float(max(threshold, peak[order][fits[0]]))


def bright_blocks(radiance, threshold, count):
    """The split of a map (H, W, C) at ``threshold``: ``(residual (H, W, C), blocks)``, ``blocks`` a dict of
    ``moment`` (K, C, 3), ``length`` (K, C), ``power`` (K, C), ``direction`` (K, 3), ``radius`` (K,), K <= ``count``
    (module docstring; map coordinates), and their cap: ``total`` (C, 3) the sum of the moments, ``center`` (3,) its
    direction, ``cap`` ``(cos rho, sin rho, rho)`` with ``rho`` the largest angle from ``center`` to a block's
    centroid plus ``asin`` of its radius (a hair more: every disc's edge within it; ``sin rho`` 2 where ``rho > pi/2``,
    a cap no horizon leaves wholly on one side), and ``count`` K.  No texel above
    ``threshold``, or ``count`` 0: the map itself and K = 0."""
    values = np.asarray(radiance, dtype=np.float64)
    H, W, C = values.shape
    excess = np.maximum(values - threshold, 0.0)
    bright = np.any(excess > 0.0, axis=-1)
    rows, cols = np.nonzero(bright)
    if count < 1 or len(rows) == 0:
        empty = np.zeros((0, C))
        return values, {"moment": np.zeros((0, C, 3)), "length": empty, "power": empty, "direction": np.zeros((0, 3)),
                        "radius": np.zeros(0), "total": np.zeros((C, 3)), "center": np.array([0.0, 0.0, 1.0]),
                        "cap": np.array([1.0, 0.0, 0.0]), "count": 0}
    theta, phi = texel_edges(H, W)
    if len(rows) <= count:              # split each bright texel while the pieces fit and are wide
        level = 0
        while len(rows) * 4 ** (level + 1) <= count and np.pi / H / 2 ** (level + 1) >= SMALLEST:
            level += 1
        k = 2 ** level
        a, b = np.meshgrid(np.arange(k), np.arange(k), indexing="ij")
        a, b = a.reshape(-1), b.reshape(-1)
        t0 = theta[rows][:, None] + (theta[rows + 1] - theta[rows])[:, None] * a / k
        t1 = theta[rows][:, None] + (theta[rows + 1] - theta[rows])[:, None] * (a + 1) / k
        p0 = phi[cols][:, None] + (phi[cols + 1] - phi[cols])[:, None] * b / k
        p1 = phi[cols][:, None] + (phi[cols + 1] - phi[cols])[:, None] * (b + 1) / k
        owner = np.arange(len(rows) * k * k)
        source = np.repeat(np.arange(len(rows)), k * k)
        t0, t1, p0, p1 = (x.reshape(-1) for x in (t0, t1, p0, p1))
    else:                               # merge them into the map's tiles of 2^m x 2^m texels
        m = 1
        while True:
            tiles, owner = np.unique((rows >> m) * W + (cols >> m), return_inverse=True)
            if len(tiles) <= count:
                break
            m += 1
        owner = owner.reshape(-1)
        source = np.arange(len(rows))
        t0, t1, p0, p1 = theta[rows], theta[rows + 1], phi[cols], phi[cols + 1]
    blocks = int(owner.max()) + 1
    x = excess[rows[source], cols[source]]                          # (P, C)
    moment = _moment(t0, t1, p0, p1)                                # (P, 3)
    omega = _solid_angle(t0, t1, p0, p1)                            # (P,)
    out = {"moment": np.zeros((blocks, C, 3)), "power": np.zeros((blocks, C)), "radius": np.zeros(blocks)}
    np.add.at(out["moment"], owner, x[:, :, None] * moment[:, None, :])
    np.add.at(out["power"], owner, x * omega[:, None])
    np.add.at(out["radius"], owner, omega)
    out["radius"] = np.sqrt(out["radius"] / np.pi)
    out["length"] = np.linalg.norm(out["moment"], axis=-1)
    out["direction"] = _unit(out["moment"].sum(axis=1))
    out["total"] = out["moment"].sum(axis=0)                        # (C, 3)
    out["center"] = _unit(out["total"].sum(axis=0))
    spread = np.arccos(np.clip(out["direction"] @ out["center"], -1.0, 1.0))
    rho = min(np.pi, float(np.max(spread + np.arcsin(np.minimum(out["radius"], 1.0)))) * (1 + 1e-5) + 1e-5)
    out["cap"] = np.array([np.cos(rho), np.sin(rho) if rho <= np.pi / 2 else 2.0, rho])   # 2: no horizon clears it
    out["count"] = blocks
    return np.minimum(values, threshold), out


def _unit(v):
    """``v / |v|`` along the last axis, +z where ``v`` is 0 (a block whose moments cancel: it has no direction)."""
    length = np.linalg.norm(v, axis=-1, keepdims=True)
    return np.where(length > 0.0, v / np.where(length > 0.0, length, 1.0), np.array([0.0, 0.0, 1.0]))


def environment_segment(c, a):
    """The part of a flat disc of radius ``a`` [rad] above a chord at signed distance ``c`` from its centre (``c > 0``:
    the centre above), (N,) each: ``t = clamp(c/a, -1, 1)``, ``u = sqrt(1 - t^2)``, ``f = (acos(-t) + t u)/pi`` (its
    area's part) and ``e = c f + (2/3) a u^3 / pi`` (``integral (c + y) dA / (pi a^2)`` over the part, ``y`` across the
    chord: the cosine-weighted part, ``c`` above the chord and 0 below), ``acos`` by `atan2_first_quadrant`
    (environment.glsl)."""
    t = np.clip(c / a, -1.0, 1.0)
    u = np.sqrt(np.maximum(1.0 - t * t, 0.0))
    angle = atan2_first_quadrant(u, np.abs(t))
    above = np.where(t >= 0.0, np.pi - angle, angle)
    f = (above + t * u) * (1.0 / np.pi)
    return f, c * f + (2.0 / (3.0 * np.pi)) * a * u * u * u


def environment_bright_irradiance(n, blocks):
    """Lambert's part of the blocks, (N, C), as environment.glsl computes it: ``n . total`` where the horizon of ``n``
    leaves the blocks' cap wholly above it (``n . center >= sin rho``), 0 where wholly below, else ``sum_b max(n .
    moment_b + length_b (e_b - c_b), 0)``, ``c_b = n . direction_b`` (`environment_segment`).  ``blocks``: the arrays
    of `bright_blocks` as the uniforms hold them.  Also returns the size of the terms, ``|n| |total|`` or ``sum_b
    (|moment_b| + length_b |e_b - c_b|)`` (N, C), for the band."""
    c_all = n @ blocks["center"]
    reach = blocks["cap"][1]
    above = c_all >= reach
    crossed = ~above & (c_all > -reach)
    total = blocks["total"]
    out = np.where(above[:, None], n @ total.T, 0.0)
    size = np.where(above[:, None], np.linalg.norm(total, axis=-1)[None, :], 0.0)
    for b in range(int(blocks["count"])):
        c = n[crossed] @ blocks["direction"][b]
        _, e = environment_segment(c, blocks["radius"][b])
        length = blocks["length"][b][None, :]
        out[crossed] += np.maximum(n[crossed] @ blocks["moment"][b].T + length * (e - c)[:, None], 0.0)
        size[crossed] += length * (1.0 + np.abs(e - c))[:, None]
    return out, size


def environment_bright_peak(r, q, power, direction):
    """``power max(r . direction, 0)^q`` of one block, (N, C), as ``exp(max(q log(x), -104))`` (0 where ``x = r .
    direction <= 0``), and ``log x`` (N,) (0 there) for the band (environment.glsl)."""
    x = r @ direction
    with np.errstate(divide="ignore"):
        log_x = np.log(np.where(x > 0.0, x, 1.0))
    return power[None, :] * np.where(x > 0.0, np.exp(np.maximum(q * log_x, -104.0)), 0.0)[:, None], log_x


def environment_bright_lobe(n, r, q, blocks):
    """The Phong lobe's part of the blocks, (N, C), as environment.glsl computes it: ``sum_b power_b max(r .
    direction_b, 0)^q f_b``, the power as ``exp(max(q log(x), -104))`` (0 where ``x <= 0``), ``f_b`` the part of the
    block's disc above the horizon of ``n`` (`environment_segment`; 1 where the blocks' cap is wholly above it, 0
    where wholly below), 0 where ``r`` is further than ``rho`` from the cap's centre and ``cos(angle - rho)^q < 1e-8``.
    Also returns each term times ``1 + q (1 + |log x|)`` summed (N, C), for the band (the power's rounding: ``x``'s
    and ``log``'s absolute error of a few ulps of 1 and ``exp``'s of its argument ``q log x``, each times ``q``)."""
    cos_rho, sin_rho, _ = blocks["cap"]
    c_all = n @ blocks["center"]
    cr = r @ blocks["center"]
    nearest = cr * cos_rho + np.sqrt(np.maximum(1.0 - cr * cr, 0.0)) * sin_rho
    with np.errstate(divide="ignore", invalid="ignore"):
        reached = (cr >= cos_rho) | ((nearest > 0.0) & (q * np.log(np.where(nearest > 0.0, nearest, 1.0))
                                                         > -18.420680743952367))
    plain = reached & (c_all >= sin_rho)
    clipped = reached & (c_all < sin_rho) & (c_all > -sin_rho)
    out = np.zeros((len(n), blocks["power"].shape[1]))
    size = np.zeros_like(out)
    for b in range(int(blocks["count"])):
        f, _ = environment_segment(n @ blocks["direction"][b], blocks["radius"][b])
        peak, log_x = environment_bright_peak(r, q, blocks["power"][b], blocks["direction"][b])
        term = peak * np.where(plain, 1.0, np.where(clipped, f, 0.0))[:, None]
        out += term
        size += term * (1.0 + q * (1.0 + np.abs(log_x)))[:, None]
    return out, size
