"""The numbers of an OBJ file's ``v``, ``vt`` and ``vn`` lines and the corners of its ``f`` lines, with numpy.

Part of `glphong.formats.obj.read_obj` (see `glphong.formats.obj`).  `_read_attributes` converts the
text of each of ``v``, ``vt`` and ``vn`` (a `glphong.formats.obj.statements._Statements`) in one
``numpy.fromstring`` call and checks each line's count of numbers and (positions, texture coordinates)
that every value is a finite float32; `_read_corners` tokenises every face corner of the file at once
(which of its ``v/vt/vn`` fields are written, which line it is on) into a `_Corners`, and
`_resolve_corners` turns the written indices (from 1, or negative counting back from the face's line)
into 0-based ones, refusing a position index out of range and marking absent or out-of-range texture
coordinate and normal indices.

Notes
-----
Imports `glphong.formats.obj.statements` only (its byte classes); errors are `SceneFileError` made by
`_Statements.error`, naming the line.
"""
import numpy as np

from glphong.formats.obj.statements import _NEWLINE, _SLASH, _SPACE, _SPACE_BYTE

#: largest finite float32: positions and texture coordinates beyond it cannot be drawn
_FLT_MAX = float(np.finfo(np.float32).max)

_DIGIT = np.zeros(256, dtype=bool)
_DIGIT[ord("0"):ord("9") + 1] = True
#: bytes a face line may hold: whitespace, digits, signs and slashes
_FACE_BYTE = _SPACE | _DIGIT
_FACE_BYTE[[ord("+"), ord("-"), _SLASH]] = True

_FACE_FORMS = "corners v, v/vt, v//vn or v/vt/vn of whole-number indices"


class _Corners:
    """Every face corner of the file, in file order.

    Attributes
    ----------
    per_row : (R,) int64
        Corners on each face line.
    position : (C,) int64
        Indices as written (1-based or negative), then, after `_resolve_corners`, 0-based.
    uv, normal : (C,) int64 or None
        As ``position``, 0 where the corner writes none (None where no corner writes one); after
        `_resolve_corners`, -1 where absent or out of range.
    uv_named, normal_named : (C,) bool or None
        Set by `_resolve_corners`: the corner writes a ``vt`` (``vn``) index.
    """

    def __init__(self, per_row, position, uv, normal):
        self.per_row, self.position, self.uv, self.normal = per_row, position, uv, normal
        self.uv_named = self.normal_named = None
        self._row_ends = np.cumsum(per_row)

    def row_of(self, corners):
        """The face line (row) of corners ``corners`` (int or (K,) int)."""
        return np.searchsorted(self._row_ends, corners, side="right")


def _read_attributes(statements):
    """The file's positions (P, 3), texture coordinates (U, 2) and normals (N, 3), float64.

    Raises
    ------
    SceneFileError
        At the first line that is not numbers, has too few, or (positions and texture coordinates) a
        value that is not a finite float32.
    """
    positions = _read_vectors(statements["v"], minimum=3, width=3, expected="three decimal numbers x y z")
    _check_finite(positions, statements["v"], "positions")
    uvs = _read_vectors(statements["vt"], minimum=1, width=2, expected="one to three decimal numbers u v w")
    _check_finite(uvs, statements["vt"], "texture coordinates")
    normals = _read_vectors(statements["vn"], minimum=3, width=3, expected="three decimal numbers x y z")
    return positions, uvs, normals


def _word_counts(raw, rows):
    """Whitespace-separated words on each line of ``raw``.

    Parameters
    ----------
    raw : (B,) uint8
        ``rows`` lines, each ended by a line feed (the last one may not be).
    rows : int

    Returns
    -------
    (rows,) int64
    """
    space = _SPACE[raw]
    after_space = np.empty_like(space)
    after_space[0:1], after_space[1:] = True, space[:-1]
    starts = np.flatnonzero(after_space & ~space)
    return np.bincount(np.searchsorted(np.flatnonzero(raw == _NEWLINE), starts), minlength=rows)


def _parse_numbers(raw, rows):
    """The decimal numbers of ``rows`` lines, or None where some line holds a word that is not one.

    Parameters
    ----------
    raw : (B,) uint8
        The lines, each ended by a line feed (the last one may not be).
    rows : int

    Returns
    -------
    values : (N,) float64
        All numbers, row after row.
    counts : (rows,) int64
        Numbers on each row.
    """
    counts = _word_counts(raw, rows)
    total = int(counts.sum())
    if total == 0:  # numpy reads a blank string as one value
        return np.zeros(0), counts
    try:
        values = np.fromstring(raw.tobytes(), dtype=np.float64, sep=" ")
    except ValueError:
        return None
    # a word numpy reads only in part raises; one read as two numbers would change the count
    return (values, counts) if len(values) == total else None


def _first_unreadable(statements):
    """The first row of ``statements`` that `_parse_numbers` refuses (bisection: about two passes)."""
    low, high = 0, statements.count
    while high - low > 1:
        middle = (low + high) // 2
        if _parse_numbers(statements.rows_block(low, middle), middle - low) is None:
            high = middle
        else:
            low = middle
    return low


def _read_vectors(statements, minimum, width, expected):
    """The numbers of ``v``, ``vt`` or ``vn`` lines as an array.

    Parameters
    ----------
    statements : _Statements
    minimum, width : int
        Numbers each line must have, and columns kept (missing ones up to ``width`` are 0; extra
        ones are ignored).
    expected : str
        What a line holds, for errors.

    Returns
    -------
    (R, width) float64

    Raises
    ------
    SceneFileError
        At the first line with a word that is not a decimal number or fewer than ``minimum`` numbers.
    """
    if not statements.count:
        return np.zeros((0, width))
    parsed = _parse_numbers(statements.block, statements.count)
    if parsed is None:
        raise statements.error(_first_unreadable(statements), expected)
    values, counts = parsed
    short = np.flatnonzero(counts < minimum)
    if len(short):
        raise statements.error(short[0], expected)
    if np.all(counts == width):
        return values.reshape(-1, width)
    columns = np.arange(width)
    present = columns < counts[:, None]
    taken = np.where(present, (np.cumsum(counts) - counts)[:, None] + columns, 0)
    return np.where(present, values[taken], 0.0)


def _check_finite(values, statements, what):
    """Refuse the first line of ``values`` ((R, k) float64) holding a value that is not a finite float32."""
    bad = ~(np.abs(values) <= _FLT_MAX)  # nan compares false
    if bad.any():
        raise statements.error(np.flatnonzero(bad.any(axis=1))[0],
                               f"{what} that are finite numbers of magnitude at most {_FLT_MAX:g} (float32)")


def _read_corners(faces):
    """Every corner of every ``f`` line, tokenised at once on the bytes of the face lines.

    Parameters
    ----------
    faces : _Statements

    Returns
    -------
    _Corners
        Indices as written.

    Raises
    ------
    SceneFileError
        At the first line holding a byte other than digits, signs, slashes and whitespace, a sign not
        leading a number, a corner that starts with a slash or has more than three fields, index 0.
    """
    codes = faces.block

    def fail(offsets):
        return faces.error(faces.row_of(offsets[:1])[0], _FACE_FORMS)

    if not len(codes):
        return _Corners(np.zeros(faces.count, np.int64), np.zeros(0, np.int64), None, None)
    wrong = np.flatnonzero(~_FACE_BYTE[codes])
    if len(wrong):
        raise fail(wrong)
    space = _SPACE[codes]
    slash = codes == _SLASH
    separator = space | slash
    after_separator = np.concatenate(([True], separator[:-1]))
    signs = np.flatnonzero((codes == ord("+")) | (codes == ord("-")))
    if len(signs):
        followed = codes[np.minimum(signs + 1, len(codes) - 1)]  # a sign ending the text "follows" itself
        bad = signs[~after_separator[signs] | ~_DIGIT[followed]]
        if len(bad):
            raise fail(bad)
    fields = np.flatnonzero(after_separator & ~separator)
    del separator, after_separator
    after_space = np.concatenate(([True], space[:-1]))
    before_space = np.concatenate((space[1:], [True]))
    corner_starts = np.flatnonzero(after_space & ~space)
    corner_ends = np.flatnonzero(before_space & ~space) + 1
    del space, after_space, before_space
    slashes = np.flatnonzero(slash)
    first_slash = np.searchsorted(slashes, corner_starts)
    bad = corner_starts[(np.searchsorted(slashes, corner_ends) - first_slash > 2) | (codes[corner_starts] == _SLASH)]
    if len(bad):
        raise fail(bad)
    del corner_ends
    if len(fields):
        values = np.fromstring(np.where(slash, np.uint8(_SPACE_BYTE), codes).tobytes(), dtype=np.int64, sep=" ")
    else:
        values = np.zeros(0, np.int64)
    del slash
    if len(values) != len(fields):  # not expected after the checks above
        raise fail(fields)
    zero = np.flatnonzero(values == 0)
    if len(zero):
        raise faces.error(faces.row_of(fields[zero[:1]])[0],
                          "indices from 1 (or negative, counting back from the last): OBJ has no index 0")
    per_row = np.bincount(faces.row_of(corner_starts), minlength=faces.count)
    if not len(slashes):  # corners ``v`` only: one field each
        return _Corners(per_row, values, None, None)
    count = len(corner_starts)
    corner = np.searchsorted(corner_starts, fields, side="right") - 1
    slot = np.searchsorted(slashes, fields) - first_slash[corner]
    del fields, first_slash, corner_starts
    attributes = []
    for k in (1, 2):
        chosen = slot == k
        if chosen.any():
            attribute = np.zeros(count, np.int64)
            attribute[corner[chosen]] = values[chosen]
            attributes.append(attribute)
        else:
            attributes.append(None)
    return _Corners(per_row, values[slot == 0], *attributes)


def _resolve(index, before, total):
    """0-based indices of OBJ indices.

    Parameters
    ----------
    index : (C,) int64
        As written: from 1, or negative counting back from ``before``; 0 for absent.
    before : (C,) int64
        How many of the indexed elements are defined before each corner's line.
    total : int
        How many the file defines.

    Returns
    -------
    resolved : (C,) int64
        In [0, total), -1 where absent or out of range.
    named : (C,) bool
        The index is written.
    """
    named = index != 0
    resolved = np.where(index > 0, index - 1, before + index)
    resolved[~named | (resolved < 0) | (resolved >= total)] = -1
    return resolved, named


def _resolve_corners(corners, faces, statements):
    """Turn ``corners``' indices into 0-based ones (in place).

    Raises
    ------
    SceneFileError
        At the first face line whose position index is out of range.
    """
    vertices = statements["v"]
    written = corners.position
    before = np.repeat(vertices.count_before(faces.numbers), corners.per_row)
    corners.position, _ = _resolve(written, before, vertices.count)
    bad = np.flatnonzero(corners.position < 0)
    if len(bad):
        k = bad[0]
        earlier, index = int(before[k]), int(written[k])
        found = "an index beyond 64-bit integers" if abs(index) >= np.iinfo(np.int64).max else index
        raise faces.error(corners.row_of(k), f"position indices from 1 to {vertices.count} (the file's v lines) or "
                          f"from -{earlier} to -1 ({earlier} before this line), not {found}")
    del before, written
    for attribute, keyword in (("uv", "vt"), ("normal", "vn")):
        if getattr(corners, attribute) is None:
            continue
        indexed = statements[keyword]
        before = np.repeat(indexed.count_before(faces.numbers), corners.per_row)
        resolved, named = _resolve(getattr(corners, attribute), before, indexed.count)
        setattr(corners, attribute, resolved)
        setattr(corners, attribute + "_named", named)
