"""Files other loaders render, rendered here (issue 41, item 4): what is merely non-conformant but unambiguous is read,
with a warning; what is dangerous or meaningless is still refused.

- A node reached by several paths (two parents share a subtree, a node listed twice in one ``children``, a child
  also listed as a scene root) is drawn once per path, at each path's world pose, with one warning naming the node
  and the parents that list it; the render equals that of the same scene written as a tree (the subtree copied), and
  verifies.  A cycle is an error with the JSON path of the child link that closes it; 30 levels of two parents
  (2^30 paths) are refused by ``Limits.nodes`` before any path is walked.
- An accessor whose data does not start on a multiple of its component size (its bufferView's ``byteOffset``, or its
  own) is read through a copy with a warning naming its JSON path: the arrays, and the render, equal those of the
  aligned file; an unaligned accessor running past its view is still refused.
- An OBJ ``mtllib`` whose file name has spaces (obj2gltf's ``box mtllib.obj``) reads that file; a list of names still
  reads each; the whole remainder never leaves the folder (nor a ``..`` folded after a missing folder).
- ``KHR_materials_*`` extensions a file uses and glphong does not apply are named in a warning.
"""
import copy
import io
import json
import warnings

import numpy as np
import PIL.Image
import pytest

import glphong
from glphong.filesafety import Limits, SceneFileError

LIGHT = glphong.PointLight((0.5, 1.0, 4.0), 300.0)


def _quad_file(builder, texture=True):
    """The builder's document: one textured quad facing +z (positions, normals, uvs float32; uint16 indices)."""
    builder.attribute("POSITION", np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32))
    builder.attribute("NORMAL", np.tile(np.array([0, 0, 1], np.float32), (4, 1)))
    builder.attribute("TEXCOORD_0", np.array([[0, 1], [1, 1], [1, 0], [0, 0]], np.float32))
    builder.indices(np.array([0, 1, 2, 0, 2, 3], np.uint16))
    document = builder.document
    document["materials"] = [{"pbrMetallicRoughness": {"metallicFactor": 0.0, "roughnessFactor": 0.6}}]
    if texture:
        pixels = np.array([[[220, 30, 30], [30, 220, 30]], [[30, 30, 220], [220, 220, 30]]], np.uint8)
        png = io.BytesIO()
        PIL.Image.fromarray(pixels).save(png, format="PNG")
        document["textures"] = [{"source": builder.image(png.getvalue(), "image/png")}]
        document["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {"index": 0}
    builder.primitive["material"] = 0
    return builder


def _load(path, **keywords):
    return glphong.load_scene(path, lights=[LIGHT], **keywords)


def _loaded_with_warnings(path, **keywords):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        scene = _load(path, **keywords)
    return scene, [str(w.message) for w in caught]


# ---------------------------------------------------------------- a node reached by several paths


def _hierarchy(builder, nodes, roots):
    """The quad file with ``nodes`` (the quad mesh is mesh 0) and the scene's ``roots``."""
    document = _quad_file(builder).document
    document["nodes"], document["scenes"] = nodes, [{"nodes": roots}]
    return document


def _shared_wheel():
    """Two parents (left, right) share a subtree: wheel (a translation) with a tyre (the mesh, a scale)."""
    return [{"name": "left", "translation": [-1.5, 0.0, 0.0], "children": [2]},
            {"name": "right", "translation": [1.5, 0.0, 0.0], "rotation": [0.0, 0.0, 0.38268343, 0.92387953],
             "children": [2]},
            {"name": "wheel", "translation": [0.0, 0.5, 0.0], "children": [3]},
            {"name": "tyre", "mesh": 0, "scale": [0.5, 0.5, 0.5]}]


def _rotation_z(angle):
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def _translation(x, y, z):
    m = np.eye(4)
    m[:3, 3] = x, y, z
    return m


def test_a_shared_subtree_is_drawn_once_per_path(tmp_path, builder, glphong_backend, glphong_make_renderer):
    """The tyre is reached through left and through right: two objects at T_left T_wheel S and T_right R_right
    T_wheel S (composed here by hand), one warning naming the wheel and both parents; the render equals that of
    the tree with the subtree copied, and verifies."""
    document = _hierarchy(builder, _shared_wheel(), [0, 1])
    path = builder.write(tmp_path / "shared")
    scene, messages = _loaded_with_warnings(path)
    scale = np.diag([0.5, 0.5, 0.5, 1.0])
    expected = [_translation(-1.5, 0, 0) @ _translation(0, 0.5, 0) @ scale,
                _translation(1.5, 0, 0) @ _rotation_z(np.pi / 4) @ _translation(0, 0.5, 0) @ scale]
    assert [o.name for o in scene.objects] == ["tyre", "tyre"]
    for obj, pose in zip(scene.objects, expected):
        np.testing.assert_allclose(obj.pose, pose, atol=1e-7)
    shared = [m for m in messages if "once per path" in m]
    assert len(shared) == 1, messages
    assert "nodes[2] ('wheel') is listed by 2 parents or scene lists (nodes[0], nodes[1])" in shared[0]
    assert "2 instances" in shared[0] and str(path) in shared[0]

    tree = copy.deepcopy(document)  # the same scene as the specification's forest: the subtree written twice
    tree["nodes"] += [dict(tree["nodes"][2], children=[5]), dict(tree["nodes"][3])]
    tree["nodes"][1]["children"] = [4]
    (tmp_path / "shared" / "tree.gltf").write_text(json.dumps(tree))
    twin_scene, tree_messages = _loaded_with_warnings(tmp_path / "shared" / "tree.gltf")
    assert not [m for m in tree_messages if "once per path" in m]
    renderer = glphong_make_renderer(64, 48, glphong_backend)
    camera = glphong.PerspectiveCamera.look_at((0.0, 0.0, 6.0), (0.0, 0.0, 0.0))
    scene.camera = twin_scene.camera = camera
    np.testing.assert_array_equal(renderer.render(scene).radiance, renderer.render(twin_scene).radiance)
    assert glphong.verify(scene, renderer).passed


@pytest.mark.parametrize("nodes, roots, links", [
    ([{"mesh": 0, "children": [1]}, {"mesh": 0, "translation": [1.0, 0.0, 0.0]}], [0, 1],
     "nodes[1] is listed by 2 parents or scene lists (scenes[0].nodes, nodes[0])"),  # a root and a child
    ([{"children": [1, 1]}, {"mesh": 0}], [0], "nodes[1] is listed by 2 parents or scene lists (nodes[0], nodes[0])"),
    ([{"mesh": 0}], [0, 0], "nodes[0] is listed by 2 parents or scene lists (scenes[0].nodes, scenes[0].nodes)"),
])
def test_a_node_listed_twice_is_drawn_twice(tmp_path, builder, nodes, roots, links):
    _hierarchy(builder, nodes, roots)
    scene, messages = _loaded_with_warnings(builder.write(tmp_path))
    assert sum(o.name == ("node1" if len(nodes) > 1 else "node0") for o in scene.objects) == 2
    assert sum(links in m for m in messages) == 1, messages


def test_a_light_under_a_shared_node_lights_from_each_path(tmp_path, builder):
    document = _hierarchy(builder, [{"translation": [-1.0, 0.0, 0.0], "children": [2]},
                                    {"translation": [1.0, 0.0, 0.0], "children": [2]},
                                    {"extensions": {"KHR_lights_punctual": {"light": 0}}}, {"mesh": 0}], [0, 1, 3])
    document["extensions"] = {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 5.0}]}}
    with pytest.warns(UserWarning, match=r"nodes\[2\] is listed by 2"):
        scene = glphong.load_scene(builder.write(tmp_path), light_units="radiometric")
    assert sorted(light.position[0] for light in scene.lights) == [-1.0, 1.0]


@pytest.mark.parametrize("nodes, where, loop", [
    ([{"children": [1]}, {"children": [2]}, {"children": [1], "mesh": 0}], r"nodes\[2\]\.children\[0\]", "1 -> 2 -> 1"),
    ([{"children": [1]}, {"mesh": 0, "children": [2, 1]}, {}], r"nodes\[1\]\.children\[1\]", "1 -> 1"),
])
def test_a_cycle_is_an_error_with_its_json_path(tmp_path, builder, nodes, where, loop):
    _hierarchy(builder, nodes, [0])
    with pytest.raises(SceneFileError, match=rf"{where}: node 1 is its own ancestor \(the cycle {loop}\)"):
        _load(builder.write(tmp_path))


def test_shared_subtrees_cannot_multiply_instances_beyond_the_limit(tmp_path, builder):
    """Each level lists the next twice: 2^levels paths reach the mesh.  30 levels (2^31 - 1 paths in all) are refused
    by Limits.nodes before a path is walked; 4 levels (31 paths, 16 meshes) load within a limit of 31, not of 30."""
    def chain(levels):
        return [{"children": [k + 1, k + 1]} for k in range(levels)] + [{"mesh": 0}]

    _hierarchy(builder, chain(30), [0])
    with pytest.raises(SceneFileError, match=r"scenes\[0\]: its nodes are reached by more than 1000000 paths \(node "
                                             r"instances.*Limits\.nodes\)"):
        _load(builder.write(tmp_path / "deep"))
    builder.document["nodes"] = chain(4)
    path = builder.write(tmp_path / "small")
    with pytest.raises(SceneFileError, match="more than 30 paths"):
        _load(path, limits=Limits(nodes=30))
    scene, messages = _loaded_with_warnings(path, limits=Limits(nodes=31))
    assert len(scene.objects) == 16
    assert sum("nodes[1] is listed by 2" in m and "3 other node(s) too" in m for m in messages) == 1


# ---------------------------------------------------------------- accessors not aligned to their component size


def _misaligned(builder, attribute, how):
    """Move the data of ``attribute`` ('POSITION', 'TEXCOORD_0' or 'indices') one byte off its component size: the
    bufferView starts at an odd byte (``how='view'``) or the accessor's ``byteOffset`` is 1 (``'accessor'``).
    Returns the accessor's index."""
    document = builder.document
    k = builder.primitive["indices"] if attribute == "indices" else builder.primitive["attributes"][attribute]
    accessor = document["accessors"][k]
    view = document["bufferViews"][accessor["bufferView"]]
    data = bytes(builder.blob[view["byteOffset"]:view["byteOffset"] + view["byteLength"]])
    builder.blob += bytes(-len(builder.blob) % 4)
    start = len(builder.blob)
    builder.blob += b"\xee" + data
    if how == "view":
        view["byteOffset"] = start + 1
    else:
        view.update(byteOffset=start, byteLength=len(data) + 1)
        accessor["byteOffset"] = 1
    return k


@pytest.mark.parametrize("attribute", ["POSITION", "TEXCOORD_0", "indices"])
@pytest.mark.parametrize("how", ["view", "accessor"])
def test_an_unaligned_accessor_is_read_through_a_copy(tmp_path, builder, attribute, how, glphong_backend,
                                                      glphong_make_renderer):
    """The unaligned file warns once, naming the accessor's JSON path and the component size; its mesh holds the
    aligned file's arrays exactly and its render is the aligned file's, bit for bit, and verifies."""
    aligned = _quad_file(builder).write(tmp_path / "aligned")
    moved = copy.deepcopy(builder)
    k = _misaligned(moved, attribute, how)
    unaligned = moved.write(tmp_path / "unaligned")
    reference, _ = _loaded_with_warnings(aligned)
    scene, messages = _loaded_with_warnings(unaligned)
    size = 2 if attribute == "indices" else 4
    warned = [m for m in messages if "aligned copy" in m]
    assert len(warned) == 1 and warned[0].startswith(f"{unaligned}: accessors[{k}].byteOffset: ")
    assert f"is not a multiple of the {size}-byte component size" in warned[0]
    ((obj,), (ref,)) = scene.objects, reference.objects
    for name in ("positions", "normals", "indices", "uvs"):
        np.testing.assert_array_equal(getattr(obj.mesh, name), getattr(ref.mesh, name))
    renderer = glphong_make_renderer(48, 32, glphong_backend)
    np.testing.assert_array_equal(renderer.render(scene).radiance, renderer.render(reference).radiance)
    assert glphong.verify(scene, renderer).passed


def test_an_unaligned_accessor_past_its_view_is_still_refused(tmp_path, builder):
    _quad_file(builder, texture=False)
    k = _misaligned(builder, "POSITION", "accessor")
    builder.document["bufferViews"][builder.document["accessors"][k]["bufferView"]]["byteLength"] -= 1
    with pytest.raises(SceneFileError, match=rf"accessors\[{k}\]: its 4 elements end at byte 49 of bufferView \d+, "
                                             "which has 48 bytes"):
        _load(builder.write(tmp_path))


# ---------------------------------------------------------------- OBJ mtllib names with spaces

QUAD = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nusemtl {}\nf 1 2 3\n"


def _obj_colour(path):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        scene = glphong.load_scene(path, lights=[LIGHT])
    assert not [w for w in caught if "mtllib" in str(w.message)], [str(w.message) for w in caught]
    return scene.objects[0].material.kd


def test_an_mtllib_name_with_spaces_is_one_file(tmp_path):
    """obj2gltf's ``box mtllib.obj``: ``mtllib box mtllib.mtl`` names one file; ``mtllib a.mtl b.mtl`` two."""
    (tmp_path / "box mtllib.mtl").write_text("newmtl Material\nKd 0.25 0.5 0.75\n")
    (tmp_path / "box mtllib.obj").write_text("mtllib box mtllib.mtl\n" + QUAD.format("Material"))
    assert tuple(_obj_colour(tmp_path / "box mtllib.obj")) == (0.25, 0.5, 0.75)
    (tmp_path / "a.mtl").write_text("newmtl a\nKd 0.1 0.2 0.3\n")
    (tmp_path / "b.mtl").write_text("newmtl b\nKd 0.4 0.5 0.6\n")
    (tmp_path / "two.obj").write_text("mtllib a.mtl b.mtl\n" + QUAD.format("b"))
    assert tuple(_obj_colour(tmp_path / "two.obj")) == (0.4, 0.5, 0.6)


def test_an_mtllib_name_with_spaces_stays_in_the_folder(tmp_path):
    """The whole remainder is a name like any other: ``../x y.mtl`` is refused (by its first word), and
    ``a.mtl /../b.mtl`` (which a resolver folds to ``b.mtl`` beside the file, past the missing folder ``a.mtl ``) is
    read as its words, the second of them an absolute path, refused."""
    folder = tmp_path / "scene"
    folder.mkdir()
    (tmp_path / "x y.mtl").write_text("newmtl m\nKd 1 0 0\n")
    (folder / "out.obj").write_text("mtllib ../x y.mtl\n" + QUAD.format("m"))
    with pytest.raises(SceneFileError, match="'../x' leaves the scene file's folder"):
        glphong.load_scene(folder / "out.obj", lights=[LIGHT])
    (folder / "a.mtl").write_text("newmtl m\nKd 0 1 0\n")
    (folder / "b.mtl").write_text("newmtl m\nKd 0 0 1\n")
    (folder / "folded.obj").write_text("mtllib a.mtl /../b.mtl\n" + QUAD.format("m"))
    with pytest.raises(SceneFileError, match="'/../b.mtl' is an absolute path"):
        glphong.load_scene(folder / "folded.obj", lights=[LIGHT])


# ---------------------------------------------------------------- extensions


def test_material_extensions_glphong_does_not_apply_are_named(tmp_path, builder):
    """KHR_materials_unlit (used, not required) is named in a warning; KHR_materials_clearcoat, which glphong
    applies, and a required KHR_texture_transform are not, and load without an error."""
    document = _quad_file(builder, texture=False).document
    document["extensionsUsed"] = ["KHR_materials_unlit", "KHR_materials_clearcoat", "KHR_texture_transform"]
    document["extensionsRequired"] = ["KHR_texture_transform"]
    document["materials"][0]["extensions"] = {"KHR_materials_unlit": {},
                                              "KHR_materials_clearcoat": {"clearcoatFactor": 0.5}}
    _, messages = _loaded_with_warnings(builder.write(tmp_path))
    unapplied = [m for m in messages if "does not apply" in m]
    assert len(unapplied) == 1 and "does not apply KHR_materials_unlit (extensionsUsed)" in unapplied[0]
