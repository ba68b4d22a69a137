"""Scene files from anyone (`glphong.load_scene`, `glphong.filesafety`): nothing leaks, nothing hangs, every file
loads or says why.  Every file is made here by the test.

- Paths: glTF buffer and image URIs, OBJ ``mtllib`` and MTL ``map_Kd`` that leave the file's folder (``..``,
  absolute, percent-encoded, through a symbolic link, with a scheme) are refused, and the secret's bytes appear in
  no message; ``allow_outside=True`` reads them; a table path in a material's extras is never opened.
- Memory and time (each in a subprocess under an address-space limit and a timeout): negative and too small
  strides, ``/dev/zero`` and a FIFO as a buffer, a node listed twice by each of 40 nodes (2^40 paths, refused by
  ``Limits.nodes``), a cycle, a PNG of 12000 x 12000 pixels, an OBJ ``mtllib`` FIFO; a legal 3000-deep node chain
  loads.
- Raw errors: out-of-range and negative indices, bad JSON, deep JSON, glTF 1.0, unknown required extensions,
  an EPS image; and a seeded fuzz of 400 mutated documents raises nothing but `SceneFileError`.
- Formats: strips, fans, sparse accessors, Draco, skins and morph targets (one warning), points skipped; an
  extension used and not applied is named in a warning, one glphong applies is not (meshopt, KTX2, WebP,
  quantization, variants and uv sets: tests/gltf).
- The Khronos Duck case: a camera and no light gets the default light with a warning; ``lights=[]`` stays dark.
- An MTL with ``map_Ks`` and its image present loads (it crashed).
"""
import base64
import copy
import json
import math
import os
import random
import struct
import warnings

import numpy as np
import pytest

import glphong
from glphong.filesafety import Limits, SceneFileError

SECRET = b"TOPSECRET-0123456789-" * 8


def _quad():
    """Positions (4, 3) float32, normals (4, 3) float32, indices (6,) uint16 of a unit quad facing +z."""
    positions = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
    normals = np.tile(np.array([0, 0, 1], np.float32), (4, 1))
    return positions, normals, np.array([0, 1, 2, 0, 2, 3], np.uint16)


def _document(blob_uri="quad.bin", camera=True, lights=True):
    """A valid glTF document of one quad (buffer ``blob_uri``: positions, normals, indices) and its bytes."""
    positions, normals, indices = _quad()
    blob = positions.tobytes() + normals.tobytes() + indices.tobytes() + b"\0\0\0\0"
    document = {
        "asset": {"version": "2.0"},
        "buffers": [{"uri": blob_uri, "byteLength": len(blob)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48},
                        {"buffer": 0, "byteOffset": 48, "byteLength": 48},
                        {"buffer": 0, "byteOffset": 96, "byteLength": 12}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
                       "min": [-1, -1, 0], "max": [1, 1, 0]},
                      {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
                      {"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": 0}]}],
        "materials": [{"name": "paint", "pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1.0],
                                                                 "metallicFactor": 0.0}}],
        "nodes": [{"name": "quad", "mesh": 0}],
        "scenes": [{"nodes": [0]}], "scene": 0,
    }
    if camera:
        document["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "zfar": 100}}]
        document["nodes"].append({"name": "cam", "camera": 0, "translation": [0, 0, 4]})
        document["scenes"][0]["nodes"].append(1)
    if lights:
        document["extensions"] = {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 50.0}]}}
        document["nodes"].append({"name": "bulb", "translation": [1, 1, 3],
                                  "extensions": {"KHR_lights_punctual": {"light": 0}}})
        document["scenes"][0]["nodes"].append(len(document["nodes"]) - 1)
    return document, blob


def _write(folder, document, blob=None, name="scene.gltf"):
    folder.mkdir(parents=True, exist_ok=True)
    if blob is not None:
        (folder / document["buffers"][0]["uri"]).write_bytes(blob)
    path = folder / name
    path.write_text(json.dumps(document))
    return path


def _load(path, **keywords):
    keywords.setdefault("light_units", "radiometric")
    return glphong.load_scene(path, **keywords)


def _png(width, height):
    from io import BytesIO

    from PIL import Image

    out = BytesIO()
    Image.new("RGB", (width, height), (200, 100, 50)).save(out, format="PNG")
    return out.getvalue()


# ---------------------------------------------------------------- paths


@pytest.fixture
def secret(tmp_path):
    (tmp_path / "secret.bin").write_bytes(SECRET)
    return tmp_path / "secret.bin"


def _refused(path, pattern, **keywords):
    with pytest.raises(SceneFileError, match=pattern) as caught:
        _load(path, **keywords)
    assert "TOPSECRET" not in str(caught.value)
    return caught.value


@pytest.mark.parametrize("uri, pattern", [
    ("../secret.bin", "leaves the scene file's folder"),
    ("%2E%2E/secret.bin", "leaves the scene file's folder"),
    ("sub/../../secret.bin", "leaves the scene file's folder"),
    ("{secret}", "is an absolute path"),
    ("file://{secret}", "URI with a scheme"),
    ("http://example.invalid/x.bin", "URI with a scheme"),
])
def test_buffer_uri_outside_the_folder_is_refused(tmp_path, secret, uri, pattern):
    document, _ = _document(uri.format(secret=secret))
    error = _refused(_write(tmp_path / "scene", document), pattern)
    assert error.where == "buffers[0].uri"


def test_symlink_out_of_the_folder_is_refused_and_allow_outside_reads(tmp_path, secret):
    document, blob = _document("link.bin")
    folder = tmp_path / "scene"
    folder.mkdir()
    (tmp_path / "real.bin").write_bytes(blob)
    os.symlink(tmp_path / "real.bin", folder / "link.bin")
    path = _write(folder, document)
    _refused(path, "leaves the scene file's folder")
    scene = _load(path, allow_outside=True)
    assert len(scene.objects) == 1
    document["buffers"][0]["uri"] = "../real.bin"
    assert len(_load(_write(folder, document), allow_outside=True).objects) == 1


def test_image_uri_outside_is_refused(tmp_path, secret):
    document, blob = _document()
    document["images"] = [{"uri": "../secret.bin"}]
    document["textures"] = [{"source": 0}]
    document["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    uvs = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32).tobytes()
    blob = blob + uvs
    document["buffers"][0]["byteLength"] = len(blob)
    document["bufferViews"].append({"buffer": 0, "byteOffset": len(blob) - 32, "byteLength": 32})
    document["accessors"].append({"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC2"})
    document["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = 3
    error = _refused(_write(tmp_path / "scene", document, blob), "leaves the scene file's folder")
    assert error.where == "images[0].uri"


def test_obj_mtllib_and_map_outside_are_refused(tmp_path, secret):
    folder = tmp_path / "scene"
    folder.mkdir()
    quad = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nf 1 2 3\n"
    (folder / "a.obj").write_text("mtllib ../outside.mtl\nusemtl m\n" + quad)
    (tmp_path / "outside.mtl").write_text("newmtl m\nKd 0.5 0.5 0.5\n")
    _refused(folder / "a.obj", "leaves the scene file's folder")
    assert len(glphong.load_scene(folder / "a.obj", allow_outside=True).objects) == 1
    (folder / "b.obj").write_text("mtllib b.mtl\nusemtl m\n" + quad)
    (folder / "b.mtl").write_text(f"newmtl m\nKd 1 1 1\nmap_Kd {secret}\n")
    error = _refused(folder / "b.obj", "is an absolute path")
    assert error.where == "line 3"


def test_a_table_path_in_extras_is_never_opened(tmp_path, secret):
    document, blob = _document()
    document["materials"][0]["extras"] = {"glphong": {"version": 1, "class": "MeasuredBRDF", "module":
                                                      "glphong.materials.measured", "arguments": {"table": str(secret)}}}
    _refused(_write(tmp_path / "scene", document, blob), "never reads a table")
    document["materials"][0]["extras"] = {"glphong": {"version": 1, "class": "CookTorrance", "arguments": {
        "fresnel": {"class": "Path", "f0": "/etc/passwd"}}}}
    _refused(_write(tmp_path / "scene", document, blob), "unknown Fresnel factor 'Path'")


# ---------------------------------------------------------------- memory and time, isolated

_ISOLATED = r"""
import json, sys, time, warnings
warnings.simplefilter("ignore")
import glphong
from glphong.filesafety import SceneFileError
out = {}
for path in sys.argv[1:]:
    start = time.perf_counter()
    try:
        scene = glphong.load_scene(path, light_units="radiometric")
        out[path] = ["loaded", len(scene.objects), time.perf_counter() - start]
    except SceneFileError as exc:
        out[path] = ["refused", str(exc), time.perf_counter() - start]
print(json.dumps(out))
"""


def _hostile_gltf_files(folder):
    """{name: (path, expected outcome regex)} of files that once crashed, hung or blew up memory."""
    files = {}
    document, blob = _document()
    for stride in (-24, -100000000, 1, 8):
        d = copy.deepcopy(document)
        d["bufferViews"][0]["byteStride"] = stride
        files[f"stride{stride}"] = (_write(folder, d, blob, f"stride{stride}.gltf"), "byteStride|less than the")
    d = copy.deepcopy(document)
    d["accessors"][0]["type"] = "MAT4"
    d["bufferViews"][0]["byteStride"] = 4
    files["mat4"] = (_write(folder, d, blob, "mat4.gltf"), "less than the 64-byte elements")
    d = copy.deepcopy(document)
    d["buffers"][0]["uri"] = "zero.bin"
    os.symlink("/dev/zero", folder / "zero.bin")
    files["devzero"] = (_write(folder, d, None, "devzero.gltf"), "leaves the scene file's folder")
    d = copy.deepcopy(document)
    d["buffers"][0]["uri"] = "fifo.bin"
    os.mkfifo(folder / "fifo.bin")
    files["fifo"] = (_write(folder, d, None, "fifo.gltf"), "not a regular file")
    d = copy.deepcopy(document)
    d["nodes"] = [{"children": [k + 1, k + 1]} for k in range(40)] + [{"mesh": 0}]
    d["scenes"] = [{"nodes": [0]}]
    files["twice"] = (_write(folder, d, None, "twice.gltf"), r"scenes\[0\]: its nodes are reached by more than 1000000 "
                      "paths")
    d = copy.deepcopy(document)
    d["nodes"] = [{"children": [1]}, {"children": [2]}, {"children": [1], "mesh": 0}]
    d["scenes"] = [{"nodes": [0]}]
    files["cycle"] = (_write(folder, d, None, "cycle.gltf"), r"nodes\[2\]\.children\[0\]: node 1 is its own ancestor")
    d = copy.deepcopy(document)
    d["nodes"] = [{"children": [k + 1]} for k in range(3000)] + [{"mesh": 0}]
    d["scenes"] = [{"nodes": [0]}]
    files["deep"] = (_write(folder, d, None, "deep.gltf"), "loaded")
    d = copy.deepcopy(document)
    png = _png(12000, 12000)
    d["images"] = [{"uri": "data:image/png;base64," + base64.b64encode(png).decode()}]
    d["textures"] = [{"source": 0}]
    d["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    uvs = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32).tobytes()
    d["buffers"][0]["uri"] = "uv.bin"
    d["buffers"][0]["byteLength"] = len(blob) + 32
    d["bufferViews"].append({"buffer": 0, "byteOffset": len(blob), "byteLength": 32})
    d["accessors"].append({"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC2"})
    d["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = 3
    (folder / "uv.bin").write_bytes(blob + uvs)
    files["bigpng"] = (_write(folder, d, None, "bigpng.gltf"), "12000 x 12000 pixels: more than the limit")
    (folder / "m.obj").write_text("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    os.mkfifo(folder / "m.mtl")
    files["objfifo"] = (folder / "m.obj", "not a regular file")
    return files


def test_memory_and_time_hostile_files_in_a_subprocess(tmp_path, run_isolated):
    folder = tmp_path / "scene"
    folder.mkdir()
    files = _hostile_gltf_files(folder)
    result = run_isolated(_ISOLATED, timeout=120, memory_bytes=2 << 30, args=[str(p) for p, _ in files.values()])
    assert result.returncode == 0, result.stderr[-3000:]
    outcome = json.loads(result.stdout.strip().splitlines()[-1])
    for name, (path, pattern) in files.items():
        kind, detail, seconds = outcome[str(path)]
        if pattern == "loaded":
            assert kind == "loaded" and detail == 1, (name, detail)
        else:
            assert kind == "refused", (name, detail)
            assert __import__("re").search(pattern, detail), (name, detail)
        assert seconds < 20, (name, seconds)


# ---------------------------------------------------------------- raw errors become SceneFileError


@pytest.mark.parametrize("change, pattern", [
    (lambda d: d["nodes"][0].update(mesh=-1), r"nodes\[0\]\.mesh: expected an integer from 0 to 0, found -1"),
    (lambda d: d["nodes"][0].update(mesh=7), r"nodes\[0\]\.mesh"),
    (lambda d: d["accessors"][2].update(count=600), r"accessors\[2\]: its 600 elements end at byte"),
    (lambda d: d["bufferViews"][0].update(byteOffset=10 ** 12), r"bufferViews\[0\]: bytes"),
    (lambda d: d["accessors"][0].update(componentType=5130), r"accessors\[0\]\.componentType"),
    (lambda d: d["meshes"][0]["primitives"][0].update(mode=9), r"primitives\[0\]\.mode"),
    (lambda d: d.update(asset={"version": "1.0"}), "glTF 1.0"),
    (lambda d: d.update(meshes={"m": {}}), "glTF 1.0"),
    (lambda d: d.update(extensionsRequired=["EXT_mesh_gpu_instancing"]), "requires EXT_mesh_gpu_instancing: GPU inst"),
    (lambda d: d.update(extensionsRequired=["VENDOR_magic"]), "requires VENDOR_magic"),
    (lambda d: d["nodes"][0].update(children=[0]), r"nodes\[0\]\.children\[0\]: node 0 is its own ancestor"),
    (lambda d: d["nodes"][0].update(translation=[0, "x", 0]), r"translation\[1\]: expected a finite number"),
    (lambda d: d.pop("asset"), "asset: expected a JSON object"),
    (lambda d: d["cameras"][0]["perspective"].update(znear=0), "znear"),
])
def test_content_errors_name_the_json_path(tmp_path, change, pattern):
    document, blob = _document()
    change(document)
    with pytest.raises(SceneFileError, match=pattern):
        _load(_write(tmp_path, document, blob))


def test_index_beyond_the_vertices_is_refused(tmp_path):
    document, blob = _document()
    blob = bytearray(blob)
    struct.pack_into("<H", blob, 96 + 4, 9)  # index 9 of 4 vertices
    with pytest.raises(SceneFileError, match=r"index 9 is beyond the 4 vertices"):
        _load(_write(tmp_path, document, bytes(blob)))


def test_broken_json_glb_and_images(tmp_path):
    (tmp_path / "bad.gltf").write_text('{"asset": {"version": "2.0"},\n "nodes": [1, }')
    with pytest.raises(SceneFileError, match=r"bad.gltf: line 2 column \d+: not valid JSON"):
        _load(tmp_path / "bad.gltf")
    (tmp_path / "deep.gltf").write_text("[" * 100000 + "]" * 100000)
    with pytest.raises(SceneFileError, match="nested too deeply|expected a JSON object"):
        _load(tmp_path / "deep.gltf")
    (tmp_path / "v1.glb").write_bytes(b"glTF" + struct.pack("<II", 1, 20) + b"\0" * 8)
    with pytest.raises(SceneFileError, match="glTF 1.0 binary"):
        _load(tmp_path / "v1.glb")
    (tmp_path / "short.glb").write_bytes(b"glTF" + struct.pack("<III", 2, 400, 300) + b"JSON")
    with pytest.raises(SceneFileError, match="truncated"):
        _load(tmp_path / "short.glb")
    document, blob = _document()
    document["images"] = [{"uri": "data:application/postscript;base64," +
                           base64.b64encode(b"%!PS-Adobe-3.0 EPSF-3.0\n%%BoundingBox: 0 0 10 10\n").decode()}]
    document["textures"] = [{"source": 0}]
    document["materials"][0]["extras"] = {"glphong": {"version": 1, "class": "Lambert", "arguments": {
        "kd": {"surface": {"scale": [1, 1, 1], "texture": 0}}}}}
    with pytest.raises(SceneFileError, match="not PNG or JPEG"):
        _load(_write(tmp_path, document, blob))


_MUTATIONS = (-1, -100000, 0, 2 ** 40, 1.5, "x", None, [], {}, True, float("nan"))


def _mutate(document, rng):
    """A copy of ``document`` with one value (anywhere in it) replaced, or one key removed."""
    document = copy.deepcopy(document)
    places = []

    def collect(node):
        items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
        for key, value in items:
            places.append((node, key))
            collect(value)

    collect(document)
    node, key = rng.choice(places)
    if isinstance(node, dict) and rng.random() < 0.25:
        del node[key]
    else:
        node[key] = rng.choice(_MUTATIONS)
    return document


def test_fuzzed_documents_raise_only_scene_file_errors(tmp_path):
    document, blob = _document()
    (tmp_path / "quad.bin").write_bytes(blob)
    rng = random.Random(22)
    outcomes = {"loaded": 0, "refused": 0}
    for k in range(400):
        path = tmp_path / "fuzz.gltf"
        path.write_text(json.dumps(_mutate(document, rng)))
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                _load(path)
            outcomes["loaded"] += 1
        except SceneFileError:
            outcomes["refused"] += 1
        except ValueError as exc:  # light units or camera name: a caller's choice, not raw
            assert "light_units" in str(exc) or "spot light" in str(exc), (k, exc)
            outcomes["refused"] += 1
    assert outcomes["refused"] > 100 and outcomes["loaded"] > 50, outcomes


# ---------------------------------------------------------------- formats other readers accept


def _single_primitive(tmp_path, positions, indices, mode):
    positions = np.asarray(positions, np.float32)
    indices = np.asarray(indices, np.uint16)
    blob = positions.tobytes() + indices.tobytes()
    blob += b"\0" * (-len(blob) % 4)
    document = {"asset": {"version": "2.0"}, "buffers": [{"uri": "p.bin", "byteLength": len(blob)}],
                "bufferViews": [{"buffer": 0, "byteLength": positions.nbytes},
                                {"buffer": 0, "byteOffset": positions.nbytes, "byteLength": indices.nbytes}],
                "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(positions), "type": "VEC3"},
                              {"bufferView": 1, "componentType": 5123, "count": len(indices), "type": "SCALAR"}],
                "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": mode}]}],
                "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]}
    (tmp_path / "p.bin").write_bytes(blob)
    return document


def test_strips_and_fans_are_triangulated(tmp_path):
    grid = [[x, y, 0] for x in range(3) for y in range(2)]  # (0,0) (0,1) (1,0) (1,1) (2,0) (2,1)
    strip = _single_primitive(tmp_path, grid, [0, 1, 2, 3, 4, 5], 5)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mesh = _load(_write(tmp_path, strip)).objects[0].mesh
    assert mesh.indices.reshape(-1, 3).tolist() == [[0, 1, 2], [2, 1, 3], [2, 3, 4], [4, 3, 5]]
    normals = np.cross(*(mesh.positions[mesh.indices.reshape(-1, 3)[:, 1:]] - mesh.positions[mesh.indices.reshape(-1, 3)[:, :1]]).transpose(1, 0, 2))
    assert np.all(np.sign(normals[:, 2]) == np.sign(normals[0, 2]))  # one winding
    fan = _single_primitive(tmp_path, grid, [0, 2, 3, 1], 6)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert _load(_write(tmp_path, fan)).objects[0].mesh.indices.reshape(-1, 3).tolist() == [[0, 2, 3], [0, 3, 1]]
    points = _single_primitive(tmp_path, grid, [0, 1, 2], 0)
    points["meshes"].append(copy.deepcopy(points["meshes"][0]))
    points["meshes"][1]["primitives"][0]["mode"] = 4
    points["nodes"].append({"mesh": 1})
    points["scenes"][0]["nodes"].append(1)
    with pytest.warns(UserWarning, match="points or lines"):
        assert len(_load(_write(tmp_path, points), lights=[]).objects) == 1


def test_sparse_accessor_is_applied(tmp_path):
    document, blob = _document()
    extra = np.array([2], np.uint16).tobytes() + b"\0\0" + np.array([5, 6, 7], np.float32).tobytes()
    document["buffers"][0]["byteLength"] = len(blob) + len(extra)
    document["bufferViews"] += [{"buffer": 0, "byteOffset": len(blob), "byteLength": 2},
                                {"buffer": 0, "byteOffset": len(blob) + 4, "byteLength": 12}]
    document["accessors"][0]["sparse"] = {"count": 1, "indices": {"bufferView": 3, "componentType": 5123},
                                          "values": {"bufferView": 4}}
    positions = _load(_write(tmp_path, document, blob + extra)).objects[0].mesh.positions
    assert positions.tolist() == [[-1, -1, 0], [1, -1, 0], [5, 6, 7], [-1, 1, 0]]


def test_skins_and_morph_targets_warn_once(tmp_path):
    document, blob = _document()
    document["skins"] = [{"joints": [0]}]
    document["nodes"][0]["skin"] = 0
    document["meshes"][0]["primitives"][0]["targets"] = [{"POSITION": 0}]
    document["meshes"][0]["primitives"].append(copy.deepcopy(document["meshes"][0]["primitives"][0]))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        _load(_write(tmp_path, document, blob))
    messages = [str(w.message) for w in caught]
    assert sum("rest pose (the base geometry)" in m for m in messages) == 1
    assert sum("skinned meshes are drawn in their rest pose" in m for m in messages) == 1


def test_appearance_only_extension_warns(tmp_path):
    document, blob = _document()
    document["extensionsRequired"] = document["extensionsUsed"] = ["EXT_texture_avif"]
    with pytest.warns(UserWarning, match="EXT_texture_avif is not implemented"):
        _load(_write(tmp_path, document, blob))


def test_used_extensions_glphong_does_not_apply_warn_and_those_it_applies_do_not(tmp_path):
    """docs/files.md: an extension the file uses and glphong ignores is named in a warning; KHR_texture_transform,
    which glphong applies, is neither warned about nor refused, required or not."""
    document, blob = _document()
    document["extensionsUsed"] = ["KHR_texture_transform", "VENDOR_sparkle", "KHR_materials_variants"]
    with pytest.warns(UserWarning, match=r"does not apply VENDOR_sparkle \(extensionsUsed\)"):
        _load(_write(tmp_path, document, blob))
    document["extensionsUsed"] = document["extensionsRequired"] = ["KHR_texture_transform", "KHR_mesh_quantization"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _load(_write(tmp_path, document, blob))


def test_draco_primitive(tmp_path, monkeypatch):
    DracoPy = pytest.importorskip("DracoPy", reason="the [draco] extra (DracoPy) is not installed")
    positions, normals, indices = _quad()
    data = DracoPy.encode(positions.astype(np.float64), indices.reshape(-1, 3), preserve_order=True,
                          quantization_bits=16)
    data += b"\0" * (-len(data) % 4)
    document = {"asset": {"version": "2.0"}, "extensionsUsed": ["KHR_draco_mesh_compression"],
                "extensionsRequired": ["KHR_draco_mesh_compression"],
                "buffers": [{"uri": "d.bin", "byteLength": len(data)}],
                "bufferViews": [{"buffer": 0, "byteLength": len(data)}],
                "accessors": [{"componentType": 5126, "count": 4, "type": "VEC3"},
                              {"componentType": 5123, "count": 6, "type": "SCALAR"}],
                "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "extensions": {
                    "KHR_draco_mesh_compression": {"bufferView": 0, "attributes": {"POSITION": 0}}}}]}],
                "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}]}
    (tmp_path / "d.bin").write_bytes(data)
    path = _write(tmp_path, document)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mesh = _load(path).objects[0].mesh
    assert np.allclose(mesh.positions, positions, atol=1e-4) and mesh.indices.reshape(-1, 3).tolist() == [[0, 1, 2], [0, 2, 3]]
    monkeypatch.setitem(__import__("sys").modules, "DracoPy", None)
    with pytest.raises(SceneFileError, match=r"pip install 'glphong\[draco\]'"):
        _load(path)


# ---------------------------------------------------------------- files that rendered black or crashed


def test_camera_without_lights_gets_the_default_light(tmp_path):
    document, blob = _document(lights=False)
    path = _write(tmp_path, document, blob)
    with pytest.warns(UserWarning, match="has no lights: glphong adds its default point light"):
        scene = _load(path)
    assert len(scene.lights) == 1 and scene.ambient is not None
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        dark = _load(path, lights=[])
    assert len(dark.lights) == 0
    with glphong.Renderer(32, 32) as renderer:
        assert renderer.render(scene).radiance.max() > 0


def test_mtl_with_map_ks_and_its_image_loads(tmp_path):
    from PIL import Image

    Image.new("RGB", (4, 4), (255, 128, 0)).save(tmp_path / "spec.png")
    (tmp_path / "a.mtl").write_text("newmtl shiny\nKd 0.5 0.5 0.5\nmap_Ks spec.png\nNs 20\n")
    (tmp_path / "a.obj").write_text("mtllib a.mtl\nusemtl shiny\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                                    "f 1/1 2/2 3/3\n")
    material = glphong.load_scene(tmp_path / "a.obj").objects[0].material
    assert material.ks.texture is not None


def test_limits_are_checked():
    with pytest.raises(ValueError, match="file_bytes"):
        Limits(file_bytes=0)
    assert Limits().image_pixels == 4096 * 4096 and math.isfinite(Limits().file_bytes)


def test_command_line_one_line_errors_and_warnings(tmp_path, run_isolated):
    document, blob = _document("../outside.bin", lights=False)
    (tmp_path / "outside.bin").write_bytes(blob)
    path = _write(tmp_path / "scene", document)
    code = "import sys; from glphong.tools.cli import main; raise SystemExit(main(sys.argv[1:]))"
    refused = run_isolated(code, timeout=120, args=["render", str(path), "--width", "16", "--height", "16",
                                                    "--out", str(tmp_path / "a.png")])
    assert refused.returncode == 2 and "Traceback" not in refused.stderr
    assert refused.stderr.strip().splitlines() == [f"glphong render: {path}: buffers[0].uri: '../outside.bin' leaves "
                                                   f"the scene file's folder {path.parent}: glphong reads files inside "
                                                   "it only (load_scene(..., allow_outside=True) for files you trust)"]
    allowed = run_isolated(code, timeout=120, args=["render", str(path), "--width", "16", "--height", "16",
                                                    "--out", str(tmp_path / "a.png"), "--allow-outside"])
    assert allowed.returncode == 0, allowed.stderr
    assert allowed.stderr.strip().splitlines() == [f"glphong render: warning: {path} has no lights: glphong adds its "
                                                   "default point light and ambient light (give lights=[] to keep the "
                                                   "scene dark)"]
    assert (tmp_path / "a.png").exists()


def test_instancing_and_aliasing_cannot_multiply_memory(tmp_path):
    """Nodes instancing one mesh share one MeshData; accessors aliasing one buffer view are each counted against
    ``Limits.decoded_bytes`` before they are made."""
    document, blob = _document(camera=False, lights=False)
    document["nodes"] = [{"mesh": 0} for _ in range(300)]
    document["scenes"] = [{"nodes": list(range(300))}]
    scene = _load(_write(tmp_path, document, blob), lights=[])
    assert len(scene.objects) == 300 and len({id(o.mesh) for o in scene.objects}) == 1
    aliased, _ = _document(camera=False, lights=False)
    aliased["accessors"] += [dict(aliased["accessors"][0]) for _ in range(2000)]
    aliased["meshes"] = [{"primitives": [{"attributes": {"POSITION": 3 + k, "NORMAL": 1}, "indices": 2}]}
                         for k in range(2000)]
    aliased["nodes"] = [{"mesh": k} for k in range(2000)]
    aliased["scenes"] = [{"nodes": list(range(2000))}]
    path = _write(tmp_path, aliased, blob, "aliased.gltf")
    with pytest.raises(SceneFileError, match=r"accessors\[\d+\]: decoding it would take more than 100000 bytes"):
        _load(path, lights=[], limits=Limits(decoded_bytes=100_000))
    assert len(_load(path, lights=[]).objects) == 2000  # within the default budget: every alias loads


def test_obj_mtllib_is_read_once_and_named_by_its_line(tmp_path, monkeypatch):
    import glphong.formats.load as load

    (tmp_path / "a.mtl").write_text("newmtl m\nKd 0.5 0.5 0.5\n")
    quad = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nusemtl m\nf 1 2 3\n"
    (tmp_path / "many.obj").write_text("mtllib a.mtl\n" * 5000 + quad)
    calls = []
    real = load.parse_mtl
    monkeypatch.setattr(load, "parse_mtl", lambda *a, **k: calls.append(a) or real(*a, **k))
    assert len(glphong.load_scene(tmp_path / "many.obj").objects) == 1 and len(calls) == 1
    (tmp_path / "late.obj").write_text("# a comment\n\n  mtllib a.mtl ../b.mtl\n" + quad)
    error = _refused(tmp_path / "late.obj", "leaves the scene file's folder")
    assert error.where == "line 3"


@pytest.mark.parametrize("suffix", [".glb", ".obj"])
def test_a_scene_too_large_for_a_default_view_names_the_file(tmp_path, suffix):
    """Finite positions of 1e30 m (a legal file, or a damaged compressed stream): float32 holds the vertices but no
    default camera and light 5 radii away (the light's power 4 pi d^2 overflows); the error names the file and what to
    give, and a given camera and lights load it."""
    import trimesh
    path = tmp_path / f"huge{suffix}"
    trimesh.Trimesh([[0, 0, 0], [1e30, 0, 0], [0, 1e30, 0]], [[0, 1, 2]], process=False).export(path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(SceneFileError, match=r"huge.*beyond 1e\+18 m.*give camera= and lights="):
            glphong.load_scene(path)
        camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 1e31), (0.0, 0.0, 0.0), znear=1e29, zfar=1e32)
        assert len(glphong.load_scene(path, camera=camera, lights=[]).objects) == 1
