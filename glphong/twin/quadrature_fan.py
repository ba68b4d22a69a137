"""The fan in direction space and the adaptive tensor Gauss-Legendre over it, with its error estimate: steps 2 to
4 of the method of `glphong.twin.quadrature` (its module docstring gives the formulas).

`_run` takes a region's boundary pieces (`glphong.twin.quadrature_regions`) and returns ``(value, error,
converged)`` as the public functions of `glphong.twin.quadrature` do.
"""
import numpy as np

from glphong.twin.quadrature_regions import _Pieces, _angle, _norm

_EPS = np.finfo(np.float64).eps
_LOW, _HIGH = 6, 9                 # the tensor Gauss-Legendre orders compared on each patch
_SPLIT_ANGLE = np.pi / 4           # a boundary piece subtends at most this at x [rad]
_CHUNK_EVALS = 300_000             # integrand evaluations per call (bounds memory)
_MAX_LIVE = 400_000                # live patches at most, or 16 per first patch (a guard for integrands
                                   # that are not smooth)


def _gauss(n):
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w


_RULES = (_gauss(_LOW), _gauss(_HIGH))


# --------------------------------------------------------------------------------------------------------------
# The fan
# --------------------------------------------------------------------------------------------------------------
def _nearest(pieces, foot, inside, N):
    """The unit direction ``F`` (N, 3) to each region's point nearest x (the foot when it is inside), and which
    points have a region at all."""
    idx = pieces.idx
    f = foot[idx]
    # segments: the projection, clamped
    g1 = pieces.g1
    with np.errstate(invalid="ignore", divide="ignore"):
        u = np.einsum("kd,kd->k", f - pieces.g0, g1) / np.einsum("kd,kd->k", g1, g1)
    u = np.clip(np.nan_to_num(u, nan=0.0), pieces.u0, pieces.u0 + pieces.du)
    # arcs: the rim point nearest the foot (angle 0) if within the arc, else the nearer end
    offset = np.mod(-pieces.u0, 2 * np.pi)
    beyond = offset - pieces.du
    sigma = np.where(offset <= pieces.du, pieces.u0 + offset,
                     np.where(beyond < 2 * np.pi - offset, pieces.u0 + pieces.du, pieces.u0))
    u = np.where(pieces.arc, sigma, u)
    point, _ = pieces.curve(u)
    distance = _norm(point - f)
    order = np.lexsort((distance, idx))
    first = order[np.r_[True, idx[order][1:] != idx[order][:-1]]] if len(order) else order
    has = np.zeros(N, bool)
    has[idx] = True
    nearest = np.zeros((N, 3))
    nearest[idx[first]] = point[first]
    nearest = np.where(inside[:, None], foot, nearest)
    F = np.zeros((N, 3))
    F[has] = nearest[has] / _norm(nearest[has])[:, None]
    return F, has


def _split_pieces(pieces):
    """Halve pieces until each subtends at most `_SPLIT_ANGLE` at x (a segment where the angle bisector meets it,
    an arc at its middle)."""
    done = []
    for _ in range(80):
        if not len(pieces):
            break
        P0, _ = pieces.curve(pieces.u0)
        P1, _ = pieces.curve(pieces.u0 + pieces.du)
        Pm, _ = pieces.curve(pieces.u0 + 0.5 * pieces.du)
        subtended = np.where(pieces.arc, _angle(P0, Pm) + _angle(Pm, P1), _angle(P0, P1))
        wide = subtended > _SPLIT_ANGLE
        done.append(pieces.take(~wide))
        if not wide.any():
            pieces = _Pieces.empty()
            break
        pieces = pieces.take(wide)
        n0, n1 = _norm(P0[wide]), _norm(P1[wide])
        fraction = np.where(pieces.arc, 0.5, n0 / (n0 + n1))              # a segment: where the bisector meets it
        first = fraction * pieces.du
        left = _Pieces(pieces.idx, pieces.arc, pieces.g0, pieces.g1, pieces.g2, pieces.u0, first, pieces.cut)
        right = _Pieces(pieces.idx, pieces.arc, pieces.g0, pieces.g1, pieces.g2, pieces.u0 + first, pieces.du - first,
                        pieces.cut)
        pieces = _Pieces.concat([left, right])
    pieces = _Pieces.concat(done + [pieces])
    return pieces.take(np.argsort(pieces.idx, kind="stable"))


def _unit_segments(pieces):
    """Segments re-parametrised between their unit end directions: the same great arc, at a nearly uniform speed."""
    seg = ~pieces.arc
    if seg.any():
        P0, _ = pieces.curve(pieces.u0[seg], seg)
        P1, _ = pieces.curve(pieces.u0[seg] + pieces.du[seg], seg)
        A, B = P0 / _norm(P0)[:, None], P1 / _norm(P1)[:, None]
        g0, g1, u0, du = pieces.g0.copy(), pieces.g1.copy(), pieces.u0.copy(), pieces.du.copy()
        g0[seg], g1[seg], u0[seg], du[seg] = A, B - A, 0.0, 1.0
        pieces = _Pieces(pieces.idx, pieces.arc, g0, g1, pieces.g2, u0, du, pieces.cut)
    return pieces


def _boundary_sensitivity(pieces, N):
    """``(Lambda (N,) [1/length], Theta (N,) [rad])``: ``Lambda`` bounds ``sum |dB| / |P|`` over the boundary
    pieces that are the emitter's own (moving each of their points by at most ``e`` turns its direction by at most
    ``e/|P|``, so the region's measure moves by at most ``e Lambda``), ``Theta`` sums the angles all pieces subtend
    (a piece cut by a plane through x moves across it only with the plane's normal, by a few eps).  Per piece: the
    angle it subtends over its distance from x (a segment's exact distance; an arc's, which subtends at most
    45 degrees, the least of three samples over 1.5)."""
    P0, _ = pieces.curve(pieces.u0)
    P1, _ = pieces.curve(pieces.u0 + pieces.du)
    Pm, _ = pieces.curve(pieces.u0 + 0.5 * pieces.du)
    subtended = np.where(pieces.arc, _angle(P0, Pm) + _angle(Pm, P1), _angle(P0, P1))
    D = P1 - P0
    with np.errstate(invalid="ignore", divide="ignore"):
        along = np.clip(-np.einsum("kd,kd->k", P0, D) / np.einsum("kd,kd->k", D, D), 0.0, 1.0)
    segment = _norm(P0 + np.nan_to_num(along)[:, None] * D)
    arc = np.minimum(np.minimum(_norm(P0), _norm(P1)), _norm(Pm)) / 1.5
    distance = np.where(pieces.arc, arc, segment)
    with np.errstate(divide="ignore", invalid="ignore"):
        own = np.where(~pieces.cut & (subtended > 0), subtended / distance, 0.0)
    return _sums(pieces.idx, own, N), _sums(pieces.idx, subtended, N)


# --------------------------------------------------------------------------------------------------------------
# Quadrature
# --------------------------------------------------------------------------------------------------------------
def _patch_rule(pieces, F, pid, sa, ds, ta, dt, nodes, weights):
    """Directions (k, n*n, 3) and weights (k, n*n) of the tensor rule on the patches' rectangles, and the weights
    with ``|det(F, P', P)|`` replaced by ``|P'| |P|``, the size its rounding error is relative to."""
    Fk = F[pieces.idx[pid]]
    s = sa[:, None] + ds[:, None] * nodes[None, :]
    u = pieces.u0[pid, None] + pieces.du[pid, None] * s
    P, dP = pieces.curve(u, pid)
    dP *= (pieces.du[pid] * ds)[:, None, None]
    length = _norm(P)
    B = P / length[..., None]
    det = np.abs(np.einsum("kd,knd->kn", Fk, np.cross(dP, P)))
    along = det / length ** 2 * weights[None, :]                           # (k, n) over s
    bound = _norm(dP) / length * weights[None, :]
    t = ta[:, None] + dt[:, None] * nodes[None, :]
    across = t * dt[:, None] * weights[None, :]                            # (k, n) over t
    p = Fk[:, None, None, :] + t[:, None, :, None] * (B - Fk[:, None, :])[:, :, None, :]
    plen = _norm(p)
    w = p / plen[..., None]
    jac = along[:, :, None] * across[:, None, :] / plen ** 3
    noise = bound[:, :, None] * across[:, None, :] / plen ** 3
    k = len(pid)
    return w.reshape(k, -1, 3), jac.reshape(k, -1), noise.reshape(k, -1)


def _call(integrand, index, w):
    g = np.asarray(integrand(index, w), dtype=np.float64)
    if g.ndim == 1:
        g = g[:, None]
    if g.ndim != 2 or g.shape[0] != len(index) or g.shape[1] not in (1, 3):
        raise ValueError(f"the integrand must return (M, 1) or (M, 3) values for M = {len(index)} directions, "
                         f"got shape {g.shape}")
    return g


def _evaluate(pieces, F, integrand, pid, sa, ds, ta, dt):
    """Both rules on every patch: ``(Q_low (K, C), Q_high (K, C), solid angle (K,), largest |g| (K,), the size
    ``sum |P'| |P| ... |g|`` that rounding errors of Q are relative to (K,))``."""
    per = _LOW ** 2 + _HIGH ** 2
    step = max(1, _CHUNK_EVALS // per)
    out = []
    for a in range(0, len(pid), step):
        sl = slice(a, a + step)
        rules = [_patch_rule(pieces, F, pid[sl], sa[sl], ds[sl], ta[sl], dt[sl], *rule) for rule in _RULES]
        w = np.concatenate([rules[0][0], rules[1][0]], axis=1)
        k = w.shape[0]
        g = _call(integrand, np.repeat(pieces.idx[pid[sl]], per), w.reshape(-1, 3)).reshape(k, per, -1)
        low = np.einsum("km,kmc->kc", rules[0][1], g[:, :_LOW ** 2])
        high = np.einsum("km,kmc->kc", rules[1][1], g[:, _LOW ** 2:])
        size = np.einsum("km,km->k", rules[1][2], np.max(np.abs(g[:, _LOW ** 2:]), axis=2))
        out.append((low, high, rules[1][1].sum(axis=1), np.max(np.abs(g), axis=(1, 2)), size))
    return tuple(np.concatenate(parts) for parts in zip(*out))


def _sums(idx, values, N):
    if values.ndim == 1:
        return np.bincount(idx, weights=values, minlength=N)
    return np.stack([np.bincount(idx, weights=values[:, c], minlength=N) for c in range(values.shape[1])], axis=1)


def _tolerance(total, rtol):
    """``max(rtol |I|, 1e-300)``, ``|I|`` the largest channel."""
    return np.maximum(rtol * np.max(np.abs(total), axis=1), 1e-300)


def _integrate(pieces, F, integrand, N, rtol, max_depth, rounding):
    """``(integral (N, C), quadrature error estimate (N, C), tolerance (N,), largest |g| (N,))`` over the patches
    (F, piece).  ``rounding`` (N,) times the largest ``|g|`` is the part of each point's error that no subdivision
    removes: it takes up to half the tolerance.  Subdivision also stops at 64 eps times the size that the rounding
    errors of the values are relative to (a sliver of a region, seen edge-on, is known to no better)."""
    K = len(pieces)
    live_limit = max(_MAX_LIVE, 16 * K)
    pid = np.arange(K)
    sa, ta = np.zeros(K), np.zeros(K)
    ds, dt = np.ones(K), np.ones(K)
    total = error = None
    omega, largest, size = np.zeros(N), np.zeros(N), np.zeros(N)
    for level in range(max_depth + 1):
        if not len(pid):
            break
        low, high, solid, biggest, noise = _evaluate(pieces, F, integrand, pid, sa, ds, ta, dt)
        if total is None:
            C = high.shape[1]
            total, error = np.zeros((N, C)), np.zeros((N, C))
        idx = pieces.idx[pid]
        np.maximum.at(largest, idx, biggest)
        diff = np.abs(high - low)
        now_total = total + _sums(idx, high, N)
        now_error = error + _sums(idx, diff, N)
        now_omega = omega + _sums(idx, solid, N)
        tol = np.maximum(_tolerance(now_total, rtol), 64 * _EPS * (size + _sums(idx, noise, N)))
        budget = tol - np.minimum(rounding * largest, 0.5 * tol)
        finished = np.max(now_error, axis=1) <= budget
        estimate = np.max(diff, axis=1)
        share = solid / np.where(now_omega > 0, now_omega, 1.0)[idx]
        accept = finished[idx] | (estimate <= 0.5 * budget[idx] * share) | (level == max_depth)
        refine = np.flatnonzero(~accept)
        if 4 * len(refine) > live_limit:  # keep the worst within the guard, take the rest as they are
            ratio = estimate[refine] / (budget[idx[refine]] * share[refine] + 1e-300)
            refine = refine[np.argsort(-ratio, kind="stable")[:live_limit // 4]]
            accept = np.ones(len(pid), bool)
            accept[refine] = False
        total += _sums(idx[accept], high[accept], N)
        error += _sums(idx[accept], diff[accept], N)
        omega += _sums(idx[accept], solid[accept], N)
        size += _sums(idx[accept], noise[accept], N)
        hs, ht = 0.5 * ds[refine], 0.5 * dt[refine]
        pid = np.tile(pid[refine], 4)
        sa = np.concatenate([sa[refine], sa[refine] + hs, sa[refine], sa[refine] + hs])
        ta = np.concatenate([ta[refine], ta[refine], ta[refine] + ht, ta[refine] + ht])
        ds, dt = np.tile(hs, 4), np.tile(ht, 4)
    if total is None:
        return np.zeros((N, 1)), np.zeros((N, 1)), np.full(N, 1e-300), largest
    return total, error, _tolerance(total, rtol), largest


def _run(pieces, foot, inside, integrand, radiance, N, rtol, max_depth, scale):
    """Integrate over the regions and apply the radiance.  ``scale`` (N,): the size of the coordinates that went into
    the pieces (in the pieces' unit), so that ``eps scale`` bounds how far rounding moved any boundary point."""
    F, _ = _nearest(pieces, foot, inside, N)
    pieces = _split_pieces(pieces)
    own, angle = _boundary_sensitivity(pieces, N)
    rounding = _EPS * (scale * own + 8.0 * angle)
    total, error, tol, largest = _integrate(_unit_segments(pieces), F, integrand, N, rtol, max_depth, rounding)
    error = error + (rounding * largest)[:, None]
    converged = np.max(error, axis=1) <= tol
    return total * radiance, np.max(error * radiance, axis=1), converged
