"""Radiance RGBE (.hdr) files (glphong.formats.hdr): the stated decoding conventions, every scanline form and
orientation, and files from anyone (bounds checked before memory is touched, a clear error naming where).

The expected values are the format's definition written out here (a mantissa m with exponent e is (m + 0.5) 2^(e-136)
for Radiance, m 2^(e-136) for stb_image), on bytes these tests write by hand, not by glphong's writer.
"""
import numpy as np
import pytest

from glphong.core.filesafety import Limits, SceneFileError
from glphong.formats.hdr import read_hdr, rgbe_decode, rgbe_encode, write_hdr


def _file(tmp_path, header, resolution, body, name="x.hdr"):
    path = tmp_path / name
    path.write_bytes(header + b"\n" + resolution + b"\n" + body)
    return path


HEADER = b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n"


def test_the_conventions_are_the_definitions():
    pixel = np.array([[128, 64, 1, 129]], np.uint8)  # e = 129: scale 2^-7
    np.testing.assert_array_equal(rgbe_decode(pixel, "radiance"), [[128.5 / 128, 64.5 / 128, 1.5 / 128]])
    np.testing.assert_array_equal(rgbe_decode(pixel, "stb"), [[1.0, 0.5, 1.0 / 128]])
    np.testing.assert_array_equal(rgbe_decode(np.array([[200, 200, 200, 0]], np.uint8)), [[0.0, 0.0, 0.0]])
    with pytest.raises(ValueError, match="convention must be one of 'radiance', 'stb'"):
        rgbe_decode(pixel, "exact")


def test_flat_file_written_by_hand(tmp_path):
    body = bytes([128, 0, 0, 129, 0, 128, 0, 130, 0, 0, 128, 131, 10, 20, 30, 128])  # 2 x 2, top row first
    image = read_hdr(_file(tmp_path, HEADER, b"-Y 2 +X 2", body), convention="stb")
    np.testing.assert_array_equal(image.pixels, [[[1.0, 0, 0], [0, 2.0, 0]], [[0, 0, 4.0], [10 / 256, 20 / 256, 30 / 256]]])
    assert image.exposure == 1.0 and image.header == ("FORMAT=32-bit_rle_rgbe",) and image.convention == "stb"


@pytest.mark.parametrize("resolution, flip", [(b"-Y 2 +X 2", (False, False)), (b"+Y 2 +X 2", (True, False)),
                                              (b"-Y 2 -X 2", (False, True)), (b"+Y 2 -X 2", (True, True))])
def test_orientations(tmp_path, resolution, flip):
    body = bytes([128, 0, 0, 129, 0, 128, 0, 129, 0, 0, 128, 129, 128, 128, 128, 129])
    pixels = read_hdr(_file(tmp_path, HEADER, resolution, body), convention="stb").pixels
    expected = np.array([[[1.0, 0, 0], [0, 1.0, 0]], [[0, 0, 1.0], [1.0, 1.0, 1.0]]])
    expected = expected[::-1] if flip[0] else expected
    expected = expected[:, ::-1] if flip[1] else expected
    np.testing.assert_array_equal(pixels, expected)


def test_run_length_scanline_written_by_hand(tmp_path):
    width = 10
    # channel r: a run of 10 x 128; g: literal 0..9; b: run 4 x 7 then literal 6 x 1; e: run 10 x 130
    body = bytes([2, 2, 0, width]) + bytes([128 + 10, 128]) + bytes([10, *range(10)]) + bytes([128 + 4, 7, 6, *[1] * 6]) \
        + bytes([128 + 10, 130])
    pixels = read_hdr(_file(tmp_path, HEADER, b"-Y 1 +X 10", body), convention="stb").pixels
    np.testing.assert_array_equal(pixels[0, :, 0], [2.0] * 10)
    np.testing.assert_array_equal(pixels[0, :, 1], np.arange(10) / 64.0)
    np.testing.assert_array_equal(pixels[0, :, 2], np.array([7] * 4 + [1] * 6) / 64.0)


def test_old_style_repeats(tmp_path):
    body = bytes([128, 128, 128, 129, 1, 1, 1, 3])  # a pixel, then repeat it 3 times
    pixels = read_hdr(_file(tmp_path, HEADER, b"-Y 1 +X 4", body), convention="stb").pixels
    np.testing.assert_array_equal(pixels, np.ones((1, 4, 3)))


@pytest.mark.parametrize("run_length", [True, False])
@pytest.mark.parametrize("shape", [(5, 40), (3, 7), (1, 1), (4, 300)])
def test_round_trip_within_the_format_precision(tmp_path, run_length, shape):
    rng = np.random.default_rng(1)
    pixels = np.exp(rng.uniform(-20, 20, shape + (3,)))
    pixels[:, : shape[1] // 2] = pixels[0, -1]  # runs for the run-length coder
    pixels[-1, -1] = (1e6, 1e-6, 1.0)
    pixels[0, 0] = 0.0
    image = read_hdr(write_hdr(tmp_path / "r.hdr", pixels, run_length=run_length, exposure=2.0))
    assert image.exposure == 2.0 and image.pixels.shape == shape + (3,)
    peak = pixels.max(axis=-1, keepdims=True)
    # each channel within half a mantissa step of the shared exponent (2^-8 of the peak's power of two), plus float32
    np.testing.assert_array_less(np.abs(image.pixels - pixels), 2.0 ** -8 * peak + 1e-7 * np.abs(pixels) + 1e-38)
    assert image.pixels[0, 0].tolist() == [0.0, 0.0, 0.0]


def test_encode_refuses_what_rgbe_cannot_hold():
    for bad in ([[-1.0, 0.0, 0.0]], [[np.inf, 0.0, 0.0]], [[np.nan, 0.0, 0.0]]):
        with pytest.raises(ValueError, match="finite values >= 0"):
            rgbe_encode(bad)


HOSTILE = {
    "not rgbe": (b"P6\n", b"-Y 1 +X 1", b"\0" * 4, "header line 1", "must begin with '#\\?'"),
    "xyze": (b"#?RADIANCE\nFORMAT=32-bit_rle_xyze\n", b"-Y 1 +X 1", b"\0" * 4, "header line 2", "XYZE files are not read"),
    "bad exposure": (b"#?RADIANCE\nEXPOSURE=-2\n", b"-Y 1 +X 1", b"\0" * 4, "header line 2", "EXPOSURE must be"),
    "no resolution": (HEADER, b"512 512", b"", "header line 4", "expected a resolution line"),
    "x-major": (HEADER, b"+X 2 -Y 2", b"", "header line 4", "Y-major orientations only"),
    "huge": (HEADER, b"-Y 999999999 +X 999999999", b"", "header line 4", "at most"),
    "truncated flat": (HEADER, b"-Y 2 +X 2", bytes([128, 0, 0, 129] * 3), "scanline 1", "the file ends at pixel 1"),
    "missing scanline": (HEADER, b"-Y 3 +X 2", bytes([128, 0, 0, 129] * 4), "scanline 2", "ends before scanline 2"),
    "run past width": (HEADER, b"-Y 1 +X 8", bytes([2, 2, 0, 8, 128 + 9, 1]), "scanline 0", "a run of 9 past"),
    "zero literal": (HEADER, b"-Y 1 +X 8", bytes([2, 2, 0, 8, 0]), "scanline 0", "a literal of 0 bytes"),
    "literal past file": (HEADER, b"-Y 1 +X 8", bytes([2, 2, 0, 8, 8, 1, 2]), "scanline 0", "a literal of 8 bytes"),
    "wrong scanline width": (HEADER, b"-Y 1 +X 8", bytes([2, 2, 0, 9]), "scanline 0", "a run-length scanline of 9 pixels"),
    "repeat first": (HEADER, b"-Y 1 +X 4", bytes([1, 1, 1, 3]), "scanline 0", "nothing to repeat"),
    "repeat past width": (HEADER, b"-Y 1 +X 2", bytes([128, 0, 0, 129, 1, 1, 1, 200]), "scanline 0", "past the scanline"),
}


@pytest.mark.parametrize("case", list(HOSTILE))
def test_hostile_files_give_clear_errors(tmp_path, case):
    header, resolution, body, where, message = HOSTILE[case]
    with pytest.raises(SceneFileError, match=message) as info:
        read_hdr(_file(tmp_path, header, resolution, body))
    assert info.value.where == where and info.value.file.endswith("x.hdr")


def test_endless_header_and_limits(tmp_path):
    endless = tmp_path / "endless.hdr"
    endless.write_bytes(b"#?RADIANCE\n" + b"X=1\n" * 2000)
    with pytest.raises(SceneFileError, match="the header has no end"):
        read_hdr(endless)
    path = write_hdr(tmp_path / "ok.hdr", np.ones((64, 64, 3)))
    with pytest.raises(SceneFileError, match="Limits.image_pixels"):
        read_hdr(path, limits=Limits(image_pixels=1000))
    with pytest.raises(SceneFileError, match="Limits.file_bytes"):
        read_hdr(path, limits=Limits(file_bytes=100))
