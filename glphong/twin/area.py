"""The twin of ``glsl/area.glsl``, function by function: a uniform convex polygon seen from a point (docs/design.md
section 13).

Vectorised over points: a polygon is ``p`` (N, M, 3) vertices relative to each point, ``e`` (N, M, 3) its edges
(``e[:, i] = p[:, i + 1] - p[:, i]``), ``count`` (N,) int its number of vertices (entries beyond are ignored),
``M = AREA_MAX_VERTICES``.  The arithmetic runs in the dtype of the inputs; ``np.arctan2`` stands for the
GLSL's 3-ulp polynomial (`glphong.twin.functions.atan2_first_quadrant`).

- `area_polygon_cosine`: ``integral (n.w) dw = -(1/2) sum_i Theta_i (n . m_i)`` (Lambert's edge formula).
- `area_polygon_lobe`: ``integral (w.u)^q du = ((q even) Omega - sum_i (w . m_i) S_i) / (q + 1)`` (Arvo 1995) for
  integer ``q``, ``S_i`` the edge's sum of power integrals (`area_edge_powers`).
- `area_clip`: Sutherland-Hodgman against a plane through the point, keeping exact edge directions.
"""
import numpy as np

from glphong.twin.band import EPS
from glphong.twin.functions import atan2_first_quadrant, dot as _dot

__all__ = ["AREA_MAX_VERTICES", "area_angle", "area_clip", "area_polygon_cosine", "area_solid_angle",
           "area_edge_powers", "area_polygon_lobe", "area_clipped_cosine", "area_clipped_cosine_of", "area_clipped_lobe", "area_cosine_rounding", "area_lobe_rounding", "area_clip_rounding", "area_triangle_sample", "polygon_arrays"]

#: vertices a polygon may have after two clips (a light has at most 8)
AREA_MAX_VERTICES = 10


def _cross(a, b):
    """``np.cross(a, b)`` of (..., 3) arrays, bit for bit (its products and differences, in its order) without its
    general-purpose overhead."""
    a, b = np.asarray(a), np.asarray(b)
    shape = np.broadcast_shapes(a.shape, b.shape)
    out = np.empty(shape, np.result_type(a, b))
    a0, a1, a2 = a[..., 0], a[..., 1], a[..., 2]
    b0, b1, b2 = b[..., 0], b[..., 1], b[..., 2]
    np.subtract(a1 * b2, a2 * b1, out=out[..., 0])
    np.subtract(a2 * b0, a0 * b2, out=out[..., 1])
    np.subtract(a0 * b1, a1 * b0, out=out[..., 2])
    return out


def _norm(x):
    """``np.linalg.norm(x, axis=-1)`` of (..., 3) floats, bit for bit: ``sqrt`` of `dot` ``(x, x)`` (its sum's
    order)."""
    return np.sqrt(_dot(x, x))


def area_angle(y, x):
    """``atan2(y, x)`` in ``[0, pi]`` for ``y >= 0`` (area.glsl)."""
    angle = atan2_first_quadrant(y, np.abs(x))
    return np.where(x >= 0, angle, np.pi - angle)


def _live_width(count, size):
    """How many leading vertex slots any polygon uses: ``max(count)``, at most ``size`` (0 without polygons).  The
    functions below compute on those slots only: beyond them every entry is masked to 0 (or left out of a loop), and a
    sum over the vertices is taken over the zeros padded back to ``size`` (`_vertex_sum`), in numpy's order, so the
    results are those of the whole width, bit for bit."""
    return min(int(count.max()), size) if len(count) else 0


def _vertex_sum(terms, size):
    """``terms`` (N, W) padded with zeros to (N, size) and summed over the vertices (axis 1): the sum of the whole
    width, bit for bit, in numpy's order."""
    if terms.shape[1] == size:
        return terms.sum(axis=1)
    padded = np.zeros((terms.shape[0], size), terms.dtype)
    padded[:, :terms.shape[1]] = terms
    return padded.sum(axis=1)


def polygon_arrays(vertices, edges, x, dtype=np.float64):
    """``(p, e, count)`` of one polygon seen from points ``x`` (N, 3): ``vertices`` (V, 3) and ``edges`` (V, 3) as the
    uniforms hold them, padded to `AREA_MAX_VERTICES`."""
    x = np.asarray(x, dtype=dtype)
    v = np.asarray(vertices, dtype=dtype)
    n, count = len(x), len(v)
    p = np.zeros((n, AREA_MAX_VERTICES, 3), dtype)
    e = np.zeros((n, AREA_MAX_VERTICES, 3), dtype)
    p[:, :count] = v[None] - x[:, None]
    e[:, :count] = np.asarray(edges, dtype=dtype)[None]
    return p, e, np.full(n, count)


def area_clip(p, e, count, c):
    """The part of each polygon with ``c.y >= 0`` (area.glsl's ``area_clip``): new ``(p, e, count)``; ``c`` (N, 3).

    Sutherland-Hodgman as area.glsl loops it, vertex by vertex, here for all vertices at once: vertex ``i`` puts itself
    where it is inside (its edge cut where the next one is outside) and the cut point where its edge crosses the plane
    (the edge to the next put where it enters; where it leaves, the closing edge back to the polygon's first put is
    made at the end), each at the number of puts before it.  A put past ``size - 1`` (the GLSL's array bound) is
    dropped, as the loop's last slot is never live.  A polygon no edge of which crosses the plane keeps every vertex
    and edge where it is inside, and none where it is outside."""
    n, size = p.shape[:2]
    width = _live_width(count, size)  # beyond every polygon's count nothing is put
    q, f = np.zeros(p.shape, p.dtype), np.zeros(e.shape, e.dtype)  # (calloc'd pages: no fill of the 10 slots)
    if not width:
        return q, f, np.zeros(n, int)
    index = np.arange(width)[None, :]
    active = index < count[:, None]
    nxt = np.where(index + 1 < count[:, None], index + 1, 0)
    pw, ew = p[:, :width], e[:, :width]
    d = np.where(active, _dot(c[:, None, :], pw), 0.0)
    a_in = d >= 0
    b_in = np.take_along_axis(a_in, nxt, axis=1)
    crossing = active & (a_in != b_in)
    kept = active & a_in & (index < size - 1)  # where nothing crosses: the inside vertices, in their slots
    np.copyto(q[:, :width], pw, where=kept[..., None])
    np.copyto(f[:, :width], ew, where=kept[..., None])
    m = kept.sum(axis=1)
    cut = np.nonzero(crossing.any(axis=1))[0]
    if len(cut):
        q[cut], f[cut], m[cut] = _clip_crossing(pw[cut], ew[cut], d[cut], np.take_along_axis(d[cut], nxt[cut], axis=1),
                                                active[cut], size, e.dtype)
    return q, f, m


def _clip_crossing(pw, ew, d_a, d_b, active, size, edge_dtype):
    """`area_clip` of polygons an edge of which crosses the plane: ``(q, f, m)`` of width ``size`` from the first
    ``W`` slots ``pw``, ``ew`` (n, W, 3), each vertex's height ``d_a`` and its successor's ``d_b`` (n, W)."""
    n, width = d_a.shape
    a_in, b_in = d_a >= 0, d_b >= 0
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(a_in == b_in, 0.0, d_a / (d_a - d_b)).astype(pw.dtype, copy=False)[..., None]
        keep = active & a_in
        crossing = active & (a_in != b_in)
        # each vertex's two candidate puts, side by side, and a zero last: itself (its edge cut where the next vertex
        # is outside) and the cut point (the edge on to the next put where it enters, none yet where it leaves)
        points = np.zeros((n, 2 * width + 1, 3), pw.dtype)
        edges = np.zeros((n, 2 * width + 1, 3), edge_dtype)
        points[:, 0:2 * width:2] = pw
        np.multiply(ew, t, out=points[:, 1:2 * width:2])
        edges[:, 0:2 * width:2] = np.where(b_in[..., None], ew, points[:, 1:2 * width:2])
        points[:, 1:2 * width:2] += pw  # p + e t
        edges[:, 1:2 * width:2] = np.where(a_in[..., None], 0.0, ew * (1 - t))
    puts = keep.astype(int) + crossing
    first = np.cumsum(puts, axis=1) - puts  # the slot of vertex i's first put
    second = first + keep  # of its cut point
    last = size - 1  # a put from here on is dropped: the slot is never live
    slot = np.empty((n, 2 * width), int)
    slot[:, 0::2] = np.where(keep & (first < last), first, size)
    slot[:, 1::2] = np.where(crossing & (second < last), second, size)
    # which candidate each slot takes (2 width: none, the zero), as rows of the flattened candidates
    offset = (np.arange(n) * (2 * width + 1))[:, None]
    source = np.full((n, size + 1), 2 * width) + offset
    np.put_along_axis(source, slot, np.arange(2 * width)[None, :] + offset, axis=1)
    source = source[:, :size]
    q = np.take(points.reshape(-1, 3), source, axis=0)
    f = np.take(edges.reshape(-1, 3), source, axis=0)
    m = np.minimum(puts.sum(axis=1), last)
    open_ = np.max(np.where(crossing & a_in, second, -1), axis=1)  # the last leaving cut's slot
    has = (open_ >= 0) & (open_ < last)
    if has.any():
        r = np.nonzero(has)[0]
        o = open_[has]
        nxt = np.where(o + 1 < m[has], o + 1, 0)
        f[r, o] = q[r, nxt] - q[r, o]
    return q, f, m


def _edge_frames(p, e):
    g = _cross(p, e)
    s = _norm(g)
    return g, s


def _cosine_edges(p, e, count):
    """What `area_polygon_cosine` takes from the polygon alone: ``(theta, g, s, live, count, size)``, each edge's
    angle ``Theta_i``, its plane's normal ``g = p x e`` and ``|g|``, (N, W), (N, W, 3), (N, W)."""
    size = p.shape[1]
    width = _live_width(count, size)
    p, e = p[:, :width], e[:, :width]
    g, s = _edge_frames(p, e)
    theta = area_angle(s, _dot(p, p + e))
    live = (np.arange(width)[None, :] < count[:, None]) & (s > 0)
    return theta, g, s, live, count, size


def _cosine_sum(edges, n):
    """`area_polygon_cosine` from `_cosine_edges` and the normal ``n`` (N, 3)."""
    theta, g, s, live, count, size = edges
    with np.errstate(divide="ignore", invalid="ignore"):
        terms = np.where(live, theta * (_dot(n[:, None, :], g) / s), 0.0)
    return np.where(count >= 3, np.maximum(-0.5 * _vertex_sum(terms, size), 0.0), 0.0)


def area_polygon_cosine(p, e, count, n):
    """``integral over the polygon of (n.w) dw`` [sr], (N,): ``max(-(1/2) sum_i Theta_i (n . m_i), 0)``."""
    return _cosine_sum(_cosine_edges(p, e, count), n)


def area_solid_angle(p, e, count):
    """The polygon's solid angle [sr], (N,): its fan's triangles by Van Oosterom and Strackee where that is below 2 sr,
    else Girard's ``2 pi - sum`` of the exterior angles between consecutive edge planes (area.glsl)."""
    width = _live_width(count, p.shape[1])  # the slots beyond add nothing to either sum
    p, e = p[:, :width], e[:, :width]
    g, s = _edge_frames(p, e)
    live = (np.arange(width)[None, :] < count[:, None]) & (s > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        m = g / s[..., None]
    turn = np.zeros(len(p), p.dtype)
    first = np.zeros((len(p), 3), p.dtype)
    previous = np.zeros((len(p), 3), p.dtype)
    edges = np.zeros(len(p), int)
    for i in range(p.shape[1]):
        here = live[:, i]
        angle = area_angle(_norm(_cross(previous, m[:, i])), _dot(previous, m[:, i]))
        turn = np.where(here & (edges > 0), turn + angle, turn)
        first = np.where((here & (edges == 0))[:, None], m[:, i], first)
        previous = np.where(here[:, None], m[:, i], previous)
        edges = edges + here
    turn = turn + area_angle(_norm(_cross(previous, first)), _dot(previous, first))
    girard = np.where(edges >= 3, np.maximum(2 * np.pi - turn, 0.0), 0.0)
    if not width:
        return np.zeros(len(p), p.dtype)
    a = p[:, 0]
    la = _norm(a)
    omega = np.zeros(len(p), p.dtype)
    for i in range(1, width - 1):
        b, c = p[:, i], p[:, i + 1]
        lb, lc = _norm(b), _norm(c)
        y = np.abs(_dot(a, _cross(b, c)))
        x = la * lb * lc + _dot(a, b) * lc + _dot(a, c) * lb + _dot(b, c) * la
        omega = omega + np.where(i + 1 < count, 2.0 * area_angle(y, x), 0.0)
    return np.where(omega < 2.0, omega, girard)


def area_edge_powers(a, e, w, q, rounding=False):
    """``S = sum_{k in K} integral_0^Theta (w.u(t))^k dt`` along each edge (area.glsl), K of the parity opposite to
    the integer ``q``, below it; ``a``, ``e`` (..., 3), ``w`` broadcastable, ``q`` a number.  Forward recurrence.

    ``rounding`` (the band's, not the GLSL's): also return a first-order bound, in units of eps, of the float32
    rounding error of ``S``: each step's own rounding (``4 eps`` of the magnitudes it adds, ``2 eps`` of the result)
    plus the previous error scaled by the step's factor ``(k + 1) R^2 / (k + 2) <= 1``, the running sum's, and the
    early stop's (the tail bound ``Theta R^k / (1 - R^2)`` below ``2^-24`` of the sum, where float32 may stop a step
    apart from float64).
    """
    g, s = _edge_frames(a, e)
    with np.errstate(divide="ignore", invalid="ignore"):
        m = g / s[..., None]
        ua = a / _norm(a)[..., None]
        b = a + e
        ub = b / _norm(b)[..., None]
    theta = area_angle(s, _dot(a, b))
    sa, da = _dot(w, ua), _dot(w, _cross(m, ua))
    sb, db = _dot(w, ub), _dot(w, _cross(m, ub))
    r2 = np.sum(_cross(w, m) ** 2, axis=-1)  # |w x m|^2 = 1 - (w.m)^2, without cancelling where w ~ m
    qi = int(q)
    even = qi % 2 == 0
    ek = da - db if even else theta
    pa = sa * sa if even else sa
    pb = sb * sb if even else sb
    total = np.zeros(theta.shape, theta.dtype)
    err = 4 * (np.abs(da) + np.abs(db)) if even else 4 * theta   # E_0, E_1: the angle's, or the difference's
    bound = np.zeros(theta.shape, theta.dtype)
    rk = np.sqrt(r2) if even else np.ones_like(r2)
    with np.errstate(divide="ignore", invalid="ignore"):
        tail = theta / np.maximum(1 - r2, 1e-30)
    going = np.ones(np.shape(theta), bool)
    for k in range(1 if even else 0, qi, 2):
        going &= ~(rk * tail < 2.0 ** -24 * np.abs(total))  # the tail bound below 2^-24 of the sum: stop
        if not going.any():
            break
        rk = rk * r2
        total = np.where(going, total + ek, total)
        kn = k + 2
        new = ((kn - 1) * r2 * ek - (pb * db - pa * da)) / kn
        if rounding:
            bound = np.where(going, bound + err + np.abs(total), bound)
            err = (kn - 1) / kn * r2 * err + 4 * ((kn - 1) * r2 * np.abs(ek) + np.abs(pb * db) + np.abs(pa * da)) / kn \
                + 2 * np.abs(new) + 2 * k * (np.abs(pa) + np.abs(pb))   # s^(k+1) by k multiplications
        ek = new
        pa = pa * (sa * sa)
        pb = pb * (sb * sb)
    total = np.where(s > 0, np.nan_to_num(total), 0.0)
    bound = bound + 2 * np.abs(total)  # where the GPU's float32 sum stops a step earlier or later
    return (total, np.where(s > 0, np.nan_to_num(bound), 0.0)) if rounding else total


def area_cosine_rounding(p, e, count, n):
    """The band's bound (not in the GLSL) on the float32 rounding error of `area_polygon_cosine`, absolute, per unit
    radiance, (N,): ``(16 + count) eps (1/2) sum_i Theta_i``.  Each edge's term ``Theta_i (n.g_i)/|g_i|`` errs by a few
    eps of ``Theta_i`` whatever ``n.m_i`` (the atan2 polynomial's 3 ulp, its arguments', the dot product's absolute
    ``eps |g_i|``), and the sum of ``count`` terms by ``count eps`` of their magnitudes: the edge formula's
    cancellation (terms of size ``Theta ~ sqrt(Omega)`` summing to ``Omega``) is what makes a small light's relative
    error grow like ``eps / sqrt(Omega)`` (docs/design.md section 13)."""
    size = p.shape[1]
    width = _live_width(count, size)
    p, e = p[:, :width], e[:, :width]
    g, s = _edge_frames(p, e)
    theta = area_angle(s, _dot(p, p + e))
    live = np.arange(width)[None, :] < count[:, None]
    return np.where(count >= 3, (16 + count) * EPS * 0.5 * _vertex_sum(np.where(live, theta, 0.0), size), 0.0)


def area_clip_rounding(p, e, count, c, lobe=None):
    """The band's bound (not in the GLSL) on what the float32 clip by the plane ``c`` moves the integral by, per unit
    radiance, (N,).  An edge from ``p_i`` to ``p_j`` crossing the plane is cut at ``t = d_i / (d_i - d_j)`` with the
    heights ``d = c.p`` off by ``8 eps |p|``, so the cut point slides along the edge by ``dt <= min(8 eps (|p_i| +
    |p_j|) / |d_i - d_j|, 1)``: a sliver of angular width ``dt |e| / min|p|`` and length at most ``pi``, on which the
    integrand is at most the height ``dt |d_i - d_j| / min|p| + 8 eps`` above the plane (the cosine of a clip by the
    normal, or a lobe clipped by its own plane, which vanish on the plane) or, for ``lobe = (r, q)`` cut by the
    horizon, where it does not vanish, ``|r x m_i|^q``, the lobe's largest value on the edge's great circle.  Besides, the cut point is made
    twice (the kept piece ``e t`` and the new edge's difference), so the clipped polygon closes only to ``eps |p|``:
    ``8 eps`` per cut, absolute, the floor of a sliver's irradiance (measured: ``2.2e-8`` on a sliver of
    ``E/L = 2.6e-8``)."""
    size = p.shape[1]
    width = _live_width(count, size)
    p, e = p[:, :width], e[:, :width]
    live = np.arange(width)[None, :] < count[:, None]
    d = np.where(live, _dot(c[:, None, :], p), 0.0)
    nxt = np.where(np.arange(width)[None, :] + 1 < count[:, None], np.arange(width)[None, :] + 1, 0)
    d_next = np.take_along_axis(d, nxt, axis=1)
    length = _norm(p)
    nearest = np.minimum(length, np.take_along_axis(length, nxt, axis=1))
    crossing = live & ((d >= 0) != (d_next >= 0))
    with np.errstate(divide="ignore", invalid="ignore"):
        dt = np.minimum(8 * EPS * (length + np.take_along_axis(length, nxt, axis=1)) / np.abs(d - d_next), 1.0)
        width = dt * _norm(e) / nearest
        if lobe is None:
            height = dt * np.abs(d - d_next) / nearest + 8 * EPS
        else:
            g, s = _edge_frames(p, e)
            r, q = lobe
            height = np.minimum(_norm(_cross(r[:, None, :], g / s[..., None])), 1.0) ** q
        sliver = np.where(crossing, np.pi * np.nan_to_num(width * height, nan=0.0, posinf=np.pi) + 8 * EPS, 0.0)
    return _vertex_sum(sliver, size)


def area_lobe_rounding(p, e, count, w, q):
    """The band's bound (not in the GLSL) on the float32 rounding error of `area_polygon_lobe`, absolute, per unit
    radiance, (N,): ``eps ((q even) 16 Omega + sum_i (|w.m_i| B_i + 8 |S_i|) + 2 count |sum|) / (q + 1)`` with ``B_i``
    the propagated bound of `area_edge_powers` (``rounding=True``)."""
    size = p.shape[1]
    width = _live_width(count, size)
    g, s = _edge_frames(p[:, :width], e[:, :width])
    live = (np.arange(width)[None, :] < count[:, None]) & (s > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        weights = np.where(live, np.abs(_dot(w[:, None, :], g)) / s, 0.0)
    sums, bounds = area_edge_powers(p[:, :width], e[:, :width], w[:, None, :], q, rounding=True)
    sums, bounds = np.where(live, np.abs(sums), 0.0), np.where(live, bounds, 0.0)
    total = _vertex_sum(weights * (bounds + 8 * sums), size) + 2 * count * _vertex_sum(weights * sums, size)
    omega = 16 * area_solid_angle(p, e, count) if int(q) % 2 == 0 else 0.0
    return np.where(count >= 3, EPS * (omega + total) / (q + 1), 0.0)


def area_polygon_lobe(p, e, count, w, q):
    """``integral over the polygon of (w.u)^q du`` [sr] for integer ``q >= 0``, the polygon clipped to ``w.u >= 0``
    first, (N,): ``max(((q even) Omega - sum_i (w . m_i) S_i) / (q + 1), 0)``."""
    size = p.shape[1]
    width = _live_width(count, size)
    g, s = _edge_frames(p[:, :width], e[:, :width])
    live = (np.arange(width)[None, :] < count[:, None]) & (s > 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        weights = np.where(live, _dot(w[:, None, :], g) / s, 0.0)
    sums = np.where(live, area_edge_powers(p[:, :width], e[:, :width], w[:, None, :], q), 0.0)
    total = _vertex_sum(weights * sums, size)
    omega = area_solid_angle(p, e, count) if int(q) % 2 == 0 else 0.0
    return np.where(count >= 3, np.maximum((omega - total) / (q + 1), 0.0), 0.0)


def area_clipped_cosine(p, e, count, n):
    """`area_polygon_cosine` of the polygon clipped by ``n`` (area.glsl), (N,)."""
    return area_polygon_cosine(*area_clip(p, e, count, n), n)


def area_clipped_cosine_of(p, e, count):
    """``n -> area_clipped_cosine(p, e, count, n)`` for one polygon and many normals (a band's moves of ``n``), bit
    for bit: where every vertex lies on or above ``n``'s horizon the clip keeps the polygon as it is (`area_clip`), so
    its edges' angles and planes, computed once, serve every ``n``; elsewhere the clip and the formula run anew."""
    edges = None
    size = p.shape[1]

    def cosine(n):
        nonlocal edges
        width = _live_width(count, size)
        active = np.arange(width)[None, :] < count[:, None]
        whole = np.all(~active | (_dot(n[:, None, :], p[:, :width]) >= 0), axis=1) & (count < size)
        if edges is None:
            edges = _cosine_edges(p, e, count)
        out = _cosine_sum(edges, n)
        rest = np.nonzero(~whole)[0]
        if len(rest):
            out[rest] = area_clipped_cosine(p[rest], e[rest], count[rest], n[rest])
        return out

    return cosine


def area_clipped_lobe(p, e, count, n, r, q):
    """`area_polygon_lobe` about ``r`` of the polygon clipped by ``n`` and by ``r`` (area.glsl), (N,)."""
    return area_polygon_lobe(*area_clip(*area_clip(p, e, count, n), r), r, q)


def area_triangle_sample(a, e1, e2, m, k):
    """Cell ``k`` of the ``m^2`` congruent sub-triangles of ``(a, a + e1, a + e2)``: ``(centroid (..., 3), area
    (...))`` (area.glsl's midpoint rule)."""
    i = int(np.floor(np.sqrt(k)))
    i = i + 1 if (i + 1) ** 2 <= k else (i - 1 if i * i > k else i)
    jj = k - i * i
    b = jj // 2
    up = jj % 2 == 0
    fa = (i - b) + 1 / 3 if up else (i - 1 - b) + 2 / 3
    fb = b + 1 / 3 if up else b + 2 / 3
    point = a + e1 * (fa / m) + e2 * (fb / m)
    weight = 0.5 * _norm(_cross(e1, e2)) / (m * m)
    return point, weight
