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
  contributes ``L_k (n . M_k)`` exactly (each row's such texels are one run of columns, summed from prefix sums); one
  wholly below, 0.  A texel the horizon crosses is integrated over its part above it: in closed form in ``theta``, by
  Gauss-Legendre in ``phi`` on the pieces over which that is smooth.
"""
import numpy as np

from glphong.twin.functions import atan2_first_quadrant

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


def irradiance(radiance, normals, nodes=12, rtol=1e-12, crossed="quadrature"):
    """Irradiance ``E(n) = integral L(w) (n.w)^+ dw`` of an equirectangular map at unit normals, float64.

    A texel wholly above the horizon contributes ``L_k (n . M_k)`` exactly, one wholly below nothing.  A texel the
    horizon crosses is integrated in ``theta`` in closed form over the part above it, ``n_z [sin^2/2] + s(phi)
    [theta/2 - sin(2 theta)/4]`` with ``s = n_x cos(phi) + n_y sin(phi)`` between the clipped ends, and in ``phi`` by
    Gauss-Legendre on the pieces between the azimuths where the horizon crosses the texel's ``theta`` edges (``s(phi)
    = -n_z cot(theta_edge)``), over which the integrand is smooth: ``nodes`` points against ``nodes / 2``, doubled
    where they differ by more than ``rtol`` times the texel's solid angle (a horizon passing near a pole of a coarse
    map is sharp in ``phi``), to 16 times ``nodes``.  The texels wholly above the horizon are summed per row from
    prefix sums of ``L_k M_k`` (they are a run of each row), so a normal costs the rows and the crossed texels, not
    every texel.

    Parameters
    ----------
    radiance : (H, W) or (H, W, 3) array_like
        Radiance per texel [W/(m^2 sr)] (module docstring for the layout).
    normals : (N, 3) array_like
        Unit normals.
    nodes : int
        Gauss-Legendre points per piece of a texel the horizon crosses, at first.
    rtol : float
        The difference between two rules, relative to a crossed texel's solid angle (the most its integral can be),
        at which the doubling stops.
    crossed : {'quadrature', 'closed'}
        How the crossed texels are integrated: by the Gauss-Legendre rule above (what the irradiance cube map's
        texels hold), or in closed form (`_crossed_closed`, Stokes: no quadrature, about ten times faster; the rule
        where it is ill-conditioned), what `glphong.lights.EnvironmentLight`'s exact reference uses.  The two agree
        to about 1e-12 of the crossed texels' solid angles (tests/lights/test_environment_verify_speed.py).

    Returns
    -------
    E : (N,) or (N, 3) float64 ndarray
        [W/m^2].
    bound : (N,) or (N, 3) float64 ndarray
        The error estimate (the difference of the two rules, summed over the crossed texels, times their radiance;
        with ``crossed='closed'``, `_closed_bound` where the closed form is used).
    """
    radiance = np.asarray(radiance, dtype=np.float64)
    grey = radiance.ndim == 2
    values = radiance[..., None] if grey else radiance
    H, W = values.shape[:2]
    channels = values.shape[-1]
    if crossed not in ("quadrature", "closed"):
        raise ValueError(f"crossed must be 'quadrature' or 'closed' (got {crossed!r})")
    normals = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    theta, phi = texel_edges(H, W)
    # per row, the prefix sums of L_k M_k along phi (the rows' texels wholly above a horizon are a run of them)
    weighted = (_moment(theta[:-1, None], theta[1:, None], phi[None, :-1], phi[None, 1:])[..., :, None]
                * values[:, :, None, :]).reshape(H, W, 3 * channels)
    prefix = np.concatenate([np.zeros((H, 1, 3 * channels)), np.cumsum(weighted, axis=1)], axis=1)
    flat = values.reshape(-1, channels)
    with np.errstate(divide="ignore", invalid="ignore"):
        cot = np.cos(theta) / np.sin(theta)
    cot[0], cot[-1] = np.inf, -np.inf
    # the distinct normals only (a flat face's pixels share theirs); each normal's sums do not depend on the others
    unique, inverse = np.unique(normals, axis=0, return_inverse=True)
    out = np.zeros((len(unique), channels))
    bound = np.zeros_like(out)
    step = max(1, min(4096, _ROW_BUDGET // H))          # normals a chunk: (step, H) runs, bounded memory
    for a in range(0, len(unique), step):
        n = unique[a:a + step]
        above, below = _row_runs(n, cot, W)
        out[a:a + step] = _run_sums(n, prefix, above, W, channels)
        k, row, col = _crossed_texels(above, below, W)
        for b in range(0, len(k), _CROSSED_BUDGET):        # the crossed texels in bounded batches, in (k, row, col) order
            kb, rb, cb = k[b:b + _CROSSED_BUDGET], row[b:b + _CROSSED_BUDGET], col[b:b + _CROSSED_BUDGET]
            args = (n[kb], theta[rb], theta[rb + 1], phi[cb], phi[cb + 1])
            if crossed == "closed":
                e, ok = _crossed_closed(*args)
                err = _closed_bound(*args)
                if not ok.all():
                    e[~ok], err[~ok] = _crossed(*(x[~ok] for x in args), nodes, rtol)
            else:
                e, err = _crossed(*args, nodes, rtol)
            texel = rb * W + cb
            np.add.at(out, a + kb, e[:, None] * flat[texel])
            np.add.at(bound, a + kb, err[:, None] * np.abs(flat[texel]))
    out, bound = out[inverse.reshape(-1)], bound[inverse.reshape(-1)]
    return (out[:, 0], bound[:, 0]) if grey else (out, bound)


#: rows x normals a chunk of `irradiance` holds its runs for, and crossed texels it integrates at once
_ROW_BUDGET = 262_144
_CROSSED_BUDGET = 65_536


def _row_runs(n, cot, W):
    """For each normal (K, 3) and row, the run of texels wholly above the horizon and the run wholly below, each
    ``(first, count)`` (K, H) int on the circle of ``W`` columns.  ``n.w = n_z cos(theta) + rho sin(theta) cos(phi -
    beta)`` is positive over a row's texel iff it is at both of the row's edges (over less than pi in theta a
    sinusoid positive at both ends is positive between), i.e. iff ``cos(phi - beta) > max_edges(-n_z cot(theta))/rho``
    over the texel: an arc about ``beta``; below, likewise, an arc about ``beta + pi``.  Undecided comparisons (a
    pole's 0 * inf) count as neither: such texels are integrated as crossed ones, which is exact for any texel."""
    rho, beta, nz = np.hypot(n[:, 0], n[:, 1]), np.arctan2(n[:, 1], n[:, 0]), n[:, 2]
    with np.errstate(divide="ignore", invalid="ignore"):
        edge = -nz[:, None, None] * np.stack([cot[:-1], cot[1:]], axis=-1)[None]          # (K, H, 2)
        high = np.max(edge, axis=-1) / rho[:, None]
        low = np.min(edge, axis=-1) / rho[:, None]
    high = np.where(np.isnan(high), np.inf, high)
    low = np.where(np.isnan(low), -np.inf, low)
    step = 2 * np.pi / W
    runs = []
    for centre, half, full, none in ((beta[:, None], np.arccos(np.clip(high, -1.0, 1.0)), high < -1.0, high >= 1.0),
                                     (beta[:, None] + np.pi, np.pi - np.arccos(np.clip(low, -1.0, 1.0)), low > 1.0,
                                      low <= -1.0)):
        first = np.floor((centre - half) / step).astype(np.int64) + 1
        last = np.ceil((centre + half) / step).astype(np.int64) - 2
        count = np.clip(last - first + 1, 0, W)
        count = np.where(full, W, np.where(none, 0, count))
        runs.append((np.mod(np.where(full, 0, first), W), count))
    return runs


def _run_sums(n, prefix, above, W, channels):
    """``n . sum L_k M_k`` over each normal's runs of wholly lit texels, (K, C)."""
    first, count = above
    rows = np.arange(prefix.shape[0])[None, :]
    end = first + count
    inside = np.minimum(end, W)
    total = prefix[rows, inside] - prefix[rows, first] + np.where((end > W)[..., None],
                                                                  prefix[rows, np.maximum(end - W, 0)], 0.0)
    total = total.sum(axis=1).reshape(len(n), 3, channels)                                   # (K, 3, C)
    return np.einsum("kd,kdc->kc", n, total)


def _crossed_texels(above, below, W):
    """``(normal, row, column)`` of every texel in neither run, sorted by normal, row and column (as ``np.nonzero``
    of the ``(K, H, W)`` masks would give them, without those masks): the candidates are the (at most two) arcs of a
    row between its runs, each column then tested against both runs as the masks would be."""
    (lit_first, lit_count), (dark_first, dark_count) = above, below
    lit_end, dark_end = lit_first + lit_count, dark_first + dark_count
    both = (lit_count > 0) & (dark_count > 0)
    # the gaps: after the lit run up to the dark one and after the dark run up to the lit one; with a run missing,
    # the rest of the row after the other; with both missing, the whole row
    start_a = np.where(lit_count > 0, lit_end, np.where(dark_count > 0, dark_end, 0))
    length_a = np.where(both, np.mod(dark_first - lit_end, W), W - lit_count - dark_count)
    start_b, length_b = dark_end, np.where(both, np.mod(lit_first - dark_end, W), 0)
    length_a, length_b = np.clip(length_a, 0, W), np.clip(length_b, 0, W - length_a)
    k, row = np.nonzero(np.ones(lit_first.shape, bool))
    starts = np.concatenate([start_a.reshape(-1), start_b.reshape(-1)])
    lengths = np.concatenate([length_a.reshape(-1), length_b.reshape(-1)])
    owner = np.concatenate([np.arange(k.size)] * 2)
    total = int(lengths.sum())
    if total == 0:
        empty = np.zeros(0, np.int64)
        return empty, empty, empty
    which = np.repeat(np.arange(len(lengths)), lengths)
    offset = np.arange(total) - np.repeat(np.cumsum(lengths) - lengths, lengths)
    col = np.mod(starts[which] + offset, W)
    cell = owner[which]
    lit = np.mod(col - lit_first.reshape(-1)[cell], W) < lit_count.reshape(-1)[cell]
    dark = np.mod(col - dark_first.reshape(-1)[cell], W) < dark_count.reshape(-1)[cell]
    keep = ~(lit | dark)
    key = np.sort(cell[keep] * W + col[keep], kind="stable")   # by (normal, row), then column (radix: the fastest)
    key = key[np.concatenate([[True], key[1:] != key[:-1]])]     # no repeats (np.unique's hashing is 10x slower)
    cell = key // W
    return k[cell], row[cell], key % W


def _crossed(n, t0, t1, p0, p1, nodes, rtol):
    """``(integral (n.w)^+ dw, error estimate)`` over lat-long rectangles the horizon crosses (each with its own
    normal ``n``, (K, 3)): closed form in ``theta``, Gauss-Legendre in ``phi`` on smooth pieces."""
    rho, beta = np.hypot(n[:, 0], n[:, 1]), np.arctan2(n[:, 1], n[:, 0])
    cuts = []
    for edge in (t0, t1):
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = -n[:, 2] * np.cos(edge) / (np.sin(edge) * rho)
        ok = (np.sin(edge) > 1e-12) & (rho > 0) & (np.abs(ratio) < 1)
        delta = np.arccos(np.clip(np.nan_to_num(ratio), -1.0, 1.0))
        cuts += [np.where(ok, np.mod(beta + sign * delta, 2 * np.pi), np.nan) for sign in (1.0, -1.0)]
    cuts = np.stack(cuts, axis=1)
    cuts = np.sort(np.where((cuts > p0[:, None]) & (cuts < p1[:, None]), cuts, p1[:, None]), axis=1)
    edges = np.concatenate([p0[:, None], cuts, p1[:, None]], axis=1)

    def rule(count, k):
        x, w = np.polynomial.legendre.leggauss(count)
        a, b = edges[k, :-1, None], edges[k, 1:, None]
        f = a + (b - a) * 0.5 * (x + 1.0)                                  # (K, pieces, count)
        s = n[k, 0, None, None] * np.cos(f) + n[k, 1, None, None] * np.sin(f)
        alpha = np.arctan2(s, np.broadcast_to(n[k, 2, None, None], s.shape))
        low, high = alpha - np.pi / 2, alpha + np.pi / 2
        wrap = high < 0
        low, high = np.where(wrap, low + 2 * np.pi, low), np.where(wrap, high + 2 * np.pi, high)
        lo = np.maximum(t0[k, None, None], low)
        hi = np.maximum(np.minimum(t1[k, None, None], high), lo)
        inner = n[k, 2, None, None] * (np.sin(hi) ** 2 - np.sin(lo) ** 2) / 2 + s * (
            (hi - lo) / 2 - (np.sin(2 * hi) - np.sin(2 * lo)) / 4)
        return np.sum(inner * (b - a) * 0.5 * w, axis=(1, 2))

    everything = np.arange(len(n))
    tolerance = rtol * _solid_angle(t0, t1, p0, p1)   # of the largest the texel's integral can be
    coarse = rule(max(nodes // 2, 2), everything)
    value = rule(nodes, everything)
    bound = np.abs(value - coarse)
    left = everything[bound > tolerance]
    count = nodes
    while len(left) and count < 16 * nodes:  # double the rule where two disagree
        count *= 2
        finer = rule(count, left)
        bound[left] = np.abs(finer - value[left])
        value[left] = finer
        left = left[bound[left] > tolerance[left]]
    return value, bound


def _closed_bound(n, t0, t1, p0, p1):
    """A bound of `_crossed_closed`'s rounding [sr]: ``512 eps (dtheta + dphi) (1 + 1/|nz| + 1/rho)`` (its terms are of
    the size of the texel's sides and cancel to its solid angle; a steep horizon, ``|nz|`` small, moves its points'
    ``theta`` by ``eps/|nz|``); measured at most a fifth of it against the rule on maps of 2 x 4 to 256 x 512."""
    with np.errstate(divide="ignore"):
        return 512 * np.finfo(np.float64).eps * ((t1 - t0) + (p1 - p0)) * (
            1.0 + 1.0 / np.abs(n[:, 2]) + 1.0 / np.hypot(n[:, 0], n[:, 1]))


def _crossed_closed(n, t0, t1, p0, p1, guard=1e-6):
    """``integral (n.w)^+ dw`` over lat-long rectangles the horizon crosses, in closed form (Stokes): ``integral_R w dw
    = (1/2) oint w x dw`` over the boundary of ``R`` = the rectangle's part above the horizon, so ``n . M_R`` is half
    the sum of ``n . integral w x dw`` along the rectangle's edges' parts above the horizon (a latitude arc at
    ``theta``, ``phi`` from ``a`` to ``b``: ``nz sin^2(theta) (b - a) - sin(theta) cos(theta) (nx (sin b - sin a) + ny
    (cos a - cos b))``; a meridian at ``phi``, ``theta`` from ``c`` to ``d``: ``(ny cos(phi) - nx sin(phi)) (d - c)``,
    each with the boundary's orientation) plus the length of the horizon inside the rectangle (along it ``w x dw =
    n dt``).  The horizon is the graph ``theta = atan2(|nz|, -sign(nz) rho cos(phi - beta))`` over ``phi``; inside the
    row where ``|phi - beta|`` is between the azimuths where it crosses the row's edges, which also bound the edges'
    parts above it.  Returns ``(value, ok)``: ``ok`` False where the formula is ill-conditioned (a normal within
    ``guard`` of the map's poles or of its equator's plane, or a rectangle edge within ``guard`` of a pole), for the
    caller to integrate those by `_crossed`."""
    nx, ny, nz = n[:, 0], n[:, 1], n[:, 2]
    rho, beta = np.hypot(nx, ny), np.mod(np.arctan2(ny, nx), 2 * np.pi)
    ok = (np.abs(nz) > guard) & (rho > guard)
    two_pi = 2 * np.pi
    copies = (-two_pi, 0.0, two_pi)
    delta = []
    for edge in (t0, t1):
        with np.errstate(divide="ignore", invalid="ignore"):
            h = -nz * np.cos(edge) / (np.sin(edge) * rho)
        delta.append(np.arccos(np.clip(np.nan_to_num(h, nan=0.0, posinf=2.0, neginf=-2.0), -1.0, 1.0)))

    def arc(theta, a, b):                     # n . integral w x dw along latitude theta, phi from a to b
        st, ct = np.sin(theta), np.cos(theta)
        return nz * st * st * (b - a) - st * ct * (nx * (np.sin(b) - np.sin(a)) + ny * (np.cos(a) - np.cos(b)))

    total = np.zeros(len(n))
    for sign, theta, d in ((1.0, t1, delta[1]), (-1.0, t0, delta[0])):      # bottom edge phi up, top edge phi down
        for c in copies:
            a, b = np.maximum(p0, beta + c - d), np.minimum(p1, beta + c + d)
            total += sign * np.where(b > a, arc(theta, a, np.maximum(a, b)), 0.0)
    for sign, phi in ((1.0, p0), (-1.0, p1)):                             # left meridian theta down, right up
        s = nx * np.cos(phi) + ny * np.sin(phi)
        alpha = np.arctan2(s, nz)
        length = np.zeros(len(n))
        for low in (alpha - np.pi / 2, alpha + 3 * np.pi / 2):
            length += np.maximum(np.minimum(t1, low + np.pi) - np.maximum(t0, low), 0.0)
        total += sign * (ny * np.cos(phi) - nx * np.sin(phi)) * length

    def horizon(phi):                          # the horizon's point at azimuth phi
        theta = np.arctan2(np.abs(nz), -np.sign(nz) * rho * np.cos(phi - beta))
        st = np.sin(theta)
        return np.stack([st * np.cos(phi), st * np.sin(phi), np.cos(theta)], axis=-1)

    near, far = np.minimum(delta[0], delta[1]), np.maximum(delta[0], delta[1])
    for c in copies:
        for lo, hi in ((beta + c + near, beta + c + far), (beta + c - far, beta + c - near)):
            a, b = np.maximum(p0, lo), np.minimum(p1, hi)
            inside = b > a
            wa, wb = horizon(a), horizon(np.maximum(a, b))
            angle = np.arctan2(np.linalg.norm(np.cross(wa, wb), axis=-1), np.sum(wa * wb, axis=-1))
            total += np.where(inside, angle, 0.0)
    ok &= (np.sin(t0) > guard) | (t0 == 0.0)
    ok &= (np.sin(t1) > guard) | (t1 == np.pi)
    return 0.5 * total, ok


# --------------------------------------------------------------------------- what EnvironmentLight's GLSL reads
# (glsl/lights/environment.glsl mirrors these function by function; docs/design.md section 13)
def cube_texel_directions(resolution):
    """The unit directions of a cube map's texels, (6 R^2, 3) float64, in the order ``face * R^2 + t * R + s``:
    face ``2 a + (major < 0)`` about axis ``a`` (x, y, z), ``s`` along axis ``(a + 1) % 3`` and ``t`` along
    ``(a + 2) % 3``, at ``-1 + 2 i/(R - 1)`` of the face's square ``[-1, 1]^2``: its edges included, so that two
    faces hold the same values along the edge they share and the blend is continuous across it."""
    R = int(resolution)
    centres = -1.0 + 2.0 * np.arange(R) / (R - 1.0)
    t, s = np.meshgrid(centres, centres, indexing="ij")
    out = []
    for face in range(6):
        axis, sign = face // 2, -1.0 if face % 2 else 1.0
        d = np.zeros((R, R, 3))
        d[..., axis] = sign
        d[..., (axis + 1) % 3] = s
        d[..., (axis + 2) % 3] = t
        out.append(d.reshape(-1, 3))
    d = np.concatenate(out)
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def environment_cube(n, table, resolution):
    """The cube map ``table`` (6 R^2, 3) at unit directions ``n`` (N, 3): the face of ``n``'s largest component
    (ties to x, then y), its texel coordinates ``u = (s + 1)(R - 1)/2`` (clamped to ``[0, R - 1]`` against
    rounding), and the bilinear blend of the four texels about ``u``.  Returns ``(value (N, 3), spread (N,))``: spread is the
    largest difference among the four texels (what a shift of ``u`` can change), for the band."""
    R = int(resolution)
    a = np.abs(n)
    axis = np.where((a[:, 0] >= a[:, 1]) & (a[:, 0] >= a[:, 2]), 0, np.where(a[:, 1] >= a[:, 2], 1, 2))
    rows = np.arange(len(n))
    major = n[rows, axis]
    s = n[rows, (axis + 1) % 3] / np.abs(major)
    t = n[rows, (axis + 2) % 3] / np.abs(major)
    face = 2 * axis + (major < 0.0)
    u = np.clip((np.stack([s, t], axis=1) + 1.0) * (0.5 * (R - 1.0)), 0.0, R - 1.0)
    i0 = np.minimum(np.floor(u).astype(np.int64), R - 2)
    fr = u - i0
    base = face * R * R

    def texel(ds, dt):
        return table[base + (i0[:, 1] + dt) * R + i0[:, 0] + ds]

    corners = [texel(0, 0), texel(1, 0), texel(0, 1), texel(1, 1)]
    low = corners[0] + (corners[1] - corners[0]) * fr[:, :1]
    high = corners[2] + (corners[3] - corners[2]) * fr[:, :1]
    value = low + (high - low) * fr[:, 1:]
    stack = np.stack(corners)
    return value, np.max(np.max(stack, axis=0) - np.min(stack, axis=0), axis=1)


def sh_count(order):
    """``(L + 1)^2`` coefficients of the real spherical harmonics up to order ``L``."""
    return (int(order) + 1) ** 2


def sh_lobe_weights(q, order):
    """``lambda_l(q) = 2 pi c_l(q)``, ``c_l(q) = integral_0^1 t^q P_l(t) dt`` (Funk-Hecke for ``max(t, 0)^q``), (L + 1,):
    ``c_0 = 1/(q + 1)``, ``c_1 = 1/(q + 2)``, ``c_l = c_(l-2) (q - l + 2)/(q + l + 1)``.  ``q = 1`` gives Ramamoorthi and
    Hanrahan's clamped-cosine weights ``pi, 2 pi/3, pi/4, 0, -pi/24, ...``."""
    q = float(q)
    c = np.zeros(int(order) + 1)
    c[0] = 1.0 / (q + 1.0)
    if order >= 1:
        c[1] = 1.0 / (q + 2.0)
    for l in range(2, int(order) + 1):
        c[l] = c[l - 2] * (q - l + 2.0) / (q + l + 1.0)
    return 2.0 * np.pi * c


def sh_legendre(z, order):
    """The normalised associated Legendre functions without their ``sin^m(theta)``, ``Pbar_l^m(z)`` for ``0 <= m <= l
    <= L``, as a dict ``(l, m) -> (N,)``: ``Pbar_0^0 = 1/sqrt(4 pi)``, ``Pbar_m^m = Pbar_(m-1)^(m-1) sqrt((2m + 1)/(2m))``,
    ``Pbar_l^m = a (z Pbar_(l-1)^m - b Pbar_(l-2)^m)`` with ``a = sqrt((4 l^2 - 1)/(l^2 - m^2))`` and ``b =
    sqrt(((l - 1)^2 - m^2)/(4 (l - 1)^2 - 1))``, so that ``Y_l0 = Pbar_l^0(z)`` and ``Y_l,+-m = sqrt(2) Pbar_l^m(z)``
    times the real and imaginary parts of ``(x + i y)^m`` are orthonormal over the sphere."""
    z = np.asarray(z, dtype=np.float64)
    out = {}
    pmm = np.full(z.shape, 0.28209479177387814)
    for m in range(int(order) + 1):
        if m > 0:
            pmm = pmm * np.sqrt((2.0 * m + 1.0) / (2.0 * m))
        pa, pb = np.zeros(z.shape), pmm
        out[(m, m)] = pmm
        for l in range(m + 1, int(order) + 1):
            a = np.sqrt((4.0 * l * l - 1.0) / (l * l - m * m))
            b = np.sqrt(((l - 1.0) ** 2 - m * m) / (4.0 * (l - 1.0) ** 2 - 1.0)) if l > m + 1 else 0.0
            p = a * (z * pb - b * pa)
            pa, pb = pb, p
            out[(l, m)] = p
    return out


def sh_project(radiance, order, nodes=None):
    """The map's real spherical-harmonic coefficients ``L_lm = sum_k L_k integral_texel Y_lm dw``, ((L + 1)^2, 3)
    float64, index ``l^2 + l + m``: the azimuthal integrals of ``cos(m phi)``, ``sin(m phi)`` exact, the polar ones by
    ``nodes``-point Gauss-Legendre in ``theta`` per row (the integrand ``Pbar_l^m(cos) sin^(m+1)`` is smooth; default
    ``max(24, order + 2)``, which integrates a row of any height)."""
    radiance = np.asarray(radiance, dtype=np.float64)
    values = radiance[..., None] if radiance.ndim == 2 else radiance
    H, W = values.shape[:2]
    theta, phi = texel_edges(H, W)
    x, w = np.polynomial.legendre.leggauss(max(24, int(order) + 2) if nodes is None else nodes)
    t = theta[:-1, None] + (theta[1:] - theta[:-1])[:, None] * 0.5 * (x[None, :] + 1.0)        # (H, G)
    weight = (theta[1:] - theta[:-1])[:, None] * 0.5 * w[None, :] * np.sin(t)
    legendre = sh_legendre(np.cos(t), order)
    out = np.zeros((sh_count(order), values.shape[-1]))
    for m in range(int(order) + 1):
        if m == 0:
            parts = ((0, phi[1:] - phi[:-1]),)
        else:
            parts = ((m, (np.sin(m * phi[1:]) - np.sin(m * phi[:-1])) / m * np.sqrt(2.0)),
                     (-m, (np.cos(m * phi[:-1]) - np.cos(m * phi[1:])) / m * np.sqrt(2.0)))
        for signed, azimuth in parts:
            per_row = np.einsum("hwc,w->hc", values, azimuth)                                    # (H, C)
            for l in range(m, int(order) + 1):
                polar = np.sum(weight * legendre[(l, m)] * np.sin(t) ** m, axis=1)               # (H,)
                out[l * l + l + signed] = polar @ per_row
    return out if radiance.ndim == 3 else out[:, 0]


def environment_sh(r, q, coefficients, frame, order):
    """``sum_l lambda_l(q) sum_m L_lm Y_lm(d)`` at ``d = frame r`` (map coordinates), (N, 3): the spherical harmonics'
    convolution with ``max(t, 0)^q`` (Funk-Hecke), evaluated as environment.glsl does (the Legendre recurrence of
    `sh_legendre`, ``(x + i y)^m`` by complex multiplication).  Also returns ``sum |terms|`` (N,), for the band."""
    d = np.asarray(r, dtype=np.float64) @ np.asarray(frame, dtype=np.float64).T
    lam = sh_lobe_weights(q, order)
    coefficients = np.asarray(coefficients, dtype=np.float64)
    legendre = sh_legendre(d[:, 2], order)
    out = np.zeros((len(d), coefficients.shape[-1]))
    magnitude = np.zeros(len(d))
    cm, sm = np.ones(len(d)), np.zeros(len(d))
    for m in range(int(order) + 1):
        if m > 0:
            cm, sm = d[:, 0] * cm - d[:, 1] * sm, d[:, 0] * sm + d[:, 1] * cm
        for l in range(m, int(order) + 1):
            p = legendre[(l, m)]
            if m == 0:
                term = p[:, None] * coefficients[l * l + l]
            else:
                term = (np.sqrt(2.0) * p)[:, None] * (cm[:, None] * coefficients[l * l + l + m]
                                                      + sm[:, None] * coefficients[l * l + l - m])
            out = out + lam[l] * term
            magnitude = magnitude + np.abs(lam[l]) * np.max(np.abs(term), axis=1)
    return out, magnitude


def downsample(radiance, rows):
    """The map averaged onto ``rows x 2 rows`` lat-long texels, exactly (each new texel's radiance is the old
    texels' radiance integrated over their overlap with it, in solid angle, over its own solid angle): (rows, 2 rows,
    C) float64."""
    radiance = np.asarray(radiance, dtype=np.float64)
    values = radiance[..., None] if radiance.ndim == 2 else radiance
    H, W = values.shape[:2]
    z_old, z_new = np.cos(texel_edges(H, 1)[0]), np.cos(texel_edges(rows, 1)[0])
    p_old, p_new = texel_edges(1, W)[1], texel_edges(1, 2 * rows)[1]

    def overlap(a, b, decreasing=False):  # lengths of the overlaps of intervals [a_i, a_i+1] and [b_j, b_j+1]
        if decreasing:
            a, b = -a, -b
        return np.maximum(np.minimum(a[1:, None], b[None, 1:]) - np.maximum(a[:-1, None], b[None, :-1]), 0.0)

    Z = overlap(z_new, z_old, decreasing=True)          # (rows, H)
    P = overlap(p_new, p_old)                           # (2 rows, W)
    flux = np.einsum("ah,hwc,bw->abc", Z, values, P, optimize=True)
    return flux / texel_solid_angles(rows, 2 * rows)[..., None]


#: environment_horizon's 24-point Gauss-Legendre nodes and weights on [0, 1], rounded to float32 as the GLSL holds them
HORIZON_NODES, HORIZON_WEIGHTS = (np.float32(0.5 * a).astype(np.float64) for a in
                                  np.polynomial.legendre.leggauss(24) + np.array([[1.0], [0.0]]))


def environment_log1p(x):
    """``log(1 + x)`` as environment.glsl computes it: ``log(u) x / (u - 1)``, ``u = 1 + x`` (``x`` where ``u == 1``)."""
    u = 1.0 + x
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(u == 1.0, x, np.log(u) * x / (u - 1.0))


def environment_horizon(q, c):
    """The part of the lobe ``max(r.w, 0)^q`` above the horizon of ``n`` under a uniform sky, ``c = n.r`` in [-1, 1],
    (N,): ``1 - (q + 1) J / pi``, ``J = 2 s^(q+1) integral_0^1 atan2(v sqrt(2 - v^2), c (1 - v^2)) (1 - v^2)^q v dv``,
    ``s = sqrt(1 - c^2)`` (``log s = log1p(-c^2)/2``), by 24-point Gauss-Legendre on ``[0, min(1, 5/sqrt(q + 1))]``;
    for ``c < 0`` the mirror image (environment.glsl).  The rule is exact to about 1e-9 for integer ``q``; for ``q <
    1`` the weight ``(1 - v^2)^q`` is singular at ``v = 1`` and the rule is within 6e-5."""
    c = np.asarray(c, dtype=np.float64)
    a = np.abs(c)
    log_s = np.where(a * a < 1.0, 0.5 * environment_log1p(-a * a), -100.0)
    span = min(1.0, 5.0 / np.sqrt(q + 1.0))
    v = span * HORIZON_NODES[None, :]
    u = 1.0 - v * v
    weight = np.exp((q + 1.0) * log_s[:, None] + q * environment_log1p(-v * v))
    angle = atan2_first_quadrant(v * np.sqrt(2.0 - v * v), a[:, None] * u)
    below = 2.0 * (q + 1.0) / np.pi * span * np.sum(HORIZON_WEIGHTS * angle * weight * v, axis=1)
    return np.where(c < 0.0, below, 1.0 - below)
