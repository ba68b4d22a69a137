"""`glphong.save_gltf` writes files the Khronos glTF validator accepts (issue 41): the rules it reported broken, and the
core layout rules beside them, asserted here on the saved JSON and buffer without the validator (CI has no Node.js;
``benchmarks/gltf_validate.py`` runs the validator itself, docs/scenes_from_files.md has its result).

Checked on ``.gltf`` and ``.glb`` alike: ``NORMAL`` at unit length and ``TANGENT`` with a unit xyz and w = +-1 (the
validator's ACCESSOR_VECTOR3_NON_UNIT error on a sphere's zero pole tangents; the expected values are closed forms:
a vector over its length, and at a zero tangent on n = (0, 0, +-1) Duff et al.'s basis vector (1, 0, 0)); a volume's
material not ``doubleSided`` (KHR_MATERIALS_VOLUME_DOUBLE_SIDED); no empty array nor 0-byte buffer for a scene
without objects (EMPTY_ENTITY, VALUE_NOT_IN_RANGE); no default (identity) node matrix (NODE_MATRIX_DEFAULT); no
iridescence thickness minimum without its texture; POSITION accessors' min and max equal to the positions' own; every
extension named anywhere in ``extensionsUsed`` and nothing else there; buffer views 4-byte aligned and within the
buffer, accessors within their views, indices in range; the GLB chunks' lengths and padding.
"""
import base64
import json
import struct

import numpy as np
import pytest

import glphong
from glphong.definitions.surface import TextureImage
from glphong.scene.geometry import MeshData

_COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
_DTYPES = {5126: np.float32, 5125: np.uint32, 5123: np.uint16, 5121: np.uint8}


def _read(path):
    """``(document, buffer bytes)`` of a saved ``.gltf`` (data URI) or ``.glb`` (its chunks checked on the way)."""
    raw = path.read_bytes()
    if path.suffix == ".gltf":
        document = json.loads(raw)
        buffers = document.get("buffers", [])
        prefix = "data:application/octet-stream;base64,"
        return document, base64.b64decode(buffers[0]["uri"][len(prefix):]) if buffers else b""
    magic, version, length = struct.unpack_from("<III", raw)
    assert (magic, version, length) == (0x46546C67, 2, len(raw))
    json_length, json_type = struct.unpack_from("<II", raw, 12)
    assert json_type == 0x4E4F534A and json_length % 4 == 0
    document = json.loads(raw[20:20 + json_length])
    rest = raw[20 + json_length:]
    if not rest:
        assert "buffers" not in document
        return document, b""
    bin_length, bin_type = struct.unpack_from("<II", rest)
    assert bin_type == 0x004E4942 and bin_length % 4 == 0 and len(rest) == 8 + bin_length
    assert bin_length == document["buffers"][0]["byteLength"]
    return document, rest[8:]


def _accessor(document, blob, index):
    accessor = document["accessors"][index]
    view = document["bufferViews"][accessor["bufferView"]]
    width = _COMPONENTS[accessor["type"]]
    dtype = np.dtype(_DTYPES[accessor["componentType"]])
    start = view.get("byteOffset", 0) + accessor.get("byteOffset", 0)
    assert "byteStride" not in view  # tightly packed: the reading below assumes it
    assert accessor.get("byteOffset", 0) + accessor["count"] * width * dtype.itemsize <= view["byteLength"]
    return np.frombuffer(blob, dtype, accessor["count"] * width, start).reshape(accessor["count"], width)


def _extension_names(value):
    """Every key of every ``extensions`` object in a JSON value."""
    if isinstance(value, dict):
        names = set(value.get("extensions", {}))
        for child in value.values():
            names |= _extension_names(child)
        return names
    if isinstance(value, list):
        return set().union(*map(_extension_names, value)) if value else set()
    return set()


def _image(seed, channels=3):
    return np.random.default_rng(seed).integers(0, 256, (8, 8, channels), dtype=np.uint8)


def _scene():
    """Objects with zero, long and w-scaled tangents and long normals, a volume, an untextured film, lights, poses."""
    sphere, quad = glphong.primitives.sphere(2), glphong.primitives.plane()
    skew = MeshData(quad.positions, quad.normals * 3.0, quad.indices, uvs=quad.uvs,
                    tangents=[[2.0, 0.0, 0.0, -5.0], [0, 0, 0, 1], [1, 1, 0, 1], [0.5, 0, 0, 0]])
    camera = glphong.PerspectiveCamera.look_at((0.0, -4.0, 2.0), (0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0))
    scene = glphong.Scene(camera, [glphong.PointLight((1.0, -2.0, 3.0), 20.0),
                                   glphong.DirectionalLight((0.0, 0.0, -1.0), 2.0)])
    normal_mapped = glphong.GltfPBR(0.5, 0.0, 0.5, normal_map=glphong.NormalMap(_image(1)))
    scene.add(sphere, normal_mapped, name="sphere")  # identity pose
    scene.add(skew, normal_mapped, pose=np.eye(4) + np.eye(4, k=3), name="skew")
    scene.add(sphere, glphong.GltfPBR(0.9, 0.0, 0.1, transmission=1.0, thickness=0.3), name="glass")
    scene.add(quad, glphong.GltfPBR(0.5, 0.0, 0.5, iridescence=0.8, iridescence_thickness_mix=0.5), name="film")
    scene.add(quad, glphong.GltfPBR(glphong.Texture(_image(2, 4)), 0.0, 0.5, specular=0.5, sheen_color=0.3,
                                    emissive=2.0, alpha_mask=glphong.AlphaMask(0.5)), name="layers")
    return scene


@pytest.fixture(scope="module", params=[".gltf", ".glb"])
def saved(request, tmp_path_factory):
    scene = _scene()
    path = glphong.save_gltf(scene, tmp_path_factory.mktemp("conformance") / f"scene{request.param}")
    return scene, path, *_read(path)


def _primitive(document, name):
    (node,) = [n for n in document["nodes"] if n.get("name") == name]
    return document["meshes"][node["mesh"]]["primitives"][0]


def test_normals_and_tangents_are_unit_with_w_plus_or_minus_one(saved):
    scene, _, document, blob = saved
    skew = _primitive(document, "skew")["attributes"]
    np.testing.assert_allclose(_accessor(document, blob, skew["NORMAL"]), np.tile([0.0, 0.0, 1.0], (4, 1)), atol=1e-7)
    expected = [[1.0, 0.0, 0.0, -1.0], [1.0, 0.0, 0.0, 1.0], [0.5 ** 0.5, 0.5 ** 0.5, 0.0, 1.0], [1.0, 0.0, 0.0, 1.0]]
    np.testing.assert_allclose(_accessor(document, blob, skew["TANGENT"]), expected, atol=1e-7)
    sphere = _primitive(document, "sphere")["attributes"]
    tangents = _accessor(document, blob, sphere["TANGENT"]).astype(np.float64)
    normals = _accessor(document, blob, sphere["NORMAL"]).astype(np.float64)
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-6)
    np.testing.assert_allclose(np.linalg.norm(tangents[:, :3], axis=1), 1.0, atol=1e-6)
    assert set(np.unique(tangents[:, 3])) <= {-1.0, 1.0}
    given = scene.objects[0].mesh.given_tangents
    poles = np.linalg.norm(given[:, :3], axis=1) == 0
    assert poles.sum() == 2  # the sphere's two poles, n = (0, 0, +-1): Duff's basis gives (1, 0, 0) at both
    np.testing.assert_allclose(tangents[poles, :3], [[1.0, 0.0, 0.0]] * 2, atol=1e-7)
    np.testing.assert_array_equal(tangents[~poles], given[~poles])  # unit already: written as given


def test_a_volume_is_one_sided_and_a_film_without_texture_has_no_minimum(saved):
    scene, _, document, _ = saved
    by_node = {n.get("name"): n for n in document["nodes"]}
    glass = document["materials"][_primitive(document, "glass")["material"]]
    assert "KHR_materials_volume" in glass["extensions"] and glass["doubleSided"] is False
    assert scene.objects[2].material.two_sided and glass["extras"]["glphong"]  # glphong's own sidedness kept there
    assert document["materials"][_primitive(document, "sphere")["material"]]["doubleSided"] is True
    film = document["materials"][_primitive(document, "film")["material"]]["extensions"]["KHR_materials_iridescence"]
    assert "iridescenceThicknessMinimum" not in film
    assert film["iridescenceThicknessMaximum"] == 250.0  # mix(100, 400, 0.5)
    assert "matrix" not in by_node["sphere"] and by_node["skew"]["matrix"][12] == 1.0  # column-major translation


def test_layout_extensions_and_bounds(saved):
    scene, _, document, blob = saved
    assert document["asset"]["version"] == "2.0"
    named = _extension_names(document)
    assert named and sorted(named) == sorted(document["extensionsUsed"])  # all named, each once, nothing else
    assert "KHR_lights_punctual" in named and "KHR_materials_volume" in named
    assert len(blob) == document["buffers"][0]["byteLength"] and len(blob) % 4 == 0
    for view in document["bufferViews"]:
        assert view["byteOffset"] % 4 == 0 and view["byteOffset"] + view["byteLength"] <= len(blob)
    for obj in scene.objects:
        primitive = _primitive(document, obj.name)
        accessor = document["accessors"][primitive["attributes"]["POSITION"]]
        positions = obj.mesh.positions.astype(np.float64)
        assert accessor["min"] == list(positions.min(axis=0)) and accessor["max"] == list(positions.max(axis=0))
        indices = _accessor(document, blob, primitive["indices"])
        assert indices.max() < accessor["count"] and len(indices) == obj.mesh.indices.size
    for field, key in (("textures", "source"), ("textures", "sampler")):
        for entry in document.get(field, []):
            assert 0 <= entry[key] < len(document[{"source": "images", "sampler": "samplers"}[key]])
    for view in (image["bufferView"] for image in document.get("images", [])):
        start = document["bufferViews"][view]["byteOffset"]
        assert blob[start:start + 8] == b"\x89PNG\r\n\x1a\n"


def test_tangents_are_written_where_the_material_reads_them_whatever_was_drawn(tmp_path):
    """A mesh with uvs and no tangents: under a normal map, the tangents glphong derives and draws with (on the plane,
    whose u runs along +x and v along +y: (1, 0, 0), w = +1); under a material without a tangent frame none, even
    after a draw derived them (they were written then, and not before)."""
    quad = glphong.primitives.plane()
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 3.0), (0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0))
    for material in (glphong.Lambert(0.5, normal_map=glphong.NormalMap(_image(1))), glphong.Lambert(0.5)):
        mesh = MeshData(quad.positions, quad.normals, quad.indices, uvs=quad.uvs)
        assert mesh.tangents is not None  # derived, as a draw does first
        scene = glphong.Scene(camera, [])
        scene.add(mesh, material, name="quad")
        document, blob = _read(glphong.save_gltf(scene, tmp_path / "quad.glb"))
        attributes = _primitive(document, "quad")["attributes"]
        if material.normal_map is None:
            assert "TANGENT" not in attributes
        else:
            np.testing.assert_array_equal(_accessor(document, blob, attributes["TANGENT"]), [[1.0, 0.0, 0.0, 1.0]] * 4)


@pytest.mark.parametrize("suffix", [".gltf", ".glb"])
def test_a_scene_without_objects_has_no_empty_arrays(suffix, tmp_path):
    camera = glphong.PerspectiveCamera.look_at((0.0, -4.0, 2.0), (0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0))
    path = glphong.save_gltf(glphong.Scene(camera, []), tmp_path / f"empty{suffix}")
    document, blob = _read(path)
    assert blob == b"" and not {"accessors", "bufferViews", "buffers"} & set(document)
    assert all(value != [] for value in document.values())
    loaded = glphong.load_scene(path, light_units="radiometric")
    assert loaded.objects == () and np.allclose(loaded.camera.pose, camera.pose)


def test_the_saved_file_reads_back(saved, tmp_path):
    """The written (unit) normals and tangents are what loading gives back: the file is the scene's."""
    _, path, document, blob = saved
    loaded = glphong.load_scene(path, light_units="radiometric")
    skew = next(o for o in loaded.objects if o.name == "skew")
    np.testing.assert_array_equal(skew.mesh.given_tangents,
                                  _accessor(document, blob, _primitive(document, "skew")["attributes"]["TANGENT"]))
    assert [o.name for o in loaded.objects] == ["sphere", "skew", "glass", "film", "layers"]


def test_ior_and_occlusion_are_in_the_gltf_fields_other_viewers_read(tmp_path):
    """KHR_materials_ior (an ior other than 1.5) and occlusionTexture are written to glTF's own fields, not only to
    glphong's extras: a loader that ignores the extras (any other viewer; here glphong's with the extras removed)
    reads the same ior and occlusion back."""
    camera = glphong.PerspectiveCamera.look_at((0.0, -4.0, 2.0), (0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0))
    scene = glphong.Scene(camera, [glphong.PointLight((1.0, -2.0, 3.0), 20.0)])
    occlusion = glphong.Texture(TextureImage(_image(5), srgb=False), channel="r")  # linear, as glTF's
    srgb_occlusion = glphong.Texture(_image(6), channel="r")  # sRGB-decoded: glTF would read its bytes as linear
    quad = glphong.primitives.plane()
    scene.add(quad, glphong.GltfPBR(0.8, 0.0, 0.3, ior=1.33, occlusion=occlusion), name="water")
    scene.add(quad, glphong.GltfPBR(0.8, 0.0, 0.3, occlusion=srgb_occlusion), name="core")  # neither written
    path = glphong.save_gltf(scene, tmp_path / "ior.gltf")
    document = json.loads(path.read_text())
    water, core = document["materials"]
    assert water["extensions"]["KHR_materials_ior"] == {"ior": pytest.approx(1.33)}
    assert "KHR_materials_ior" in document["extensionsUsed"]
    assert "occlusionTexture" in water and "occlusionTexture" not in core
    assert "KHR_materials_ior" not in core.get("extensions", {})
    for material in document["materials"]:
        material.pop("extras")
    path.write_text(json.dumps(document))
    loaded = glphong.load_scene(path, light_units="radiometric")
    (term,) = loaded.objects[0].material.components
    assert term.ior == pytest.approx(1.33)
    np.testing.assert_array_equal(term.occlusion.texture.levels[0], occlusion.texture.levels[0])
    assert loaded.objects[1].material.components[0].ior == 1.5
