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
    """One trimesh of every caster's triangles in world space (cached on the scene per set of objects)."""
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
    scene._shadow_casters = (tuple(id(o) for o in casters), intersector)
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


def _first_hits(intersector, origins, directions):
    """Distance along each ray to its first hit (inf where none), float64 (N,).

    With Embree, trimesh's ``intersects_id`` first-hit path, step by step and bit for bit (the directions unitized by
    trimesh, one query of its Embree scene, the hit's float64 point on the triangle's plane by
    ``trimesh.intersections.planes_lines``), without its copies of every ray (a ray-offset array, the live rays'
    gather, the stuck-ray bookkeeping) that a single first hit does not use, and without gathering the rays where
    every one hit (each ray a shadow test casts ends on a caster, nearly always)."""
    out = np.full(len(origins), np.inf)
    if intersector is None or not len(origins):
        return out
    origins = np.asarray(origins, dtype=np.float64)
    if not type(intersector).__module__.endswith("ray_pyembree"):  # trimesh's float64 intersector
        _, ray, location = intersector.intersects_id(origins, directions, multiple_hits=False, return_locations=True)
        start, toward = origins[ray], directions[ray]
    else:
        unit = trimesh.util.unitize(np.asarray(directions, dtype=np.float64))
        triangle = intersector._scene.run(origins, unit)
        every = bool(np.all(triangle != -1))
        ray = np.arange(len(origins)) if every else np.nonzero(triangle != -1)[0]
        start, unit = (origins, unit) if every else (origins[ray], unit[ray])
        mesh = intersector.mesh
        hit = triangle if every else triangle[ray]
        location, valid = trimesh.intersections.planes_lines(mesh.triangles[hit, 0, :], mesh.face_normals[hit],
                                                             start, unit)
        toward = directions if every else directions[ray]
        if not valid.all():
            ray, start, toward = ray[valid], start[valid], toward[valid]
    if len(ray):
        t = np.einsum("ij,ij->i", location - start, toward)
        keep = t > 0.0
        rays = ray[keep]
        if np.all(rays[1:] > rays[:-1]):  # each ray once, in order (Embree's first hits): a plain assignment
            out[rays] = np.minimum(out[rays], t[keep])
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


def _clear_without_a_cast(scene, receiver, origins, directions, threshold):
    """Rays that provably meet no caster nearer than ``threshold`` (their first hit, whichever triangle Embree
    reports, no nearer), so that casting them would find them clear: (RING + 1, N) bool.

    Where the receiver casts shadows it must be flat (`_flat`): a ray meets it only in its slab, at ``t_r +-
    slack / |n.u|`` from ``t_r``, the distance to its plane, which must lie beyond the threshold (the receiver's own
    plane at ``x`` is the tangent plane the threshold is measured from, less ``p + q``).  Every other caster must
    keep its bounding sphere off the segment from the ray's origin to the threshold, the sphere widened by 5 % of the
    scene's size: the distance trimesh reports is to the plane of the triangle Embree's float32 says the ray hits,
    which a ray down to ``|u.n| = 1e-5`` (trimesh's cut) meets up to ``1e5`` float32 errors (``3e-7`` of the size)
    away from the triangle.  At most 8 other casters are tested (beyond, nothing is proven)."""
    others = [obj for obj in scene.objects if obj.casts_shadow and obj is not receiver]
    flat = _flat(receiver) if receiver is not None and receiver.casts_shadow else None
    if receiver is None or len(others) > 8 or (receiver.casts_shadow and flat is None):
        return np.zeros(threshold.shape, bool)
    proven = np.isfinite(threshold) & (threshold > 0.0)
    limit = threshold * (1.0 + 1e-9)
    vertices = [_world_vertices(obj) for obj in others]
    one = origins.ndim == 1 or not any(origins.strides[:-1])  # the light's position for every ray (a cube map)
    size = max([float(np.max(np.abs(v))) for v in vertices]
               + [float(np.max(np.abs(origins[(0,) * (origins.ndim - 1)] if one else origins)))])
    origins = np.broadcast_to(origins, threshold.shape + (3,))
    directions = np.broadcast_to(directions, threshold.shape + (3,))
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        if flat is not None:
            n, c, slack = flat
            cos = np.abs(dot(directions, n))
            t = (c - dot(origins, n)) / dot(directions, n)
            proven &= (cos > 1e-6) & (t - slack / cos >= limit)
        for v in vertices:
            centre = 0.5 * (v.max(axis=0) + v.min(axis=0))
            radius = float(np.max(np.linalg.norm(v - centre, axis=1))) * (1.0 + 1e-9) + 0.05 * size
            w = centre - origins
            along = np.clip(dot(w, directions), 0.0, limit)
            proven &= dot(w - along[..., None] * directions, w - along[..., None] * directions) > radius * radius
    return proven & np.isfinite(limit)


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
    """
    intersector = _caster_mesh(scene)
    n_points = len(position)
    if not n_points:
        empty = np.zeros(0)
        return empty, empty, empty
    reach = (filter_radius + 0.5) * np.sqrt(2.0) * setup.texel  # the farthest texel centre the lookup reads
    band = (filter_radius * np.sqrt(2.0) + 1.0) * setup.texel  # the filter's radius plus one texel
    scale_x = np.max(np.abs(position), axis=1) + np.max(np.abs(setup.origin))
    if setup.map == "cube":
        light = setup.origin
        v = position - light
        d = np.linalg.norm(v, axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            u = v / d[:, None]
        m = np.max(np.abs(u), axis=1)  # a cube texel along u subtends at most texel m (glsl/shadows.glsl)
        reach, radius = reach * m, band * m
        c = np.abs(dot(normal, u))
        plane = shadow_plane_angle(d, c, reach)
        ring, _ = _ring(u, radius)
        origins = np.broadcast_to(light, (RING + 1, n_points, 3))
        directions = np.concatenate([u[None], ring])
    else:
        axis = setup.axis
        d = (position - setup.origin) @ axis
        c = np.abs(normal @ axis)
        plane = shadow_plane_length(c, reach)
        start = position - d[:, None] * axis
        _, across = _ring(np.broadcast_to(axis, (n_points, 3)), np.full(n_points, band))
        origins = np.concatenate([start[None], start[None] + band * across])
        directions = np.broadcast_to(axis, (RING + 1, n_points, 3))
    q = SHADOW_QUANTUM * (np.abs(d) + scale_x)
    bias = shadow_bias(plane, np.abs(d) + scale_x)
    planes = _plane_distance(normal[None], position[None], origins, directions)
    planes[0] = d
    threshold = np.concatenate([(d - q)[None], planes[1:] - plane - q])  # clear where the first hit is no nearer
    cast = ~_clear_without_a_cast(scene, receiver, origins, directions, threshold).reshape(-1)
    rays = np.ascontiguousarray(directions).reshape(-1, 3)
    starts = np.broadcast_to(setup.origin, rays.shape) if setup.map == "cube" else origins.reshape(-1, 3)
    if cast.all():
        hits = _first_hits(intersector, starts, rays)
    else:  # a ray proven clear: as if it met nothing
        hits = np.full(len(rays), np.inf)
        hits[cast] = _first_hits(intersector, starts[cast], rays[cast])
    hits = hits.reshape(RING + 1, n_points)
    # the centre ray reaches x unless something is nearer than d - q, and is blocked for the map by what is nearer
    # than d - B; a ring ray reaches the receiver where nothing comes nearer than its distance to x's tangent plane
    # less p + q (the neighbouring triangles' share of B: with x's own plane's p, the map cannot fall short of
    # d - B), and is blocked where something does by more than B + p (so the map's texels within the filter's reach,
    # whose own plane is at most p nearer than d, hold something nearer than d - B)
    with np.errstate(invalid="ignore"):  # inf - inf where a ring ray meets neither the receiver's plane nor a caster
        deficit = np.nan_to_num(planes - hits, nan=-np.inf)
    clear = deficit <= plane + q
    blocked = deficit > bias + plane
    clear[0] = hits[0] >= d - q
    blocked[0] = hits[0] < d - bias
    exact = clear[0].astype(np.float64)
    certain = np.all(clear, axis=0) | np.all(blocked, axis=0)
    return exact, np.where(certain, exact, 0.0), np.where(certain, exact, 1.0)
