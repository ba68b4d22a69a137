"""The exact integral of the lecture's Phong lobe over an equirectangular radiance map, fast enough for every pixel of a
verify (issue 40): ``I(n, r) = sum_k L_k integral over texel k of max(r.w, 0)^q [n.w > 0] dw``, float64, with ``r``
the view's reflection about the normal ``n`` (docs/design.md section 13).  It shares with the methods it measures
(`glphong.lights.EnvironmentLight`'s harmonics) nothing but the map; `glphong.twin.environment_quadrature` is the
independent check it is tested against (tests/lights/test_environment_lobe.py).

The method
----------
1. *Pruning, with its bound.*  The lobe is ``cos^q`` of the angle to ``r``: every texel whose every point lies beyond
   ``alpha`` from ``r`` (its centre beyond ``alpha`` plus its reach) is skipped, and all of them together contribute
   at most ``cos(alpha)^q sum_k max_c(L_k) Omega_k``; ``alpha`` is chosen so that this is ``rtol / 100`` of the pixel's
   scale (the ``floor`` the caller gives, the rest of the pixel's exact value, or the map's mean radiance times the
   lobe's integral), and the bound is added to the error estimate.
2. *The texels wholly above the horizon, by shared-node stencils.*  The integrand ``g = max(r.w, 0)^q sin(theta)`` is
   smooth over the texels kept here (those whose stencils would reach ``r.w = 0`` go to step 3), while the radiance is constant per texel: so each texel's integral of ``g`` is taken from the ``2 m`` nodes of an
   equispaced grid around it in ``theta`` and in ``phi`` (the integral of the interpolating polynomial, ``m = 5``:
   error ``O(h^10 g^(10))``), the grid ``k`` times finer than the map where ``h sqrt(q)`` asks for it.  Neighbouring
   texels share their nodes: about ``k^2`` evaluations of ``g`` a texel instead of a tensor rule's ``G^2``.  The
   error estimate is the difference from the ``2 m - 2`` inner nodes' rule, summed over the rows; a pixel whose
   estimate exceeds half its tolerance is done again with ``k`` doubled (to 64).
3. *The texels the horizon crosses*, by the clipped tensor Gauss-Legendre rule of `environment_quadrature` (``theta``
   clipped exactly at every ``phi`` node, the texel cut where the horizon crosses its edges), order 3 against order 2,
   each rectangle split into four where they differ by more than ``rtol`` of its value (or its share, by solid angle,
   of half the pixel's tolerance), to 8 levels.

Kept texels that the plane ``r.w = 0`` or their stencils' reach crosses (small ``q``, coarse maps) join the crossed
ones, clipped by that plane too.  ``converged`` is the sum of the three estimates at most ``rtol`` of ``max(floor,
value)``; where it is not, the point is done again with the pruning sized for the value found (the first pass sizes it
for ``floor`` or a guess).  Memory is bounded: at most ``_NODE_BUDGET`` node values at once, and the crossed texels
of ``_BLOCK`` points.
"""
import numpy as np
from scipy import sparse

from glphong.twin.environment import _row_runs, texel_edges, texel_solid_angles
from glphong.twin.environment_quadrature import _breakpoints, _rule, _solid_angle, _split, _take

__all__ = ["lobe_integral", "stencil_weights"]

_M = 5                    # 2 m nodes per stencil
_RHO = 0.15               # node spacing times sqrt(q) at first
_MAX_K = 64
_NODE_BUDGET = 1_500_000  # values of g held at once (pixels x nodes), bounded memory
_CROSSED_ORDER = 3
_BLOCK = 256               # points whose crossed texels are held at once
_PIXELS = 16              # pixels a chunk at most


def stencil_weights(m, k):
    """The weights ``gamma_u`` (``u = -m + 1 .. k - 1 + m``) of ``integral over [0, k] g dx ~ sum_u gamma_u g(u)``:
    each unit cell's integral of the polynomial interpolating ``g`` at its ``2 m`` nearest integers, summed over the
    ``k`` cells; (k + 2 m - 1,) float64."""
    t = np.arange(-m + 1, m + 1)
    beta = np.empty(2 * m)
    for a, ta in enumerate(t):
        c = np.array([1.0])
        for tb in t:
            if tb != ta:
                c = np.polynomial.polynomial.polymul(c, [-tb, 1.0]) / (ta - tb)
        ci = np.polynomial.polynomial.polyint(c)
        beta[a] = np.polynomial.polynomial.polyval(1.0, ci) - np.polynomial.polynomial.polyval(0.0, ci)
    gamma = np.zeros(k + 2 * m - 1)
    for cell in range(k):
        gamma[cell:cell + 2 * m] += beta
    return gamma


def _banded(B, k, high, low, columns):
    """The theta stencils as one sparse (2 B, columns) matrix: row ``b`` the texel row ``b``'s ``high`` weights at
    node rows ``b k ..``, row ``B + b`` its ``low`` ones."""
    span = len(high)
    b = np.repeat(np.arange(B), span)
    u = np.tile(np.arange(span), B)
    data = np.concatenate([np.tile(high, B), np.tile(low, B)])
    return sparse.csr_matrix((data, (np.concatenate([b, B + b]), np.concatenate([b * k + u] * 2))),
                             shape=(2 * B, columns))


def _gather(at, weights, columns):
    """The phi stencils as a sparse (J, columns) matrix: texel column ``j``'s weights at its nodes ``at[j]``."""
    J, span = at.shape
    return sparse.csr_matrix((np.tile(weights, J), (np.repeat(np.arange(J), span), at.reshape(-1))),
                             shape=(J, columns))


def _in_run(col, first, count, W):
    """Whether each column ``col`` (P, J) lies in each row's run ``(first, count)`` (B, P) on the circle of ``W``:
    (B, P, J) bool."""
    d = col[None, :, :] - first[:, :, None]
    d += W * (d < 0)
    return d < count[:, :, None]


def lobe_integral(radiance, r, n, q, rtol=1e-9, floor=None):
    """``sum_k L_k integral_k max(r.w, 0)^q [n.w > 0] dw`` per point, in the map's frame (module docstring).

    Parameters
    ----------
    radiance : (H, W, C) array_like
        Radiance per texel [W/(m^2 sr)], row 0 at the map's +z.
    r, n : (N, 3) array_like
        The lobe's unit axes and the unit normals, in the map's frame.
    q : float
        The exponent, >= 0.
    rtol : float
        Relative tolerance of each point's value, relative to ``max(floor, value)``.
    floor : (N,) array_like, optional
        A scale below which the point's error does not matter [same unit as the value]: what the rest of the pixel's
        exact value is, divided by the lobe's coefficient; at least ``1e-6`` of the lobe under a uniform sky of the
        map's mean radiance.

    Returns
    -------
    value : (N, C) float64 ndarray
    error : (N,) float64 ndarray
        The error estimate (largest channel): the stencils' and the rule's differences, plus the pruning bound.
    converged : (N,) bool ndarray
    """
    values = np.asarray(radiance, dtype=np.float64)
    H, W, C = values.shape
    r = np.asarray(r, np.float64).reshape(-1, 3)
    n = np.asarray(n, np.float64).reshape(-1, 3)
    N = len(r)
    q = float(q)
    floor = np.zeros(N) if floor is None else np.broadcast_to(np.asarray(floor, np.float64), (N,))
    omega = texel_solid_angles(H, W)
    peak = np.max(np.abs(values), axis=-1)
    total = float(np.sum(peak * omega))
    value, error = np.zeros((N, C)), np.zeros(N)
    if N == 0 or total == 0.0:
        return value, error, np.ones(N, bool)
    guess = total / (4 * np.pi) * 2 * np.pi / (q + 1.0)      # a uniform sky of the map's mean under the whole lobe
    floor = np.maximum(floor, 1e-6 * guess)                   # no pixel asks for more than 1e-15 of that
    theta, _ = texel_edges(H, W)
    with np.errstate(divide="ignore", invalid="ignore"):
        cot = np.cos(theta) / np.sin(theta)
    cot[0], cot[-1] = np.inf, -np.inf
    h = max(np.pi / H, 2 * np.pi / W)
    k = int(min(_MAX_K, max(1, np.ceil(h * np.sqrt(q) / _RHO))))
    todo = np.arange(N)
    scale = np.maximum(floor, guess)                          # what the pruning is sized for, at first
    for attempt in range(2):  # again with the pruning sized for the value found, where the guess was too large
        part = _solve(values, r[todo], n[todo], q, rtol, floor[todo], scale[todo], total, k, cot)
        value[todo], error[todo] = part
        found = np.maximum(floor, np.max(np.abs(value), axis=1))
        converged = error <= rtol * found
        todo = np.nonzero(~converged)[0]
        if not todo.size:
            break
        scale = found
    return value, error, converged


def _solve(values, r, n, q, rtol, floor, scale, total, k, cot):
    """Steps 1 to 3 of the module docstring, the pruning sized for ``scale`` (N,): ``(value (N, C), error (N,))``."""
    N, C = len(r), values.shape[-1]
    cos_alpha = np.clip((1e-2 * rtol * scale / total) ** (1.0 / max(q, 1e-300)), 0.0, 1.0)
    alpha = np.arccos(cos_alpha)
    prune = np.where(cos_alpha > 0.0, cos_alpha ** q * total, 0.0)
    # points in an order that keeps a chunk's lobes together (their windows of columns alike), in blocks that bound
    # the crossed texels held at once
    tr, pr = np.arccos(np.clip(r[:, 2], -1.0, 1.0)), np.mod(np.arctan2(r[:, 1], r[:, 0]), 2 * np.pi)
    order = np.lexsort((np.floor(pr * np.maximum(np.sin(tr), 0.1) / 0.15), np.floor(tr / 0.15)))
    value, error = np.zeros((N, C)), np.zeros(N)
    for block in np.array_split(order, max(1, -(-N // _BLOCK))):
        pending = [(block, k)]
        crossed = []
        while pending:
            idx, nodes = pending.pop()
            v, e, (owner, texel) = _interior(values, r[idx], n[idx], q, alpha[idx], nodes, cot)
            tol = 0.5 * rtol * np.maximum(floor[idx], np.max(np.abs(v), axis=1))
            redo = (e > tol) & (nodes < _MAX_K)
            value[idx[~redo]], error[idx[~redo]] = v[~redo], e[~redo]
            crossed.append((idx[owner][~redo[owner]], texel[~redo[owner]]))       # a redone point's pairs dropped
            if redo.any():
                pending.append((idx[redo], min(2 * nodes, _MAX_K)))
        owner = np.concatenate([c[0] for c in crossed])
        texel = np.concatenate([c[1] for c in crossed])
        points = np.sort(block)
        local = np.searchsorted(points, owner)
        c_value, c_error = _crossed(values, r[points], n[points], q, local, texel, rtol,
                                    0.5 * rtol * np.maximum(floor[points], np.max(np.abs(value[points]), axis=1)))
        value[points] += c_value
        error[points] += c_error
    return value, error + prune


def _extent(tr, cos_limit, t0, t1):
    """Each lobe's half-width in ``phi`` [rad] over each row (P, R): where the cone of cosine ``cos_limit`` (P, R)
    about the axis at polar angle ``tr`` (P,) meets the row's ``[t0, t1]`` (R,); pi where the row's whole circle may
    be in it, -1 where none of it is.  At fixed theta the cone's half-width is ``arccos((c - cos t cos tr) / (sin t
    sin tr))``; over the row it is largest at an edge or at ``cos t = cos tr / c``."""
    ct_r, st_r = np.cos(tr)[:, None], np.sin(tr)[:, None]
    best = np.full(cos_limit.shape, -1.0)
    inner = np.clip(np.cos(tr)[:, None] / np.maximum(cos_limit, 1e-300), -1.0, 1.0)
    tangent = np.arccos(inner)
    for t in (np.broadcast_to(t0, cos_limit.shape), np.broadcast_to(t1, cos_limit.shape),
              np.clip(tangent, t0, t1)):
        with np.errstate(divide="ignore", invalid="ignore"):
            ratio = (cos_limit - np.cos(t) * ct_r) / (np.sin(t) * st_r)
        ratio = np.where(np.isnan(ratio), np.where(cos_limit - np.cos(t) * ct_r <= 0.0, -np.inf, np.inf), ratio)
        best = np.maximum(best, np.where(ratio > 1.0, -1.0, np.arccos(np.clip(ratio, -1.0, 1.0))))
    return best


def _interior(values, r, n, q, alpha, k, cot):
    """Step 2 of the module docstring for the points ``r``, ``n`` (K, 3) at ``k`` nodes a texel side: ``(value (K, C),
    estimate (K,), crossed pairs (point, texel) of the kept texels)``.  Each point reads a window of columns about its
    lobe's azimuth (as wide as the chunk's widest lobe over a band of rows), not the chunk's union."""
    H, W, C = values.shape
    m = _M
    g10, g8 = stencil_weights(m, k), np.pad(stencil_weights(m - 1, k), 1)
    span = len(g10)                                         # nodes a texel's stencil reads, per axis
    ht, hp = np.pi / (H * k), 2 * np.pi / (W * k)
    theta, phi = texel_edges(H, W)
    tc, pc = 0.5 * (theta[:-1] + theta[1:]), 0.5 * (phi[:-1] + phi[1:])
    reach = 0.5 * (theta[1] - theta[0]) + 0.5 * (phi[1] - phi[0]) * np.maximum(np.sin(theta[:-1]), np.sin(theta[1:]))
    stretch = m * np.hypot(ht, hp)                          # how far beyond a texel its stencils' nodes lie
    Wk = W * k
    node_phi = np.arange(Wk) * hp
    cphi, sphi = np.cos(node_phi), np.sin(node_phi)
    offsets = np.arange(span) - (m - 1)
    twice = np.concatenate([values, values], axis=1)                                          # (H, 2 W, C)
    K = len(r)
    value, estimate = np.zeros((K, C)), np.zeros(K)
    pairs_owner, pairs_texel = [], []
    for a in range(0, K, _PIXELS):
        rr, nn, aa = r[a:a + _PIXELS], n[a:a + _PIXELS], alpha[a:a + _PIXELS]
        P = len(rr)
        (lit_first, lit_count), (dark_first, dark_count) = _row_runs(nn, cot, W)
        tr = np.arccos(np.clip(rr[:, 2], -1.0, 1.0))
        centre_col = np.floor(np.mod(np.arctan2(rr[:, 1], rr[:, 0]), 2 * np.pi) / (phi[1] - phi[0])).astype(np.int64)
        cos_limit = np.cos(np.minimum(aa[:, None] + reach[None, :], np.pi))                # (P, H)
        half = _extent(tr, cos_limit, theta[:-1], theta[1:])                                # (P, H)
        cols_half = np.where(half < 0.0, -1, np.ceil(half / (phi[1] - phi[0])).astype(np.int64) + 1)
        rows = np.nonzero(np.any(cols_half >= 0, axis=0))[0]
        i = rows[0] if rows.size else H
        while i <= (rows[-1] if rows.size else -1):
            # a band of rows whose nodes fit the budget
            b1, widest = i, 0
            while b1 <= rows[-1]:
                w = min(W, 2 * max(widest, int(cols_half[:, b1].max())) + 1)
                if b1 > i and ((b1 + 1 - i) * k + span) * P * (w * k + span) > _NODE_BUDGET:
                    break
                widest, b1 = max(widest, int(cols_half[:, b1].max())), b1 + 1
            b0, B = i, b1 - i
            i = b1
            J = min(W, 2 * widest + 1)
            windows = np.lib.stride_tricks.sliding_window_view(twice, J, axis=1)              # (H, 2 W - J + 1, C, J)
            start = np.zeros(P, np.int64) if J == W else centre_col - widest                   # (P,) first column
            col = np.mod(start[:, None] + np.arange(J)[None, :], W)                              # (P, J)
            if widest < 0:
                continue
            # every per-texel array in (row, point, column) order, contiguous
            cosine = (rr[None, :, 2, None] * np.cos(tc[b0:b1])[:, None, None] + np.sin(tc[b0:b1])[:, None, None]
                      * (rr[None, :, 0, None] * np.cos(pc[col])[None] + rr[None, :, 1, None] * np.sin(pc[col])[None]))
            kept = cosine >= cos_limit[:, b0:b1].T[:, :, None]                                # (B, P, J)
            if not kept.any():
                continue
            safe = cosine > np.sin(reach[b0:b1] + stretch)[:, None, None]                      # stencils above r.w = 0
            del cosine
            node_col = np.mod(start[:, None] * k - (m - 1) + np.arange(J * k + span - 1)[None, :], Wk)   # (P, T)
            node_theta = (b0 * k + np.arange(B * k + span - 1) - (m - 1)) * ht                # beyond [0, pi]: the formula
            st, ct = np.sin(node_theta), np.cos(node_theta)
            dot = (rr[None, :, 2, None] * ct[:, None, None] + st[:, None, None]
                   * (rr[None, :, 0, None] * cphi[node_col][None] + rr[None, :, 1, None] * sphi[node_col][None]))
            with np.errstate(divide="ignore"):
                g = np.where(dot > 0.0, np.exp(q * np.log(np.where(dot > 0.0, dot, 1.0))), 0.0)
            del dot
            g *= st[:, None, None]                                                           # (NR, P, T)
            # the theta stencils (both orders) and then the phi stencils, as sparse banded products
            both = (_banded(B, k, g10, g8, len(node_theta)) @ g.reshape(len(node_theta), -1)).reshape(2 * B * P, -1)
            del g
            T = both.shape[-1]
            both = np.ascontiguousarray(both.T)                                                  # (T, 2 B P)
            at = np.arange(J)[:, None] * k + offsets[None, :] + (m - 1)                         # (J, span) in the window
            hi_c = np.ascontiguousarray((_gather(at, g10, T) @ both[:, :B * P]).T).reshape(B, P, J)
            lo_c = np.ascontiguousarray((_gather(at, g8, T) @ both[:, B * P:]).T).reshape(B, P, J)
            del both
            rows_idx = np.arange(b0, b1)
            lit = _in_run(col, lit_first[:, rows_idx].T, lit_count[:, rows_idx].T, W)
            dark = _in_run(col, dark_first[:, rows_idx].T, dark_count[:, rows_idx].T, W)
            inside = kept & lit & safe
            # each point's window of the rows' radiance (the map's columns twice over: a window is one slice)
            L = windows[b0:b1][np.arange(B)[:, None], start[None, :] % W]                          # (B, P, C, J)
            hi_c[~inside] = 0.0
            lo_c[~inside] = 0.0
            lo_c = hi_c - lo_c
            sums = (ht * hp) * np.matmul(np.stack([hi_c, lo_c], axis=2), np.swapaxes(L, -1, -2))  # (B, P, 2, C)
            value[a:a + P] += sums[:, :, 0].sum(axis=0)
            estimate[a:a + P] += np.sum(np.max(np.abs(sums[:, :, 1]), axis=-1), axis=0)
            b_, p_, j_ = np.nonzero(kept & ~dark & ~(lit & safe))
            pairs_owner.append(a + p_)
            pairs_texel.append(((b0 + b_) * W + col[p_, j_]) * 2 + ~safe[b_, p_, j_])     # the flag: clip r.w = 0 too
    empty = np.zeros(0, np.intp)
    owner = np.concatenate(pairs_owner) if pairs_owner else empty
    texel = np.concatenate(pairs_texel) if pairs_texel else empty
    return value, estimate, (owner.astype(np.intp), texel.astype(np.intp))


def _crossed(values, r, n, q, owner, flagged, rtol, atol, max_depth=8):
    """Step 3 of the module docstring: the texels ``flagged // 2`` (flat index) the horizon of the points ``owner``
    crosses, clipped by ``r.w = 0`` too where ``flagged`` is odd; ``atol`` (N,) each point's tolerance, shared among
    its rectangles by solid angle.  ``(value (N, C), estimate (N,))``."""
    value, error = np.zeros((len(r), values.shape[-1])), np.zeros(len(r))
    for clip_r in (False, True):
        pick = (flagged % 2 == 1) == clip_r
        if pick.any():
            _clipped(values, r, n, q, owner[pick], flagged[pick] // 2, [n, r] if clip_r else [n], rtol, atol, max_depth,
                     value, error)
    return value, error


def _clipped(values, r, n, q, owner, texel, planes, rtol, atol, max_depth, value, error):
    """The clipped rule of step 3 over ``planes``, added into ``value`` and ``error``."""
    H, W, C = values.shape
    N = len(r)
    theta, phi = texel_edges(H, W)
    row, col = texel // W, texel % W
    rects = (owner, texel, theta[row], theta[row + 1], phi[col], phi[col + 1])
    flat = values.reshape(-1, C)
    rects, _ = _breakpoints(rects, planes)
    for depth in range(max_depth + 1):
        if not len(rects[0]):
            break
        fine = _rule(rects, planes, None, flat, None, order=_CROSSED_ORDER, zonal=(r, q))
        coarse = _rule(rects, planes, None, flat, None, order=_CROSSED_ORDER - 1, zonal=(r, q))
        diff = np.max(np.abs(fine - coarse), axis=1)
        share = _solid_angle(rects)
        allowed = np.maximum(rtol * np.max(np.abs(fine), axis=1),
                             atol[rects[0]] * share / np.maximum(np.bincount(rects[0], share, N)[rects[0]], 1e-300))
        done = (diff <= allowed) | (depth == max_depth)
        np.add.at(value, rects[0][done], fine[done])
        np.add.at(error, rects[0][done], diff[done])
        rects, _ = _breakpoints(_split(_take(rects, ~done)), planes)
