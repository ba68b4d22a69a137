"""Built-in primitives with analytic normals, at a chosen tessellation.

The vertex normals are the exact surface normals (not face averages), so refining the
tessellation converges to the exact surface.
"""
import functools

import numpy as np

from . import _validate
from .geometry import MeshData

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
        Vertex normals are the exact unit normals ``p / radius``.  Cached: calls with the same
        arguments return the same object, so GPU buffers are shared.
    """
    import trimesh

    subdivisions = _validate.positive_int("subdivisions", subdivisions, 0, 8)
    radius = _validate.scalar("radius", radius, low=0.0, low_inclusive=False)
    mesh = trimesh.creation.icosphere(subdivisions=subdivisions, radius=radius)
    vertices = np.asarray(mesh.vertices)
    normals = vertices / np.linalg.norm(vertices, axis=1, keepdims=True)
    return MeshData(normals * radius, normals, mesh.faces)


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
    return MeshData(positions, normals, faces)
