"""glphong's PNG writer (glphong.core.png) and the threaded sRGB encode: every file decodes, with an independent
reader (Pillow) and by hand (zlib and the Sub filter undone in numpy), to the image it was given."""
import io
import struct
import zlib

import numpy as np
import pytest
from PIL import Image

from glphong.core.imaging import encode_srgb8, encode_srgb8_reference, png_bytes, save_png
from glphong.core.png import encode_png


def _image(height, width, seed=0, smooth=False):
    rng = np.random.default_rng(seed)
    if smooth:
        y, x = np.mgrid[0:height, 0:width]
        return np.stack([(x * 255 // max(width - 1, 1)), (y * 255 // max(height - 1, 1)), (x + y) % 256],
                        axis=-1).astype(np.uint8)
    return rng.integers(0, 256, (height, width, 3), dtype=np.uint8)


def _chunks(data):
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    at, out = 8, []
    while at < len(data):
        (length,) = struct.unpack(">I", data[at:at + 4])
        name, body = data[at + 4:at + 8], data[at + 8:at + 8 + length]
        (crc,) = struct.unpack(">I", data[at + 8 + length:at + 12 + length])
        assert crc == zlib.crc32(name + body), name
        out.append((name, body))
        at += 12 + length
    return out


@pytest.mark.parametrize("shape", [(1, 1), (1, 7), (5, 3), (64, 33), (480, 640)])
@pytest.mark.parametrize("level", [0, 1, 6, 9])
@pytest.mark.parametrize("threads", [1, 2, 4])
def test_every_file_decodes_to_its_image(shape, level, threads):
    image = _image(*shape, seed=sum(shape), smooth=shape[0] > 100)
    data = encode_png(image, level, threads)
    np.testing.assert_array_equal(np.asarray(Image.open(io.BytesIO(data)).convert("RGB")), image)
    # by hand: the chunks' CRCs, one zlib stream whose Adler-32 holds, rows with filter Sub that undo to the image
    chunks = _chunks(data)
    assert [name for name, _ in chunks] == [b"IHDR", b"IDAT", b"IEND"]
    width, height, depth, colour = struct.unpack(">IIBB", chunks[0][1][:10])
    assert (height, width, depth, colour) == (shape[0], shape[1], 8, 2)
    rows = np.frombuffer(zlib.decompress(chunks[1][1]), np.uint8).reshape(height, 1 + width * 3)
    assert np.all(rows[:, 0] == 1)  # filter Sub
    undone = np.cumsum(rows[:, 1:].reshape(height, width, 3).astype(np.int64), axis=1) % 256
    np.testing.assert_array_equal(undone, image)


def test_about_pillows_size_at_the_same_level_on_a_render_like_image():
    """A shaded sphere over a dark floor, as a render looks (Pillow filters adaptively; glphong uses Sub)."""
    y, x = (np.mgrid[0:480, 0:640] - np.array([240, 320])[:, None, None]) / 200.0
    z = np.sqrt(np.clip(1 - x * x - y * y, 0, None))
    lit = np.clip(0.3 * x - 0.5 * y + 0.8 * z, 0, 1) * (z > 0) + 0.05 * (z == 0) * (1 + 0.5 * y)
    image = (np.stack([lit, 0.6 * lit, 0.3 * lit], axis=-1) ** (1 / 2.2) * 255).astype(np.uint8)
    ours = encode_png(image, 1)
    pillow = io.BytesIO()
    Image.fromarray(image).save(pillow, format="PNG", compress_level=1)
    assert len(ours) <= 1.25 * len(pillow.getvalue())


def test_bad_images_are_refused():
    with pytest.raises(ValueError, match=r"\(H, W, 3\) uint8"):
        encode_png(np.zeros((4, 4, 3), np.float32))
    with pytest.raises(ValueError, match=r"\(H, W, 3\) uint8"):
        encode_png(np.zeros((0, 4, 3), np.uint8))
    with pytest.raises(ValueError, match="level"):
        encode_png(np.zeros((4, 4, 3), np.uint8), level=10)


def test_threaded_encode_equals_the_formula_on_a_strided_frame(tmp_path):
    """A frame's radiance is a strided, row-flipped view of an RGBA read-back: encoded in row blocks on threads, it
    gives the formula's codes exactly; save_png and png_bytes write them."""
    rng = np.random.default_rng(4)
    rgba = (rng.random((300, 500, 4)) * 1.3).astype(np.float32)
    rgba[::7, ::5, 1] = np.nan
    rgba[3, :, 0] = -1.0
    radiance = rgba[::-1, :, :3]
    assert radiance.size >= 1 << 18 and not radiance.flags["C_CONTIGUOUS"]
    for exposure in (1.0, 0.37):
        np.testing.assert_array_equal(encode_srgb8(radiance, exposure), encode_srgb8_reference(radiance, exposure))
    save_png(tmp_path / "frame.png", radiance, 0.37)
    decoded = np.asarray(Image.open(tmp_path / "frame.png"))
    np.testing.assert_array_equal(decoded, encode_srgb8_reference(radiance, 0.37))
    assert png_bytes(radiance, 0.37) == (tmp_path / "frame.png").read_bytes()
