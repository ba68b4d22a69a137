"""Triangle geometry as the GPU and the numpy twin consume it.

`MeshData` is an immutable float32 copy of a `trimesh.Trimesh`: positions, one
normal per vertex (smooth: the mesh's vertex normals; flat: each face's normal on
its own three vertices) and triangle indices.
"""
import numpy as np

from . import _validate

__all__ = ["MeshData"]


class MeshData:
    """Vertex arrays of one triangle mesh.

    Parameters
    ----------
    positions : (V, 3) array_like
        Vertex positions in object space [m].
    normals : (V, 3) array_like
        Vertex normals (any length; the fragment stage renormalises; zero or non-finite
        normals give ambient-only shading).
    indices : (F, 3) array_like of int
        Triangle vertex indices, counter-clockwise front faces.
    """

    def __init__(self, positions, normals, indices):
        positions = _validate.real_array("positions", positions, "a (V, 3) array of real numbers")
        normals = _validate.real_array("normals", normals, "a (V, 3) array of real numbers")
        indices = np.asarray(indices)
        if positions.ndim != 2 or positions.shape[1] != 3 or len(positions) == 0:
            raise ValueError(f"positions must have shape (V, 3) with V >= 1 (got shape {positions.shape})")
        if not (np.all(np.isfinite(positions)) and np.all(np.abs(positions) <= _validate.FLT_MAX)):
            raise ValueError(f"positions must be finite with |components| <= {_validate.FLT_MAX:g} (float32)")
        if normals.shape != positions.shape:
            raise ValueError(f"normals must have the shape of positions {positions.shape} (got {normals.shape})")
        if indices.ndim != 2 or indices.shape[1] != 3 or len(indices) == 0:
            raise ValueError(f"indices must have shape (F, 3) with F >= 1 (got shape {indices.shape})")
        if not np.issubdtype(indices.dtype, np.integer):
            raise TypeError(f"indices must be integers in [0, {len(positions) - 1}] (got dtype {indices.dtype})")
        if indices.min() < 0 or indices.max() >= len(positions):
            raise ValueError(f"indices must be in [0, {len(positions) - 1}] (got values from {indices.min()} "
                             f"to {indices.max()})")
        positions = np.ascontiguousarray(positions, dtype=np.float32)
        with np.errstate(over="ignore"):  # normals above FLT_MAX become inf: ambient-only, as documented
            normals = np.ascontiguousarray(normals, dtype=np.float32)
        self.positions = positions
        self.normals = normals
        self.indices = np.ascontiguousarray(indices, dtype=np.uint32)
        for a in (self.positions, self.normals, self.indices):
            a.setflags(write=False)

    @classmethod
    def from_trimesh(cls, mesh, smooth=True):
        """Convert a `trimesh.Trimesh`.

        Parameters
        ----------
        mesh : trimesh.Trimesh
        smooth : bool
            True: the mesh's vertex normals, interpolated across faces (Phong shading).
            False: flat shading, every face with its own face normal.
        """
        import trimesh

        if not isinstance(mesh, trimesh.Trimesh):
            raise TypeError(f"mesh must be a trimesh.Trimesh (got {type(mesh).__name__})")
        if len(mesh.faces) == 0:
            raise ValueError("mesh must have at least one face")
        if smooth:
            return cls(mesh.vertices, mesh.vertex_normals, mesh.faces)
        faces = np.asarray(mesh.faces)
        positions = np.asarray(mesh.vertices)[faces].reshape(-1, 3)
        normals = np.repeat(np.asarray(mesh.face_normals), 3, axis=0)
        return cls(positions, normals, np.arange(len(positions)).reshape(-1, 3))

    @property
    def triangle_count(self):
        """Number of triangles."""
        return len(self.indices)

    def __repr__(self):
        return f"MeshData({len(self.positions)} vertices, {self.triangle_count} triangles)"
