"""Triangle geometry as the GPU and the numpy twin consume it.

`MeshData` is an immutable float32 copy of a `trimesh.Trimesh`: positions, one
normal per vertex (smooth: the mesh's vertex normals; flat: each face's normal on
its own three vertices) and triangle indices; optionally texture coordinates and
tangents, for materials whose terms need ``'uv'`` or ``'tangent'`` (docs/design.md section 8), and linear
vertex colours, for parameters that take them (`glphong.VertexColors`).

Tangents, where a mesh does not supply them, come from its UVs by the standard method of
Lengyel (2001, "Computing tangent space basis vectors for an arbitrary mesh"): per triangle
``T = (e1 dv2 - e2 dv1) / (du1 dv2 - du2 dv1)`` and ``B = (e2 du1 - e1 du2) / (...)``, summed
at its vertices (triangles with a degenerate UV map are skipped), then per vertex
``t = normalize(T - (n.T) n)`` and the handedness ``w = sign((n x t) . B)`` (+1 where 0).  A
vertex with no usable tangent gets t = 0; the shader then uses an orthonormal basis around n.
"""
import numpy as np

from glphong.core import validate as _validate
from glphong.core.imaging import srgb_decode

__all__ = ["MeshData", "tangents_from_uvs"]


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
    uvs : (V, 2) array_like, optional
        Texture coordinates.
    tangents : (V, 4) or (V, 3) array_like, optional
        Object-space tangents (any length; orthonormalised against the normal per fragment),
        handedness in the fourth column (+1 when omitted).  Default: from ``uvs`` (see the module).
    colors : (V, 3) or (V, 4) array_like, optional
        Linear vertex colours in [0, 1] (a fourth, alpha column is dropped); `from_trimesh` decodes a
        trimesh's 8-bit sRGB vertex colours.
    """

    def __init__(self, positions, normals, indices, uvs=None, tangents=None, colors=None):
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
        self.uvs = None if uvs is None else _vertex_array("uvs", uvs, len(positions), (2,))
        self._tangents = None if tangents is None else _vertex_array("tangents", tangents, len(positions), (3, 4))
        self.colors = None if colors is None else _vertex_array("colors", colors, len(positions), (3, 4))
        if self.colors is not None:
            self.colors = np.ascontiguousarray(self.colors[:, :3])
            if self.colors.min() < 0.0 or self.colors.max() > 1.0:
                raise ValueError(f"colors must be linear values in [0, 1] (got values from {self.colors.min():g} "
                                 f"to {self.colors.max():g})")
        if self._tangents is not None and self._tangents.shape[1] == 3:
            self._tangents = np.ascontiguousarray(np.concatenate(
                [self._tangents, np.ones((len(positions), 1), np.float32)], axis=1))
        self._supplied = self._tangents
        for a in (self.positions, self.normals, self.indices, self.uvs, self._tangents, self.colors):
            if a is not None:
                a.setflags(write=False)

    @property
    def box(self):
        """``(lo, hi)``: the positions' axis-aligned bounding box, each (3,) float64 [m] (read-only; computed once:
        the positions are immutable).  The NOCS pass maps it to the unit cube (`glphong.gpu.passes`)."""
        box = getattr(self, "_box", None)
        if box is None:
            box = tuple(a.astype(np.float64) for a in (self.positions.min(axis=0), self.positions.max(axis=0)))
            for a in box:
                a.setflags(write=False)
            self._box = box
        return box

    @property
    def has_tangents(self):
        """True when the mesh supplies tangents or UVs to derive them from."""
        return self._tangents is not None or self.uvs is not None

    @property
    def given_tangents(self):
        """The tangents the mesh was made with (V, 4) float32, or None where they are derived (or absent)."""
        return self._supplied

    @property
    def tangents(self):
        """Per-vertex tangents (V, 4) float32 with handedness in w: the supplied ones, else derived
        from the UVs (Lengyel's method, see the module), else None.  Computed once."""
        if self._tangents is None and self.uvs is not None:
            self._tangents = tangents_from_uvs(self.positions, self.normals, self.indices, self.uvs)
            self._tangents.setflags(write=False)
        return self._tangents

    @classmethod
    def from_trimesh(cls, mesh, smooth=True, colors="srgb"):
        """Convert a `trimesh.Trimesh`.

        Parameters
        ----------
        mesh : trimesh.Trimesh
        smooth : bool
            True: the mesh's vertex normals, interpolated across faces (Phong shading).
            False: flat shading, every face with its own face normal.

        colors : {'srgb', 'linear'}
            How the mesh's vertex colours are encoded: 8-bit sRGB (PLY, OBJ and most tools: decoded to
            linear) or linear (glTF's COLOR_0).

        UVs come from a ``TextureVisuals`` with one uv per vertex; vertex colours from a
        ``ColorVisuals`` of kind 'vertex', or a ``TextureVisuals``' ``vertex_attributes['color']``
        (glTF COLOR_0 beside a texture; integers are normalised); face colours are not read.
        """
        import trimesh

        if not isinstance(mesh, trimesh.Trimesh):
            raise TypeError(f"mesh must be a trimesh.Trimesh (got {type(mesh).__name__})")
        if len(mesh.faces) == 0:
            raise ValueError("mesh must have at least one face")
        vertices, faces = np.asarray(mesh.vertices), np.asarray(mesh.faces)
        if faces.min() < 0 or faces.max() >= len(vertices):
            raise ValueError(f"mesh.faces must index its {len(vertices)} vertices, 0 to {len(vertices) - 1} "
                             f"(got indices from {faces.min()} to {faces.max()})")
        if not (np.all(np.isfinite(vertices)) and np.all(np.abs(vertices) <= _validate.FLT_MAX)):
            raise ValueError(f"positions must be finite with |components| <= {_validate.FLT_MAX:g} (float32): "
                             "the trimesh has a vertex that is not")
        uv = getattr(getattr(mesh, "visual", None), "uv", None)
        uv = None if uv is None or len(uv) != len(mesh.vertices) else np.asarray(uv, dtype=np.float64)
        if colors not in ("srgb", "linear"):
            raise ValueError(f"colors must be 'srgb' or 'linear' (got {colors!r})")
        colors = _trimesh_vertex_colors(mesh, colors)
        if smooth:
            return cls(mesh.vertices, mesh.vertex_normals, mesh.faces, uvs=uv, colors=colors)
        faces = np.asarray(mesh.faces)
        positions = np.asarray(mesh.vertices)[faces].reshape(-1, 3)
        normals = np.repeat(np.asarray(mesh.face_normals), 3, axis=0)
        return cls(positions, normals, np.arange(len(positions)).reshape(-1, 3),
                   uvs=None if uv is None else uv[faces].reshape(-1, 2),
                   colors=None if colors is None else colors[faces].reshape(-1, 3))

    @property
    def triangle_count(self):
        """Number of triangles."""
        return len(self.indices)

    def __repr__(self):
        extras = "".join([", uvs" if self.uvs is not None else "", ", tangents" if self._tangents is not None else "",
                          ", colors" if self.colors is not None else ""])
        return f"MeshData({len(self.positions)} vertices, {self.triangle_count} triangles{extras})"


def _trimesh_vertex_colors(mesh, encoding):
    """Linear (V, 3) float64 vertex colours of a trimesh, or None (see `MeshData.from_trimesh`)."""
    visual = getattr(mesh, "visual", None)
    raw = None
    if getattr(visual, "kind", None) == "vertex":
        raw = np.asarray(visual.vertex_colors)
    elif getattr(visual, "vertex_attributes", None) is not None and "color" in visual.vertex_attributes:
        raw = np.asarray(visual.vertex_attributes["color"])
    if raw is None or raw.ndim != 2 or len(raw) != len(mesh.vertices) or raw.shape[1] < 3:
        return None
    values = raw[:, :3].astype(np.float64)
    if raw.dtype.kind in "ui":
        values /= 255.0 if raw.dtype.itemsize == 1 else 65535.0
    if encoding == "srgb":
        values = srgb_decode(values)
    return np.clip(values, 0.0, 1.0)


def _vertex_array(name, value, count, widths):
    a = _validate.real_array(name, value, f"a (V, {' or '.join(map(str, widths))}) array of real numbers")
    if a.ndim != 2 or a.shape[0] != count or a.shape[1] not in widths:
        raise ValueError(f"{name} must have shape ({count}, {' or '.join(map(str, widths))}) (got {a.shape})")
    if not (np.all(np.isfinite(a)) and np.all(np.abs(a) <= _validate.FLT_MAX)):
        raise ValueError(f"{name} must be finite with |components| <= {_validate.FLT_MAX:g} (float32)")
    return np.ascontiguousarray(a, dtype=np.float32)


def tangents_from_uvs(positions, normals, indices, uvs):
    """Per-vertex tangents from texture coordinates (Lengyel 2001; see the module docstring).

    Parameters
    ----------
    positions, normals : (V, 3) array_like
    indices : (F, 3) array_like of int
    uvs : (V, 2) array_like

    Returns
    -------
    (V, 4) float32 ndarray
        Unit tangent orthogonal to the normal and the handedness w = +-1; t = 0 where no
        triangle at the vertex has a usable UV map.
    """
    p = np.asarray(positions, dtype=np.float64)
    n = np.asarray(normals, dtype=np.float64)
    uv = np.asarray(uvs, dtype=np.float64)
    f = np.asarray(indices, dtype=np.int64)
    e1, e2 = p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]]
    d1, d2 = uv[f[:, 1]] - uv[f[:, 0]], uv[f[:, 2]] - uv[f[:, 0]]
    det = d1[:, 0] * d2[:, 1] - d2[:, 0] * d1[:, 1]
    usable = np.abs(det) > 1e-300
    r = np.where(usable, 1.0 / np.where(usable, det, 1.0), 0.0)[:, None]
    t_face = (e1 * d2[:, 1:2] - e2 * d1[:, 1:2]) * r
    b_face = (e2 * d1[:, 0:1] - e1 * d2[:, 0:1]) * r
    t_sum = np.zeros_like(p)
    b_sum = np.zeros_like(p)
    for k in range(3):
        np.add.at(t_sum, f[:, k], t_face)
        np.add.at(b_sum, f[:, k], b_face)
    n_len = np.linalg.norm(n, axis=1, keepdims=True)
    n_hat = np.divide(n, n_len, out=np.zeros_like(n), where=n_len > 0)
    t = t_sum - np.sum(n_hat * t_sum, axis=1, keepdims=True) * n_hat
    t_len = np.linalg.norm(t, axis=1, keepdims=True)
    t = np.divide(t, t_len, out=np.zeros_like(t), where=t_len > 1e-300)
    w = np.where(np.sum(np.cross(n_hat, t) * b_sum, axis=1) < 0.0, -1.0, 1.0)
    return np.ascontiguousarray(np.concatenate([t, w[:, None]], axis=1), dtype=np.float32)
