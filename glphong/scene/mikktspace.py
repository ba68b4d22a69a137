"""MikkTSpace tangents (Mikkelsen 2008, "Simulation of wrinkled surfaces revisited"), vectorised in numpy.

The glTF specification asks a client to compute missing tangents "using default MikkTSpace algorithms with the
specified vertex positions, normals, and texture coordinates"; Blender, three.js and the glTF Sample Viewer run the
reference ``mikktspace.c`` (``genTangSpaceDefault``).  This module computes what that code computes for triangles,
in float32 as it does, step by step:

1. **Welding.**  Corners with equal position, normal and uv (float32 values: ``-0 == 0``; a NaN welds with nothing)
   are one vertex; the mesh's own indices play no part, so an indexed mesh and its unindexed copy give the same
   tangents.  Which corner stands for the vertex (its ``4 triangle + corner``) is the reference's, its grid-and-split
   weld emulated (`_weld`), because step 4's sort depends on it.
2. **Degenerate triangles** (two corners at the same position) take no part; each of their corners copies the
   tangent of the first healthy corner of the same welded vertex (triangle order), else ``(1, 0, 0)``, sign -1.
3. **Per triangle**, with ``e1, e2`` the edges from corner 0 and ``(s1, t1), (s2, t2)`` the uv differences,
   ``A = s1 t2 - t1 s2`` (twice the signed uv area): ``Os = t2 e1 - t1 e2``, ``Ot = s1 e2 - s2 e1``, each
   normalised and multiplied by ``sign(A)`` (``A > 0``: orientation preserving), magnitudes ``|Os| / |A|``,
   ``|Ot| / |A|``.  A triangle with ``|A|`` or a magnitude at most ``FLT_MIN`` is "group with any".
4. **Neighbours**: two triangles that share a welded edge with opposite winding (the first unpaired one in triangle
   order where more than two share it), in the order of the reference's edge sort, which leaves its last run (the
   edges whose smaller welded index is the largest) as its quicksort left them, so that some of those edges stay
   unpaired: reproduced (`_sorted_tail`).
5. **Groups**: around each welded vertex, the triangles reached from one another across such edges with the same
   orientation; a "group with any" triangle takes the orientation of the first group (in the order of the groups'
   first triangle and corner) that reaches it, which is the reference's one order dependence, reproduced exactly.
6. **Subgroups** (the angular threshold, 180 degrees by default, ``cos = -1`` in float32): a corner's tangent
   averages the triangles of its group whose projected ``Os`` and ``Ot`` are not exactly opposite its own.  The
   reference compares every pair of a group's triangles; here a group of more than 1024 triangles (at one vertex) is
   never split, a bound on the work on hostile files, the only departure besides `_sorted_tail`'s.
7. **The tangent**: the sum of the group's healthy triangles' ``Os``, each projected onto the plane of the vertex
   normal (as given: the reference assumes unit normals), normalised and weighted by the triangle's angle at the
   vertex (between its two edges projected onto that plane), normalised; the sign ``w`` is +1 for an orientation
   preserving group, -1 otherwise (the bitangent is ``w n x t``).  A corner no group reaches gets ``(1, 0, 0)``, -1.

Vectors are normalised only where a component exceeds ``FLT_MIN`` in magnitude (the reference's ``VNotZero``).  The
result is per corner; `mikktspace_vertices` gives each vertex whose corners differ (a vertex on a mirror line of the
uv map, between groups) one copy per tangent, as an indexed mesh needs.  Checked against the reference's WebAssembly
build (npm ``mikktspace``) in tests/test_mikktspace.py (tests/data/mikktspace/README.md).  Quads are not handled
(glphong's meshes are triangles).
"""
import collections

import numpy as np

__all__ = ["mikktspace_corners", "mikktspace_vertices"]

_F = np.float32
_FLT_MIN = _F(np.finfo(np.float32).tiny)
_THRESHOLD_COS = _F(np.cos(_F(180.0) * _F(np.pi) / _F(180.0)))  # genTangSpaceDefault's 180 degrees: -1 in float32
_DEFAULT = np.array([1.0, 0.0, 0.0, -1.0], np.float32)  # an unreached corner: vOs (1, 0, 0), bOrient false
_SUBGROUP_LIMIT = 1024  # groups above it are not split by the threshold (a bound on the pairs' work)
_PAIRS = 1 << 22  # corner pairs compared at once


def _dot(a, b):
    """``a.x b.x + a.y b.y + a.z b.z`` in the reference's order, (..., 3) -> (...)."""
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def _normalized(v):
    """``v / |v|`` where a component of ``v`` exceeds FLT_MIN in magnitude, else ``v`` (float32, (..., 3))."""
    nonzero = np.any(np.abs(v) > _FLT_MIN, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        scaled = v * (_F(1.0) / np.sqrt(_dot(v, v)))[..., None]
    return np.where(nonzero[..., None], scaled, v)


def _projected(v, n):
    """``normalized(v - (n.v) n)``, the reference's projection onto the plane of ``n`` (float32, (..., 3))."""
    return _normalized(v - _dot(n, v)[..., None] * n)


def _equal_ids(rows):
    """(C,) ids equal exactly where the float32 rows are equal as values (-0 == 0; a row with a NaN equals none)."""
    rows = np.ascontiguousarray(rows + _F(0.0))  # -0 + 0 = +0
    ids = np.unique(rows.view(np.dtype((np.void, rows.itemsize * rows.shape[1]))).ravel(),
                    return_inverse=True)[1].reshape(-1)
    nan = np.isnan(rows).any(axis=1)
    ids[nan] = ids.max(initial=-1) + 1 + np.arange(int(nan.sum()))
    return ids


def _runs(*columns):
    """``(first, size)`` of the runs of equal rows in sorted (N,) columns."""
    change = np.zeros(max(len(columns[0]) - 1, 0), bool)
    for c in columns:
        change |= c[1:] != c[:-1]
    first = np.flatnonzero(np.r_[len(columns[0]) > 0, change])
    return first, np.diff(np.r_[first, len(columns[0])])


def _stop_pairs(at, seg, stops_left, stops_right):
    """Per segment, the k-th position from the left where ``stops_left`` and the k-th from the right where
    ``stops_right``, for k below the smaller count: ``(a, b)`` aligned, by segment then k (``at``: the positions,
    ascending within each segment; ``seg``: their segment, ascending)."""
    lp, rp = np.flatnonzero(stops_left), np.flatnonzero(stops_right)
    count = int(seg.max(initial=-1)) + 1
    nl, nr = np.bincount(seg[lp], minlength=count), np.bincount(seg[rp], minlength=count)
    pairs = np.minimum(nl, nr)
    kl = np.arange(len(lp)) - np.repeat(np.cumsum(nl) - nl, nl)
    kr = np.repeat(np.cumsum(nr) - 1, nr) - np.arange(len(rp))  # counted from the segment's right end
    rp[np.repeat(np.cumsum(nr) - nr, nr) + kr] = rp.copy()
    kr = np.arange(len(rp)) - np.repeat(np.cumsum(nr) - nr, nr)
    return at[lp[kl < pairs[seg[lp]]]], at[rp[kr < pairs[seg[rp]]]]


def _weld(p, key):
    """(C,) welded index of each corner ``k`` (triangle ``k // 3``): the reference's ``4 triangle + corner`` of the
    corner its weld keeps (step 1).  Which corner it keeps decides the order of its edge sort (`_pair_edges`), so the
    weld is the reference's: corners in 2048 cells along the bounding box's longest axis, each cell split at the middle
    of its box's longest axis until flat (``MergeVertsFast``, its swaps emulated level by level), then each corner
    welded to the first equal one in its cell's final order (``p``: (C, 3) float32 positions; ``key``: (C,) ids equal
    where position, normal and uv are)."""
    count = len(p)
    make_index = 4 * (np.arange(count) // 3) + np.arange(count) % 3
    lo, hi = p.min(axis=0), p.max(axis=0)
    dim = hi - lo
    axis = 1 if dim[1] > dim[0] and dim[1] > dim[2] else (2 if dim[2] > dim[0] else 0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        x = _F(2048) * ((p[:, axis] - lo[axis]) / (hi[axis] - lo[axis]))
    cell = np.where(np.isnan(x) | (x < 0), 0, np.minimum(np.nan_to_num(x, posinf=2047), 2047)).astype(np.int64)
    order = np.argsort(cell, kind="stable")  # each cell's corners in corner order
    first, size = _runs(cell[order])
    rep = make_index.copy()
    while len(first):
        keep = size >= 2
        first, size = first[keep], size[keep]
        starts = np.cumsum(size) - size
        seg = np.repeat(np.arange(len(first)), size)
        at = np.repeat(first, size) + (np.arange(len(seg)) - np.repeat(starts, size))
        pts = p[order[at]]
        mn, mx = np.minimum.reduceat(pts, starts), np.maximum.reduceat(pts, starts)
        d = mx - mn
        axis = np.where((d[:, 1] > d[:, 0]) & (d[:, 1] > d[:, 2]), 1, np.where(d[:, 2] > d[:, 0], 2, 0))
        pick = np.arange(len(first))
        with np.errstate(over="ignore", invalid="ignore"):
            sep = _F(0.5) * (mx[pick, axis] + mn[pick, axis])
        leaf = (sep >= mx[pick, axis]) | (sep <= mn[pick, axis])
        in_leaf = leaf[seg]
        if in_leaf.any():  # weld each corner to the first equal corner of its leaf, in the leaf's order
            corners, leaf_of = order[at[in_leaf]], seg[in_leaf]
            both = np.lexsort((np.arange(len(corners)), key[corners], leaf_of))
            runs, sizes = _runs(leaf_of[both], key[corners][both])
            rep[corners[both]] = make_index[corners[both[np.repeat(runs, sizes)]]]
        moving = ~in_leaf
        at, seg, pts = at[moving], seg[moving], pts[moving]
        goes_left = pts[np.arange(len(at)), axis[seg]] < sep[seg]
        a, b = _stop_pairs(at, seg, ~goes_left, goes_left)
        swap = a < b
        order[a[swap]], order[b[swap]] = order[b[swap]], order[a[swap]]
        left = np.bincount(seg, goes_left, minlength=len(first)).astype(np.int64)
        split = ~leaf
        first = np.concatenate([first[split], first[split] + left[split]])
        size = np.concatenate([left[split], size[split] - left[split]])
    return rep


def _next_seed(seed):
    """The reference's quicksort's pseudo-random step (32-bit)."""
    t = seed & 31
    return (seed + (((seed << t) | (seed >> (32 - t))) & 0xFFFFFFFF if t else seed) + 3) & 0xFFFFFFFF


def _sorted_tail(keys):
    """The entries (indices into ``keys``) of the largest key in the order the reference's edge quicksort
    (``QuickSortEdges``: Hoare's partition around a pseudo-randomly chosen pivot) leaves them, which the reference
    never sorts further (its second and third passes stop before the last run).  Past ``64 N`` entries partitioned
    (a sort gone quadratic, which the pseudo-random pivots make unlikely) the entries are returned in index order."""
    order = np.arange(len(keys))
    tail = len(keys) - int(np.sum(keys == keys.max()))
    stack, work = [(0, len(keys) - 1, 39871946)], 0
    while stack:
        left, right, seed = stack.pop()
        size = right - left + 1
        work += size
        if work > 64 * len(keys):
            return np.flatnonzero(keys == keys.max())
        if size == 2 and keys[order[left]] > keys[order[right]]:
            order[[left, right]] = order[[right, left]]
        if size <= 2:
            continue
        seed = _next_seed(seed)
        part = keys[order[left:right + 1]]
        mid = part[seed % size]
        a, b = np.flatnonzero(part >= mid), np.flatnonzero(part <= mid)[::-1]
        pairs = min(len(a), len(b))
        k = int(np.sum(a[:pairs] <= b[:pairs]))  # swaps until the stops cross (k >= 1: the pivot stops both scans)
        order[left + a[:k]], order[left + b[:k]] = order[left + b[:k]], order[left + a[:k]]
        if a[k - 1] == b[k - 1]:
            low, high = b[k - 1] - 1, a[k - 1] + 1
        else:  # the next scans stop at the next original stop or at the last swapped pair
            high = min(a[k], b[k - 1]) if k < len(a) else b[k - 1]
            low = max(b[k], a[k - 1]) if k < len(b) else a[k - 1]
        if left < left + low and left + low >= tail:
            stack.append((left, left + low, seed))
        if left + high < right:
            stack.append((left + high, right, seed))
    return order[tail:]


def _pair_edges(cw):
    """(G, 3) neighbour of each good triangle across its edge k (corners k, k+1), or -1 (step 4): the first later
    entry of the same welded edge with the opposite direction, in the order of the reference's edge sort (welded
    indices, then triangle; the run of the largest smaller index in its quicksort's order, `_sorted_tail`)."""
    count = len(cw)
    a, b = cw.reshape(-1), np.roll(cw, -1, axis=1).reshape(-1)
    lo, hi, tri = np.minimum(a, b), np.maximum(a, b), np.repeat(np.arange(count), 3)
    last = lo == lo.max()
    order = np.lexsort((tri, hi, lo))
    order = order[~last[order]]
    first, sizes = _runs(lo[order], hi[order])
    neighbours = np.full(3 * count, -1, np.int64)
    two = first[sizes == 2]
    one, other = order[two], order[two + 1]
    opposite = a[one] == b[other]
    neighbours[one[opposite]], neighbours[other[opposite]] = other[opposite] // 3, one[opposite] // 3
    pieces = [order[s:s + z] for s, z in zip(first[sizes > 2], sizes[sizes > 2])]  # edges of three or more
    tail = _sorted_tail(lo)
    starts, lengths = _runs(hi[tail])
    for i, (s, z) in enumerate(zip(starts, lengths)):  # the third pass sorts each piece by triangle but the last
        pieces.append(tail[s:s + z] if i == len(starts) - 1 else np.sort(tail[s:s + z]))
    forward = a < b
    for slots in pieces:  # each unpaired entry takes the first later unpaired one of the other direction: a queue
        waiting = collections.deque()
        for slot in slots.tolist():
            if waiting and forward[waiting[0]] != forward[slot]:
                other = waiting.popleft()
                neighbours[slot], neighbours[other] = other // 3, slot // 3
            else:
                waiting.append(slot)
    return neighbours.reshape(count, 3)


def _corner_neighbours(cw, neighbours):
    """``(left, right)``: per corner ``3 g + i`` the corner of the same welded vertex in the neighbour across edge
    ``i`` and across edge ``i - 1`` (or -1)."""
    out = []
    for edge in (neighbours, np.roll(neighbours, 1, axis=1)):
        t = edge.reshape(-1)
        safe = np.maximum(t, 0)
        j = np.argmax(cw[safe] == cw.reshape(-1)[:, None], axis=1)
        out.append(np.where(t >= 0, 3 * safe + j, -1))
    return out


def _components(count, a, b):
    """Connected-component labels (the smallest member) of ``count`` nodes joined by the edges ``(a, b)``."""
    parent = np.arange(count)
    while True:
        while True:
            jumped = parent[parent]
            if np.array_equal(jumped, parent):
                break
            parent = jumped
        ra, rb = parent[a], parent[b]
        apart = ra != rb
        if not apart.any():
            return parent
        np.minimum.at(parent, np.maximum(ra, rb)[apart], np.minimum(ra, rb)[apart])


def _groups(cw, orient, gwa, left, right):
    """(3G,) group label per corner (-1: in no group) and the (3G,) orientation each corner's group has (step 5)."""
    corners = 3 * len(cw)
    tri = np.arange(corners) // 3
    affected = np.zeros(cw.max(initial=0) + 1, bool)
    affected[cw[gwa].reshape(-1)] = True
    at_affected = affected[cw.reshape(-1)]
    labels = np.full(corners, -1, np.int64)
    plain = ~at_affected  # vertices without a group-with-any triangle: components of equal orientation
    a = np.concatenate([np.flatnonzero(plain)] * 2)
    b = np.concatenate([left[plain], right[plain]])
    keep = (b >= 0) & (orient[tri[a]] == orient[tri[np.maximum(b, 0)]])
    labels[plain] = _components(corners, a[keep], b[keep])[plain]
    group_orient = orient[tri].copy()
    seeds = np.flatnonzero(at_affected & ~gwa[tri])
    if len(seeds):  # the reference's order, at the vertices where it matters (python lists: a sequential walk)
        lab, l_list, r_list = labels.tolist(), left.tolist(), right.tolist()
        ori, gw, touched = orient.tolist(), gwa.tolist(), [False] * len(cw)
        for seed in seeds.tolist():
            if lab[seed] >= 0:
                continue
            label, mine = corners + seed, ori[seed // 3]
            stack = [seed]
            while stack:
                c = stack.pop()
                t = c // 3
                if lab[c] >= 0:
                    continue
                if gw[t] and not touched[t]:
                    ori[t] = mine
                if ori[t] != mine:
                    continue
                lab[c], touched[t] = label, True
                if l_list[c] >= 0:
                    stack.append(l_list[c])
                if r_list[c] >= 0:
                    stack.append(r_list[c])
        labels = np.array(lab, np.int64)
        done = labels >= corners
        group_orient[done] = np.array(ori, bool)[(labels[done] - corners) // 3]
    return labels, group_orient


def _corner_terms(p, n, tri_os, tri_ot):
    """Per corner of the good triangles: ``Os`` and ``Ot`` projected at the corner's normal, and the corner's angle
    between its edges projected onto that plane (each (3G, 3) or (3G,) float32)."""
    nc = n.reshape(-1, 3)
    os_ = _projected(np.repeat(tri_os, 3, axis=0), nc)
    ot = _projected(np.repeat(tri_ot, 3, axis=0), nc)
    here = p.reshape(-1, 3)
    previous, following = np.roll(p, 1, axis=1).reshape(-1, 3), np.roll(p, -1, axis=1).reshape(-1, 3)
    v1, v2 = _projected(previous - here, nc), _projected(following - here, nc)
    angle = np.arccos(np.clip(_dot(v1, v2), _F(-1.0), _F(1.0)).astype(np.float64)).astype(np.float32)
    return os_, ot, angle


def mikktspace_corners(positions, normals, indices, uvs):
    """MikkTSpace tangent of every triangle corner (the module's steps; the reference's defaults).

    Parameters
    ----------
    positions, normals : (V, 3) array_like
        Vertex positions [any length unit] and normals (unit length, as the reference assumes); read as float32.
    indices : (F, 3) array_like of int
        Triangles.
    uvs : (V, 2) array_like
        Texture coordinates (the tangent follows ``+u``; ``w`` is the sign with which ``w n x t`` follows ``+v``).

    Returns
    -------
    (F, 3, 4) float32 ndarray
        Per corner the unit tangent (or zero where its projected sum vanishes) and ``w = +-1``.
    """
    p32, n32, uv32 = (np.asarray(a, np.float32) for a in (positions, normals, uvs))
    f = np.asarray(indices, np.int64).reshape(-1, 3)
    if len(f) == 0:
        return np.zeros((0, 3, 4), np.float32)
    key = _equal_ids(np.concatenate([p32, n32, uv32], axis=1))[f].reshape(-1)
    wid = _weld(p32[f].reshape(-1, 3), key).reshape(-1, 3)
    p = p32[f]
    degenerate = np.any((p == np.roll(p, -1, axis=1)).all(axis=2), axis=1)
    good = np.flatnonzero(~degenerate)
    out = np.tile(_DEFAULT, (len(f), 3, 1))
    if len(good):
        cw, p, n, uv = wid[good], p[good], n32[f[good]], uv32[f[good]]
        t21, t31 = uv[:, 1] - uv[:, 0], uv[:, 2] - uv[:, 0]
        d1, d2 = p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]
        area = t21[:, 0] * t31[:, 1] - t21[:, 1] * t31[:, 0]
        tri_os = t31[:, 1:2] * d1 - t21[:, 1:2] * d2
        tri_ot = -t31[:, 0:1] * d1 + t21[:, 0:1] * d2
        orient = area > 0
        usable = np.abs(area) > _FLT_MIN
        sign = np.where(orient, _F(1.0), _F(-1.0))
        tri_terms = []
        with np.errstate(divide="ignore", invalid="ignore"):
            for v in (tri_os, tri_ot):
                length = np.sqrt(_dot(v, v))
                unit = v * (sign / length)[:, None]
                tri_terms.append((np.where((usable & (length > _FLT_MIN))[:, None], unit, _F(0.0)),
                                  np.where(usable, length / np.abs(area), _F(0.0))))
        (tri_os, mag_s), (tri_ot, mag_t) = tri_terms
        gwa = ~(usable & (mag_s > _FLT_MIN) & (mag_t > _FLT_MIN))
        left, right = _corner_neighbours(cw, _pair_edges(cw))
        labels, group_orient = _groups(cw, orient, gwa, left, right)
        os_, ot, angle = _corner_terms(p, n, tri_os, tri_ot)
        gwa_corner = np.repeat(gwa, 3)
        result = _group_tangents(labels, os_, ot, angle, gwa_corner)
        result = np.concatenate([result, np.where(group_orient, _F(1.0), _F(-1.0))[:, None]], axis=1)
        result[labels < 0] = _DEFAULT
        out[good] = result.reshape(-1, 3, 4)
        bad = np.flatnonzero(degenerate)
        if len(bad):  # step 2: the first healthy corner of the same welded vertex
            ids, first = np.unique(cw.reshape(-1), return_index=True)
            where = np.searchsorted(ids, wid[bad])
            where = np.minimum(where, len(ids) - 1)
            found = ids[where] == wid[bad]
            copied = result[first[where]]
            out[bad] = np.where(found[..., None], copied, _DEFAULT)
    return out


def _group_tangents(labels, os_, ot, angle, gwa_corner):
    """(3G, 3) float32 tangent per corner: its group's angle-weighted ``Os`` (steps 6 and 7; labels -1 ignored)."""
    corners = len(labels)
    order = np.lexsort((np.arange(corners), labels))
    order = order[labels[order] >= 0]
    sorted_labels = labels[order]
    starts = np.flatnonzero(np.r_[True, sorted_labels[1:] != sorted_labels[:-1]]) if len(order) else np.zeros(0, int)
    sizes = np.diff(np.r_[starts, len(order)])
    group_of = np.repeat(np.arange(len(starts)), sizes)
    weighted = np.where(gwa_corner[order][:, None], _F(0.0), angle[order][:, None] * os_[order])
    sums = np.zeros((len(starts), 3), np.float32)
    np.add.at(sums, group_of, weighted)
    out = np.zeros((corners, 3), np.float32)
    out[order] = _normalized(sums)[group_of]
    # step 6: pairs of healthy corners of one group whose Os or Ot are exactly opposite split the group.  Where every
    # healthy member is within 89.9 degrees of the group's first (both Os and Ot), no two are 180 degrees apart.
    lead = order[starts][group_of]
    near = (_dot(os_[order], os_[lead]) > _F(1e-3)) & (_dot(ot[order], ot[lead]) > _F(1e-3))
    suspect = np.zeros(len(starts), bool)
    suspect[group_of[~near & ~gwa_corner[order]]] = True
    suspect &= sizes <= _SUBGROUP_LIMIT
    chosen = np.flatnonzero(suspect)
    cuts = np.searchsorted(np.cumsum(sizes[chosen] ** 2), np.arange(1, 1 + len(chosen)) * _PAIRS, side="right")
    for part in np.split(chosen, np.unique(cuts[cuts < len(chosen)])):  # at most about _PAIRS pairs at once
        picked = np.concatenate([np.arange(starts[g], starts[g] + sizes[g]) for g in part] or [np.zeros(0, int)])
        per = sizes[group_of[picked]]
        first = np.repeat(picked, per)
        second = np.repeat(starts[group_of[picked]], per) + np.arange(len(first)) - np.repeat(np.cumsum(per) - per, per)
        ca, cb = order[first], order[second]  # cb ascending per ca: the reference's order of summation
        apart = ~(gwa_corner[ca] | gwa_corner[cb]) & ~((_dot(os_[ca], os_[cb]) > _THRESHOLD_COS)
                                                       & (_dot(ot[ca], ot[cb]) > _THRESHOLD_COS))
        split = np.zeros(len(starts), bool)
        split[group_of[first[apart]]] = True
        keep = split[group_of[first]] & ~apart
        ca, cb = ca[keep], cb[keep]
        sums = np.zeros((corners, 3), np.float32)
        np.add.at(sums, ca, np.where(gwa_corner[cb][:, None], _F(0.0), angle[cb][:, None] * os_[cb]))
        mine = np.unique(ca)
        out[mine] = _normalized(sums[mine])
    return out


def mikktspace_vertices(positions, normals, indices, uvs):
    """MikkTSpace tangents per vertex, a vertex split where its corners' tangents differ.

    Parameters
    ----------
    positions, normals, indices, uvs
        As for `mikktspace_corners`.

    Returns
    -------
    source : (V',) int64 ndarray
        The original vertex of each output vertex: ``source[:V]`` is ``arange(V)``, the copies follow.
    indices : (F, 3) int64 ndarray
        The triangles over the output vertices (a corner keeps its vertex unless its tangent differs from the
        tangent of the vertex's first corner).
    tangents : (V', 4) float32 ndarray
        Tangent and sign ``w`` per output vertex; ``(0, 0, 0, 1)`` for a vertex no triangle uses.
    """
    f = np.asarray(indices, np.int64).reshape(-1, 3)
    count = len(np.asarray(positions))
    corners = mikktspace_corners(positions, normals, f, uvs).reshape(-1, 4)
    vertex = f.reshape(-1)
    first = np.full(count, -1, np.int64)
    first[vertex[::-1]] = np.arange(len(vertex))[::-1]  # each vertex's first corner
    bits = corners.view(np.uint32)
    moved = np.flatnonzero(np.any(bits != bits[first[vertex]], axis=1))  # corners whose tangent is not the first's
    rows = np.concatenate([vertex[moved, None].astype(np.uint64), bits[moved].astype(np.uint64)], axis=1)
    _, head, variant = np.unique(rows.reshape(-1, 5), axis=0, return_index=True, return_inverse=True)
    by_corner = np.argsort(head, kind="stable")  # the copies in the order of their first corner
    rank = np.empty(len(head), np.int64)
    rank[by_corner] = np.arange(len(head))
    out = vertex.copy()
    out[moved] = count + rank[variant.reshape(-1)]
    tangents = np.tile(np.array([0.0, 0.0, 0.0, 1.0], np.float32), (count + len(head), 1))
    used = np.flatnonzero(first >= 0)
    tangents[used] = corners[first[used]]
    tangents[count:] = corners[moved[head[by_corner]]]
    return np.concatenate([np.arange(count), vertex[moved[head[by_corner]]]]), out.reshape(-1, 3), tangents
