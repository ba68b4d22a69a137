"""`read_obj`: an OBJ file's triangles, one `MeshData` per material, from the reader's steps.

The steps, in order: `glphong.formats.obj.statements` cuts the file into keyword statements,
`glphong.formats.obj.values` reads the numbers of ``v``, ``vt`` and ``vn`` and the face corners and
resolves their indices, `glphong.formats.obj.mesh` makes the parts' meshes; `_meshes` gathers what
was skipped or dropped into the file's one warning.  What is read and how: `glphong.formats.obj`.
"""
import warnings

import numpy as np

from glphong.formats.obj.mesh import _face_parts, _fan, _part_mesh, _split_by_part
from glphong.formats.obj.statements import _split_statements
from glphong.formats.obj.values import _read_attributes, _read_corners, _resolve_corners

__all__ = ["read_obj"]


def read_obj(path, limits=None):
    """The triangles of a Wavefront OBJ file, one `MeshData` per material (``usemtl``) in order of first use.

    Parameters
    ----------
    path : path-like
        The OBJ file.
    limits : glphong.filesafety.Limits, optional
        ``file_bytes`` bounds the file read (default `glphong.filesafety.LIMITS`).

    Returns
    -------
    list of (str, MeshData)
        One entry per part that has triangles: its ``usemtl`` name (``""`` for faces before any) and
        its mesh.  Vertices are the distinct (position, texture coordinate, normal) index triples its
        corners name, in increasing order.  Normals: the file's, as written, where every corner names
        one, else smooth vertex normals as trimesh's `trimesh.Trimesh.vertex_normals` (weighted by
        corner angle); ``uvs`` (V, 2) where every corner names a ``vt``.  ``[]`` for a file without
        faces.

    Raises
    ------
    SceneFileError
        Naming the file and line: what was found and what was expected (a number that does not
        parse, a position that is not finite, a malformed corner, index 0, a position index out of
        range); the file is not a regular file or is beyond ``limits.file_bytes``.

    Warns
    -----
    UserWarning
        Once per file, where texture coordinates or normals of a part were dropped or faces of fewer
        than three corners were skipped (see `glphong.formats.obj`).
    """
    statements = _split_statements(path, limits)
    attributes = _read_attributes(statements)
    faces = statements["f"]
    if not faces.count:
        return []
    part_names, face_parts = _face_parts(statements["usemtl"], faces)
    corners = _read_corners(faces)
    _resolve_corners(corners, faces, statements)
    del statements
    out, notes = _meshes(corners, faces, part_names, face_parts, *attributes)
    if notes:
        warnings.warn(f"{path}: " + "; ".join(notes) + " (as trimesh reads it)", UserWarning, stacklevel=2)
    return out


def _meshes(corners, faces, part_names, face_parts, positions, uvs, normals):
    """The mesh of each part, and notes on what was skipped or dropped.

    Parameters
    ----------
    corners : _Corners
        Resolved.
    faces : _Statements
    part_names : list of str
    face_parts : (R,) int64 or None
        See `_face_parts`.
    positions, uvs, normals : (P, 3), (U, 2), (N, 3) float64

    Returns
    -------
    out : list of (str, MeshData)
    notes : list of str
    """
    triangles, triangle_rows = _fan(corners.per_row)
    notes = []
    skipped = np.flatnonzero(corners.per_row < 3)
    if len(skipped):
        notes.append(f"{len(skipped)} face(s) of fewer than three corners skipped (first: line "
                     f"{faces.line_number(skipped[0])})")
    triangle_parts = None if face_parts is None else face_parts[triangle_rows]
    del triangle_rows, skipped
    out = []
    for part, part_triangles in _split_by_part(triangles, triangle_parts, len(part_names)):
        name = part_names[part]
        mesh, dropped = _part_mesh(part_triangles, corners, positions, uvs, normals)
        for what, corner, reason in dropped:
            notes.append(f"part {name!r}: {what} (line {faces.line_number(corners.row_of(corner))}: {reason})")
        out.append((name, mesh))
    return out, notes
