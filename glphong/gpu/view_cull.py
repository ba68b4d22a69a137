"""Triangles that cannot reach the image, left out of the draw: a large mesh that reaches out of the view keeps only
the triangles that may meet it, in their order (docs/speed.md, "Against PyVista and Open3D").

The clip volume is ``-w <= x, y, z <= w`` of the clip coordinates ``c = (P V) M p`` (the vertex stage's
``gl_Position``, depth clamping off).  A triangle whose three vertices all lie beyond one of its six planes lies
beyond it wholly (the planes are linear in ``c``, and GL interpolates and clips in ``c``), so the rasteriser makes no
fragment of it: leaving it out changes no pixel, and the kept triangles are drawn in the same order, so every depth
tie resolves as before.  The test here is in float64 and calls a vertex beyond a plane only by a margin
(`MARGIN` relative to ``|c| + |w|``, some 800 times float32's rounding of the GPU's own ``c``), so no triangle the
GPU could draw is left out.

Worth it only where a mesh has many triangles and reaches out of the view: llvmpipe shades every vertex it fetches
(some two a triangle: its vertex cache holds the indices of a segment of 1024) and tests every triangle against the
planes before it drops it; the fine plane of the speed family keeps 8 % of its vertices in view.  A mesh whose
bounding sphere's box lies inside the view, or one of fewer than `MIN_TRIANGLES`, is drawn whole without a test.
"""
import numpy as np

__all__ = ["MIN_TRIANGLES", "MARGIN", "visible_triangles", "box_inside"]

#: meshes of fewer triangles are drawn whole (the test costs more than llvmpipe's own rejection)
MIN_TRIANGLES = 16384
#: a vertex is beyond a plane where it is beyond it by more than this times ``|c| + |w|``
MARGIN = 1e-4


def _clip(points, clip_matrix):
    """Clip coordinates (N, 4) float64 of points (N, 3): written out as sums of columns (no BLAS call: its threads
    would wait on cores that llvmpipe keeps busy)."""
    m = np.asarray(clip_matrix, np.float64)
    p = np.asarray(points, np.float64)
    return p[:, 0:1] * m[:, 0] + p[:, 1:2] * m[:, 1] + p[:, 2:3] * m[:, 2] + m[:, 3]


def _codes(clip):
    """(N,) uint8: bit k set where the point is beyond plane k (``x > w, x < -w, y > w, y < -w, z > w, z < -w``) by
    the margin."""
    w = clip[:, 3]
    slack_w = MARGIN * np.abs(w)
    codes = np.zeros(len(clip), np.uint8)
    for axis in range(3):
        c = clip[:, axis]
        slack = MARGIN * np.abs(c) + slack_w
        codes |= (c - w > slack).view(np.uint8) << np.uint8(2 * axis)
        codes |= (-c - w > slack).view(np.uint8) << np.uint8(2 * axis + 1)
    return codes


def box_inside(centre, radius, clip_matrix):
    """True where the box of the sphere ``(centre (3,), radius)`` (world) lies inside the clip volume of
    ``clip_matrix`` (4, 4) with the margin: its eight corners do (the volume is convex in ``c``)."""
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], np.float64)
    clip = _clip(np.asarray(centre, np.float64) + radius * corners, clip_matrix)
    xyz, w = clip[:, :3], clip[:, 3:4]
    return bool(np.all(np.abs(xyz) + MARGIN * (np.abs(xyz) + np.abs(w)) < w))


def visible_triangles(positions, indices, clip_matrix):
    """The triangles of a mesh that may meet the view, in their order.

    Parameters
    ----------
    positions : (N, 3) array_like
        Vertex positions in the object's frame [m].
    indices : (3 F,) array_like of int
        The triangles' vertex indices.
    clip_matrix : (4, 4) array_like
        ``(P V) M``: object to clip coordinates, float64.

    Returns
    -------
    (3 K,) uint32 ndarray or None
        The kept triangles' indices (K <= F), or None where every triangle is kept.
    """
    codes = _codes(_clip(positions, clip_matrix))
    triangles = np.asarray(indices).reshape(-1, 3)
    dropped = codes[triangles[:, 0]] & codes[triangles[:, 1]] & codes[triangles[:, 2]]
    if not dropped.any():
        return None
    return np.ascontiguousarray(triangles[dropped == 0], np.uint32).reshape(-1)
