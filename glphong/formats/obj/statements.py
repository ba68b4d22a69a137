"""Cutting an OBJ file's bytes into keyword statements, with numpy, a chunk of whole lines at a time.

Part of `glphong.formats.obj.read_obj` (see `glphong.formats.obj`).  `_split_statements` reads the file
through `glphong.filesafety.read_bytes`, turns UTF-16 (with a byte-order mark) into UTF-8, drops a UTF-8
byte-order mark, makes CRLF and CR line ends line feeds, then examines `CHUNK_BYTES` of whole lines at
a time (`_chunks`, `_scan_chunk`): lines ending in a backslash are joined to the next with spaces,
comments are blanked, each line's first word is found and the text after each keyword of `KEYWORDS`
is kept, with the file's line number of each line, as one `_Statements` per keyword.  No Python object
is made per line.

Notes
-----
The lowest of the reader's modules: it imports none of them.  `_Statements.error` makes the
`SceneFileError` of a line (quoted to `QUOTE_CHARS` characters) for the modules above.
"""
import re

import numpy as np

from glphong.core.filesafety import LIMITS, SceneFileError, read_bytes

#: characters of a line quoted in an error
QUOTE_CHARS = 80

_NEWLINE, _SPACE_BYTE, _SLASH, _BACKSLASH, _HASH = (ord(c) for c in "\n /\\#")
#: byte classes: whitespace (tab, newline, vertical tab, form feed, carriage return, space)
_SPACE = np.zeros(256, dtype=bool)
_SPACE[[9, 10, 11, 12, 13, 32]] = True

#: the keywords of the statements read
KEYWORDS = ("v", "vt", "vn", "f", "usemtl")


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


def _quote(text):
    """``text`` stripped and cut to `QUOTE_CHARS` characters, quoted."""
    text = text.strip()
    return repr(text if len(text) <= QUOTE_CHARS else text[:QUOTE_CHARS] + "...")


#: bytes of working memory the scan of one chunk takes per byte of it, at most (measured: about 18 for a file of
#: nothing but continued lines, 17 for one face line of a million corners); a chunk is CHUNK_BYTES of whole
#: lines, or one longer line, which `Limits.decoded_bytes` bounds through this factor
WORKING_BYTES_PER_BYTE = 32


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
    longest = (limits or LIMITS).decoded_bytes // WORKING_BYTES_PER_BYTE
    for begin, end in _chunks(text, CHUNK_BYTES):
        if end - begin > longest:
            raise SceneFileError(path, f"a line (with its '\\' continuations) of more than {longest} bytes: reading it "
                                 f"would take more than Limits.decoded_bytes ({(limits or LIMITS).decoded_bytes} bytes)",
                                 f"lines from {first_line}")
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
