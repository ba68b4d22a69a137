"""Radiance RGBE images (``.hdr``): glphong's own reader and writer, for radiance maps (docs/design.md section 10).

A pixel is four bytes ``(r, g, b, e)``: a shared exponent and three 8-bit mantissas.  Decoding conventions differ
by half a mantissa step, and `read_hdr` states which it uses:

- ``'radiance'`` (default, Radiance's own ``colr_color``): ``c = (m + 0.5) 2^(e - 136)`` for ``e > 0``, the centre
  of the interval the encoder rounded into; 0 for ``e = 0``;
- ``'stb'`` (stb_image, and the many readers built on it): ``c = m 2^(e - 136)``, the interval's lower end.

The two differ by ``0.5 / m`` relative: up to 0.4% on a channel of mantissa 128, 50% on a mantissa of 1.

What is read: the ``#?`` magic line, header variables up to the blank line (``FORMAT`` must be
``32-bit_rle_rgbe``: XYZE files are refused; ``EXPOSURE`` values multiply into `HdrImage.exposure`, which the pixel
values carry: physical radiance is ``pixels / exposure``), the resolution line in any of the four Y-major orientations
(``-Y H +X W`` is the common one), and scanlines flat, in the old run-length form (``1 1 1 n``) or the new per-channel
one.  Every count is checked against the scanline and the file before a byte is used; the image is checked against
``Limits.image_pixels`` from its resolution line, before anything is allocated.  Errors are
`glphong.filesafety.SceneFileError` naming the file and the header line or scanline.
"""
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from glphong.core.filesafety import LIMITS, SceneFileError, read_bytes

__all__ = ["HdrImage", "read_hdr", "write_hdr", "rgbe_decode", "rgbe_encode", "CONVENTIONS"]

#: decoding conventions of `rgbe_decode`: the mantissa's offset within its rounding interval
CONVENTIONS = {"radiance": 0.5, "stb": 0.0}
_HEADER_LINES = 1024
_RESOLUTION = re.compile(rb"^([-+])Y (\d{1,9}) ([-+])X (\d{1,9})$")


@dataclass(frozen=True)
class HdrImage:
    """A decoded RGBE image.

    Attributes
    ----------
    pixels : (H, W, 3) float32 ndarray
        Row 0 at the top, column 0 at the left, as the image is viewed; the values the file holds (times its
        exposure).
    exposure : float
        The product of the header's ``EXPOSURE`` values (1 without): radiance is ``pixels / exposure``.
    header : tuple of str
        The header's variable lines, as written.
    convention : str
        The decoding convention used (`CONVENTIONS`).
    """

    pixels: np.ndarray
    exposure: float
    header: tuple
    convention: str


def rgbe_decode(rgbe, convention="radiance"):
    """RGBE bytes (..., 4) uint8 as float32 RGB (..., 3), in ``convention`` (`CONVENTIONS`)."""
    offset = _convention(convention)
    rgbe = np.asarray(rgbe, dtype=np.uint8)
    e = rgbe[..., 3].astype(np.int32)
    scale = np.where(e > 0, np.ldexp(1.0, e - 136), 0.0)
    return ((rgbe[..., :3].astype(np.float64) + offset) * scale[..., None]).astype(np.float32)


def rgbe_encode(rgb):
    """Float RGB (..., 3) (finite, >= 0) as RGBE bytes (..., 4) uint8, rounding the mantissas to nearest under the
    shared exponent of the largest channel (Radiance's ``setcolr``); values below 1e-38 become 0."""
    rgb = np.asarray(rgb, dtype=np.float64)
    if not np.all(np.isfinite(rgb)) or np.any(rgb < 0):
        raise ValueError("RGBE holds finite values >= 0 only")
    peak = rgb.max(axis=-1)
    mantissa, exponent = np.frexp(peak)  # peak = mantissa 2^exponent, mantissa in [0.5, 1)
    small = peak < 1e-38
    scale = np.where(small, 0.0, np.ldexp(256.0, -exponent))
    m = np.minimum(np.floor(rgb * scale[..., None]), 255.0)
    out = np.zeros(rgb.shape[:-1] + (4,), np.uint8)
    out[..., :3] = np.where(small[..., None], 0, m).astype(np.uint8)
    out[..., 3] = np.where(small, 0, np.clip(exponent + 128, 0, 255)).astype(np.uint8)
    return out


def _convention(convention):
    if convention not in CONVENTIONS:
        raise ValueError(f"convention must be one of {', '.join(map(repr, CONVENTIONS))} (got {convention!r})")
    return CONVENTIONS[convention]


def read_hdr(path, convention="radiance", limits=None):
    """Read a Radiance RGBE file.

    Parameters
    ----------
    path : path-like
    convention : {'radiance', 'stb'}
        How a mantissa decodes (module docstring).
    limits : glphong.filesafety.Limits, optional
        ``file_bytes`` and ``image_pixels`` apply.

    Returns
    -------
    HdrImage

    Raises
    ------
    glphong.filesafety.SceneFileError
        Not an RGBE file, an unsupported format or orientation, an image beyond the limits, or scanline data that
        runs past its scanline or the file, naming where.
    """
    _convention(convention)
    limits = limits or LIMITS
    data = read_bytes(path, limits)
    header, position, exposure, line = [], 0, 1.0, 0
    while True:
        end = data.find(b"\n", position)
        line += 1
        if end < 0 or line > _HEADER_LINES:
            raise SceneFileError(path, "the header has no end (a blank line before the resolution line, within "
                                 f"{_HEADER_LINES} lines)", f"header line {line}")
        text = data[position:end].rstrip(b"\r")
        position = end + 1
        if line == 1:
            if not text.startswith(b"#?"):
                raise SceneFileError(path, "not a Radiance RGBE file: it must begin with '#?' (such as #?RADIANCE)",
                                     "header line 1")
            continue
        if not text:
            break
        if text.startswith(b"FORMAT="):
            value = text[7:].strip()
            if value != b"32-bit_rle_rgbe":
                raise SceneFileError(path, f"FORMAT={value.decode('latin-1')[:40]!r}: glphong reads 32-bit_rle_rgbe "
                                     "(RGB) files; XYZE files are not read", f"header line {line}")
        elif text.startswith(b"EXPOSURE="):
            try:
                value = float(text[9:].strip())
            except ValueError:
                value = float("nan")
            if not np.isfinite(value) or value <= 0:
                raise SceneFileError(path, "EXPOSURE must be a positive finite number", f"header line {line}")
            exposure *= value
        header.append(text.decode("latin-1"))
    end = data.find(b"\n", position)
    resolution = _RESOLUTION.match(data[position:end if end >= 0 else len(data)].rstrip(b"\r"))
    if resolution is None:
        raise SceneFileError(path, "expected a resolution line such as '-Y 512 +X 1024' (Y-major orientations only)",
                             f"header line {line + 1}")
    y_sign, height, x_sign, width = resolution.group(1), int(resolution.group(2)), resolution.group(3), int(resolution.group(4))
    if width < 1 or height < 1 or width * height > limits.image_pixels:
        raise SceneFileError(path, f"{width} x {height} pixels: at least 1 x 1 and at most {limits.image_pixels} "
                             "(glphong.filesafety.Limits.image_pixels)", f"header line {line + 1}")
    rgbe = _scanlines(path, data, end + 1, width, height)
    pixels = rgbe_decode(rgbe, convention)
    if y_sign == b"+":  # the first scanline is the bottom one
        pixels = pixels[::-1]
    if x_sign == b"-":
        pixels = pixels[:, ::-1]
    return HdrImage(np.ascontiguousarray(pixels), float(exposure), tuple(header), convention)


def _scanlines(path, data, position, width, height):
    """The (height, width, 4) RGBE bytes of the scanlines from ``position``."""
    out = np.empty((height, width, 4), np.uint8)
    size = len(data)
    buffer = np.frombuffer(data, dtype=np.uint8)
    for y in range(height):
        where = f"scanline {y}"
        if position + 4 > size:
            raise SceneFileError(path, f"the file ends before scanline {y} of {height}", where)
        head = buffer[position:position + 4]
        if 8 <= width < 32768 and head[0] == 2 and head[1] == 2 and not head[2] & 0x80:
            if (int(head[2]) << 8 | int(head[3])) != width:
                raise SceneFileError(path, f"a run-length scanline of {int(head[2]) << 8 | int(head[3])} pixels in an "
                                     f"image {width} wide", where)
            position = _rle_scanline(path, buffer, position + 4, out[y], width, where)
        else:
            position = _flat_scanline(path, buffer, position, out[y], width, where, out[y - 1] if y else None)
    return out


def _rle_scanline(path, buffer, position, row, width, where):
    """One new-style scanline: four channels, each runs (count > 128: the next byte count - 128 times) and literals."""
    size = len(buffer)
    for channel in range(4):
        x = 0
        while x < width:
            if position >= size:
                raise SceneFileError(path, f"the file ends inside channel {channel}", where)
            count = int(buffer[position])
            position += 1
            if count > 128:
                count -= 128
                if x + count > width or position >= size:
                    raise SceneFileError(path, f"a run of {count} past the scanline's {width} pixels (at {x}) or the "
                                         "file's end", where)
                row[x:x + count, channel] = buffer[position]
                position += 1
            else:
                if count == 0 or x + count > width or position + count > size:
                    raise SceneFileError(path, f"a literal of {count} bytes that is empty or runs past the scanline's "
                                         f"{width} pixels (at {x}) or the file's end", where)
                row[x:x + count, channel] = buffer[position:position + count]
                position += count
            x += count
    return position


def _flat_scanline(path, buffer, position, row, width, where, previous):
    """One flat scanline, with the old run-length form: ``1 1 1 n`` repeats the previous pixel ``n << shift`` times
    (``shift`` grows by 8 for consecutive repeat pixels)."""
    size = len(buffer)
    x, shift = 0, 0
    while x < width:
        if position + 4 > size:
            raise SceneFileError(path, f"the file ends at pixel {x} of {width}", where)
        pixel = buffer[position:position + 4]
        position += 4
        if pixel[0] == 1 and pixel[1] == 1 and pixel[2] == 1:
            count = int(pixel[3]) << shift
            last = row[x - 1] if x else (previous[-1] if previous is not None else None)
            if last is None or count == 0 or x + count > width or shift > 16:
                raise SceneFileError(path, f"an old-style repeat of {count} pixels with nothing to repeat, or past the "
                                     f"scanline's {width} pixels (at {x})", where)
            row[x:x + count] = last
            x += count
            shift += 8
        else:
            row[x] = pixel
            x += 1
            shift = 0
    return position


def write_hdr(path, pixels, run_length=True, exposure=None):
    """Write float RGB pixels as a Radiance RGBE file.

    Parameters
    ----------
    path : path-like
    pixels : (H, W, 3) array_like
        Finite values >= 0, row 0 at the top (written ``-Y H +X W``).
    run_length : bool
        New-style run-length scanlines (images 8 to 32767 wide) or flat ones.
    exposure : float, optional
        An ``EXPOSURE`` header value to write (the pixels are written as given).

    Returns
    -------
    pathlib.Path
    """
    pixels = np.asarray(pixels, dtype=np.float64)
    if pixels.ndim != 3 or pixels.shape[2] != 3 or not pixels.shape[0] or not pixels.shape[1]:
        raise ValueError(f"pixels must have shape (H, W, 3) (got {pixels.shape})")
    height, width = pixels.shape[:2]
    rgbe = rgbe_encode(pixels)
    lines = [b"#?RADIANCE", b"FORMAT=32-bit_rle_rgbe"] + ([f"EXPOSURE={float(exposure)!r}".encode()] if exposure else [])
    out = bytearray(b"\n".join(lines) + b"\n\n" + f"-Y {height} +X {width}\n".encode())
    for row in rgbe:
        if run_length and 8 <= width < 32768:
            out += bytes((2, 2, width >> 8, width & 0xFF))
            for channel in range(4):
                out += _rle_channel(row[:, channel])
        else:
            out += row.tobytes()
    path = Path(path)
    path.write_bytes(bytes(out))
    return path


def _rle_channel(values):
    """One channel of a new-style scanline: runs of 3 or more equal bytes (at most 127), literals of at most 128."""
    out, x, n = bytearray(), 0, len(values)
    while x < n:
        run = 1
        while x + run < n and run < 127 and values[x + run] == values[x]:
            run += 1
        if run >= 3:
            out += bytes((128 + run, int(values[x])))
            x += run
            continue
        start = x
        while x < n and x - start < 128:
            if x + 2 < n and values[x] == values[x + 1] == values[x + 2]:
                break
            x += 1
        out += bytes((x - start,)) + bytes(values[start:x])
    return bytes(out)
