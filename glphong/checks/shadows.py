"""The twin of shadows: visibility by a float64 ray cast, and where a shadow map may disagree with it
(docs/design.md section 12).

For each pixel (a G-buffer position ``x`` with normal ``n``) and shadowing light, rays are cast against the
triangles of every object that casts shadows, through trimesh's ray module: with Embree (``embreex``, the
``[shadows]`` extra; single precision inside Embree, about 100 times faster) where it is installed, else trimesh's
own float64 intersector (which needs ``rtree``).  The rays are the ray from the light to ``x`` (from the map's near plane, along the light's
direction, for a light at infinity), and eight rays around it, a band radius ``rho`` away: the filter's radius
``r sqrt(2)`` texels (the corner of its square) plus one texel (an angle for a cube map: a texel seen along the unit
direction ``u`` subtends at most ``(2 / N) max |u_i|``; a length for an orthographic one), which holds the nearest
texel's centre (half a texel diagonal away) too.

- The exact visibility is 1 where the ray reaches ``x`` (its first hit no nearer than ``d - q``, ``q`` the depth
  quantum of glsl/shadows.glsl), else 0.
- It is certain where every one of the nine rays agrees, against the derived bias ``B = 2 p + q`` of
  glsl/shadows.glsl (``p`` the most the receiver's own plane comes nearer the light within the filter's reach): all
  reach the receiver (the centre ray no hit nearer than ``d - q``, each other one none nearer than its own distance
  to the receiver's tangent plane at ``x`` less ``p + q``), or all are blocked (the centre ray by something nearer
  than ``d - B``, the others by more than ``B + p``).  Elsewhere a shadow boundary, seen from
  the light, lies within ``rho`` of ``x``'s ray, or the occluder is nearer the receiver than ``b`` (contact, and a
  receiver seen edge-on, whose bias is unbounded): the shadow map may decide either way, and the band holds the
  term between visibility 0 and 1 there.

The ring is a sampling of the disc of radius ``rho``: a shadow boundary that enters the disc and leaves it between
two neighbouring ring rays without crossing the centre ray (a caster thinner than ``rho`` at that distance) is not
seen.  The test scenes have none.

What is cast (docs/speed.md, "Verify against the render"): the centre rays first; where one is neither clear nor
blocked the point is in the band whatever its ring meets, and the ring is not cast; rays proven clear without a cast
(`_clear_without_a_cast`) are not cast either.  Both leave the visibility and the band as casting every ray would.
Embree's first hits are read as trimesh's ``intersects_id`` reads them, bit for bit, without its wrapper's copies
(`_first_hits`), and the points and rays are taken in chunks (`CHUNK_POINTS`, `CHUNK`) whose temporaries stay small
(below the C allocator's threshold for fresh pages from the kernel, and in cache).
"""
import numpy as np
import trimesh

from glphong.core.validate import FLT_MAX
from glphong.twin.functions import dot, perpendiculars

__all__ = ["shadow_visibility", "shadow_plane_angle", "shadow_plane_length", "shadow_bias", "SHADOW_QUANTUM", "RING"]

#: glsl/shadows.glsl SHADOW_QUANTUM: 16 eps, the stored distance's float32 error relative to its scale
SHADOW_QUANTUM = 16 * 2.0 ** -24
#: rays around the centre one
RING = 8
#: rays `_first_hits` casts at once
CHUNK = 1 << 14
#: points `shadow_visibility` takes at once (nine rays each)
CHUNK_POINTS = 1 << 11


def shadow_plane_angle(d, c, offset):
    """glsl/shadows.glsl ``shadow_plane_angle`` in float64: ``p = d (cos(t) / cos(t + offset) - 1)`` (FLT_MAX edge-on)."""
    s = np.sqrt(np.maximum(1.0 - c * c, 0.0))
    c_far = c * np.cos(offset) - s * np.sin(offset)
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(c_far > 0.0, d * (c / c_far - 1.0), FLT_MAX)


def shadow_plane_length(c, offset):
    """glsl/shadows.glsl ``shadow_plane_length`` in float64: ``p = offset tan(t)`` (FLT_MAX edge-on)."""
    s = np.sqrt(np.maximum(1.0 - c * c, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(c > 0.0, offset * (s / c), FLT_MAX)


def shadow_bias(plane, scale):
    """glsl/shadows.glsl ``shadow_bias`` in float64: ``B = 2 p + q``, ``q = SHADOW_QUANTUM scale`` (at most FLT_MAX)."""
    return np.minimum(2.0 * plane + SHADOW_QUANTUM * scale, FLT_MAX)


def _caster_mesh(scene):
    """One trimesh of every caster's triangles in world space (cached on the scene per set of objects, with each
    receiver's `_cull`)."""
    casters = tuple(obj for obj in scene.objects if obj.casts_shadow)
    cached = getattr(scene, "_shadow_casters", None)
    if cached is not None and cached[0] == tuple(id(o) for o in casters):
        return cached[1]
    vertices, faces, offset = [], [], 0
    for obj in casters:
        vertices.append(obj.mesh.positions @ obj.pose[:3, :3].T + obj.pose[:3, 3])
        faces.append(obj.mesh.indices.reshape(-1, 3) + offset)
        offset += len(obj.mesh.positions)
    mesh = trimesh.Trimesh(np.concatenate(vertices), np.concatenate(faces), process=False) if casters else None
    intersector = None if mesh is None else _intersector(mesh)
    scene._shadow_casters = (tuple(id(o) for o in casters), intersector, {})
    return intersector


def _intersector(mesh):
    """Embree's intersector where ``embreex`` is installed, else trimesh's float64 one (which needs ``rtree``)."""
    try:
        from trimesh.ray import ray_pyembree  # noqa: PLC0415 - optional: embreex

        return ray_pyembree.RayMeshIntersector(mesh)
    except ImportError:
        pass
    try:
        intersector = trimesh.ray.ray_triangle.RayMeshIntersector(mesh)
        intersector.intersects_id(np.zeros((1, 3)), np.array([[0.0, 0.0, 1.0]]))  # builds its tree: rtree
        return intersector
    except ImportError as exc:
        raise ImportError(f"verifying shadows casts rays with trimesh, which needs embreex or {exc.name or 'rtree'}: "
                          "pip install 'glphong[shadows]'") from None


def _unitize(directions):
    """``trimesh.util.unitize`` of rows (N, 3), bit for bit: its sums of squares in its order (``(x^2 + y^2) + z^2``,
    by `dot`, without its BLAS call), the same reciprocal of the norms above its zero and the same product."""
    norm = np.sqrt(dot(directions, directions))
    valid = norm > trimesh.util.TOL_ZERO
    norm[valid] **= -1
    return directions * norm[:, None]


def _faces(intersector, origin=None):
    """Each caster triangle's first corner and unit normal, (F, 3) float64 each, as ``mesh.triangles[:, 0]`` and
    ``mesh.face_normals`` hold them; with ``origin`` (3,), also ``planes_lines``' offset ``(corner - origin) .
    normal`` of each triangle's plane, (F,) (`dot`: its order and rounding).  Cached on the intersector (the offsets
    of the last 8 origins)."""
    faces = getattr(intersector, "_glphong_faces", None)
    if faces is None:
        mesh = intersector.mesh
        faces = intersector._glphong_faces = (np.ascontiguousarray(mesh.triangles[:, 0, :]),
                                              np.ascontiguousarray(mesh.face_normals), {})
    corner, normal, offsets = faces
    if origin is None:
        return corner, normal
    key = origin.tobytes()
    offset = offsets.get(key)
    if offset is None:
        if len(offsets) >= 8:
            offsets.clear()
        offset = offsets[key] = dot(corner - origin, normal)
    return corner, normal, offset


def _repeated(intersector, row, count):
    """``count`` rows (count, 3) of ``row`` (1, 3) float32, from a block of `CHUNK` rows cached on the intersector."""
    block = getattr(intersector, "_glphong_origins", None)
    if block is None or len(block) < count or block[0].tobytes() != row[0].tobytes():
        block = intersector._glphong_origins = np.repeat(row, max(count, CHUNK), axis=0)
    return block[:count]


def _first_hits(intersector, origins, directions):
    """`_first_hits_of` in chunks of `CHUNK` rays (each ray's arithmetic is its own: the same bits, with small
    temporaries)."""
    origins = np.asarray(origins, dtype=np.float64)
    if len(directions) <= CHUNK:
        return _first_hits_of(intersector, origins, directions)
    out = np.empty(len(directions))
    for a in range(0, len(directions), CHUNK):
        b = a + CHUNK
        out[a:b] = _first_hits_of(intersector, origins if origins.ndim == 1 else origins[a:b], directions[a:b])
    return out


def _first_hits_of(intersector, origins, directions):
    """Distance along each ray to its first hit (inf where none), float64 (N,).

    ``origins`` (N, 3), or (3,) for one point every ray starts from; ``directions`` (N, 3).  With Embree, trimesh's
    ``intersects_id`` first-hit path, step by step and bit for bit: the directions unitized as trimesh does
    (`_unitize`), one query of its Embree scene with its float32 origins and directions, and the hit's float64 point
    on the reported triangle's plane as ``trimesh.intersections.planes_lines`` forms it (its row dot products, a
    BLAS product with ones, are the sequential sums of `dot`; a line within 1e-5 of the plane is no hit).  Without
    trimesh's copies of every ray, gathers where every ray hit, and with one origin the origin's offset to each
    triangle's plane formed once per triangle, not once per ray."""
    out = np.full(len(directions), np.inf)
    if intersector is None or not len(directions):
        return out
    origins = np.asarray(origins, dtype=np.float64)
    one = origins.ndim == 1
    if not type(intersector).__module__.endswith("ray_pyembree"):  # trimesh's float64 intersector
        origins = np.broadcast_to(origins, directions.shape)
        _, ray, location = intersector.intersects_id(origins, directions, multiple_hits=False, return_locations=True)
        start, toward = origins[ray], directions[ray]
        if one:
            start = origins[0]
        ordered = False
    else:
        unit = _unitize(np.asarray(directions, dtype=np.float64))
        embree = intersector._scene  # trimesh's wrap of the Embree scene: its offset, scale and the scene
        scaled = ((origins.reshape(-1, 3) - embree.origin) * embree.scale).astype(np.float32)
        if one:  # the same float32 origin in every row
            scaled = _repeated(intersector, scaled, len(unit))
        triangle = embree.scene.run(scaled, unit.astype(np.float32))
        every = bool(np.all(triangle != -1))
        ray = np.arange(len(unit)) if every else np.nonzero(triangle != -1)[0]
        hit = triangle if every else triangle[ray]
        if not every:
            unit = np.take(unit, ray, axis=0)
        start = origins if one or every else np.take(origins, ray, axis=0)
        if one:  # planes_lines' (corner - origin) . normal, once per triangle
            _, normal, offset = _faces(intersector, origins)
            normal, offset = np.take(normal, hit, axis=0), np.take(offset, hit)
        else:
            corner, normal = _faces(intersector)
            normal = np.take(normal, hit, axis=0)
            offset = dot(np.take(corner, hit, axis=0) - start, normal)
        along = dot(unit, normal)
        valid = np.abs(along) > 1e-5
        toward = directions if every else np.take(directions, ray, axis=0)
        if not valid.all():
            ray, unit, toward, offset, along = ray[valid], unit[valid], toward[valid], offset[valid], along[valid]
            start = start if one else start[valid]
        ordered = every and len(ray) == len(out)  # each ray's hit, in order
        location = unit * (offset / along)[:, None]
        location += start
    if len(ray):
        location -= start  # a fresh array: from here the hit's offset from the ray's origin
        t = np.einsum("ij,ij->i", location, toward)
        keep = t > 0.0
        if ordered and keep.all():  # every ray hit, each once, in order
            return t
        rays = ray[keep]
        if np.all(rays[1:] > rays[:-1]):  # each ray once, in order (Embree's first hits): a plain assignment
            out[rays] = t[keep]
        else:
            np.minimum.at(out, rays, t[keep])
    return out


def _ring(u, radius):
    """``RING`` unit vectors at angle ``radius`` (N,) around each unit ``u`` (N, 3): (RING, N, 3)."""
    a, b = perpendiculars(u)
    phi = 2.0 * np.pi * np.arange(RING) / RING
    across = np.cos(phi)[:, None, None] * a + np.sin(phi)[:, None, None] * b
    return np.cos(radius)[None, :, None] * u + np.sin(radius)[None, :, None] * across, across


def _plane_distance(n, point, origins, directions):
    """Distance along each ray to the plane through ``point`` with normal ``n`` (inf where it is not ahead)."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t = dot(n, point - origins) / dot(n, directions)
    return np.where(np.isfinite(t) & (t > 0.0), t, np.inf)


def _world_vertices(obj):
    """An object's vertices in world space (N, 3) float64, as `_caster_mesh` places them."""
    return obj.mesh.positions @ obj.pose[:3, :3].T + obj.pose[:3, 3]


def _flat(obj):
    """``(n, c, slack)`` where every triangle of ``obj`` lies in the slab ``|n.y - c| <= slack`` and every triangle's
    own plane stays in it to within ``slack`` of the triangle (Embree's float32 may report a hit just outside one);
    None where the object is not flat to ``1e-7`` of its size."""
    v = _world_vertices(obj)
    tri = v[obj.mesh.indices.reshape(-1, 3)]
    g = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    area = np.linalg.norm(g, axis=1)
    if not len(area) or not area.max() > 0.0:
        return None
    n = g[np.argmax(area)] / area.max()
    height = v @ n
    size = float(np.max(np.abs(v))) + float(np.max(np.ptp(v, axis=0)))
    thickness = 0.5 * float(height.max() - height.min())
    tilt = float(np.max(np.linalg.norm(g[area > 0] / area[area > 0, None] - n, axis=1)))
    if not thickness <= 1e-7 * size:
        return None
    return n, 0.5 * float(height.max() + height.min()), thickness + tilt * 1e-5 * size + 1e-12 * size


def _cull(scene, receiver):
    """What `_clear_without_a_cast` proves rays clear by, for the points of ``receiver``: ``(flat, spheres, size)``,
    the receiver's `_flat` slab (None where it casts no shadow), every other caster's bounding sphere ``(centre,
    radius)`` and the largest ``|coordinate|`` of their vertices; None where nothing is proven (no receiver, more than 8
    other casters, or a receiver that casts shadows and is not flat)."""
    others = [obj for obj in scene.objects if obj.casts_shadow and obj is not receiver]
    flat = _flat(receiver) if receiver is not None and receiver.casts_shadow else None
    if receiver is None or len(others) > 8 or (receiver.casts_shadow and flat is None):
        return None
    vertices = [_world_vertices(obj) for obj in others]
    spheres = []
    for v in vertices:
        centre = 0.5 * (v.max(axis=0) + v.min(axis=0))
        spheres.append((centre, float(np.max(np.linalg.norm(v - centre, axis=1))) * (1.0 + 1e-9)))
    return flat, spheres, max([float(np.max(np.abs(v))) for v in vertices], default=0.0)


def _clear_without_a_cast(cull, origins, directions, threshold):
    """Rays that provably meet no caster nearer than ``threshold`` (their first hit, whichever triangle Embree
    reports, no nearer), so that casting them would find them clear: (R, N) bool, for rays of ``origins`` (R, N, 3)
    or (3,), ``directions`` (R, N, 3) and ``threshold`` (R, N), by ``cull`` (`_cull`; None: none).

    Where the receiver casts shadows it must be flat (`_flat`): a ray meets it only in its slab, at ``t_r +-
    slack / |n.u|`` from ``t_r``, the distance to its plane, which must lie beyond the threshold (the receiver's own
    plane at ``x`` is the tangent plane the threshold is measured from, less ``p + q``).  Every other caster must
    keep its bounding sphere off the segment from the ray's origin to the threshold, the sphere widened by 5 % of the
    scene's size (the casters' and these rays' origins' largest coordinate): the distance trimesh reports is to the
    plane of the triangle Embree's float32 says the ray hits, which a ray down to ``|u.n| = 1e-5`` (trimesh's cut)
    meets up to ``1e5`` float32 errors (``3e-7`` of the size) away from the triangle.  At most 8 other casters are
    tested (beyond, nothing is proven)."""
    if cull is None:
        return np.zeros(threshold.shape, bool)
    flat, spheres, size = cull
    proven = np.isfinite(threshold) & (threshold > 0.0)
    limit = threshold * (1.0 + 1e-9)
    size = max(size, float(np.max(np.abs(origins))))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        if flat is not None:
            n, c, slack = flat
            along = dot(directions, n)
            cos = np.abs(along)
            t = (c - dot(origins, n)) / along
            proven &= (cos > 1e-6) & (t - slack / cos >= limit)
        for centre, radius in spheres:
            radius = radius + 0.05 * size
            w = centre - origins
            along = np.clip(dot(w, directions), 0.0, limit)
            off = w - along[..., None] * directions
            proven &= dot(off, off) > radius * radius
    return proven & np.isfinite(limit)


def _cast(intersector, origins, directions, which, hits):
    """`_first_hits` of the rays ``which`` (R, N) bool, of ``origins`` (R, N, 3) or (3,) and ``directions`` (R, N,
    3), into ``hits`` (R, N) there (each ray is cast on its own: which others go with it changes nothing)."""
    if which.all():
        hits[...] = _first_hits(intersector, origins if origins.ndim == 1 else origins.reshape(-1, 3),
                                np.ascontiguousarray(directions).reshape(-1, 3)).reshape(hits.shape)
    elif which.any():
        rays = np.flatnonzero(which)
        np.put(hits, rays, _first_hits(
            intersector, origins if origins.ndim == 1 else np.take(origins.reshape(-1, 3), rays, axis=0),
            np.take(np.ascontiguousarray(directions).reshape(-1, 3), rays, axis=0)))


def shadow_visibility(scene, setup, position, normal, filter_radius, receiver=None):
    """A shadowing light's visibility at given points: the exact value and its interval.

    Parameters
    ----------
    scene : glphong.Scene
    setup : glphong.scene.shadows.ShadowSetup
    position : (N, 3) float64 ndarray
        Receiver points [m] (the G-buffer's).
    normal : (N, 3) float64 ndarray
        Their unit normals (either orientation).
    filter_radius : int
        The renderer's ``shadow_filter_radius``.
    receiver : glphong.scene.SceneObject, optional
        The object the points lie on: rays that provably meet nothing before their threshold are then not cast
        (`_clear_without_a_cast`; the same visibility and band as casting them).

    Returns
    -------
    exact, low, high : (N,) float64 ndarray
        The ray-cast visibility (0 or 1) and the interval the shadow map's may lie in (the exact value where
        certain, [0, 1] in the band).

    Notes
    -----
    The points are taken `CHUNK_POINTS` at a time (each point's arithmetic is its own: the same bits, with small
    temporaries).  The centre rays are cast first; where one is neither clear nor blocked, the point is in
    the band whatever its ring rays meet, and they are not cast.
    """
    intersector = _caster_mesh(scene)
    culls = scene._shadow_casters[2]  # per receiver, dropped with the casters
    if id(receiver) not in culls:
        culls[id(receiver)] = _cull(scene, receiver)
    cull = culls[id(receiver)]
    exact, certain = np.zeros(len(position)), np.zeros(len(position), bool)
    for a in range(0, len(position), CHUNK_POINTS):
        b = a + CHUNK_POINTS
        exact[a:b], certain[a:b] = _visibility(intersector, cull, setup, position[a:b], normal[a:b], filter_radius)
    return exact, np.where(certain, exact, 0.0), np.where(certain, exact, 1.0)


def _visibility(intersector, cull, setup, position, normal, filter_radius):
    """`shadow_visibility` of points (N, 3) and normals (N, 3): ``(exact, certain)``, (N,) float64 and bool."""
    n_points = len(position)
    reach = (filter_radius + 0.5) * np.sqrt(2.0) * setup.texel  # the farthest texel centre the lookup reads
    band = (filter_radius * np.sqrt(2.0) + 1.0) * setup.texel  # the filter's radius plus one texel
    scale_x = np.max(np.abs(position), axis=1) + np.max(np.abs(setup.origin))
    if setup.map == "cube":
        v = position - setup.origin
        d = np.linalg.norm(v, axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            u = v / d[:, None]
        m = np.max(np.abs(u), axis=1)  # a cube texel along u subtends at most texel m (glsl/shadows.glsl)
        plane = shadow_plane_angle(d, np.abs(dot(normal, u)), reach * m)
        origins, directions = setup.origin, u[None]  # every ray starts at the light
    else:
        d = (position - setup.origin) @ setup.axis
        plane = shadow_plane_length(np.abs(normal @ setup.axis), reach)
        start = position - d[:, None] * setup.axis
        origins, directions = start[None], np.broadcast_to(setup.axis, (1, n_points, 3))
    q = SHADOW_QUANTUM * (np.abs(d) + scale_x)
    bias = shadow_bias(plane, np.abs(d) + scale_x)
    # the centre ray reaches x unless something is nearer than d - q, and is blocked for the map by what is nearer
    # than d - B
    hits = np.full((1, n_points), np.inf)  # a ray proven clear: as if it met nothing
    _cast(intersector, origins, directions, ~_clear_without_a_cast(cull, origins, directions, (d - q)[None]), hits)
    clear = hits[0] >= d - q
    blocked = hits[0] < d - bias
    # where the centre ray is neither, the point is in the band whatever the ring rays meet: they are not cast
    certain = np.zeros(n_points, bool)
    k = np.flatnonzero(clear | blocked)
    if not len(k):
        return clear.astype(np.float64), certain
    k = slice(None) if len(k) == n_points else k
    position, normal, plane, q, bias = position[k], normal[k], plane[k], q[k], bias[k]
    if setup.map == "cube":
        ring, _ = _ring(u[k], band * m[k])
        origins, directions = setup.origin, ring
        with np.errstate(divide="ignore", invalid="ignore"):  # the light's offset to x's plane is every ray's
            t = dot(normal, v[k]) / dot(normal, ring)
        planes = np.where(np.isfinite(t) & (t > 0.0), t, np.inf)  # `_plane_distance`, (RING, N)
    else:
        _, across = _ring(np.broadcast_to(setup.axis, (len(position), 3)), np.full(len(position), band))
        origins = start[k][None] + band * across
        directions = np.broadcast_to(setup.axis, origins.shape)
        planes = _plane_distance(normal, position, origins, setup.axis)
    # a ring ray reaches the receiver where nothing comes nearer than its distance to x's tangent plane less p + q
    # (the neighbouring triangles' share of B: with x's own plane's p, the map cannot fall short of d - B), and is
    # blocked where something does by more than B + p (so the map's texels within the filter's reach, whose own plane
    # is at most p nearer than d, hold something nearer than d - B)
    hits = np.full(planes.shape, np.inf)
    _cast(intersector, origins, directions, ~_clear_without_a_cast(cull, origins, directions, planes - plane - q), hits)
    with np.errstate(invalid="ignore"):  # inf - inf where a ring ray meets neither the receiver's plane nor a caster
        deficit = planes - hits
    np.nan_to_num(deficit, copy=False, nan=-np.inf)
    certain[k] = ((clear[k] & np.all(deficit <= plane + q, axis=0))
                  | (blocked[k] & np.all(deficit > bias + plane, axis=0)))
    return clear.astype(np.float64), certain
