"""glTF extensions glphong reads or refuses by name (`glphong.formats.gltf_choices`), on files made here.

- ``KHR_mesh_quantization``: POSITION as unsigned shorts, NORMAL as normalized bytes (-128 included), TANGENT as
  normalized shorts and TEXCOORD_0 as normalized unsigned shorts read as the extension's table and the core
  specification's normalization formulas say (``c / (2^n - 1)`` unsigned, ``max(c / (2^(n-1) - 1), -1)`` signed,
  transcribed here); types outside the table are refused naming the attribute and what is allowed.
- ``KHR_materials_variants``: ``load_scene(path, variant=name)`` gives each primitive its mapping's material; an
  unknown name is an error listing the variants.
- Texture coordinate sets: a material whose textures read ``TEXCOORD_1`` (by ``texCoord``, or by its
  ``KHR_texture_transform``'s ``texCoord``) is drawn with that set as the uvs; one whose textures read different
  sets is refused naming each texture and its set (a user's material for it loads).
- ``KHR_materials_dispersion``: applied in a transmissive volume (tests/test_transmission.py), never warned about.
"""
import io
import warnings

import numpy as np
import pytest

import glphong
from glphong.filesafety import SceneFileError

TRIANGLE = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0]], np.float32)


def _load(path, **keywords):
    keywords.setdefault("lights", [])
    keywords.setdefault("camera", glphong.PerspectiveCamera(0.8))
    return glphong.load_scene(path, **keywords)


def _normalized(c, bits, signed):
    """The glTF specification's normalized-integer decoding (section 3.11), in float64."""
    c = np.asarray(c, np.float64)
    return np.maximum(c / (2.0 ** (bits - 1) - 1), -1.0) if signed else c / (2.0 ** bits - 1)


def test_quantized_attributes_read_as_the_extension_says(tmp_path, builder):
    positions = np.array([[0, 0, 0], [1000, 0, 7], [1000, 65535, 0]], np.uint16)
    normals = np.array([[0, 0, 127], [-128, 0, 0], [0, 127, 0]], np.int8)
    tangents = np.array([[32767, 0, 0, 32767], [0, -32768, 0, -32767], [0, 0, 32767, 32767]], np.int16)
    uvs = np.array([[0, 65535], [12345, 0], [65535, 30000]], np.uint16)
    builder.attribute("POSITION", positions, stride=8)
    builder.attribute("NORMAL", normals, normalized=True, stride=4)
    builder.attribute("TANGENT", tangents, normalized=True)
    builder.attribute("TEXCOORD_0", uvs, normalized=True)
    builder.document["extensionsUsed"] = builder.document["extensionsRequired"] = ["KHR_mesh_quantization"]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        mesh = _load(builder.write(tmp_path)).objects[0].mesh
    assert np.array_equal(mesh.positions, positions.astype(np.float64))
    assert np.array_equal(mesh.normals, _normalized(normals, 8, True))
    assert np.array_equal(mesh.given_tangents, _normalized(tangents, 16, True))
    expected_uv = _normalized(uvs, 16, False)
    expected_uv = np.stack([expected_uv[:, 0], 1.0 - expected_uv[:, 1]], axis=1)  # glphong's v is 1 - glTF's
    assert np.array_equal(mesh.uvs, expected_uv.astype(mesh.uvs.dtype))  # MeshData keeps uvs in float32


@pytest.mark.parametrize("name, values, normalized, pattern", [
    ("NORMAL", np.array([[0, 0, 255]] * 3, np.uint8), True, r"NORMAL of normalized unsigned byte components: .*allow "
     r"float, normalized byte, normalized short"),
    ("POSITION", np.array([[0, 0, 0]] * 3, np.uint32), False, r"attributes\.POSITION: POSITION of unsigned int"),
    ("TANGENT", np.array([[0, 0, 1, 1]] * 3, np.int16), False, r"TANGENT of short components"),
    ("NORMAL", np.array([[0, 0, 1]] * 3, np.float32), True, r"accessors\[1\]\.normalized: true for FLOAT"),
    ("TEXCOORD_0", np.array([[0, 1]] * 3, np.uint32), True, r"accessors\[1\]\.normalized: true for FLOAT or UNSIGNED_INT"),
])
def test_attribute_types_outside_the_table_are_refused(tmp_path, builder, name, values, normalized, pattern):
    if name != "POSITION":
        builder.attribute("POSITION", TRIANGLE)
    builder.attribute(name, values, normalized=normalized, stride=-(-values[0].nbytes // 4) * 4)
    with pytest.raises(SceneFileError, match=pattern):
        _load(builder.write(tmp_path))


def _variants(builder):
    builder.attribute("POSITION", TRIANGLE)
    builder.document["materials"] = [{"name": name, "pbrMetallicRoughness": {"baseColorFactor": [*colour, 1.0]}}
                                     for name, colour in (("plain", (0.5, 0.5, 0.5)), ("red", (0.75, 0.0, 0.0)),
                                                          ("blue", (0.0, 0.0, 0.25)))]
    builder.primitive["material"] = 0
    builder.primitive["extensions"] = {"KHR_materials_variants": {"mappings": [
        {"material": 1, "variants": [0]}, {"material": 2, "variants": [1, 2]}]}}
    builder.document["extensions"] = {"KHR_materials_variants": {"variants": [
        {"name": "ruby"}, {"name": "sapphire"}, {"name": "night"}]}}
    builder.document["extensionsUsed"] = ["KHR_materials_variants"]


@pytest.mark.parametrize("variant, colour", [(None, (0.5, 0.5, 0.5)), ("ruby", (0.75, 0.0, 0.0)),
                                             ("night", (0.0, 0.0, 0.25))])
def test_a_variant_is_chosen_by_name(tmp_path, builder, variant, colour):
    _variants(builder)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        material = _load(builder.write(tmp_path), variant=variant).objects[0].material
    assert tuple(material.base_color) == colour


def test_an_unknown_variant_names_the_variants(tmp_path, builder):
    _variants(builder)
    with pytest.raises(ValueError, match=r"no material variant named 'emerald': its variants are 'ruby', 'sapphire', "
                       r"'night'"):
        _load(builder.write(tmp_path), variant="emerald")
    builder.document["extensions"]["KHR_materials_variants"]["variants"] = []
    with pytest.raises(SceneFileError, match=r"KHR_materials_variants\.variants: expected at least 1 entries"):
        _load(builder.write(tmp_path))


def _png():
    from PIL import Image

    out = io.BytesIO()
    Image.new("RGB", (2, 2), (200, 100, 50)).save(out, "PNG")
    return out.getvalue()


def _two_uv_sets(builder, texcoord=1, occlusion=None, transform=None):
    builder.attribute("POSITION", TRIANGLE)
    builder.attribute("TEXCOORD_0", np.zeros((3, 2), np.float32))
    builder.attribute("TEXCOORD_1", np.array([[0.25, 0.5], [0.75, 0.125], [0.5, 1.0]], np.float32))
    builder.document["textures"] = [{"source": builder.image(_png(), "image/png")}]
    info = {"index": 0, "texCoord": texcoord}
    if transform is not None:
        info["extensions"] = {"KHR_texture_transform": transform}
    material = {"name": "paint", "pbrMetallicRoughness": {"baseColorTexture": info}}
    if occlusion is not None:
        material["occlusionTexture"] = {"index": 0, "texCoord": occlusion}
    builder.document["materials"] = [material]
    builder.primitive["material"] = 0


@pytest.mark.parametrize("texcoord, transform", [(1, None), (0, {"texCoord": 1})])
def test_a_material_on_the_second_uv_set_is_drawn_with_it(tmp_path, builder, texcoord, transform):
    _two_uv_sets(builder, texcoord, transform=transform)
    scene = _load(builder.write(tmp_path))
    assert np.array_equal(scene.objects[0].mesh.uvs, [[0.25, 0.5], [0.75, 0.875], [0.5, 0.0]])
    assert scene.objects[0].material.base_color.texture is not None


def test_a_material_on_two_uv_sets_is_refused_by_name(tmp_path, builder):
    _two_uv_sets(builder, 1, occlusion=0)
    path = builder.write(tmp_path)
    with pytest.raises(SceneFileError, match=r"materials\[0\]: its textures read different texture coordinate sets "
                       r"\(occlusionTexture TEXCOORD_0, pbrMetallicRoughness\.baseColorTexture TEXCOORD_1\)"):
        _load(path)
    assert _load(path, materials={"paint": glphong.Lambert(0.5)}).objects[0].material.kd is not None


def _dispersion(builder, thickness):
    builder.attribute("POSITION", TRIANGLE)
    extensions = {"KHR_materials_dispersion": {"dispersion": 0.5}}
    if thickness is not None:
        extensions["KHR_materials_volume"] = {"thicknessFactor": thickness}
    builder.document["materials"] = [{"extensions": extensions}]
    builder.primitive["material"] = 0
    builder.document["extensionsUsed"] = ["KHR_materials_dispersion"]


def test_dispersion_without_a_volume_changes_nothing_and_is_not_warned_about(tmp_path, builder):
    _dispersion(builder, None)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _load(builder.write(tmp_path))


def test_dispersion_in_a_volume_is_applied_and_not_warned_about(tmp_path, builder):
    _dispersion(builder, 1.0)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        _load(builder.write(tmp_path))


def test_the_set_of_a_texture_glphong_does_not_draw_does_not_matter(tmp_path, builder):
    """A vendor extension's texture (not applied) on TEXCOORD_0 beside a base colour on TEXCOORD_1."""
    _two_uv_sets(builder, 1)
    builder.document["materials"][0]["extensions"] = {"VENDOR_glitter": {"glitterTexture": {"index": 0}}}
    assert np.array_equal(_load(builder.write(tmp_path)).objects[0].mesh.uvs, [[0.25, 0.5], [0.75, 0.875], [0.5, 0.0]])
