"""Texture sources beyond PNG and JPEG: ``KHR_texture_basisu`` (KTX2 with a Basis Universal payload, transcoded by
``opengl_basisu``) and ``EXT_texture_webp`` (decoded by Pillow).

The KTX2 files are written here byte by byte from the KTX2 specification (header, level index, data format
descriptor of the UASTC colour model 166) with UASTC LDR 4x4 blocks of mode 8, the solid-colour block of the UASTC
specification (the 5-bit mode code 0x17, then R, G, B, A as 8 bits each): a 2 x 3 grid of blocks of six colours must
come back as exactly those colours, each filling its 4 x 4 pixels, top row first.  The WebP image is lossless: its
pixels come back exactly, chosen over the PNG fallback of another colour.

Hostile KTX2 images: truncated, a size beyond ``Limits.image_pixels`` (refused before the transcoder runs), a cube
map, a format that is not Basis, a block of the reserved mode 19: each a `SceneFileError` naming the image.  Without
the transcoder the error names the extra, and a texture with a PNG fallback is drawn from it with a warning.
"""
import io
import struct
import sys
import warnings

import numpy as np
import pytest

import glphong
from glphong.filesafety import Limits, SceneFileError
from glphong.formats.gltf_data import GltfFile, read_gltf_image

COLOURS = [[(255, 0, 0, 255), (0, 255, 0, 255), (0, 0, 255, 128)],
           [(10, 20, 30, 40), (250, 128, 1, 255), (0, 0, 0, 0)]]


def _uastc_solid(rgba):
    """One 16-byte UASTC block of mode 8 (solid colour); bits from the first byte's least significant bit."""
    bits = 0x17 | rgba[0] << 5 | rgba[1] << 13 | rgba[2] << 21 | rgba[3] << 29
    return bits.to_bytes(16, "little")


def _ktx2(blocks, vk_format=0, faces=1, size=None, cut=None):
    """A KTX2 file of one level of UASTC LDR 4x4 blocks, no supercompression (KTX2 specification, section 3)."""
    rows, columns = len(blocks), len(blocks[0])
    width, height = size or (4 * columns, 4 * rows)
    data = b"".join(block if isinstance(block, bytes) else _uastc_solid(block) for row in blocks for block in row)
    sample = struct.pack("<HBB", 0, 127, 3) + bytes(4) + struct.pack("<II", 0, 0xFFFFFFFF)  # 128 bits of RGBA
    descriptor = struct.pack("<IHH", 0, 2, 24 + len(sample)) + bytes([166, 1, 2, 0]) + bytes([3, 3, 0, 0]) \
        + bytes([16, 0, 0, 0, 0, 0, 0, 0]) + sample  # UASTC, BT.709, sRGB; 4x4 blocks of 16 bytes
    dfd = struct.pack("<I", 4 + len(descriptor)) + descriptor
    level_offset = 80 + 24 + len(dfd)
    level_offset += -level_offset % 16
    out = b"\xabKTX 20\xbb\r\n\x1a\n" + struct.pack("<9I", vk_format, 1, width, height, 0, 0, faces, 1, 0)
    out += struct.pack("<IIIIQQ", 104, len(dfd), 0, 0, 0, 0) + struct.pack("<QQQ", level_offset, len(data), len(data))
    out += dfd
    out += bytes(level_offset - len(out)) + data
    return out[:cut] if cut else out


def _with(payload, offset, fmt, value):
    """``payload`` with ``value`` packed as ``fmt`` at byte ``offset`` (a header or level-index field changed)."""
    out = bytearray(payload)
    struct.pack_into(fmt, out, offset, value)
    return bytes(out)


def _expected(blocks):
    return np.kron(np.asarray(blocks, np.uint8), np.ones((4, 4, 1), np.uint8))  # each colour over 4 x 4 pixels


def _textured(builder, ktx2=None, webp=None, fallback=None, required=True):
    builder.attribute("POSITION", np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0]], np.float32))
    builder.attribute("TEXCOORD_0", np.array([[0, 0], [1, 0], [1, 1]], np.float32))
    texture, used = {}, []
    if fallback is not None:
        texture["source"] = builder.image(fallback, "image/png")
    for name, payload, mime in (("KHR_texture_basisu", ktx2, "image/ktx2"), ("EXT_texture_webp", webp, "image/webp")):
        if payload is not None:
            texture.setdefault("extensions", {})[name] = {"source": builder.image(payload, mime)}
            used.append(name)
    builder.document["textures"] = [texture]
    builder.document["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
    builder.primitive["material"] = 0
    builder.document["extensionsUsed"] = used
    if required:
        builder.document["extensionsRequired"] = used


def _png(colour):
    from PIL import Image

    out = io.BytesIO()
    Image.new("RGBA", (4, 4), colour).save(out, "PNG")
    return out.getvalue()


def _pixels(path, limits=None):
    return read_gltf_image(GltfFile(path, limits), 0)


def test_ktx2_uastc_texture_transcodes_to_its_block_colours(tmp_path, builder):
    pytest.importorskip("opengl_basisu", reason="the [ktx2] extra (opengl_basisu) is not installed")
    _textured(builder, ktx2=_ktx2(COLOURS))
    assert np.array_equal(_pixels(builder.write(tmp_path)), _expected(COLOURS))


def test_ktx2_texture_reaches_the_material(tmp_path, builder):
    pytest.importorskip("opengl_basisu", reason="the [ktx2] extra (opengl_basisu) is not installed")
    _textured(builder, ktx2=_ktx2(COLOURS), fallback=_png((9, 9, 9, 255)), required=False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # no lights
        scene = glphong.load_scene(builder.write(tmp_path))
    level = scene.objects[0].material.base_color.texture.levels[0]
    assert level.shape[:2] == (8, 12)  # the KTX2 image, not the 4 x 4 fallback


def test_a_planted_block_layout_error_is_caught(tmp_path, builder):
    """Rows swapped in the expectation: the comparison above would fail."""
    pytest.importorskip("opengl_basisu", reason="the [ktx2] extra (opengl_basisu) is not installed")
    _textured(builder, ktx2=_ktx2(COLOURS))
    assert not np.array_equal(_pixels(builder.write(tmp_path)), _expected(COLOURS[::-1]))


@pytest.mark.parametrize("payload, pattern", [
    (_ktx2(COLOURS, cut=60), r"images\[0\]: expected a KTX2 file \(80 bytes of header at least"),
    (_ktx2(COLOURS, cut=130), r"images\[0\]: its data format descriptor|cannot be transcoded"),
    (_ktx2(COLOURS, size=(65536, 65536)), r"images\[0\]: a 65536 x 65536 KTX2 image is more than"),
    (_ktx2(COLOURS, faces=6), r"images\[0\]: a KTX2 image of depth 0, 0 layers and 6 faces"),
    (_ktx2(COLOURS, vk_format=37), r"images\[0\]: a KTX2 image of vkFormat 37"),
    (_ktx2([[(1, 2, 3, 4), b"\x45" + bytes(15)]]), r"images\[0\]: a UASTC LDR 4x4 KTX2 image of 8 x 4 pixels that "
     r"cannot be transcoded"),
    (_ktx2(COLOURS)[:-20], r"images\[0\]: KTX2 level 0 \(bytes \d+ to \d+\) lies outside"),
    (_with(_ktx2(COLOURS), 96, "<Q", 1 << 40), r"images\[0\]: KTX2 level 0 declares 1099511627776 uncompressed bytes"),
    (_with(_ktx2(COLOURS), 80, "<Q", 1 << 40), r"images\[0\]: KTX2 level 0 \(bytes 1099511627776 to"),
    (_with(_ktx2(COLOURS), 40, "<I", 10), r"images\[0\]: 10 levels for a 12 x 8 KTX2 image \(at most 4\)"),
])
def test_hostile_ktx2_images_are_clear_errors(tmp_path, builder, payload, pattern):
    pytest.importorskip("opengl_basisu", reason="the [ktx2] extra (opengl_basisu) is not installed")
    _textured(builder, ktx2=payload)
    with pytest.raises(SceneFileError, match=pattern):
        _pixels(builder.write(tmp_path), Limits(image_pixels=1 << 20))


def test_without_the_transcoder_the_error_names_the_extra_or_the_fallback_is_drawn(tmp_path, builder, monkeypatch):
    monkeypatch.setitem(sys.modules, "opengl_basisu", None)
    _textured(builder, ktx2=_ktx2(COLOURS))
    with pytest.raises(SceneFileError, match=r"extensionsRequired: needs KHR_texture_basisu.*glphong\[ktx2\]"):
        _pixels(builder.write(tmp_path))
    builder.document.pop("extensionsRequired")
    with pytest.raises(SceneFileError, match=r"textures\[0\]: a KHR_texture_basisu texture without a PNG or JPEG "
                       r"fallback.*glphong\[ktx2\]"):
        _pixels(builder.write(tmp_path))
    builder.document["textures"][0]["source"] = builder.image(_png((9, 8, 7, 255)), "image/png")
    with pytest.warns(UserWarning, match="drawn from their PNG or JPEG fallback"):
        pixels = _pixels(builder.write(tmp_path))
    assert pixels.shape == (4, 4, 4) and tuple(pixels[0, 0]) == (9, 8, 7, 255)


def test_webp_texture_is_read_before_its_fallback(tmp_path, builder):
    from PIL import Image

    rng = np.random.default_rng(3)
    expected = rng.integers(0, 256, (5, 7, 4), dtype=np.uint8)
    out = io.BytesIO()
    Image.fromarray(expected, "RGBA").save(out, "WEBP", lossless=True, exact=True)
    _textured(builder, webp=out.getvalue(), fallback=_png((1, 2, 3, 255)), required=False)
    assert np.array_equal(_pixels(builder.write(tmp_path)), expected)


def test_a_webp_image_that_is_a_png_is_refused(tmp_path, builder):
    _textured(builder, webp=_png((1, 2, 3, 255)))
    with pytest.raises(SceneFileError, match=r"images\[0\]"):
        _pixels(builder.write(tmp_path))


def test_a_ktx2_textured_quad_renders_and_verifies(tmp_path, builder, glphong_backend, glphong_make_renderer):
    pytest.importorskip("opengl_basisu", reason="the [ktx2] extra (opengl_basisu) is not installed")
    _textured(builder, ktx2=_ktx2(COLOURS))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # no lights: the default view's
        scene = glphong.load_scene(builder.write(tmp_path))
    assert glphong.verify(scene, glphong_make_renderer(40, 32, glphong_backend)).passed


def test_save_gltf_writes_a_ktx2_texture_as_png(tmp_path, builder):
    pytest.importorskip("opengl_basisu", reason="the [ktx2] extra (opengl_basisu) is not installed")
    _textured(builder, ktx2=_ktx2(COLOURS))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # no lights
        scene = glphong.load_scene(builder.write(tmp_path))
        glphong.save_gltf(scene, tmp_path / "plain.gltf")
        again = glphong.load_scene(tmp_path / "plain.gltf")
    document = (tmp_path / "plain.gltf").read_text()
    assert "ktx2" not in document and "basisu" not in document and "image/png" in document
    assert np.array_equal(again.objects[0].material.base_color.texture.levels[0],
                          scene.objects[0].material.base_color.texture.levels[0])


def test_without_webp_support_the_fallback_is_drawn_or_the_error_says_why(tmp_path, builder, monkeypatch):
    from glphong.formats import gltf_data

    monkeypatch.setattr(gltf_data, "_webp_available", lambda: False)
    _textured(builder, webp=b"RIFF", fallback=_png((4, 5, 6, 255)), required=False)
    with pytest.warns(UserWarning, match="EXT_texture_webp textures are drawn from their PNG or JPEG fallback"):
        assert tuple(_pixels(builder.write(tmp_path))[0, 0]) == (4, 5, 6, 255)
    builder.document["textures"][0].pop("source")
    with pytest.raises(SceneFileError, match=r"textures\[0\]: a EXT_texture_webp texture without a PNG or JPEG "
                       r"fallback: glphong decodes it with Pillow, which was built without WebP"):
        _pixels(builder.write(tmp_path))
