"""Built-in primitives with analytic normals, at a chosen tessellation.

The vertex normals are the exact surface normals (not face averages), so refining the
tessellation converges to the exact surface.  Texture coordinates and tangents are analytic
too: the sphere's ``u`` runs with the azimuth and its tangent is ``dp/dphi`` (zero at the poles,
where the shader falls back to an orthonormal basis around n); the plane's tangent is +x.
"""
import functools

import numpy as np

from glphong.core import validate as _validate
from glphong.scene.geometry import MeshData

__all__ = ["sphere", "plane"]


@functools.lru_cache(maxsize=16)
def sphere(subdivisions=4, radius=1.0):
    """A sphere centred at the origin from a subdivided icosahedron.

    Parameters
    ----------
    subdivisions : int
        0 to 8: 20 * 4^subdivisions triangles (level 4: 5120, level 6: 81920).
    radius : float
        Radius [m], > 0.

    Returns
    -------
    MeshData
        Vertex normals are the exact unit normals ``p / radius``; ``uvs`` are
        ``(phi / (2 pi), theta / pi)`` (azimuth about +z from +x, polar angle from +z) and the
        tangents the unit ``dp/dphi = (-y, x, 0) / sqrt(x^2 + y^2)``, handedness -1 (``v`` grows with the
        polar angle, southward, so ``dp/dv`` is ``-(n x t)``: the sign `tangents_from_uvs` derives).  Cached: calls
        with the same arguments return the same object, so GPU buffers are shared.
    """
    import trimesh

    subdivisions = _validate.positive_int("subdivisions", subdivisions, 0, 8)
    radius = _validate.scalar("radius", radius, low=0.0, low_inclusive=False)
    mesh = trimesh.creation.icosphere(subdivisions=subdivisions, radius=radius)
    vertices = np.asarray(mesh.vertices)
    normals = vertices / np.linalg.norm(vertices, axis=1, keepdims=True)
    phi = np.arctan2(normals[:, 1], normals[:, 0]) % (2 * np.pi)
    uvs = np.stack([phi / (2 * np.pi), np.arccos(np.clip(normals[:, 2], -1.0, 1.0)) / np.pi], axis=1)
    rho = np.hypot(normals[:, 0], normals[:, 1])
    safe = np.where(rho > 0, rho, 1.0)
    tangents = np.stack([-normals[:, 1] / safe, normals[:, 0] / safe, np.zeros(len(normals)), -np.ones(len(normals))],
                        axis=1) * np.where(rho > 0, 1.0, 0.0)[:, None] + np.array([0.0, 0.0, 0.0, -1.0]) * (rho == 0)[:, None]
    return MeshData(normals * radius, normals, mesh.faces, uvs=uvs, tangents=tangents)


@functools.lru_cache(maxsize=16)
def plane(size=2.0, segments=1):
    """A square in the z = 0 plane, centred at the origin, facing +z.

    Parameters
    ----------
    size : float
        Side length [m], > 0.
    segments : int
        Grid cells per side, 1 to 1024 (2 * segments^2 triangles).

    Returns
    -------
    MeshData
        Normal +z; ``uvs`` ``(x / size + 1/2, y / size + 1/2)``; tangent +x, handedness +1.
    """
    size = _validate.scalar("size", size, low=0.0, low_inclusive=False)
    segments = _validate.positive_int("segments", segments, 1, 1024)
    t = np.linspace(-size / 2, size / 2, segments + 1)
    x, y = np.meshgrid(t, t)
    positions = np.stack([x.ravel(), y.ravel(), np.zeros(x.size)], axis=1)
    normals = np.tile([0.0, 0.0, 1.0], (len(positions), 1))
    i, j = np.meshgrid(np.arange(segments), np.arange(segments))
    a = (j * (segments + 1) + i).ravel()
    b, c, d = a + 1, a + segments + 1, a + segments + 2
    faces = np.concatenate([np.stack([a, b, d], axis=1), np.stack([a, d, c], axis=1)])
    uvs = positions[:, :2] / size + 0.5
    tangents = np.tile([1.0, 0.0, 0.0, 1.0], (len(positions), 1))
    return MeshData(positions, normals, faces, uvs=uvs, tangents=tangents)
