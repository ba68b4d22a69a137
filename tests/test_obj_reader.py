"""`glphong.formats.obj.read_obj`: OBJ geometry read with numpy, errors and warnings that say where.

- Handwritten files give their values and faces exactly (vertices are the sorted distinct index
  triples, polygons fanned from the first corner, parts in order of first use); random valid files give
  bit for bit what a per-corner reference reader (the previous glphong reader) gives.
- Continuations, comments, tabs, blank lines, CRLF and CR line ends, a UTF-8 byte-order mark and UTF-16
  read as the plain file; negative indices count back from the face's line.
- Missing texture coordinates and normals are dropped per part as trimesh drops them, with one warning
  per file; faces of fewer than three corners are skipped (trimesh too).
- Every malformed line is a `SceneFileError` naming its line; a FIFO and ``/dev/zero`` are refused at
  once; a face of 10^6 corners loads in a subprocess limited to 1.5 GiB of address space.
"""
import io
import os
import random
import warnings

import numpy as np
import pytest
import trimesh

from glphong.filesafety import Limits, SceneFileError
from glphong.formats.obj import _smooth_normals, read_obj

SQUARE = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"


def _write(tmp_path, text, name="mesh.obj"):
    path = tmp_path / name
    path.write_bytes(text if isinstance(text, bytes) else text.encode())
    return path


def _read(path, **kwargs):
    """``read_obj(path)`` and the warnings it raised (list of str)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        out = read_obj(path, **kwargs)
    return out, [str(w.message) for w in caught]


def _arrays(out):
    """(name, positions, normals, indices, uvs) of each part, as plain arrays (uvs None where absent)."""
    return [(name, m.positions, m.normals, m.indices, m.uvs) for name, m in out]


def _assert_same(a, b):
    assert [p[0] for p in a] == [p[0] for p in b]
    for x, y in zip(_arrays(a), _arrays(b)):
        for u, v in zip(x[1:], y[1:]):
            assert (u is None) == (v is None)
            if u is not None:
                assert u.dtype == v.dtype and u.shape == v.shape and np.array_equal(u, v)


def test_handwritten_file_gives_its_values_and_faces_exactly(tmp_path):
    text = ("v 0 0 0\nv 2 0 0\nv 2 3 0\nv 0 3 0.5\n"
            "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1 0.25\n"
            "vn 0 0 1\nvn 0 0.6 0.8\n"
            "f 1/1/1 2/2/1 3/3/2 4/4/2\n"
            "f 3/3/2 4/4/2 1/1/1\n")
    [(name, mesh)] = _read(_write(tmp_path, text))[0]
    assert name == ""
    # distinct (v, vt, vn) triples in increasing order; the quad fanned (1 2 3), (1 3 4)
    np.testing.assert_array_equal(mesh.positions, np.float32([[0, 0, 0], [2, 0, 0], [2, 3, 0], [0, 3, 0.5]]))
    np.testing.assert_array_equal(mesh.uvs, np.float32([[0, 0], [1, 0], [1, 1], [0, 1]]))
    np.testing.assert_array_equal(mesh.normals, np.float32([[0, 0, 1], [0, 0, 1], [0, 0.6, 0.8], [0, 0.6, 0.8]]))
    np.testing.assert_array_equal(mesh.indices, [[0, 1, 2], [0, 2, 3], [2, 3, 0]])


def test_corners_sharing_a_position_with_other_uvs_are_other_vertices(tmp_path):
    text = SQUARE + "vt 0 0\nvt 1 0\nvt 1 1\nvt 0.5 0.5\nf 1/1 2/2 3/3\nf 1/4 3/3 4/4\n"
    [(_, mesh)] = _read(_write(tmp_path, text))[0]
    # triples (v, vt): (1,1) (1,4) (2,2) (3,3) (4,4)
    np.testing.assert_array_equal(mesh.positions, np.float32([[0, 0, 0], [0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]))
    np.testing.assert_array_equal(mesh.uvs, np.float32([[0, 0], [0.5, 0.5], [1, 0], [1, 1], [0.5, 0.5]]))
    np.testing.assert_array_equal(mesh.indices, [[0, 2, 3], [1, 3, 4]])


def test_parts_in_order_of_first_use_with_faces_before_any_usemtl_in_part_empty(tmp_path):
    text = (SQUARE + "usemtl unused\nusemtl b\nf 1 2 3\nusemtl\nf 1 3 4\nusemtl  a   b \nf 2 3 4\n"
            "usemtl b\nf 1 2 4\n")
    out = _read(_write(tmp_path, text))[0]
    assert [name for name, _ in out] == ["b", "", "a b"]
    b = out[0][1]
    np.testing.assert_array_equal(b.indices, [[0, 1, 2], [0, 1, 3]])  # its two faces, in file order
    np.testing.assert_array_equal(b.positions, np.float32([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]))


def test_polygon_fanned_from_its_first_corner(tmp_path):
    [(_, mesh)] = _read(_write(tmp_path, SQUARE + "v 0.5 2 0\nf 2 3 5 4 1\n"))[0]
    # vertices 1..5 (sorted), fan (2 3 5) (2 5 4) (2 4 1)
    np.testing.assert_array_equal(mesh.indices, [[1, 2, 4], [1, 4, 3], [1, 3, 0]])


def test_negative_indices_count_back_from_the_faces_line(tmp_path):
    text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 5 5 5\nf -4 -3 -1\n"
    [(_, mesh)] = _read(_write(tmp_path, text))[0]
    np.testing.assert_array_equal(mesh.positions, np.float32([[0, 0, 0], [1, 0, 0], [0, 1, 0], [5, 5, 5]]))
    np.testing.assert_array_equal(mesh.indices, [[0, 1, 2], [0, 1, 3]])


def test_a_face_may_name_vertices_defined_after_it(tmp_path):
    [(_, mesh)] = _read(_write(tmp_path, "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"))[0]
    np.testing.assert_array_equal(mesh.indices, [[0, 1, 2]])


def test_extra_and_missing_optional_numbers(tmp_path):
    # v with a w or a colour: the first three; vt with u only: v = 0; vt with w: (u, v)
    text = "v 0 0 0 1 0.5 0.5\nv 1 0 0 1\nv 0 1 0\nvt 0.25\nvt 0.5 0.75 1\nf 1/1 2/2 3/1\n"
    [(_, mesh)] = _read(_write(tmp_path, text))[0]
    np.testing.assert_array_equal(mesh.positions, np.float32([[0, 0, 0], [1, 0, 0], [0, 1, 0]]))
    np.testing.assert_array_equal(mesh.uvs, np.float32([[0.25, 0], [0.5, 0.75], [0.25, 0]]))


PLAIN = SQUARE + "vt 0 0\nvt 1 1\nvn 0 0 1\nusemtl wood\nf 1/1/1 2/2/1 3/1/1 4/2/1\n"


@pytest.mark.parametrize("variant", [
    "f 1/1/1 2/2/1 \\\n3/1/1 4/2/1\n",                      # a continued face line
    "f 1/1/1 \\\n 2/2/1 \\\n3/1/1 4/2/1  \\\n\n",           # three continuations, the last before a blank line
    "\t f\t1/1/1   2/2/1\t3/1/1 4/2/1   # a comment\n# only a comment\n\n   \n",
])
def test_continuations_comments_tabs_blank_lines_read_as_the_plain_file(tmp_path, variant):
    text = PLAIN.replace("f 1/1/1 2/2/1 3/1/1 4/2/1\n", variant)
    _assert_same(_read(_write(tmp_path, text))[0], _read(_write(tmp_path, PLAIN, "plain.obj"))[0])


@pytest.mark.parametrize("encode", [
    lambda text: text.replace("\n", "\r\n").encode(),
    lambda text: text.replace("\n", "\r").encode(),
    lambda text: b"\xef\xbb\xbf" + text.encode(),
    lambda text: text.encode("utf-16"),
    lambda text: b"\xfe\xff" + text.encode("utf-16-be"),
], ids=["crlf", "cr", "utf8-bom", "utf16-le", "utf16-be"])
def test_line_ends_and_encodings_read_as_the_plain_file(tmp_path, encode):
    text = PLAIN.replace("usemtl wood", "usemtl bois_\u00e9\u00e8")
    out = _read(_write(tmp_path, encode(text)))[0]
    assert out[0][0] == "bois_\u00e9\u00e8"
    _assert_same(out, _read(_write(tmp_path, text, "plain.obj"))[0])


def test_line_numbers_count_the_files_lines_across_continuations(tmp_path):
    text = SQUARE + "f 1 2 \\\n 3 4\nf 1 \\\n 2 \\\n 3\nv 1 2 oops\n"
    with pytest.raises(SceneFileError) as caught:
        read_obj(_write(tmp_path, text))
    assert caught.value.where == "line 10"
    with pytest.raises(SceneFileError) as caught:
        read_obj(_write(tmp_path, text.replace("f 1 \\\n 2 \\\n 3\nv 1 2 oops", "f 1 \\\n 2 \\\n x")))
    assert caught.value.where == "line 7" and "'f 1    2    x'" in caught.value.message  # a space each


def test_chunk_boundaries_change_nothing(tmp_path, monkeypatch):
    import glphong.formats.obj.statements

    text = ("# header \\\n continued comment\n" + SQUARE + "vt 0 0\\\n 1\nvt 1 1\n\t usemtl  a # b\n"
            "f 1/1 2/2 \\\n 3/1 \\\n\\\n 4/2\n  \n# f 9 9 9\nusemtl c\nf -4/1 -3/2 -2/1 # x\n")
    path = _write(tmp_path, text)
    whole = _read(path)[0]
    assert [(name, mesh.triangle_count) for name, mesh in whole] == [("a", 2), ("c", 1)]
    bad = _write(tmp_path, text + "f 1 \\\n 2 x\n", "bad.obj")
    for size in (1, 5, 13, 64):
        monkeypatch.setattr(glphong.formats.obj.statements, "CHUNK_BYTES", size)
        _assert_same(_read(path)[0], whole)
        with pytest.raises(SceneFileError) as caught:
            read_obj(bad)
        assert caught.value.where == "line 19"


def _trimesh_groups(text):
    """trimesh's reading of an OBJ text: per geometry, (has uv, has normals from the file)."""
    loaded = trimesh.exchange.obj.load_obj(io.BytesIO(text.encode()))
    return sorted((getattr(g.get("visual"), "uv", None) is not None, "vertex_normals" in g)
                  for g in loaded["geometry"].values())


MISSING = [
    # (faces, uvs kept, normals kept, words of the one warning)
    ("f 1/1/1 2/2/1 3/9/1\n", False, True, ["texture coordinates dropped", "line 8", "vt index beyond"]),
    ("f 1/1/1 2/2/1 3/-9/1\n", False, True, ["texture coordinates dropped", "line 8", "vt index beyond"]),
    ("f 1/1/1 2/2/1 3/2/5\n", True, False, ["normals dropped", "line 8", "vn index beyond"]),
    ("f 1//1 2//1 3//7\n", False, False, ["normals dropped", "line 8", "vn index beyond"]),
    ("f 1/1 2/2 3/1\nf 1 3 4\n", False, False, ["texture coordinates dropped", "line 9", "some corners name a vt"]),
    ("f 1//1 2//1 3//1\nf 1 3 4\n", False, False, ["normals dropped", "line 9", "some corners name a vn"]),
    ("f 1/1/1 2/2/1 3/9/9\n", False, False, ["texture coordinates dropped", "normals dropped"]),
]


@pytest.mark.parametrize("faces, uvs_kept, normals_kept, words", MISSING)
def test_missing_uvs_and_normals_are_dropped_as_trimesh_drops_them_with_one_warning(
        tmp_path, faces, uvs_kept, normals_kept, words):
    text = SQUARE + "vt 0 0\nvt 1 0\nvn 0 0.6 0.8\n" + faces
    out, caught = _read(_write(tmp_path, text))
    [(_, mesh)] = out
    assert _trimesh_groups(text) == [(uvs_kept, normals_kept)]
    assert (mesh.uvs is not None) == uvs_kept
    if normals_kept:
        np.testing.assert_array_equal(mesh.normals, np.float32([[0, 0.6, 0.8]] * len(mesh.normals)))
    else:  # trimesh's smooth normals of the part
        expected = trimesh.Trimesh(mesh.positions.astype(np.float64), mesh.indices, process=False).vertex_normals
        np.testing.assert_allclose(mesh.normals, expected, atol=1e-7)
    assert len(caught) == 1 and all(word in caught[0] for word in words), caught


def test_one_warning_for_a_whole_file_and_each_part_judged_alone(tmp_path):
    text = (SQUARE + "vt 0 0\nvn 0 0 1\nusemtl a\nf 1/1/1 2/1/1 3/9/1\nusemtl b\nf 1//1 2//1 3//7\nf 1 2\n"
            "usemtl c\nf 1/1/1 3/1/1 4/1/1\n")
    out, caught = _read(_write(tmp_path, text))
    assert [(n, m.uvs is not None) for n, m in out] == [("a", False), ("b", False), ("c", True)]
    np.testing.assert_array_equal(out[2][1].normals, np.float32([[0, 0, 1]] * 3))
    assert len(caught) == 1
    assert ("1 face(s) of fewer than three corners skipped (first: line 11)" in caught[0]
            and "part 'a': texture coordinates dropped (line 8" in caught[0]
            and "part 'b': normals dropped, smooth ones computed (line 10" in caught[0]), caught[0]


def test_faces_of_fewer_than_three_corners_are_skipped_as_trimesh_skips_them(tmp_path):
    out, caught = _read(_write(tmp_path, SQUARE + "f 1 2\nf\nf 1 2 3\n"))
    assert len(trimesh.exchange.obj.load_obj(io.BytesIO((SQUARE + "f 1 2\nf 1 2 3\n").encode()))["geometry"]
               .popitem()[1]["faces"]) == 1
    [(_, mesh)] = out
    np.testing.assert_array_equal(mesh.indices, [[0, 1, 2]])
    assert len(caught) == 1 and "2 face(s) of fewer than three corners skipped (first: line 5)" in caught[0]
    out, caught = _read(_write(tmp_path, SQUARE + "f 1 2\n"))
    assert out == [] and len(caught) == 1


def test_files_without_faces_give_no_parts(tmp_path):
    assert _read(_write(tmp_path, ""))[0] == []
    assert _read(_write(tmp_path, SQUARE + "# no faces\n"))[0] == []


ERRORS = [
    # (text after SQUARE, line, what the message holds)
    ("v 1 2 abc\n", 5, ["found 'v 1 2 abc'", "expected three decimal numbers"]),
    ("v 1,5 2 3\n", 5, ["found 'v 1,5 2 3'"]),
    ("v 1 2\n", 5, ["found 'v 1 2'", "three decimal numbers"]),
    ("v nan 0 0\n", 5, ["positions that are finite numbers"]),
    ("v 0 -inf 0\n", 5, ["positions that are finite numbers"]),
    ("v 1e39 0 0\n", 5, ["positions that are finite numbers", "float32"]),
    ("vt nan 0\n", 5, ["texture coordinates that are finite"]),
    ("vt\n", 5, ["one to three decimal numbers"]),
    ("vn 0 0 x\n", 5, ["found 'vn 0 0 x'"]),
    ("f 1 2 3\nf 1 a 2\n", 6, ["found 'f 1 a 2'", "corners v, v/vt, v//vn or v/vt/vn"]),
    ("f 1.5 2 3\n", 5, ["found 'f 1.5 2 3'"]),
    ("f 1 2 3 -\n", 5, ["corners v, v/vt"]),
    ("f 1 2- 3\n", 5, ["corners v, v/vt"]),
    ("f /1 2 3\n", 5, ["corners v, v/vt"]),
    ("f 1/2/3/4 2 3\n", 5, ["found 'f 1/2/3/4 2 3'"]),
    ("f 1 2 caf\u00e9\n", 5, ["corners v, v/vt"]),
    ("f 1 2 0\n", 5, ["found 'f 1 2 0'", "no index 0"]),
    ("f 1 2 5\n", 5, ["found 'f 1 2 5'", "position indices from 1 to 4", "not 5"]),
    ("f 1 2 -5\n", 5, ["from -4 to -1", "not -5"]),
    ("f 1 2 99999999999999999999999\n", 5, ["beyond 64-bit integers"]),
    ("f 1/1 2/1 0/1\n", 5, ["no index 0"]),
]


@pytest.mark.parametrize("text, line, words", ERRORS)
def test_errors_name_the_line_what_was_found_and_what_was_expected(tmp_path, text, line, words):
    path = _write(tmp_path, SQUARE + text)
    with pytest.raises(SceneFileError) as caught:
        read_obj(path)
    error = caught.value
    assert error.file == str(path) and error.where == f"line {line}"
    assert all(word in error.message for word in words), error.message
    # what trimesh does instead: no error where it can parse, a raw exception or garbage elsewhere;
    # here at least no exception escapes that is not a SceneFileError (pytest.raises checked the type)


def test_a_long_line_is_quoted_shortened(tmp_path):
    with pytest.raises(SceneFileError) as caught:
        read_obj(_write(tmp_path, SQUARE + "f 1 2 3 " + " ".join(["9"] * 10 ** 5) + "\n"))
    assert len(caught.value.message) < 300 and "..." in caught.value.message


def test_limits_bound_the_file(tmp_path):
    path = _write(tmp_path, SQUARE + "f 1 2 3\n")
    with pytest.raises(SceneFileError, match="more than the limit of 10"):
        read_obj(path, limits=Limits(file_bytes=10))


def test_a_fifo_and_dev_zero_are_refused_at_once(tmp_path, run_isolated):
    fifo = tmp_path / "pipe.obj"
    os.mkfifo(fifo)
    code = ("import sys\nfrom glphong.formats.obj import read_obj\nfrom glphong.filesafety import SceneFileError\n"
            "for path in sys.argv[1:]:\n"
            "    try:\n        read_obj(path)\n    except SceneFileError as e:\n        print('refused', e)\n")
    done = run_isolated(code, timeout=30, memory_bytes=3 << 29, args=(str(fifo), "/dev/zero"))
    assert done.returncode == 0, done.stderr
    assert done.stdout.count("not a regular file") == 2, done.stdout


def test_a_face_of_a_million_corners_loads_in_bounded_memory_and_time(tmp_path, run_isolated):
    # 1000 vertices on a circle, one face line going round them a thousand times: 999,998 triangles
    angle = np.arange(1000) * (2 * np.pi / 1000)
    lines = [f"v {np.cos(a):.6f} {np.sin(a):.6f} 0" for a in angle]
    path = _write(tmp_path, "\n".join(lines) + "\nf " + " ".join(str(k % 1000 + 1) for k in range(10 ** 6)) + "\n")
    code = ("import sys, time\nfrom glphong.formats.obj import read_obj\nstart = time.perf_counter()\n"
            "[(name, mesh)] = read_obj(sys.argv[1])\n"
            "print(mesh.triangle_count, len(mesh.positions), round(time.perf_counter() - start, 2))\n")
    done = run_isolated(code, timeout=60, memory_bytes=3 << 29, args=(str(path),))
    assert done.returncode == 0, done.stderr[-2000:]
    triangles, vertices, _ = done.stdout.split()
    assert (int(triangles), int(vertices)) == (999_998, 1000)


def test_smooth_normals_are_trimeshs_vertex_normals():
    rng = np.random.default_rng(7)
    for trial in range(20):
        positions = rng.normal(size=(40, 3))
        if trial % 4 == 0:
            positions = np.round(positions)  # degenerate triangles too
        faces = rng.integers(0, 40, size=(80, 3))
        faces[:3, 1] = faces[:3, 0]
        expected = trimesh.Trimesh(positions, faces, process=False).vertex_normals
        np.testing.assert_allclose(_smooth_normals(positions, faces, block=7), expected, rtol=0, atol=1e-14)


def _reference_read_obj(path):
    """The previous reader, one Python tuple per corner (valid files only): the result to match bit for bit."""
    from glphong.scene.geometry import MeshData

    positions, normals, uvs, parts, current = [], [], [], {}, ""
    for raw in path.read_text().splitlines():
        words = raw.split("#", 1)[0].split()
        if not words:
            continue
        if words[0] == "v":
            positions.append([float(x) for x in words[1:4]])
        elif words[0] == "vn":
            normals.append([float(x) for x in words[1:4]])
        elif words[0] == "vt":
            uvs.append([float(x) for x in (words[1:3] + ["0"])[:2]])
        elif words[0] == "usemtl":
            current = " ".join(words[1:])
        elif words[0] == "f":
            corners = []
            for word in words[1:]:
                fields = (word.split("/") + ["", ""])[:3]
                corner = []
                for field, count in zip(fields, (len(positions), len(uvs), len(normals))):
                    k = int(field) if field else 0
                    corner.append(k - 1 if k > 0 else (count + k if k < 0 else -1))
                corners.append(tuple(corner))
            parts.setdefault(current, []).extend((corners[0], corners[i], corners[i + 1])
                                                 for i in range(1, len(corners) - 1))
    positions = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
    out = []
    for name, triangles in parts.items():
        unique, inverse = np.unique(np.asarray(triangles).reshape(-1, 3), axis=0, return_inverse=True)
        faces = inverse.reshape(-1, 3)
        if np.all(unique[:, 2] >= 0):
            vertex_normals = np.asarray(normals)[unique[:, 2]]
        else:
            vertex_normals = trimesh.Trimesh(positions[unique[:, 0]], faces, process=False).vertex_normals
        vertex_uvs = np.asarray(uvs)[unique[:, 1]] if np.all(unique[:, 1] >= 0) else None
        out.append((name, MeshData(positions[unique[:, 0]], vertex_normals, faces, uvs=vertex_uvs)))
    return out


def _random_obj(rng):
    """A valid OBJ text: random values written with 17 digits, one corner form per file, random parts."""
    form = rng.choice(["v", "v/vt", "v//vn", "v/vt/vn"])
    nv, nt, nn = rng.randint(3, 30), rng.randint(1, 10), rng.randint(1, 5)
    lines = ["v %r %r %r" % tuple(rng.uniform(-5, 5) for _ in range(3)) for _ in range(nv)]
    lines += ["vt %r %r" % (rng.random(), rng.random()) for _ in range(nt)]
    lines += ["vn %.6f %.6f %.6f" % tuple(rng.uniform(-1, 1) for _ in range(3)) for _ in range(nn)]
    for _ in range(rng.randint(1, 12)):
        if rng.random() < 0.3:
            lines.append("usemtl " + rng.choice(["", "a", "b b", "c"]))
        corners = []
        for _ in range(rng.randint(3, 7)):
            v = rng.randint(1, nv) if rng.random() < 0.8 else -rng.randint(1, nv)
            t, n = rng.randint(1, nt), rng.randint(1, nn)
            corners.append({"v": f"{v}", "v/vt": f"{v}/{t}", "v//vn": f"{v}//{n}", "v/vt/vn": f"{v}/{t}/{n}"}[form])
        lines.append("f " + " ".join(corners))
    return "\n".join(lines) + "\n"


def test_random_valid_files_read_bit_for_bit_as_the_per_corner_reference(tmp_path):
    rng = random.Random(3)
    for trial in range(60):
        path = _write(tmp_path, _random_obj(rng), f"random{trial}.obj")
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            _assert_same(read_obj(path), _reference_read_obj(path))


def test_one_huge_joined_line_is_bounded_by_the_decoded_budget(tmp_path):
    """A file of nothing but continued lines is one logical line: its scan would take about 18 bytes a byte, so
    a line longer than ``Limits.decoded_bytes / 32`` is refused, naming the lines it is among."""
    from glphong.core.filesafety import Limits, SceneFileError
    from glphong.formats.obj import read_obj

    path = tmp_path / "joined.obj"
    path.write_bytes(b"v 0 0 0\nv 1 0 0\nv 0 1 0\n" + b"f 1 2 3 \\\n" * 20000 + b"f 1 2 3\n")
    with pytest.raises(SceneFileError, match=r"lines from 1: a line \(with its '\\' continuations\) of more than "
                                             r"3125 bytes"):
        read_obj(path, Limits(decoded_bytes=100_000))
