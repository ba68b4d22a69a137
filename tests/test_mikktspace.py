"""MikkTSpace tangents (`glphong.scene.mikktspace`) against the reference implementation, and the glTF loader's use.

Independent check: tests/data/mikktspace/reference.json holds the tangents that the reference ``mikktspace.c``
algorithm, built to WebAssembly (npm package ``mikktspace`` 1.1.1, the build three.js uses), computes for the meshes of
tests/data/mikktspace/meshes.json (README.md there says how both were made).  The meshes: a quad, a
latitude-longitude sphere (u seam, one pole vertex per segment), a bent grid with uvs mirrored about its middle and a
second island mirrored in v across a seam, a strip with degenerate triangles and zero-uv-area ones between regions of
either orientation, a fin folded over its neighbour (the angular threshold's subgroups), a lumpy icosphere with noisy
uvs, and six seeded small meshes whose result depends on the reference's weld order and on the last run of its edge
sort (edges it leaves unpaired).

- every corner's tangent and sign equal the reference's to float32 rounding (the reference works in float32), for the
  mesh indexed and unindexed; Lengyel's per-vertex method (glphong's before, `tangents_from_uvs`) is far off;
- `mikktspace_vertices` gives each corner the reference's tangent, copying exactly the vertices whose corners differ;
- a glTF file with a normal texture and no ``TANGENT`` loads the reference's tangents (its uvs flipped to glphong's
  v-up, the convention of glTF's ``TANGENT``); a file whose material reads no tangents keeps its arrays as stored;
  non-finite normals or uvs load with finite tangents (0 where MikkTSpace's is not finite).

Planted bugs each fail the reference comparison on some of the meshes (checked when this was written): no angular
threshold, the group-with-any order ignored, degenerate corners not copied, the edge sort's last run sorted, the weld
keeping the first corner, the sign flipped, no angle weights, no projection, welds ignoring the normal, an unreached
corner's sign +1.
"""
import base64
import io
import json
import warnings
from pathlib import Path

import numpy as np
import PIL.Image
import pytest

import glphong
from glphong.filesafety import Limits, SceneFileError
from glphong.formats.gltf_data import MIKKTSPACE_BYTES_PER_TRIANGLE
from glphong.scene.geometry import tangents_from_uvs
from glphong.scene.mikktspace import mikktspace_corners, mikktspace_vertices

DATA = Path(__file__).resolve().parent / "data" / "mikktspace"
MESHES = json.loads((DATA / "meshes.json").read_text())
REFERENCE = json.loads((DATA / "reference.json").read_text())["tangents"]
#: float32 rounding of unit vectors (the reference and glphong agree bit for bit on these meshes with numpy 2.4)
TOLERANCE = 4 * np.finfo(np.float32).eps


def _decoded(b64, dtype):
    return np.frombuffer(base64.b64decode(b64), np.dtype(dtype).newbyteorder("<"))


def _mesh(name):
    """``(positions, normals, uvs, indices, reference (F, 3, 4))`` of a mesh of meshes.json."""
    m = MESHES[name]
    indices = _decoded(m["indices"], "i4").reshape(-1, 3)
    return (_decoded(m["positions"], "f4").reshape(-1, 3), _decoded(m["normals"], "f4").reshape(-1, 3),
            _decoded(m["uvs"], "f4").reshape(-1, 2), indices, _decoded(REFERENCE[name], "f4").reshape(-1, 3, 4))


def _assert_tangents(got, reference):
    """Tangents within float32 rounding of the reference and signs equal, every corner."""
    np.testing.assert_allclose(got[..., :3], reference[..., :3], rtol=0, atol=TOLERANCE)
    np.testing.assert_array_equal(got[..., 3], reference[..., 3])


@pytest.mark.parametrize("name", sorted(MESHES))
def test_corners_are_the_reference_tangents(name):
    positions, normals, uvs, indices, reference = _mesh(name)
    _assert_tangents(mikktspace_corners(positions, normals, indices, uvs), reference)
    corners = np.arange(indices.size).reshape(-1, 3)  # unindexed: the weld finds the shared vertices by value
    _assert_tangents(mikktspace_corners(positions[indices].reshape(-1, 3), normals[indices].reshape(-1, 3), corners,
                                        uvs[indices].reshape(-1, 2)), reference)


def test_the_meshes_exercise_what_they_are_for():
    """The reference has vertices whose corners differ (mirrored uvs, a fold, degenerate triangles) and both signs,
    and Lengyel's per-vertex method (glphong's before) is off by more than 0.05 on every mesh but the quad."""
    far = []
    for name in MESHES:
        positions, normals, uvs, indices, reference = _mesh(name)
        old = tangents_from_uvs(positions, normals, indices, uvs)[indices]
        far.append(np.abs(old - reference).max() > 0.05)
        if name in ("mirrored", "folded", "degenerate"):  # a vertex whose corners get different tangents
            assert any(len(np.unique(reference[indices == v], axis=0)) > 1 for v in np.unique(indices))
    assert sum(far) == len(MESHES) - 1  # all but the quad, whose per-vertex tangents are the same
    signs = np.concatenate([_mesh(name)[4][..., 3].ravel() for name in MESHES])
    assert set(np.unique(signs)) == {-1.0, 1.0}


@pytest.mark.parametrize("name", ["mirrored", "degenerate", "uv_sphere", "fuzz_3_23"])
def test_vertices_split_only_where_corners_differ(name):
    positions, normals, uvs, indices, reference = _mesh(name)
    source, split, tangents = mikktspace_vertices(positions, normals, indices, uvs)
    _assert_tangents(tangents[split], reference)
    np.testing.assert_array_equal(source[split], indices)  # each corner keeps its vertex's data
    np.testing.assert_array_equal(source[:len(positions)], np.arange(len(positions)))
    distinct = {(int(v), tuple(reference[indices == v][k])) for v in np.unique(indices)
                for k in range(int(np.sum(indices == v)))}
    assert len(source) == len(positions) + len(distinct) - len(np.unique(indices))


def _gltf(path, positions, normals, uvs, indices, material):
    """A .gltf file with one primitive (float32 attributes, uint32 indices, one data: buffer) and ``material``, whose
    normalTexture (if any) is texture 0, a 2 x 2 flat normal map."""
    arrays = [np.asarray(a, np.float32) for a in (positions, normals, uvs)] + [np.asarray(indices, np.uint32).ravel()]
    blob, views, accessors = b"", [], []
    for array, kind in zip(arrays, ("VEC3", "VEC3", "VEC2", "SCALAR")):
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": array.nbytes})
        accessor = {"bufferView": len(views) - 1, "componentType": 5125 if kind == "SCALAR" else 5126,
                    "count": len(array), "type": kind}
        if len(accessors) == 0:
            accessor.update(min=array.min(axis=0).tolist(), max=array.max(axis=0).tolist())
        accessors.append(accessor)
        blob += array.tobytes()
    png = io.BytesIO()
    PIL.Image.new("RGB", (2, 2), (128, 128, 255)).save(png, format="PNG")
    document = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
                "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3,
                                            "material": 0}]}],
                "materials": [material], "accessors": accessors, "bufferViews": views,
                "buffers": [{"byteLength": len(blob),
                             "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}],
                "images": [{"uri": "data:image/png;base64," + base64.b64encode(png.getvalue()).decode()}],
                "textures": [{"source": 0}]}
    path.write_text(json.dumps(document))
    return path


def _load(path):
    return glphong.load_scene(path, lights=[], camera=glphong.PerspectiveCamera(0.8)).objects[0].mesh


@pytest.mark.parametrize("name", ["mirrored", "uv_sphere", "folded"])
def test_a_gltf_file_without_tangents_loads_the_reference_tangents(tmp_path, name):
    """glTF's TEXCOORD has v down; glphong's uvs (and the TANGENT convention of glTF's exporters: Blender computes
    MikkTSpace on its own v-up uvs) are ``1 - v``: the file holds ``1 - v`` of the reference's uvs (exact in float32
    for these meshes' v)."""
    positions, normals, uvs, indices, reference = _mesh(name)
    file_uvs = np.stack([uvs[:, 0], np.float32(1.0) - uvs[:, 1]], axis=1)
    assert np.array_equal(np.float32(1.0) - file_uvs[:, 1], uvs[:, 1])
    path = _gltf(tmp_path / "mesh.gltf", positions, normals, file_uvs, indices, {"normalTexture": {"index": 0}})
    mesh = _load(path)
    assert mesh.given_tangents is not None and len(mesh.indices) == len(indices)
    _assert_tangents(mesh.tangents[mesh.indices], reference)
    np.testing.assert_array_equal(mesh.positions[mesh.indices], positions[indices])
    np.testing.assert_array_equal(mesh.uvs[mesh.indices], uvs[indices])


def test_a_material_that_reads_no_tangents_keeps_the_arrays(tmp_path):
    positions, normals, uvs, indices, _ = _mesh("mirrored")
    mesh = _load(_gltf(tmp_path / "plain.gltf", positions, normals, uvs, indices, {}))
    assert mesh.given_tangents is None and len(mesh.positions) == len(positions)
    np.testing.assert_array_equal(mesh.indices, indices)


@pytest.mark.parametrize("what", ["normal", "uv"])
def test_non_finite_normals_or_uvs_load_with_zero_tangents(tmp_path, what):
    """A NaN normal or a uv near FLT_MAX (overflowing the uv differences) is no error: where MikkTSpace's tangent is
    not finite the loaded tangent is 0 (the shader's basis around n), every tangent finite, no numpy warning."""
    positions, normals, uvs, indices, _ = _mesh("quad")
    normals, uvs = normals.copy(), uvs.copy()
    if what == "normal":
        normals[0] = np.nan
    else:
        uvs[1] = 3e38
    path = _gltf(tmp_path / "odd.gltf", positions, normals, uvs, indices, {"normalTexture": {"index": 0}})
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        mesh = _load(path)
    assert np.all(np.isfinite(mesh.tangents))
    if what == "normal":
        np.testing.assert_array_equal(mesh.tangents[0], [0.0, 0.0, 0.0, 1.0])


@pytest.mark.parametrize("name, column", [("TANGENT", None), ("TEXCOORD_0", 2)])
def test_non_finite_tangents_or_uvs_in_a_file_are_refused_by_path(tmp_path, name, column):
    """A file's TANGENT or uvs holding NaN or inf: a SceneFileError with the file and the JSON path (not MeshData's
    ValueError)."""
    positions, normals, uvs, indices, _ = _mesh("quad")
    uvs = uvs.copy()
    if column is not None:
        uvs[0, 1] = np.inf
    path = _gltf(tmp_path / "bad.gltf", positions, normals, uvs, indices, {"normalTexture": {"index": 0}})
    if name == "TANGENT":  # a fifth accessor, TANGENT, with a NaN
        document = json.loads(path.read_text())
        blob = base64.b64decode(document["buffers"][0]["uri"].split(",", 1)[1])
        tangents = np.tile(np.float32([1, 0, 0, 1]), (len(positions), 1))
        tangents[1, 0] = np.nan
        document["bufferViews"].append({"buffer": 0, "byteOffset": len(blob), "byteLength": tangents.nbytes})
        document["accessors"].append({"bufferView": len(document["bufferViews"]) - 1, "componentType": 5126,
                                      "count": len(tangents), "type": "VEC4"})
        document["meshes"][0]["primitives"][0]["attributes"]["TANGENT"] = len(document["accessors"]) - 1
        blob += tangents.tobytes()
        document["buffers"][0].update(byteLength=len(blob),
                                      uri="data:application/octet-stream;base64," + base64.b64encode(blob).decode())
        path.write_text(json.dumps(document))
    with pytest.raises(glphong.filesafety.SceneFileError,
                       match=rf"meshes\[0\]\.primitives\[0\]\.attributes\.{name}: {name} holds NaN or infinite"):
        _load(path)


def test_the_tangents_working_memory_counts_against_the_decoded_bytes_limit(tmp_path):
    """MikkTSpace's arrays (about 1 KiB a triangle at their peak, `MIKKTSPACE_BYTES_PER_TRIANGLE`) are charged to
    ``Limits.decoded_bytes`` before they are made: a file whose accessors fit a limit but whose tangents would not is
    refused by name, and loads under a limit with room for them."""
    positions, normals, uvs, indices, _ = _mesh("uv_sphere")
    path = _gltf(tmp_path / "mesh.gltf", positions, normals, uvs, indices, {"normalTexture": {"index": 0}})
    triangles = len(np.asarray(indices).reshape(-1, 3))
    accessors = sum(np.asarray(a).nbytes for a in (positions, normals, uvs)) + 4 * triangles * 3
    tight = Limits(decoded_bytes=accessors + MIKKTSPACE_BYTES_PER_TRIANGLE * triangles // 2)
    with pytest.raises(SceneFileError, match="MikkTSpace") as caught:
        glphong.load_scene(path, lights=[], camera=glphong.PerspectiveCamera(0.8), limits=tight)
    assert "decoded_bytes" in str(caught.value)
    room = Limits(decoded_bytes=8 * accessors + MIKKTSPACE_BYTES_PER_TRIANGLE * triangles)
    mesh = glphong.load_scene(path, lights=[], camera=glphong.PerspectiveCamera(0.8), limits=room).objects[0].mesh
    assert mesh.given_tangents is not None
