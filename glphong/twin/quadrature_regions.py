"""The region an emitter covers, seen from each surface point and clipped exactly: step 1 of the method of
`glphong.twin.quadrature` (its module docstring gives the geometry).

A region is returned as its boundary pieces (`_Pieces`: segments and arcs of a circle relative to the point), the
foot of the perpendicular from the point to the emitter's plane, and whether that foot lies inside the region; the
fan and the quadrature over it are `glphong.twin.quadrature_fan`'s.
"""
import numpy as np

_RIM_PIECES = 8                    # the rim is first cut into arcs of 2 pi / 8
_PARALLEL = 1e-13                  # two clip planes closer than this (|c_j x c_k|) are the same plane


# --------------------------------------------------------------------------------------------------------------
# Boundary pieces: curves P(u) relative to x, owned by point idx, u in [u0, u0 + du]: P = g0 + g1 u (a segment) or
# P = g0 + g1 (cos(u) - 1) + g2 sin(u) (an arc of a circle of centre g0 - g1, measured from its point g0: the rim
# point nearest the foot of x, so that near x the arc is computed to the precision of its small |P|).
# --------------------------------------------------------------------------------------------------------------
class _Pieces:
    __slots__ = ("idx", "arc", "g0", "g1", "g2", "u0", "du", "cut")

    def __init__(self, idx, arc, g0, g1, g2, u0, du, cut):
        self.idx, self.arc = np.asarray(idx, dtype=np.intp), np.asarray(arc, dtype=bool)
        self.g0, self.g1, self.g2 = g0, g1, g2
        self.u0, self.du = np.asarray(u0, dtype=np.float64), np.asarray(du, dtype=np.float64)
        self.cut = np.broadcast_to(np.asarray(cut, dtype=bool), self.idx.shape)   # lies on a plane through x

    def __len__(self):
        return len(self.idx)

    def take(self, sel):
        return _Pieces(*(getattr(self, name)[sel] for name in self.__slots__))

    @staticmethod
    def concat(parts):
        parts = [p for p in parts if len(p)]
        if not parts:
            return _Pieces.empty()
        return _Pieces(*(np.concatenate([getattr(p, name) for p in parts]) for name in _Pieces.__slots__))

    @staticmethod
    def empty():
        z3 = np.zeros((0, 3))
        return _Pieces(np.zeros(0, np.intp), np.zeros(0, bool), z3, z3, z3, np.zeros(0), np.zeros(0), False)

    def curve(self, u, sel=slice(None)):
        """``(P, dP/du)`` at parameters ``u`` of shape (K,) or (K, n) for the pieces ``sel``."""
        arc, g0, g1, g2 = self.arc[sel], self.g0[sel], self.g1[sel], self.g2[sel]
        if u.ndim == 2:
            arc, g0, g1, g2 = arc[:, None], g0[:, None, :], g1[:, None, :], g2[:, None, :]
        if not np.any(arc):                                       # segments only
            return g0 + g1 * u[..., None], np.broadcast_to(g1, u.shape + (3,)).copy()
        cu, su = np.cos(u), np.sin(u)
        a = np.where(arc, -2.0 * np.sin(0.5 * u) ** 2, u)        # cos(u) - 1 without cancellation
        b = np.where(arc, su, 0.0)
        da = np.where(arc, -su, 1.0)
        db = np.where(arc, cu, 0.0)
        P = g0 + g1 * a[..., None] + g2 * b[..., None]
        dP = g1 * da[..., None] + g2 * db[..., None]
        return P, dP


def _norm(v):
    return np.sqrt(np.einsum("...k,...k->...", v, v))


def _angle(a, b):
    return np.arctan2(_norm(np.cross(a, b)), np.einsum("...k,...k->...", a, b))


def _unit(v, what):
    v = np.asarray(v, dtype=np.float64)
    length = _norm(v)
    if np.any(~np.isfinite(length)) or np.any(length == 0.0):
        raise ValueError(f"{what}: zero or non-finite vectors")
    return v / length[..., None]


def _perpendiculars(m):
    """Two unit vectors completing the unit vectors ``m`` (..., 3) to right-handed orthonormal frames."""
    helper = np.where((np.abs(m[..., 0]) < 0.6)[..., None], np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0]))
    e1 = np.cross(m, helper)
    e1 /= _norm(e1)[..., None]
    return e1, np.cross(m, e1)


# --------------------------------------------------------------------------------------------------------------
# Regions
# --------------------------------------------------------------------------------------------------------------
def _clip_polygons(Q, count, on, c, bit):
    """Sutherland-Hodgman: the convex polygons ``Q`` (N, V, 3) with ``count`` (N,) vertices, clipped to ``c.y >= 0``.
    ``on`` (N, V) int: bit masks of the clip planes each vertex lies on (a crossing of plane ``bit`` lies on it and
    on the planes both ends of its edge lie on)."""
    N, V, _ = Q.shape
    j = np.arange(V)[None, :]
    live = j < count[:, None]
    following = np.where(j + 1 < count[:, None], j + 1, 0)
    B = np.take_along_axis(Q, following[..., None], axis=1)
    on_b = np.take_along_axis(on, following, axis=1)
    dA = np.einsum("nvk,nk->nv", Q, c)
    dB = np.take_along_axis(dA, following, axis=1)
    inA, inB = dA >= 0.0, dB >= 0.0
    emit_a = live & inA
    emit_i = live & (inA != inB)
    with np.errstate(invalid="ignore", divide="ignore"):
        t = np.where(emit_i, dA / np.where(emit_i, dA - dB, 1.0), 0.0)
    crossing = Q + t[..., None] * (B - Q)
    emitted = emit_a.astype(np.intp) + emit_i
    start = np.cumsum(emitted, axis=1) - emitted
    new_count = emitted.sum(axis=1)
    out = np.zeros((N, max(int(new_count.max(initial=0)), 1), 3))
    rows = np.broadcast_to(np.arange(N)[:, None], (N, V))
    out[rows[emit_a], start[emit_a]] = Q[emit_a]
    at = start + emit_a
    out[rows[emit_i], at[emit_i]] = crossing[emit_i]
    out_on = np.zeros(out.shape[:2], dtype=on.dtype)
    out_on[rows[emit_a], start[emit_a]] = on[emit_a]
    out_on[rows[emit_i], at[emit_i]] = (on & on_b)[emit_i] | (1 << bit)
    return out, new_count, out_on


def _polygon_region(x, planes, vertices, front):
    """Boundary pieces of each point's clipped polygon, the foot of the perpendicular and whether it is inside."""
    N = len(x)
    Q = vertices[None, :, :] - x[:, None, :]
    height = -(Q[:, 0, :] @ front)
    seen = height > 0.0
    count = np.where(seen, len(vertices), 0)
    foot = -height[:, None] * front
    # the foot is inside iff it is on the inner side of every edge and of every clip plane
    edges = np.roll(Q, -1, axis=1) - Q
    inside = np.all(np.einsum("nvk,k->nv", np.cross(edges, foot[:, None, :] - Q), front) >= 0.0, axis=1)
    on = np.zeros(Q.shape[:2], dtype=object if len(planes) > 62 else np.int64)
    for bit, c in enumerate(planes):
        Q, count, on = _clip_polygons(Q, count, on, c, bit)
        inside &= np.einsum("nk,nk->n", c, foot) >= 0.0
    count = np.where(count >= 3, count, 0)
    j = np.arange(Q.shape[1])[None, :]
    live = j < count[:, None]
    following = np.where(j + 1 < count[:, None], j + 1, 0)
    A = Q[live]
    B = np.take_along_axis(Q, following[..., None], axis=1)[live]
    cut = (on & np.take_along_axis(on, following, axis=1))[live] != 0
    idx = np.broadcast_to(np.arange(N)[:, None], live.shape)[live]
    pieces = _Pieces(idx, np.zeros(len(idx), bool), A, B - A, np.zeros_like(A), np.zeros(len(idx)), np.ones(len(idx)),
                     cut)
    return pieces, foot, inside & (count > 0)


def _disk_region(centre, normal, radius, e1, e2, planes, seen):
    """Boundary pieces of each point's clipped disk (centre (N, 3) relative to x, unit normal (N, 3) toward the side
    it emits to, radius (N,), a rim frame e1, e2 (N, 3) with e1 x e2 = normal), the foot of the perpendicular and
    whether it is inside.  Rim angles are measured from the rim point nearest the foot."""
    N = len(centre)
    foot = np.einsum("nk,nk->n", normal, centre)[:, None] * normal
    towards = foot - centre
    towards -= np.einsum("nk,nk->n", towards, normal)[:, None] * normal
    length = _norm(towards)
    e1 = np.where((length > 0)[:, None], towards / np.where(length > 0, length, 1.0)[:, None], e1)
    e2 = np.cross(normal, e1)
    closest = centre + radius[:, None] * e1                             # the rim's angle 0

    def rim(s):
        return closest[:, None, :] + radius[:, None, None] * (-2.0 * np.sin(0.5 * s)[..., None] ** 2 * e1[:, None, :]
                                                             + np.sin(s)[..., None] * e2[:, None, :])

    K = len(planes)
    C = np.stack(planes, axis=1)                                         # (N, K, 3)
    alpha = np.einsum("nkj,nj->nk", C, centre)
    ca = radius[:, None] * np.einsum("nkj,nj->nk", C, e1)
    cb = radius[:, None] * np.einsum("nkj,nj->nk", C, e2)
    rho = np.hypot(ca, cb)
    active = np.ones((N, K), bool)
    empty = ~seen
    lengths = _norm(C)
    for k in range(K):                                                  # the same plane twice counts once
        for j in range(k):
            same = (lengths[:, j] > 0) & (lengths[:, k] > 0) & (_norm(np.cross(C[:, j], C[:, k])) <= _PARALLEL)
            agree = np.einsum("nk,nk->n", C[:, j], C[:, k]) > 0
            active[:, k] &= ~(same & agree & active[:, j])
            empty |= same & ~agree
    crosses = active & (rho > np.abs(alpha))
    empty |= np.any(active & ~crosses & (alpha < 0.0), axis=1)          # the whole disk outside a half-space
    inside = ~empty & (length <= radius)
    for k in range(K):
        inside &= np.einsum("nk,nk->n", C[:, k], foot) >= 0.0
    with np.errstate(invalid="ignore", divide="ignore"):
        phase = np.arctan2(cb, ca)
        half = np.arccos(np.clip(-alpha / np.where(rho > 0, rho, 1.0), -1.0, 1.0))
    s_plus = np.where(crosses, np.mod(phase + half + np.pi, 2 * np.pi) - np.pi, -np.pi)
    s_minus = np.where(crosses, np.mod(phase - half + np.pi, 2 * np.pi) - np.pi, -np.pi)
    # the rim, cut at every crossing and every 2 pi / 8: each arc wholly inside or outside each half-space
    grid = -np.pi + np.arange(_RIM_PIECES) * (2 * np.pi / _RIM_PIECES)
    cuts = np.sort(np.concatenate([np.broadcast_to(grid, (N, _RIM_PIECES)), s_plus, s_minus], axis=1), axis=1)
    width = np.diff(np.concatenate([cuts, cuts[:, :1] + 2 * np.pi], axis=1), axis=1)
    middle = cuts + 0.5 * width
    valid = (width > 0) & ~empty[:, None]
    for k in range(K):
        level = alpha[:, k, None] + ca[:, k, None] * np.cos(middle) + cb[:, k, None] * np.sin(middle)
        valid &= ~active[:, k, None] | (level >= 0.0)
    rows, cols = np.nonzero(valid)
    arcs = _Pieces(rows, np.ones(len(rows), bool), closest[rows], radius[rows, None] * e1[rows],
                   radius[rows, None] * e2[rows], cuts[rows, cols], width[rows, cols], False)
    # each crossing plane's chord, clipped by the other planes
    U, V = rim(s_plus), rim(s_minus)                                    # (N, K, 3)
    lo, hi = np.zeros((N, K)), np.ones((N, K))
    keep = crosses & ~empty[:, None]
    for j in range(K):
        a = np.einsum("nkd,nd->nk", U, C[:, j])
        b = np.einsum("nkd,nd->nk", V - U, C[:, j])
        use = active[:, j, None] & (np.arange(K)[None, :] != j)
        with np.errstate(invalid="ignore", divide="ignore"):
            root = -a / b
        lo = np.where(use & (b > 0), np.maximum(lo, root), lo)
        hi = np.where(use & (b < 0), np.minimum(hi, root), hi)
        keep &= ~(use & (b == 0) & (a < 0))
    keep &= hi > lo
    rows, cols = np.nonzero(keep)
    chords = _Pieces(rows, np.zeros(len(rows), bool), U[rows, cols], (V - U)[rows, cols], np.zeros((len(rows), 3)),
                     lo[rows, cols], (hi - lo)[rows, cols], True)
    pieces = _Pieces.concat([arcs, chords])
    return pieces.take(np.argsort(pieces.idx, kind="stable")), foot, inside
