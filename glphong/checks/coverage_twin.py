"""The exact per-pixel coverage of each object, in float64: the twin of a Cryptomatte-style 'matte' frame pass
(``frame.matte_ids``, ``frame.matte_fractions``; docs/design.md section 15 is the design section for frame passes).

For every pixel (row j, column i; row 0 at the top) this module gives the exact share of the pixel's unit square
``[i, i + 1] x [j, j + 1]`` of image positions (``(xp, yp)``, x right, y down, `glphong.checks.frame_twin`'s
convention) where each object is the visible (nearest) one.  No GPU code, projection matrix or shader is used: the
screen mapping is the camera's own image plane (`Camera._image_plane`, through `glphong.checks.frame_twin`'s
projection), as for the ray cast of `glphong.checks.frame_twin.cast_pixels`.

Method
------
1. Objects and triangles as `glphong.checks.frame_twin` takes them: objects whose material has a constant alpha
   mask below its cutoff are skipped, a textured alpha mask is refused (ValueError); world triangles ``pose @
   positions`` in float64; both faces count (no culling).
2. Depth clipping in 3D: each triangle is clipped (Sutherland-Hodgman) to the slab of view depths ``znear <= (p -
   c) . f <= zfar`` (``c`` the camera's position, ``f = -pose[:3, 2]`` its viewing axis): the GPU clips at both the
   near and the far plane, and the ray cast keeps hits with depth in ``[znear, zfar]``.  A triangle crossing the
   near plane (including one reaching behind a perspective camera) is visible only in front of it; one crossing the
   far plane only before it.  The clipped convex polygon is split into a fan of triangles.
3. Projection: the vertices go to image positions by `glphong.checks.frame_twin`'s projection.  A perspective
   projection maps planes to planes, so the projected triangles have straight edges.  Each triangle carries a
   *nearness* affine in ``(xp, yp)`` (larger is nearer) from its 3D plane ``n . q = d`` (``q`` the camera-frame
   point): ``1 / depth = (n_x x + n_y y - n_z) / d`` for a perspective camera (``(x, y)`` on the plane ``z = -1``)
   and ``-depth = (d - n_x x - n_y y) / n_z`` for an orthographic one, then composed with the affine image plane.
   Triangles seen edge-on (doubled screen area at most ``DEGENERATE`` times the square of their longest screen
   edge, or a nearness that is not finite) cover no area and are skipped.
4. Candidates: every triangle is paired with the pixels its screen box overlaps.
5. Fast path: a pixel is wholly one object's where some triangle of it contains the pixel's four corners and every
   candidate triangle of another object is strictly farther than that triangle's plane at the four corners (an
   affine difference positive at the corners is positive on the square).
6. Exact path, every other pixel with candidates (in the pixel's own frame ``[0, 1]^2``): the boundaries are the
   triangles' edges and, for each candidate pair of different objects whose planes are not parallel in nearness,
   the line where their nearnesses are equal (a straight line in the image), each clipped to the pixel (the lines
   also to both triangles), plus the pixel's top and bottom edges.  The x-coordinates of all boundary end points and
   of all pairwise boundary intersections cut the pixel into vertical slabs in which no two boundaries cross; in
   each slab the boundaries spanning it, sorted by y, bound trapezoids.  The nearest triangle at a trapezoid's
   centre (the midpoint of its vertical chord through the slab's middle) is nearest on the whole trapezoid, and the
   trapezoid's area goes to its object.

Conventions
-----------
- Fractions are areas in units of the pixel's area, in [0, 1]; a pixel's fractions sum to its covered area (<= 1 up
  to float64 rounding, about 1e-15).
- Ids are ``scene.objects[i].instance_id`` (unique, >= 1); 0 with fraction 0 pads.  Each pixel's entries are sorted
  by fraction descending, ties by id ascending; an object with zero area in a pixel has no entry.
- Coincident coplanar faces of different objects: where their nearnesses are exactly equal the lower object index
  (the object drawn first, which the GPU's ``GL_LESS`` depth test keeps) wins; where float64 rounding makes them
  differ, the rounding decides.  The GPU check is to allow either (the depth-buffer ties of
  `glphong.checks.frame_twin.depth_tie`).
- The mapping to pixels is exact; the GPU's coverage (a sample per pixel, or several) is an estimate of it.

Speed
-----
Pure numpy: the fast path is vectorised over all pixels, the exact path is one round of numpy calls per pixel
(about 1 ms each).  Measured (best of 3, one process on a 2-core CPU machine): an 80x60 image of a 1280-triangle
sphere (``primitives.sphere(3, 0.8)`` 3 m from a 45-degree perspective camera, about 1330 pixels covered, 400 of
them partly) takes about 0.6 s; with a quad filling the image behind it 0.8 s; the same orthographic 0.5 s and 0.6
s.  The exact path's cost per pixel grows with the square of its boundaries (edges and lines of equal depth) times
its candidates, so it is meant for test-sized images and meshes, not for many triangles per pixel.
"""
import numpy as np

from glphong.twin.functions import dot
from glphong.checks.frame_twin import _drawn_objects, _world_triangles, _project, _image_map, _parallel, _pairs

__all__ = ["DEGENERATE", "exact_coverage", "top_k"]

#: a projected triangle whose doubled area is at most this times its longest edge squared is seen edge-on (skipped)
DEGENERATE = 1e-13
#: the pixel's square as half-planes ``n . p + c >= 0`` in its own frame [0, 1]^2
_SQUARE_N = np.array([[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]])
_SQUARE_C = np.array([0.0, 1.0, 0.0, 1.0])


# --------------------------------------------------------------------------- triangles: depth clip, project, plane
def _clip_polygon(points, depth, bound, keep_greater):
    """Sutherland-Hodgman of a convex polygon (P, 3) with view depths (P,) against ``depth >= bound``
    (``keep_greater``) or ``depth <= bound``: ``(points, depth)`` of the clipped polygon."""
    inside = depth >= bound if keep_greater else depth <= bound
    out_p, out_d = [], []
    count = len(points)
    for k in range(count):
        a, b = k, (k + 1) % count
        if inside[a]:
            out_p.append(points[a])
            out_d.append(depth[a])
        if inside[a] != inside[b]:
            s = (bound - depth[a]) / (depth[b] - depth[a])
            out_p.append(points[a] + s * (points[b] - points[a]))
            out_d.append(bound)
    return np.array(out_p).reshape(-1, 3), np.array(out_d)


def _depth_clip(camera, corners):
    """``(triangles, source)``: the world triangles (F', 3, 3) [m] covering the parts of ``corners`` (F, 3, 3) with
    view depth in ``[znear, zfar]`` (fans of the clipped polygons), and the row of ``corners`` each comes from."""
    depth = dot(corners - camera.pose[:3, 3], -camera.pose[:3, 2])
    n, f = camera.znear, camera.zfar
    inside = np.all((depth >= n) & (depth <= f), axis=1)
    outside = np.all(depth < n, axis=1) | np.all(depth > f, axis=1)
    triangles, source = [corners[inside]], [np.flatnonzero(inside)]
    for row in np.flatnonzero(~inside & ~outside):
        p, d = _clip_polygon(corners[row], depth[row], n, True)
        if len(p) >= 3:
            p, d = _clip_polygon(p, d, f, False)
        for k in range(1, len(p) - 1):
            triangles.append(np.stack([p[0], p[k], p[k + 1]])[None])
            source.append(np.array([row]))
    return np.concatenate(triangles), np.concatenate(source)


def _nearness(camera, width, height, corners):
    """``(g, h)``: each triangle's nearness ``g . (xp, yp) + h`` (larger is nearer; see the module), (F, 2) and (F,)
    float64, from its world triangle (F, 3, 3); not finite where the plane is seen edge-on."""
    q = (corners - camera.pose[:3, 3]) @ camera.pose[:3, :3]  # camera frame, row-wise R^T (p - t)
    normal = np.cross(q[:, 1] - q[:, 0], q[:, 2] - q[:, 0])
    d = dot(normal, q[:, 0])
    with np.errstate(divide="ignore", invalid="ignore"):
        if _parallel(camera):
            gx, gy, h = -normal[:, 0] / normal[:, 2], -normal[:, 1] / normal[:, 2], d / normal[:, 2]
        else:
            gx, gy, h = normal[:, 0] / d, normal[:, 1] / d, -normal[:, 2] / d
    a, b = _image_map(camera, width, height)  # (x, y) = a (xp, yp) + b
    g = np.stack([gx, gy], axis=-1)
    with np.errstate(invalid="ignore", over="ignore"):
        return g @ a, g @ b + h


def _screen_triangles(scene, width, height):
    """The drawn, depth-clipped, projected triangles that cover area: ``(points, g, h, owner)``, points (F, 3, 2)
    image positions [px] wound so that the edge functions are positive inside, nearness ``(g, h)`` (F, 2), (F,), and
    the owning object's index (F,) int64."""
    camera = scene.camera
    corners, owner, _ = _world_triangles(scene, _drawn_objects(scene))
    corners, source = _depth_clip(camera, corners)
    owner = owner[source]
    xp, yp, _ = _project(camera, width, height, corners)
    points = np.stack([xp, yp], axis=-1)
    g, h = _nearness(camera, width, height, corners)
    e1, e2 = points[:, 1] - points[:, 0], points[:, 2] - points[:, 0]
    area2 = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
    longest = np.max(np.sum((points - np.roll(points, 1, axis=1)) ** 2, axis=-1), axis=1)
    keep = (np.abs(area2) > DEGENERATE * longest) & np.all(np.isfinite(points), axis=(1, 2))
    keep &= np.isfinite(h) & np.all(np.isfinite(g), axis=1)
    flip = area2 < 0.0
    points[flip] = points[flip][:, [0, 2, 1]]
    return points[keep], g[keep], h[keep], owner[keep]


def _edges(points):
    """The triangles' edges as half-planes ``n . p + c >= 0`` inside: ``(n, c)``, (..., 3, 2) and (..., 3)."""
    d = np.roll(points, -1, axis=-2) - points
    n = np.stack([-d[..., 1], d[..., 0]], axis=-1)
    return n, -np.sum(n * points, axis=-1)


# --------------------------------------------------------------------------- one pixel, exactly
def _clip_lines(p0, u, t0, t1, n, c):
    """Cyrus-Beck: the parameter range ``[t0, t1]`` (each (M,)) of the lines ``p0 + t u`` ((M, 2)) inside the
    half-planes ``n . p + c >= 0`` ((M, K, 2), (M, K)); empty where ``t0 > t1``."""
    nu = np.einsum("mkj,mj->mk", n, u)
    value = np.einsum("mkj,mj->mk", n, p0) + c
    with np.errstate(divide="ignore", invalid="ignore"):
        bound = -value / nu
    lo = np.max(np.where(nu > 0.0, bound, -np.inf), axis=1, initial=-np.inf)
    hi = np.min(np.where(nu < 0.0, bound, np.inf), axis=1, initial=np.inf)
    hi = np.where(np.any((nu == 0.0) & (value < 0.0), axis=1), -np.inf, hi)
    return np.maximum(t0, lo), np.minimum(t1, hi)


def _pixel_areas(points, g, h, owner):
    """The exact area of the unit square ``[0, 1]^2`` where each object is nearest, for the candidate triangles
    ``points`` (T, 3, 2) [px, in the pixel's frame] with nearness ``(g, h)`` and owners (T,):
    ``(objects, areas)``, (n,) int64 and float64."""
    count = len(points)
    en, ec = _edges(points)
    square_n = np.broadcast_to(_SQUARE_N, (count * 3, 4, 2))
    square_c = np.broadcast_to(_SQUARE_C, (count * 3, 4))
    # triangle edges clipped to the square
    a = points.reshape(-1, 2)
    u = np.roll(points, -1, axis=1).reshape(-1, 2) - a
    t0, t1 = _clip_lines(a, u, np.zeros(len(a)), np.ones(len(a)), square_n, square_c)
    keep = t0 <= t1
    starts, ends = [a[keep] + t0[keep, None] * u[keep]], [a[keep] + t1[keep, None] * u[keep]]
    # the lines of equal nearness of triangles of different objects, clipped to the square and both triangles
    first, second = np.triu_indices(count, 1)
    pick = owner[first] != owner[second]
    first, second = first[pick], second[pick]
    dg, dh = g[first] - g[second], h[first] - h[second]
    norm2 = np.sum(dg * dg, axis=1)
    pick = norm2 > 0.0
    if np.any(pick):
        first, second, dg, dh, norm2 = first[pick], second[pick], dg[pick], dh[pick], norm2[pick]
        p0 = -(dh / norm2)[:, None] * dg
        direction = np.stack([-dg[:, 1], dg[:, 0]], axis=-1)
        m = len(p0)
        n = np.concatenate([np.broadcast_to(_SQUARE_N, (m, 4, 2)), en[first], en[second]], axis=1)
        c = np.concatenate([np.broadcast_to(_SQUARE_C, (m, 4)), ec[first], ec[second]], axis=1)
        t0, t1 = _clip_lines(p0, direction, np.full(m, -np.inf), np.full(m, np.inf), n, c)
        keep = t0 <= t1
        starts.append(p0[keep] + t0[keep, None] * direction[keep])
        ends.append(p0[keep] + t1[keep, None] * direction[keep])
    starts.append(np.array([[0.0, 0.0], [0.0, 1.0]]))
    ends.append(np.array([[1.0, 0.0], [1.0, 1.0]]))
    a, b = np.concatenate(starts), np.concatenate(ends)
    swap = b[:, 0] < a[:, 0]
    a[swap], b[swap] = b[swap], a[swap].copy()
    # slabs: end points and pairwise crossings
    d = b - a
    r = a[None, :, :] - a[:, None, :]  # a_j - a_i
    denom = d[:, None, 0] * d[None, :, 1] - d[:, None, 1] * d[None, :, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        s = (r[..., 0] * d[None, :, 1] - r[..., 1] * d[None, :, 0]) / denom
        t = (r[..., 0] * d[:, None, 1] - r[..., 1] * d[:, None, 0]) / denom
    slack = 1e-9
    cross = (denom != 0.0) & (s >= -slack) & (s <= 1.0 + slack) & (t >= -slack) & (t <= 1.0 + slack)
    xs = a[:, None, 0].repeat(len(a), axis=1)[cross] + s[cross] * d[:, None, 0].repeat(len(a), axis=1)[cross]
    xs = np.unique(np.clip(np.concatenate([xs, a[:, 0], b[:, 0], [0.0, 1.0]]), 0.0, 1.0))
    x0, x1 = xs[:-1], xs[1:]
    xm = 0.5 * (x0 + x1)
    # the boundaries spanning each slab, sorted by y at its middle
    spans = (a[None, :, 0] <= x0[:, None]) & (b[None, :, 0] >= x1[:, None]) & (b[None, :, 0] > a[None, :, 0])
    with np.errstate(divide="ignore", invalid="ignore"):
        slope = np.where(d[:, 0] > 0.0, d[:, 1] / d[:, 0], 0.0)

    def y_at(x):
        return np.where(spans, a[None, :, 1] + (x[:, None] - a[None, :, 0]) * slope[None, :], np.inf)

    ym = y_at(xm)
    order = np.argsort(ym, axis=1)
    y0 = np.take_along_axis(y_at(x0), order, axis=1)
    y1 = np.take_along_axis(y_at(x1), order, axis=1)
    ym = np.take_along_axis(ym, order, axis=1)
    valid = np.isfinite(ym[:, 1:]) & np.isfinite(ym[:, :-1])
    with np.errstate(invalid="ignore"):
        area = (x1 - x0)[:, None] * 0.5 * ((y0[:, 1:] - y0[:, :-1]) + (y1[:, 1:] - y1[:, :-1]))
    valid &= area > 0.0
    area = area[valid]
    centre = np.stack([np.broadcast_to(xm[:, None], valid.shape)[valid],
                       0.5 * (ym[:, 1:] + ym[:, :-1])[valid]], axis=-1)  # (Q, 2)
    # the nearest triangle at each trapezoid's centre
    inside = np.all(np.einsum("tkj,qj->qtk", en, centre) + ec[None] >= 0.0, axis=2)  # (Q, T)
    near = np.where(inside, centre @ g.T + h[None], -np.inf)
    best = np.max(near, axis=1, initial=-np.inf)
    covered = np.any(inside, axis=1)
    winner = np.min(np.where(inside & (near == best[:, None]), owner[None], np.iinfo(np.int64).max), axis=1)
    winner, area = winner[covered], area[covered]
    objects = np.unique(winner)
    return objects, np.array([np.sum(area[winner == o]) for o in objects])


# --------------------------------------------------------------------------- the image
def _candidates(points, width, height):
    """Candidate ``(triangle, pixel)`` pairs, each (N,) int64 (``pixel = j width + i``): the pixels the triangles'
    screen boxes overlap."""
    lo, hi = np.min(points, axis=1), np.max(points, axis=1)
    i0 = np.clip(np.floor(lo[:, 0]), 0, width).astype(np.int64)
    i1 = np.clip(np.ceil(hi[:, 0]) - 1, -1, width - 1).astype(np.int64)
    j0 = np.clip(np.floor(lo[:, 1]), 0, height).astype(np.int64)
    j1 = np.clip(np.ceil(hi[:, 1]) - 1, -1, height - 1).astype(np.int64)
    nx, ny = np.maximum(i1 - i0 + 1, 0), np.maximum(j1 - j0 + 1, 0)
    ends = np.cumsum(nx * ny)
    total = int(ends[-1]) if len(ends) else 0
    if total == 0:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    return _pairs(ends - nx * ny, ends, nx, i0, j0, 0, total, width)


def _fast_pixels(points, g, h, owner, tri, pixel, width):
    """``(whole, who)``: per candidate pair (sorted by pixel) whether its pixel is wholly one object's (see the
    module, step 5), and that object's index."""
    corner_offsets = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]])
    corners = np.stack([pixel % width, pixel // width], axis=-1)[:, None, :] + corner_offsets  # (N, 4, 2)
    en, ec = _edges(points[tri])  # (N, 3, 2), (N, 3)
    contains = np.all(np.einsum("nkj,ncj->nck", en, corners) + ec[:, None, :] >= 0.0, axis=(1, 2))
    near = np.einsum("nj,ncj->nc", g[tri], corners) + h[tri][:, None]  # (N, 4)
    start = np.r_[True, pixel[1:] != pixel[:-1]]
    group = np.cumsum(start) - 1
    heads = np.flatnonzero(start)
    # per pixel, the containing pair with the largest nearness at the centre
    order = np.lexsort((-np.mean(near, axis=1), ~contains, group))
    chosen = order[np.searchsorted(group[order], np.arange(len(heads)))]
    has = contains[chosen]
    mine = chosen[group]
    ok = (owner[tri] == owner[tri[mine]]) | np.all(near < near[mine], axis=1)
    whole = has[group] & (np.bincount(group, weights=~ok, minlength=len(heads)) == 0)[group]
    return whole, owner[tri[mine]]


def exact_coverage(scene, width, height):
    """The exact area of each pixel where each object is the visible (nearest) one, in float64.

    Parameters
    ----------
    scene : glphong.Scene
    width, height : int
        Image size [px].

    Returns
    -------
    ids : (height, width, K) int64 ndarray
        ``instance_id`` of the objects seen in each pixel, by fraction descending (ties by id ascending), padded
        with 0; ``K`` is the largest number of objects seen in any pixel (at least 1).
    fractions : (height, width, K) float64 ndarray
        The share of the pixel's area [1 = the whole pixel] where that object is nearest, descending, padded with
        0; a pixel's sum is its covered area, at most 1 (up to float64 rounding).

    Raises
    ------
    ValueError
        An object's material has a textured alpha mask (not twinned).

    Notes
    -----
    See the module for the method and conventions.
    """
    width, height = int(width), int(height)
    points, g, h, owner = _screen_triangles(scene, width, height)
    tri, pixel = _candidates(points, width, height)
    order = np.argsort(pixel, kind="stable")
    tri, pixel = tri[order], pixel[order]
    found_pixel, found_object, found_area = [np.zeros(0, np.int64)], [np.zeros(0, np.int64)], [np.zeros(0)]
    if len(tri):
        whole, who = _fast_pixels(points, g, h, owner, tri, pixel, width)
        head = np.r_[True, pixel[1:] != pixel[:-1]]
        fast = head & whole
        found_pixel.append(pixel[fast])
        found_object.append(who[fast])
        found_area.append(np.ones(int(np.sum(fast))))
        bounds = np.r_[np.flatnonzero(head), len(pixel)]
        for k in range(len(bounds) - 1):
            lo, hi = bounds[k], bounds[k + 1]
            if whole[lo]:
                continue
            p = pixel[lo]
            shift = np.array([p % width, p // width], dtype=np.float64)
            rows = tri[lo:hi]
            objects, areas = _pixel_areas(points[rows] - shift, g[rows], h[rows] + g[rows] @ shift, owner[rows])
            found_pixel.append(np.full(len(objects), p, np.int64))
            found_object.append(objects)
            found_area.append(areas)
    pix, obj, area = (np.concatenate(v) for v in (found_pixel, found_object, found_area))
    keep = area > 0.0
    pix, obj, area = pix[keep], obj[keep], area[keep]
    ids_of = np.array([o.instance_id for o in scene.objects] or [0], dtype=np.int64)
    ident = ids_of[obj]
    order = np.lexsort((ident, -area, pix))
    pix, ident, area = pix[order], ident[order], area[order]
    start = np.r_[True, pix[1:] != pix[:-1]] if len(pix) else np.zeros(0, bool)
    rank = np.arange(len(pix)) - np.maximum.accumulate(np.where(start, np.arange(len(pix)), 0))
    k = max(1, int(rank.max()) + 1 if len(rank) else 1)
    ids = np.zeros((height * width, k), np.int64)
    fractions = np.zeros((height * width, k))
    ids[pix, rank], fractions[pix, rank] = ident, area
    return ids.reshape(height, width, k), fractions.reshape(height, width, k)


def top_k(ids, fractions, k):
    """The first ``k`` entries of each pixel of `exact_coverage`'s output (its ``k`` largest fractions), padded with
    id 0 / fraction 0 where it has fewer, as a matte pass with ``k`` layers stores them.

    Parameters
    ----------
    ids : (H, W, K) int64 ndarray
    fractions : (H, W, K) float64 ndarray
    k : int
        Entries to keep, >= 1.

    Returns
    -------
    ids : (H, W, k) int64 ndarray
    fractions : (H, W, k) float64 ndarray
    """
    k = int(k)
    if k < 1:
        raise ValueError(f"k must be at least 1 (got {k})")
    ids, fractions = np.asarray(ids), np.asarray(fractions)
    pad = max(0, k - ids.shape[-1])
    widths = [(0, 0)] * (ids.ndim - 1) + [(0, pad)]
    return np.pad(ids[..., :k], widths), np.pad(fractions[..., :k], widths)
