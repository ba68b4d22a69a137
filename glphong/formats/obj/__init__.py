"""Wavefront OBJ geometry read into numpy arrays, in memory and time proportional to the file.

`read_obj` reads the file through `glphong.filesafety.read_bytes` (a regular file of at most
``Limits.file_bytes`` bytes; UTF-8 with or without a byte-order mark, UTF-16 with one) and makes no
Python object per line or per corner (``usemtl`` names aside): line ends, comments, continuations and
keywords are found with numpy on the file's bytes, `statements.CHUNK_BYTES` of whole lines at a time, so that
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

Notes
-----
One job each, each importing at most those before it: `statements` (the file's bytes cut into keyword
statements: chunks, continuations, comments, first words, line ends and encodings), `values` (the
numbers of ``v``, ``vt``, ``vn``, the face corners, their indices resolved and checked), `mesh` (fanning,
parts, attributes dropped as trimesh does, corners merged, smooth normals) and `reader` (`read_obj`).
Time and memory against trimesh's reader: ``benchmarks/obj_reader.py``.
"""
from glphong.formats.obj.mesh import _smooth_normals  # noqa: F401 (tests compare it with trimesh)
from glphong.formats.obj.reader import read_obj

__all__ = ["read_obj"]
