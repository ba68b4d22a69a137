"""Wavefront OBJ geometry read into numpy arrays, in memory and time proportional to the file.

`read_obj` reads the file through `glphong.filesafety.read_bytes` (a regular file of at most
``Limits.file_bytes`` bytes; UTF-8 with or without a byte-order mark, UTF-16 with one) and makes no
Python object per line or per corner (``usemtl`` names aside): line ends, comments, continuations and
keywords are found with numpy on the file's bytes, `CHUNK_BYTES` of whole lines at a time, so that
blank, comment and unread lines cost bounded memory and only the text after the ``v``, ``vt``, ``vn``
and ``f`` keywords is kept; that text is converted in one ``numpy.fromstring`` call per keyword, and all
face corners of the file are tokenised at once (which of their ``v/vt/vn`` fields are written, which
line each is on).  A face of a million corners costs a few integer arrays of a million entries.

What is read
------------
- ``v x y z ...``: positions (the first three numbers; a w or a colour after them is ignored).  Every
  value must be a finite float32 number.
- ``vt u [v [w]]``: texture coordinates (u, v; v = 0 where the line has u only), finite float32.
- ``vn x y z``: normals.
- ``f c1 c2 c3 ...`` with corners ``v``, ``v/vt``, ``v//vn`` or ``v/vt/vn``: polygons fanned from their
  first corner, ``(c1, c_k, c_k+1)``.  A positive index counts from 1 and may name any vertex of the
  file (trimesh reads forward references too); a negative one counts back from the last vertex defined
  before the face's line (-1 is that last one); 0 is an error.
- ``usemtl name``: the faces that follow form the part ``name``; faces before any ``usemtl`` form the
  part ``""``.
- ``#`` starts a comment; blank lines, tabs, CRLF and CR line ends are accepted; a line ending in a
  backslash continues on the next (the two are joined with a space; errors name the first line).
- Other statements (``o``, ``g``, ``s``, ``mtllib``, ``l``, ``p``, ...) are left to other readers.

Missing texture coordinates and normals
---------------------------------------
As trimesh's OBJ reader (``trimesh.exchange.obj.load_obj``, per material group): a part keeps the
file's texture coordinates only where every corner of its triangles names a ``vt`` that exists, and its
normals only where every corner names a ``vn`` that exists.  A ``vt`` (or ``vn``) index beyond the
file's count, or a part where some corners name one and others do not, drops the part's texture
coordinates (or its normals: smooth vertex normals are computed instead), and the file raises one
`UserWarning` saying what was dropped from which part and where.  Faces of fewer than three corners
are skipped (trimesh skips them too) and counted in the same warning.  Position indices out of range
are an error (trimesh raises an IndexError), as are index 0 (trimesh takes it as the first vertex)
and fields that are not whole numbers.  Unlike trimesh, corners are not told apart by an attribute the
part dropped, and negative indices count back from the face's line, as the format says, not from the
file's end.
"""
import re
import warnings

import numpy as np

from .filesafety import SceneFileError, read_bytes

__all__ = ["read_obj"]

#: characters of a line quoted in an error
QUOTE_CHARS = 80

#: largest finite float32: positions and texture coordinates beyond it cannot be drawn
_FLT_MAX = float(np.finfo(np.float32).max)

_NEWLINE, _SPACE_BYTE, _SLASH, _BACKSLASH, _HASH = (ord(c) for c in "\n /\\#")
#: byte classes: whitespace (tab, newline, vertical tab, form feed, carriage return, space)
_SPACE = np.zeros(256, dtype=bool)
_SPACE[[9, 10, 11, 12, 13, 32]] = True
_DIGIT = np.zeros(256, dtype=bool)
_DIGIT[ord("0"):ord("9") + 1] = True
#: bytes a face line may hold: whitespace, digits, signs and slashes
_FACE_BYTE = _SPACE | _DIGIT
_FACE_BYTE[[ord("+"), ord("-"), _SLASH]] = True

#: the keywords of the statements read
KEYWORDS = ("v", "vt", "vn", "f", "usemtl")

_FACE_FORMS = "corners v, v/vt, v//vn or v/vt/vn of whole-number indices"


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
        than three corners were skipped (see the module).
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


class _Statements:
    """The lines of one keyword, in file order.

    Parameters
    ----------
    path : path-like
        The file, for errors.
    keyword : str
    numbers : (R,) int64
        The file's line number (from 1) where each starts: increasing, they order the lines among
        other statements too.
    block : (B,) uint8
        The text after the keyword of every line, each followed by a line feed (the last one may not
        be), in file order.

    Attributes
    ----------
    count : int
        R.
    """

    def __init__(self, path, keyword, numbers, block):
        self.path, self.keyword, self.numbers, self.block = path, keyword, numbers, block
        self.count = len(numbers)

    def newlines(self):
        """Offsets of the line feeds in ``block`` ((R or R - 1,) int64): row ``r`` ends at the r-th."""
        return np.flatnonzero(self.block == _NEWLINE)

    def line_number(self, row):
        """The file's line number (from 1) where row ``row`` starts."""
        return int(self.numbers[row])

    def error(self, row, expected):
        """A `SceneFileError` at row ``row``, quoting its line, saying what was ``expected``."""
        found = self.keyword + self.rows_block(row, row + 1).tobytes().decode("utf-8", errors="replace")
        return SceneFileError(self.path, f"found {_quote(found)}: expected {expected}",
                              where=f"line {self.line_number(row)}")

    def rows_block(self, first, stop):
        """The part of ``block`` holding rows ``first`` to ``stop - 1`` ((b,) uint8)."""
        newlines = self.newlines()
        begin = 0 if first == 0 else int(newlines[first - 1]) + 1
        end = len(self.block) if stop > len(newlines) else int(newlines[stop - 1]) + 1
        return self.block[begin:end]

    def row_of(self, offsets):
        """The row of each byte offset ((K,) int) of ``block`` -> (K,) int64."""
        return np.searchsorted(self.newlines(), offsets)

    def count_before(self, numbers):
        """How many of these lines come before the lines starting at line numbers ``numbers`` ((K,) int)
        -> (K,) int64."""
        return np.searchsorted(self.numbers, numbers)


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


def _quote(text):
    """``text`` stripped and cut to `QUOTE_CHARS` characters, quoted."""
    text = text.strip()
    return repr(text if len(text) <= QUOTE_CHARS else text[:QUOTE_CHARS] + "...")


def _split_statements(path, limits):
    """Read a file and sort the lines of each keyword of `KEYWORDS` out of it, a chunk of lines at a time.

    Parameters
    ----------
    path : path-like
    limits : Limits or None
        For `glphong.filesafety.read_bytes`.

    Returns
    -------
    dict of str to _Statements
    """
    text = _utf8_with_line_feeds(read_bytes(path, limits))
    found = {keyword: ([], []) for keyword in KEYWORDS}  # lists of line numbers and of block pieces
    first_line = 1
    for begin, end in _chunks(text, CHUNK_BYTES):
        codes = np.frombuffer(text, dtype=np.uint8, count=end - begin, offset=begin)
        first_line = _scan_chunk(codes, first_line, found)
    del text
    statements = {}
    for keyword, (numbers, pieces) in found.items():
        block = np.concatenate(pieces) if len(pieces) != 1 else pieces[0]
        pieces.clear()
        statements[keyword] = _Statements(path, keyword, np.concatenate(numbers), block)
    return statements


def _utf8_with_line_feeds(data):
    """A file's bytes (bytes) as UTF-8 without a byte-order mark, lines ended by line feeds only.

    UTF-16 with a byte-order mark is decoded; CRLF and CR become LF.
    """
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        data = data.decode("utf-16", errors="replace").encode("utf-8", errors="replace")
    elif data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    if b"\r" in data:
        data = data.replace(b"\r\n", b"\n").replace(b"\r", b"\n")
    return data


#: bytes of the file examined at a time: bounds the memory its blank, comment and other lines take
CHUNK_BYTES = 1 << 21

#: a line feed that does not end a continued line
_LINE_END = re.compile(rb"(?<!\\)\n")


def _chunks(text, size):
    """``(begin, end)`` byte ranges of ``text`` of about ``size`` bytes (at least one), each ending after a
    line feed that ends a line (not a continued one), the last at the end of ``text``."""
    begin = 0
    while True:
        cut = _LINE_END.search(text, begin + size - 1) if begin + size < len(text) else None
        end = len(text) if cut is None else cut.end()
        yield begin, end
        if end == len(text):
            return
        begin = end


def _scan_chunk(codes, first_line, found):
    """Sort the keyword lines of one chunk of whole lines into ``found``.

    Parameters
    ----------
    codes : (n,) uint8
        The chunk: whole lines, line feeds only.
    first_line : int
        The file's line number (from 1) of its first line.
    found : dict of str to (list, list)
        Per keyword: arrays appended of line numbers ((R,) int64) and of the text after the keyword
        ((b,) uint8, each line's with its line feed).

    Returns
    -------
    int
        The line number of the next chunk's first line.
    """
    size = len(codes)
    before_line_feeds = codes[:-1][codes[1:] == _NEWLINE]
    continued = bool(np.any(before_line_feeds == _BACKSLASH)) or (size > 0 and codes[-1] == _BACKSLASH)
    commented = bool(np.any(codes == _HASH))
    del before_line_feeds
    if continued or commented:
        codes = codes.copy()
    physical = np.flatnonzero(codes == _NEWLINE) if continued else None
    if continued:
        _join_continued(codes)
    if commented:
        _blank_comments(codes)
    newlines = np.flatnonzero(codes == _NEWLINE)
    starts = np.concatenate(([0], newlines + 1))
    ends = np.append(newlines, size)
    firsts = _first_words(codes, starts, ends)
    first_bytes = _bytes_at(codes, firsts)
    label = np.zeros(len(firsts), dtype=np.uint8)  # 1 + the line's keyword's index in KEYWORDS, 0 for others
    lines = []
    for index, keyword in enumerate(KEYWORDS):
        word = keyword.encode()
        candidates = np.flatnonzero(first_bytes == word[0])
        lines.append(candidates[_starts_with_word(codes, firsts[candidates], word)])
        label[lines[-1]] = index + 1
    chosen = np.flatnonzero(label)
    lengths = np.array([0] + [len(k) for k in KEYWORDS])[label[chosen]]
    painted = _paint(size, firsts[chosen] + lengths, np.minimum(ends[chosen] + 1, size), label[chosen])
    for index, keyword in enumerate(KEYWORDS):
        numbers, pieces = found[keyword]
        below = lines[index] if physical is None else np.searchsorted(physical, starts[lines[index]])
        numbers.append(first_line + below)
        pieces.append(codes[painted == index + 1])
    return first_line + len(newlines if physical is None else physical)


def _bytes_at(codes, offsets):
    """``codes[offsets]`` ((K,) uint8), a line feed where an offset is at or beyond the end."""
    if not len(codes):
        return np.full(len(offsets), _NEWLINE, dtype=np.uint8)
    return np.where(offsets < len(codes), codes[np.minimum(offsets, len(codes) - 1)], np.uint8(_NEWLINE))


def _paint(size, starts, ends, labels):
    """(size,) uint8: ``labels[k]`` in ``[starts[k], ends[k])``, 0 elsewhere.

    Parameters
    ----------
    size : int
    starts, ends : (K,) int
        Disjoint ranges in increasing order (``ends[k] <= starts[k + 1]``).
    labels : (K,) uint8 or scalar
    """
    bounds = np.empty(2 * len(starts) + 2, dtype=np.int64)
    bounds[0], bounds[-1] = 0, size
    bounds[1:-1:2], bounds[2:-1:2] = starts, ends
    values = np.zeros(len(bounds) - 1, dtype=np.uint8)
    values[1::2] = labels
    return np.repeat(values, np.diff(bounds))


def _range_mask(size, starts, ends):
    """(size,) bool: True in the ranges ``[starts[k], ends[k])`` (as `_paint`)."""
    return _paint(size, starts, ends, 1).view(bool)


def _join_continued(codes):
    """Join lines that end in a backslash to the next (in place): the backslash and the line feed become spaces.

    Parameters
    ----------
    codes : (N,) uint8, writable
    """
    backslashes = np.flatnonzero(codes == _BACKSLASH)
    joins = backslashes[_bytes_at(codes, backslashes + 1) == _NEWLINE]  # the file's end counts as a line end
    codes[joins] = _SPACE_BYTE
    joins = joins[joins + 1 < len(codes)] + 1
    codes[joins] = _SPACE_BYTE


def _blank_comments(codes):
    """Replace every comment (from ``#`` to the line's end) by spaces, in place ((N,) uint8, writable)."""
    hashes = np.flatnonzero(codes == _HASH)
    newlines = np.flatnonzero(codes == _NEWLINE)
    line = np.searchsorted(newlines, hashes)
    first = np.concatenate(([True], line[1:] != line[:-1]))
    hashes, line = hashes[first], line[first]
    ends = np.append(newlines, len(codes))[line]
    codes[_range_mask(len(codes), hashes, ends)] = _SPACE_BYTE


def _first_words(codes, starts, ends):
    """Offset of the first non-blank byte of each line ((L,) int64; its end where the line is blank).

    Parameters
    ----------
    codes : (N,) uint8
    starts, ends : (L,) int64
        Each line's first byte and its end (exclusive).
    """
    size = len(codes)
    firsts = starts.copy()
    leading = np.flatnonzero((starts < ends) & _SPACE[_bytes_at(codes, starts)])
    if len(leading):  # lines starting with blanks: find their first word
        space = _SPACE[codes]
        word_start = ~space
        word_start[1:] &= space[:-1]
        del space
        word_start &= _range_mask(size, starts[leading], ends[leading])
        words = np.flatnonzero(word_start)
        del word_start
        if len(words):
            found = words[np.minimum(np.searchsorted(words, starts[leading]), len(words) - 1)]
        else:
            found = ends[leading]
        firsts[leading] = np.where((found >= starts[leading]) & (found < ends[leading]), found, ends[leading])
    return firsts


def _starts_with_word(codes, offsets, word):
    """Whether the text at each offset ((L,) int) is ``word`` (bytes) followed by whitespace or the end
    (the first byte is taken as matched)."""
    match = np.ones(len(offsets), dtype=bool)
    for k, byte in enumerate(word[1:], start=1):
        match &= _bytes_at(codes, offsets + k) == byte
    return match & _SPACE[_bytes_at(codes, offsets + len(word))]


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
    from .geometry import MeshData

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
