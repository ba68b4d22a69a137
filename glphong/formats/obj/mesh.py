"""The meshes of an OBJ file's faces: parts, fanning, attributes kept or dropped as trimesh does, vertices, normals.

Part of `glphong.formats.obj.read_obj` (see `glphong.formats.obj`).  `_face_parts` names the part
(``usemtl``) of each face line; `_fan` fans polygons from their first corner and `_split_by_part`
groups the triangles by part; `_part_mesh` makes one part's `MeshData`: `_attribute_kept` keeps the
part's texture coordinates (normals) only where every corner names one that exists, as trimesh's
``load_obj`` does per material group, `_merge_corners` merges corners into the distinct (position,
texture coordinate, normal) index triples, and `_smooth_normals` computes vertex normals weighted by
corner angle, as trimesh's `trimesh.Trimesh.vertex_normals`, where the part keeps none of the file's.

Notes
-----
Imports none of the reader's other modules: it works on their `_Statements` and `_Corners` through
their attributes and methods.
"""
import numpy as np

from glphong.scene.geometry import MeshData


def _face_parts(materials, faces):
    """The parts of the face lines, named by the ``usemtl`` before them.

    Parameters
    ----------
    materials : _Statements
        The ``usemtl`` lines.
    faces : _Statements

    Returns
    -------
    part_names : list of str
        In order of first use by a face line (``""`` for faces before any ``usemtl``).
    face_parts : (R,) int64 or None
        Each face line's index into ``part_names``; None where there is one part.
    """
    ids = {"": 0}
    names = [" ".join(materials.rows_block(row, row + 1).tobytes().decode("utf-8", errors="replace").split())
             for row in range(materials.count)]
    # runs of face lines: those before the first usemtl, then those after each usemtl
    run_ids = np.array([0] + [ids.setdefault(name, len(ids)) for name in names], dtype=np.int64)
    run_starts = np.concatenate(([0], faces.count_before(materials.numbers)))
    run_lengths = np.diff(np.append(run_starts, faces.count))
    used = run_ids[run_lengths > 0]
    unique, first = np.unique(used, return_index=True)
    order = unique[np.argsort(first)]
    all_names = list(ids)
    part_names = [all_names[k] for k in order]
    if len(part_names) == 1:
        return part_names, None
    part_of_name = np.zeros(len(ids), dtype=np.int64)
    part_of_name[order] = np.arange(len(order))
    return part_names, np.repeat(part_of_name[run_ids], run_lengths)


def _fan(per_row):
    """Polygons fanned from their first corner.

    Parameters
    ----------
    per_row : (R,) int64
        Corners on each face line; lines of fewer than three give no triangle.

    Returns
    -------
    triangles : (T, 3) int64
        Corner indices ``(c0, c_k, c_k+1)`` for ``k = 1 .. n - 2`` of each line, line after line.
    rows : (T,) int64
        The face line of each triangle.
    """
    polygons = np.flatnonzero(per_row >= 3)
    corners = per_row[polygons]
    count = corners - 2
    start = np.repeat((np.cumsum(per_row)[polygons] - corners), count)
    rows = np.repeat(polygons, count)
    del polygons, corners
    step = np.arange(len(rows)) - np.repeat(np.cumsum(count) - count, count)
    return np.stack([start, start + step + 1, start + step + 2], axis=1), rows


def _split_by_part(triangles, parts, part_count):
    """``(part, triangles of that part in file order)`` for each part with triangles, by part index.

    Parameters
    ----------
    triangles : (T, 3) int64
    parts : (T,) int64 or None
        Each triangle's part, in [0, part_count); None where ``part_count`` is 1.
    part_count : int
    """
    if parts is None:
        if len(triangles):
            yield 0, triangles
        return
    order = np.argsort(parts, kind="stable")
    ends = np.cumsum(np.bincount(parts, minlength=part_count))
    for part in range(part_count):
        start = ends[part - 1] if part else 0
        if ends[part] > start:
            yield part, triangles[order[start:ends[part]]]


def _attribute_kept(resolved, named, used):
    """A part's corners' indices of an attribute (texture coordinate or normal) where it keeps it.

    Parameters
    ----------
    resolved : (C,) int64 or None
        Every corner's 0-based index, -1 where absent or out of range (None: no corner names one).
    named : (C,) bool or None
        The corner writes an index.
    used : (K,) int64
        The part's corners.

    Returns
    -------
    kept : (K,) int64 or None
        ``resolved[used]`` where every one of them exists, else None.
    blame : (int, bool) or None
        Where some of the part's corners name one but not all of those exist: (the first corner at
        fault, an index into ``resolved``; whether it names one beyond the file's count rather than none).
    """
    if resolved is None:
        return None, None
    named = named[used]
    if not named.any():
        return None, None
    kept = resolved[used]
    missing = kept < 0
    if not missing.any():
        return kept, None
    out_of_range = np.flatnonzero(named & missing)
    if len(out_of_range):
        return None, (int(used[out_of_range[0]]), True)
    return None, (int(used[np.flatnonzero(missing)[0]]), False)


def _merge_corners(position, uv, normal, counts):
    """The distinct (position, uv, normal) triples of corners in lexicographic order, and each corner's one.

    Parameters
    ----------
    position : (K,) int64
    uv, normal : (K,) int64 or None
        None where the part does not keep the attribute.
    counts : tuple of int
        How many positions, uvs and normals the file defines.

    Returns
    -------
    vertices : list of three (V,) int64 or None
        Position, uv and normal index of each distinct triple.
    inverse : (K,) int64
        Each corner's vertex.
    """
    columns = [position, uv, normal]
    radix = [count if column is not None else 1 for column, count in zip(columns, counts)]
    span = radix[0] * radix[1] * radix[2]
    if span >= 2 ** 62:  # a single key would overflow int64: sort the triples themselves
        kept = np.stack([c for c in columns if c is not None], axis=1)
        _, first, inverse = np.unique(kept, axis=0, return_index=True, return_inverse=True)
        return [None if c is None else c[first] for c in columns], inverse.reshape(-1)
    key = position.copy()
    for column, base in zip(columns[1:], radix[1:]):
        if column is not None:
            key *= base
            key += column
    if span <= len(key):  # as many possible keys as corners or fewer: mark them instead of sorting
        present = np.zeros(span, dtype=bool)
        present[key] = True
        unique = np.flatnonzero(present)
        del present
        rank = np.zeros(span, dtype=np.int64)
        rank[unique] = np.arange(len(unique))
        inverse = rank[key]
    else:
        unique, inverse = np.unique(key, return_inverse=True)
    del key
    vertices = [None, None, None]
    for k in (2, 1):
        if columns[k] is not None:
            unique, vertices[k] = np.divmod(unique, radix[k])
    vertices[0] = unique
    return vertices, inverse.reshape(-1)


def _part_mesh(triangles, corners, positions, uvs, normals):
    """The `MeshData` of one part.

    Parameters
    ----------
    triangles : (T, 3) int64
        The part's triangles as corner indices.
    corners : _Corners
        Resolved.
    positions : (P, 3) float64
    uvs : (U, 2) float64
    normals : (N, 3) float64

    Returns
    -------
    mesh : MeshData
    dropped : list of (str, int, str)
        What was dropped (texture coordinates or normals), the corner to blame (index into ``corners``)
        and why.
    """

    used = triangles.reshape(-1)
    uv, uv_blame = _attribute_kept(corners.uv, corners.uv_named, used)
    normal, normal_blame = _attribute_kept(corners.normal, corners.normal_named, used)
    dropped = []
    for what, blame, key, count in (("texture coordinates dropped", uv_blame, "vt", len(uvs)),
                                    ("normals dropped, smooth ones computed", normal_blame, "vn", len(normals))):
        if blame is not None:
            corner, beyond = blame
            why = (f"a {key} index beyond the file's {count} {key} line(s)" if beyond else
                   f"some corners name a {key}, others do not")
            dropped.append((what, corner, why))
    (vertex_position, vertex_uv, vertex_normal), inverse = _merge_corners(
        corners.position[used], uv, normal, (len(positions), len(uvs), len(normals)))
    del uv, normal
    faces = inverse.reshape(-1, 3)
    vertex_positions = positions[vertex_position]
    if vertex_normal is not None:
        vertex_normals = normals[vertex_normal]
    else:
        vertex_normals = _smooth_normals(vertex_positions, faces)
    vertex_uvs = None if vertex_uv is None else uvs[vertex_uv]
    return MeshData(vertex_positions, vertex_normals, faces, uvs=vertex_uvs), dropped


#: trimesh's zero: vectors shorter than this are not normalised (``trimesh.util.TOL_ZERO``)
_TOL_ZERO = float(np.finfo(np.float64).resolution * 100)
#: trimesh's merge tolerance: a triangle with a corner angle below it [rad] is degenerate (``tol.merge``)
_DEGENERATE_ANGLE = 1e-8


def _smooth_normals(positions, faces, block=1 << 17):
    """Vertex normals weighted by corner angle, as trimesh's `trimesh.Trimesh.vertex_normals`.

    Each vertex's normal is the normalised sum of the unit normals of the triangles at it, each
    weighted by the triangle's angle at the vertex (Thürrner & Wüthrich 1998); triangles without a
    normal (zero area) or with an angle below 1e-8 rad add nothing.  The same arithmetic as trimesh's
    (5.2), summed in another order: equal to about 1e-15.

    Parameters
    ----------
    positions : (V, 3) float64
        Vertex positions [m].
    faces : (F, 3) int
        Counter-clockwise triangles.
    block : int
        Triangles processed at a time (memory: about 400 bytes each).

    Returns
    -------
    (V, 3) float64
        Unit normals; zero at vertices no triangle uses.
    """
    summed = np.zeros((len(positions), 3))
    for start in range(0, len(faces), block):
        chunk = faces[start:start + block]
        weighted = _weighted_face_normals(positions, chunk)  # (n, 3 corners, 3)
        corners = chunk.reshape(-1)
        for axis in range(3):
            summed[:, axis] += np.bincount(corners, weights=weighted[:, :, axis].reshape(-1),
                                           minlength=len(positions))
    return _unitize(summed)[0]


def _weighted_face_normals(positions, faces):
    """Each triangle's unit normal times its angle at each corner: (F, 3, 3) float64."""
    p0, p1, p2 = (positions[faces[:, k]] for k in range(3))
    e01, e02, e12 = p1 - p0, p2 - p0, p2 - p1
    del p0, p1, p2
    normal, valid = _unitize(np.cross(e01, e12))
    u, v, w = _unitize(e01)[0], _unitize(e02)[0], _unitize(e12)[0]
    del e01, e02, e12
    angles = np.empty((len(faces), 3))
    angles[:, 0] = np.arccos(np.clip(_row_dot(u, v), -1.0, 1.0))
    angles[:, 1] = np.arccos(np.clip(-_row_dot(u, w), -1.0, 1.0))
    angles[:, 2] = np.pi - angles[:, 0] - angles[:, 1]
    angles[(angles < _DEGENERATE_ANGLE).any(axis=1) | ~valid] = 0.0
    return angles[:, :, None] * normal[:, None, :]


def _row_dot(a, b):
    """Dot products of the rows of two (N, 3) arrays -> (N,)."""
    product = a * b
    return product[:, 0] + product[:, 1] + product[:, 2]


def _unitize(vectors):
    """Rows of ``vectors`` ((N, 3) float64) divided by their length in place, as trimesh's `trimesh.util.unitize`.

    Returns
    -------
    unit : (N, 3) float64
        Rows of length at most `_TOL_ZERO` are multiplied by their length instead (trimesh's rule).
    valid : (N,) bool
        The row was longer than `_TOL_ZERO`.
    """
    norm = np.sqrt(_row_dot(vectors, vectors))
    valid = norm > _TOL_ZERO
    norm[valid] **= -1
    vectors *= norm[:, None]
    return vectors, valid
