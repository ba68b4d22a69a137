"""An independent float64 reference for area lights: the exact integral of a uniformly emitting polygon, sphere or
disk, at many surface points at once (docs/design.md section 13, the continuous version; section 11 for what a
light delivers).  It is the yardstick that closed forms and approximations of extended lights are measured against,
and it shares no code with them.

What is integrated
------------------
At a surface point ``x`` with unit normal ``n``, for a light of uniform radiance ``L`` [W/(m^2 sr)] (RGB)::

    I(x) = L * integral over Omega(x) of g(w) dw

``Omega(x)`` is the set of unit directions ``w`` from ``x`` that hit the light's emitting side and satisfy
``n.w >= 0`` and ``c.w >= 0`` for every extra clip plane ``c`` (planes through ``x``, e.g. the half-space of a
Phong lobe ``r.w >= 0``).  ``g`` is the caller's integrand (a BRDF response times the cosine, or just ``n.w`` for
the irradiance ``E``); ``dw`` is solid angle [sr].

The method
----------
1. *The region, clipped exactly.*  Every emitter is reduced to a convex planar region seen from ``x`` (coordinates
   relative to ``x``):

   - a polygon (emitting toward ``n_l = normalize((v1 - v0) x (v2 - v0))``, counter-clockwise seen from the front)
     is clipped by Sutherland-Hodgman against each plane ``{y : c.(y - x) >= 0}``; a point with
     ``n_l.(x - v0) <= 0`` (behind the light or on its plane) gets 0;
   - a disk (centre ``c``, unit normal ``m``, radius ``R``) is cut by the lines where each plane through ``x`` meets
     its plane: the rim crossings solve ``c.O + R (c.e1 cos(s) + c.e2 sin(s)) = 0`` (``O`` the centre relative to
     ``x``, angles ``s`` measured from the rim point nearest the foot of ``x``, and rim points computed as that
     point plus ``R ((cos(s) - 1) e1 + sin(s) e2)``, ``cos(s) - 1 = -2 sin^2(s/2)``, so that a rim passing a hair
     from ``x`` keeps its shape), the rim is split there into arcs each wholly inside or outside every half-space,
     and each plane's chord is clipped by the others (linear in the chord's parameter);
   - a sphere (centre ``c``, radius ``r``, at distance ``d > r``) is the cone of half angle ``alpha``, ``sin(alpha)
     = r/d``, about ``a = (c - x)/d``: exactly the cone over the *virtual disk* of centre ``x + cos(alpha) a``,
     radius ``sin(alpha)`` and normal ``-a`` (the circle where the cone touches the sphere, scaled to unit
     distance; ``cos(alpha) = sqrt((d - r)(d + r))/d``), so it is integrated as that disk.

   The horizon ``n.w >= 0`` is always the first plane; a plane given twice counts once, and two opposite planes
   leave nothing.  The integrand is then smooth over the region (kinks such as ``max(r.w, 0)`` belong in ``clip``).

2. *A fan in direction space.*  ``F`` is the direction to the region's point nearest ``x`` (the foot of the
   perpendicular when it lies inside).  For a convex set that point ``f`` satisfies ``(y - f).(f - x) >= 0`` for
   every ``y`` of the region, so every direction of the region lies within 90 degrees of ``F``.  The boundary is
   split into pieces (segments; arcs of at most 45 degrees of the rim) until each subtends at most 45 degrees at
   ``x`` (a segment at the point where the angle bisector meets it, ``t = |A| / (|A| + |B|)``; an arc at its
   middle, so a rim passing close to ``x`` is cut geometrically toward it), and segments are re-parametrised by
   their unit end directions.  Each piece ``P(s)``, ``s in [0, 1]``, with ``F`` spans one patch::

       w(s, t) = p / |p|,   p = F + t (B(s) - F),   B = P / |P|,   (s, t) in [0, 1]^2
       dw = t |det(F, P'(s), P(s))| / (|P(s)|^2 |p|^3) ds dt

   (``dw = p.(p_s x p_t) / |p|^3``).  ``|p| >= cos(45 deg)``, and nothing is divided by the distance to the light,
   so a light touching ``x`` (``x`` a hair in front of its plane or edge, where the area measure's ``cos_l / d^2``
   is singular) gives a smooth integrand all the same.

3. *Adaptive tensor Gauss-Legendre.*  Each patch is integrated with the 6 x 6 and the 9 x 9 tensor Gauss-Legendre
   rules on ``(s, t)``; the 9 x 9 value is kept and ``|Q9 - Q6|`` is its error estimate.  A point is done when the
   sum of its estimates is within ``tol = max(rtol |I|, 1e-300)`` (``|I|`` its largest channel), less what
   rounding takes (below); otherwise a patch whose estimate is within half that times its share of the point's
   solid angle is kept and the others are split 2 x 2 in ``(s, t)``, level by level, all ``(point, patch)`` pairs
   of a level as arrays, to ``max_depth`` levels.  Subdivision also stops at ``64 eps`` times the sum of
   ``|P'| |P| ... |g|`` (what the rounding of ``det`` is relative to: a region seen edge-on is known no better),
   and a guard holds the live patches to 400 000 (or 16 per first patch), refining the worst.

4. *The error estimate* is the sum over the final patches of ``|Q9 - Q6|`` (a generous bound on the 9 x 9 value's
   error: measured, it is 100 to 10 000 times the true error) plus a bound on rounding: every boundary point is
   computed within ``e = eps S`` of where it belongs (``S`` the size of the coordinates: ``|x| + max |v_i|``,
   ``|x| + |c| + R``, or for the sphere at unit distance ``(|x| + |c| + r)/d + sqrt(d/(d - r))``), which turns its
   direction by ``e/|P|``; so the region's measure is off by at most ``max |g|`` times ``e sum theta_k / dist_k``
   over the emitter's own boundary pieces (``theta_k`` the angle a piece subtends, ``dist_k`` its distance from
   ``x``) plus ``8 eps sum theta_k`` over the pieces cut by planes through ``x`` (they move across their plane only
   with its normal).  Near an edge at distance ``rho`` this grows like ``eps S / rho``, as the exact answer for
   inputs an ulp apart does.  ``converged`` is ``error <= tol``: False where the depth ran out or where rounding
   alone exceeds the tolerance.

The value is ``L`` times the integral: ``(N, 3)`` for an integrand of one channel (times the RGB radiance) or of
three (channel by channel).
"""
import numpy as np

__all__ = ["polygon_integral", "sphere_integral", "disk_integral"]

_EPS = np.finfo(np.float64).eps
_LOW, _HIGH = 6, 9                 # the tensor Gauss-Legendre orders compared on each patch
_SPLIT_ANGLE = np.pi / 4           # a boundary piece subtends at most this at x [rad]
_RIM_PIECES = 8                    # the rim is first cut into arcs of 2 pi / 8
_CHUNK_EVALS = 300_000             # integrand evaluations per call (bounds memory)
_MAX_LIVE = 400_000                # live patches at most, or 16 per first patch (a guard for integrands
                                   # that are not smooth)
_PARALLEL = 1e-13                  # two clip planes closer than this (|c_j x c_k|) are the same plane


def _gauss(n):
    x, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (x + 1.0), 0.5 * w


_RULES = (_gauss(_LOW), _gauss(_HIGH))


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
# Inputs
# --------------------------------------------------------------------------------------------------------------
def _points(x, normals):
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 2 or x.shape[1] != 3:
        raise ValueError(f"x must be (N, 3), got {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError("x has non-finite coordinates")
    normals = _unit(np.broadcast_to(np.asarray(normals, dtype=np.float64), x.shape), "normals")
    return x, np.ascontiguousarray(normals)


def _planes(normals, clip):
    """The horizon and the clip planes, each (N, 3), normalised (a zero vector stays zero: no constraint)."""
    if isinstance(clip, np.ndarray) and clip.ndim in (1, 2) and clip.shape[-1] == 3:
        clip = (clip,)
    planes = [normals]
    for c in clip:
        c = np.array(np.broadcast_to(np.asarray(c, dtype=np.float64), normals.shape))
        if not np.all(np.isfinite(c)):
            raise ValueError("a clip plane has non-finite components")
        length = _norm(c)
        c[length > 0] /= length[length > 0, None]
        planes.append(c)
    return planes


def _radiance(radiance):
    radiance = np.asarray(radiance, dtype=np.float64)
    if radiance.shape != (3,) or not np.all(np.isfinite(radiance)):
        raise ValueError(f"radiance must be three finite values (RGB), got shape {radiance.shape}")
    return radiance


def _round_emitter(x, normals, center, radius, radiance, clip, rtol, max_depth):
    """The checked arguments of a sphere or a disk: ``(x, center, radius, radiance, rtol, max_depth, planes)``."""
    x, normals = _points(x, normals)
    center = np.asarray(center, dtype=np.float64)
    radius = float(radius)
    if center.shape != (3,) or not np.all(np.isfinite(center)) or not (np.isfinite(radius) and radius > 0):
        raise ValueError("center must be (3,) and radius a positive number")
    rtol, max_depth = _check_budget(rtol, max_depth)
    return x, center, radius, _radiance(radiance), rtol, max_depth, _planes(normals, clip)


def _check_budget(rtol, max_depth):
    if not (np.isfinite(rtol) and rtol > 0):
        raise ValueError("rtol must be a positive number")
    if int(max_depth) != max_depth or max_depth < 0:
        raise ValueError("max_depth must be a non-negative integer")
    return float(rtol), int(max_depth)


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


def _check_polygon(vertices):
    vertices = np.asarray(vertices, dtype=np.float64)
    if vertices.ndim != 2 or vertices.shape[1] != 3 or len(vertices) < 3:
        raise ValueError(f"vertices must be (V, 3) with V >= 3, got {vertices.shape}")
    if not np.all(np.isfinite(vertices)):
        raise ValueError("vertices have non-finite coordinates")
    # the front normal normalize((v1 - v0) x (v2 - v0)), taken from the area vector (the same for a convex polygon,
    # and accurate when those three are nearly collinear)
    centred = vertices - vertices.mean(axis=0)
    front = np.sum(np.cross(centred, np.roll(centred, -1, axis=0)), axis=0)
    if _norm(front) == 0.0:
        raise ValueError("the polygon has no area: its front normal is undefined")
    front /= _norm(front)
    if np.cross(vertices[1] - vertices[0], vertices[2] - vertices[0]) @ front < 0:
        raise ValueError("the polygon is not convex and counter-clockwise seen from its front "
                         "(normalize((v1 - v0) x (v2 - v0)))")
    size = np.max(_norm(centred))
    if np.max(np.abs((vertices - vertices[0]) @ front)) > 1e-9 * size:
        raise ValueError("the polygon is not planar")
    edges = np.roll(vertices, -1, axis=0) - vertices
    turns = np.cross(edges, np.roll(edges, -1, axis=0)) @ front
    turning = np.sum(np.arctan2(turns, np.sum(edges * np.roll(edges, -1, axis=0), axis=1)))
    if np.min(turns) < -1e-12 * size ** 2 or abs(turning - 2.0 * np.pi) > 1e-6:
        raise ValueError("the polygon is not convex and counter-clockwise seen from its front "
                         "(normalize((v1 - v0) x (v2 - v0)))")
    return vertices, front


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


def polygon_integral(x, normals, vertices, radiance, integrand, clip=(), rtol=1e-9, max_depth=12):
    """The integral of ``g(w) L`` over the directions from each point to a uniformly emitting convex polygon.

    Parameters
    ----------
    x : (N, 3) array_like
        Surface points [m].
    normals : (N, 3) or (3,) array_like
        Unit surface normals (normalised here).
    vertices : (V, 3) array_like
        A planar convex polygon, ``V >= 3`` [m].  It emits only toward the side from which its vertices appear
        counter-clockwise: the front normal ``normalize((v1 - v0) x (v2 - v0))``.  A point behind the polygon's
        plane or on it gets 0.
    radiance : (3,) array_like
        The light's uniform radiance ``L`` [W/(m^2 sr)], RGB.
    integrand : callable
        ``integrand(index, w) -> (M, C)`` float64, ``C`` 1 or 3 (or ``(M,)``): ``index`` (M,) int, the point each
        direction belongs to; ``w`` (M, 3), unit directions from ``x[index]``.  It must be smooth over the clipped
        region (put a kink such as ``max(r.w, 0)`` into ``clip``).  ``M`` is a few hundred thousand at most.
    clip : tuple of (N, 3) or (3,) array_like
        Extra planes through each ``x``: only directions with ``c.w >= 0`` count.  The horizon ``n.w >= 0`` is
        always applied.
    rtol : float
        Relative tolerance on each point's integral (its largest channel).
    max_depth : int
        Levels of 2 x 2 subdivision of a patch at most.

    Returns
    -------
    value : (N, 3) float64 ndarray
        ``L`` times the integral: an integrand of one channel times the RGB radiance, one of three channel by
        channel [W/m^2 for ``g = n.w``; W/m^2 times the unit of ``g/(n.w)`` in general].
    error : (N,) float64 ndarray
        Estimated absolute error of ``value`` (its largest channel), same unit: the quadrature's estimate plus a
        bound on what rounding the geometry (``eps`` times the coordinates' size) moves the region's boundary by,
        which grows like ``1/distance`` as ``x`` nears the polygon's edge (module docstring).
    converged : (N,) bool ndarray
        Whether the error is within ``rtol`` times the integral (its largest channel): False where the depth ran
        out or where rounding alone exceeds that (a point a hair from an edge).
    """
    x, normals = _points(x, normals)
    vertices, front = _check_polygon(vertices)
    radiance = _radiance(radiance)
    rtol, max_depth = _check_budget(rtol, max_depth)
    planes = _planes(normals, clip)
    pieces, foot, inside = _polygon_region(x, planes, vertices, front)
    scale = _norm(x) + np.max(_norm(vertices))
    return _run(pieces, foot, inside, integrand, radiance, len(x), rtol, max_depth, scale)


def sphere_integral(x, normals, center, radius, radiance, integrand, clip=(), rtol=1e-9, max_depth=12):
    """The integral of ``g(w) L`` over the cone of directions from each point to a uniformly emitting sphere.

    The cone has half angle ``alpha = asin(r/d)`` about the direction to the centre (``d`` the distance to it);
    it is integrated as the disk it passes through at unit distance (module docstring).

    Parameters
    ----------
    x : (N, 3) array_like
        Surface points [m], all outside the sphere (``ValueError`` otherwise, saying how many are not).
    normals : (N, 3) or (3,) array_like
        Unit surface normals (normalised here).
    center : (3,) array_like
        The sphere's centre [m].
    radius : float
        The sphere's radius [m], positive.
    radiance : (3,) array_like
        The sphere's uniform radiance ``L`` [W/(m^2 sr)], RGB.
    integrand : callable
        ``integrand(index, w) -> (M, C)``, as for `polygon_integral`.
    clip : tuple of (N, 3) or (3,) array_like
        Extra planes through each ``x`` (``c.w >= 0`` counts); the horizon ``n.w >= 0`` is always applied.
    rtol : float
        Relative tolerance on each point's integral (its largest channel).
    max_depth : int
        Levels of 2 x 2 subdivision of a patch at most.

    Returns
    -------
    value : (N, 3) float64 ndarray
        ``L`` times the integral (as for `polygon_integral`).
    error : (N,) float64 ndarray
        Estimated absolute error of ``value`` (its largest channel).
    converged : (N,) bool ndarray
        Whether the error is within ``rtol`` times the integral (as for `polygon_integral`).
    """
    x, center, radius, radiance, rtol, max_depth, planes = _round_emitter(x, normals, center, radius, radiance, clip,
                                                                           rtol, max_depth)
    offset = center - x
    d = _norm(offset)
    outside = d > radius
    if not outside.all():
        raise ValueError(f"{int(np.count_nonzero(~outside))} of {len(x)} points are inside the sphere or on it "
                         f"(distance to the centre <= radius)")
    a = offset / d[:, None]
    sin_a = radius / d
    cos_a = np.sqrt((d - radius) * (d + radius)) / d
    e1, e2 = _perpendiculars(a)
    pieces, foot, inside = _disk_region(cos_a[:, None] * a, -a, sin_a, e1, e2, planes, np.ones(len(x), bool))
    # at unit distance: the direction to the centre is known to eps (|x| + |c|)/d, the cone's edge to about
    # eps sqrt(d/(d - r)) (cos(alpha) from d - r)
    scale = (_norm(x) + _norm(center) + radius) / d + np.sqrt(d / (d - radius))
    return _run(pieces, foot, inside, integrand, radiance, len(x), rtol, max_depth, scale)


def disk_integral(x, normals, center, normal, radius, radiance, integrand, clip=(), rtol=1e-9, max_depth=12):
    """The integral of ``g(w) L`` over the directions from each point to a one-sided uniformly emitting disk.

    Parameters
    ----------
    x, normals, center, radius, radiance, integrand, clip, rtol, max_depth
        As for `sphere_integral` (the disk's centre, radius and radiance).
    normal : (3,) array_like
        The side the disk emits toward (normalised here).  A point behind the disk's plane or on it gets 0.

    Returns
    -------
    value, error, converged
        As for `sphere_integral`; the error grows like ``1/distance`` as ``x`` nears the rim (`polygon_integral`).
    """
    x, center, radius, radiance, rtol, max_depth, planes = _round_emitter(x, normals, center, radius, radiance, clip,
                                                                           rtol, max_depth)
    normal = _unit(normal, "normal")
    if normal.shape != (3,):
        raise ValueError("normal must be (3,)")
    N = len(x)
    O = center - x
    seen = -(O @ normal) > 0.0
    e1, e2 = _perpendiculars(normal)
    pieces, foot, inside = _disk_region(O, np.broadcast_to(normal, (N, 3)), np.full(N, radius),
                                        np.broadcast_to(e1, (N, 3)), np.broadcast_to(e2, (N, 3)), planes, seen)
    scale = _norm(x) + _norm(center) + radius
    return _run(pieces, foot, inside, integrand, radiance, N, rtol, max_depth, scale)
