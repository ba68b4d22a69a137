"""Reading files that someone else made: confined paths, regular files, size and pixel limits, clear errors.

glphong's trust model (docs: "Files from anyone"):

- A scene file may name other files (a glTF buffer or image ``uri``, an OBJ ``mtllib``, an MTL
  ``map_Kd``).  Each name is percent-decoded (glTF's URIs are RFC 3986 references), then refused if it is
  a URI with a scheme (only ``data:`` is read, by the glTF reader itself), an absolute path, or a path
  that leaves the folder of the file that names it once symbolic links are resolved
  (`resolve_reference`).  ``allow_outside=True`` (``load_scene(..., allow_outside=True)``) lifts the
  folder rule for files the caller trusts; the other rules stay.
- Only regular files are read (a FIFO, a device such as ``/dev/zero``, a folder are refused before
  anything is read), and at most `Limits.file_bytes` bytes of each (`read_bytes`).
- Images named by a file are opened as PNG or JPEG only, and their size is read from the header and
  checked against `Limits.image_pixels` before a pixel is decoded (`open_image`).
- Whatever a file's content gets wrong is a `SceneFileError` (a ``ValueError``) naming the file, where
  in it (a JSON path such as ``accessors[3].byteStride`` or a line number), what was found and what was
  expected.  Its text never quotes bytes of a file other than the scene file itself.

The limits are module-wide defaults (`LIMITS`), overridable per call (``load_scene(..., limits=...)``).
"""
import json
import os
import re
import stat
import warnings
from dataclasses import dataclass, replace
from io import BytesIO
from pathlib import Path, PurePosixPath, PureWindowsPath
from urllib.parse import unquote

import numpy as np

__all__ = ["SceneFileError", "Limits", "LIMITS", "resolve_reference", "read_bytes", "read_text", "parse_json",
           "open_image", "decode_image"]


class SceneFileError(ValueError):
    """A scene file (or a file it names) is malformed, hostile or beyond a limit.

    Parameters
    ----------
    file : str or path-like
        The file whose content is at fault.
    message : str
        What was found and what was expected.
    where : str, optional
        Where in the file: a JSON path (``meshes[0].primitives[1].indices``) or ``line 12``.

    Attributes
    ----------
    file, where, message : str
    """

    def __init__(self, file, message, where=None):
        self.file, self.where, self.message = str(file), where, message
        super().__init__(f"{self.file}: {where}: {message}" if where else f"{self.file}: {message}")


@dataclass(frozen=True)
class Limits:
    """How much of a foreign file glphong reads.

    Attributes
    ----------
    file_bytes : int
        Largest file read (a scene file, a buffer, an image, an MTL file) [bytes]; default 1 GiB.
    image_pixels : int
        Largest image decoded, width times height [px]; default 4096 x 4096 (a 16.8 Mpx texture takes
        about 0.5 GB while its mip pyramid is built in float64).
    nodes : int
        Most glTF nodes, meshes, accessors (each), and node instances a scene draws (a node shared by several
        parents counts once per path); default 1,000,000.
    decoded_bytes : int
        Most bytes of arrays and pixels decoded from one scene file, counted at their widest (float64) before
        they are made [bytes]; default 4 GiB.  Bounds what instancing and aliasing could multiply: many
        accessors over one buffer view, many meshes over one accessor.
    """

    file_bytes: int = 1 << 30
    image_pixels: int = 4096 * 4096
    nodes: int = 1_000_000
    decoded_bytes: int = 4 << 30

    def __post_init__(self):
        for name in ("file_bytes", "image_pixels", "nodes", "decoded_bytes"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise ValueError(f"Limits.{name} must be an integer >= 1 (got {value!r})")

    def replace(self, **changes):
        """A copy with ``changes``."""
        return replace(self, **changes)


#: the defaults (`Limits`)
LIMITS = Limits()

_SCHEME = re.compile(r"^[A-Za-z][A-Za-z0-9+.\-]*:")


def resolve_reference(base_file, reference, where, allow_outside=False, percent_encoded=True):
    """The path of the file that ``reference`` (written in ``base_file``) names, checked.

    Parameters
    ----------
    base_file : path-like
        The file that holds the reference; relative references are against its folder.
    reference : str
        As written in the file (percent-encoded for glTF URIs; plain names decode unchanged).
    where : str
        Where the reference is written (for the error).
    allow_outside : bool
        Let the reference leave ``base_file``'s folder (absolute paths too).
    percent_encoded : bool
        Percent-decode first (glTF URIs); False for plain file names (OBJ ``mtllib``, MTL maps).

    Returns
    -------
    pathlib.Path
        Resolved (symbolic links followed).  Existence is the caller's business (`read_bytes`).

    Raises
    ------
    SceneFileError
        A scheme other than a drive letter, an absolute path or one leaving the folder (unless
        ``allow_outside``), an empty or NUL-holding name.
    """
    if not isinstance(reference, str) or not reference:
        raise SceneFileError(base_file, f"a file reference must be a non-empty string (got {reference!r:.80})", where)
    name = unquote(reference) if percent_encoded else reference
    if "\x00" in name:
        raise SceneFileError(base_file, "a file reference holds a NUL character", where)
    windows = PureWindowsPath(name)
    if _SCHEME.match(name) and not windows.drive:
        raise SceneFileError(base_file, f"{reference!r:.120} is a URI with a scheme: glphong reads files beside the "
                             "scene file and data: URIs only", where)
    base = Path(base_file).resolve().parent
    absolute = PurePosixPath(name).is_absolute() or windows.is_absolute() or bool(windows.drive) or name.startswith("\\")
    if absolute and not allow_outside:
        raise SceneFileError(base_file, f"{reference!r:.120} is an absolute path: glphong reads files inside the scene "
                             "file's folder only (load_scene(..., allow_outside=True) for files you trust)", where)
    target = (base / name.replace("\\", "/")).resolve()
    if not allow_outside and not target.is_relative_to(base):
        raise SceneFileError(base_file, f"{reference!r:.120} leaves the scene file's folder {base}: glphong reads files "
                             "inside it only (load_scene(..., allow_outside=True) for files you trust)", where)
    return target


def read_bytes(path, limits=None, source=None, where=None):
    """The bytes of a regular file of at most ``limits.file_bytes`` bytes.

    The file is opened without blocking and checked with ``fstat`` on the open descriptor, so a FIFO,
    a device or a folder is refused before a byte is read, and the file checked is the file read.

    Parameters
    ----------
    path : path-like
    limits : Limits, optional
    source : path-like, optional
        The scene file that named ``path`` (the error names both).
    where : str, optional

    Raises
    ------
    SceneFileError
        Missing, not a regular file, or larger than the limit.
    """
    limits = limits or LIMITS
    path = Path(path)
    blame = source if source is not None else path
    label = "" if source is None else f"{path.name}: "
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except FileNotFoundError:
        raise SceneFileError(blame, f"{label}no such file" + ("" if source is None else " beside the scene file"),
                             where) from None
    except OSError as exc:
        raise SceneFileError(blame, f"{label}cannot be opened ({exc.strerror})", where) from None
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise SceneFileError(blame, f"{label}not a regular file (a folder, FIFO, device or socket): glphong reads "
                                 "regular files only", where)
        if info.st_size > limits.file_bytes:
            raise SceneFileError(blame, f"{label}{info.st_size} bytes, more than the limit of {limits.file_bytes} "
                                 "(glphong.filesafety.Limits.file_bytes)", where)
        chunks, left = [], info.st_size + 1
        while left > 0:
            chunk = os.read(fd, min(left, 1 << 24))
            if not chunk:
                break
            chunks.append(chunk)
            left -= len(chunk)
        data = b"".join(chunks)
        if len(data) > limits.file_bytes:
            raise SceneFileError(blame, f"{label}grew past the limit of {limits.file_bytes} bytes while read", where)
        return data
    finally:
        os.close(fd)


def read_text(path, limits=None, source=None, where=None):
    """The text of a regular file (`read_bytes`): UTF-8 with or without a byte-order mark, UTF-16 with
    one; undecodable bytes become U+FFFD."""
    data = read_bytes(path, limits, source, where)
    if data.startswith((b"\xff\xfe", b"\xfe\xff")):
        return data.decode("utf-16", errors="replace")
    return data.decode("utf-8-sig", errors="replace")


def parse_json(path, data, what="a JSON document"):
    """The JSON value of ``data`` (bytes, UTF-8 with or without a byte-order mark) read from ``path``; a
    `SceneFileError` naming the line and column for invalid JSON, and for nesting deeper than Python's recursion
    limit (``what`` says what the file should have been)."""
    try:
        return json.loads(data.decode("utf-8-sig"))
    except UnicodeDecodeError as exc:
        raise SceneFileError(path, f"the JSON is not UTF-8 (byte {exc.start})") from None
    except json.JSONDecodeError as exc:
        raise SceneFileError(path, f"not valid JSON: {exc.msg}", f"line {exc.lineno} column {exc.colno}") from None
    except RecursionError:
        raise SceneFileError(path, f"JSON nested too deeply to be {what}") from None


#: image formats glphong decodes from scene files (Pillow is asked for these plugins only)
IMAGE_FORMATS = ("PNG", "JPEG")


def open_image(payload, limits=None, source=None, where=None, formats=IMAGE_FORMATS):
    """A Pillow image of ``payload`` whose format and size were checked from its header.

    Parameters
    ----------
    payload : bytes
    limits : Limits, optional
    source : path-like
        The file to blame.
    where : str, optional
    formats : tuple of str or None
        Pillow format names accepted (PNG and JPEG: glTF's image formats; nothing else is handed to a
        Pillow plugin, so no EPS reaches Ghostscript); None: any (for files the caller chose).

    Returns
    -------
    PIL.Image.Image
        Opened (header read), not decoded; close it.

    Raises
    ------
    SceneFileError
        Not one of ``formats``, or more than ``limits.image_pixels`` pixels.
    """
    from PIL import Image, UnidentifiedImageError  # Pillow loads its plugins on first use: only where an image is read

    limits = limits or LIMITS
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            image = Image.open(BytesIO(payload), formats=None if formats is None else list(formats))
    except (UnidentifiedImageError, Image.DecompressionBombError, OSError, ValueError, SyntaxError):
        kinds = "an image format Pillow reads" if formats is None else " or ".join(formats)
        raise SceneFileError(source, f"an image that is not {kinds} (or is damaged)", where) from None
    width, height = image.size
    if width < 1 or height < 1 or width * height > limits.image_pixels:
        image.close()
        raise SceneFileError(source, f"an image of {width} x {height} pixels: more than the limit of "
                             f"{limits.image_pixels} pixels (glphong.filesafety.Limits.image_pixels)", where)
    return image


def decode_image(payload, limits=None, source=None, where=None, formats=IMAGE_FORMATS, mode=None):
    """The pixels of an image (`open_image` checks first): (H, W) or (H, W, C) uint8 or uint16.

    ``mode`` (a Pillow mode such as ``'RGB'``) converts to it; by default L, I;16, RGB and RGBA images
    keep their mode and others become RGB.

    Raises
    ------
    SceneFileError
        As `open_image`, or pixel data that cannot be decoded.
    """
    from PIL import Image

    image = open_image(payload, limits, source, where, formats)
    try:
        with image, warnings.catch_warnings():
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            if mode is not None and image.mode != mode:
                image = image.convert(mode)
            elif mode is None and image.mode not in ("L", "I;16", "RGB", "RGBA"):
                image = image.convert("RGB")
            return np.asarray(image)
    except (OSError, ValueError, SyntaxError, Image.DecompressionBombError) as exc:
        raise SceneFileError(source, f"an image whose pixels cannot be decoded ({type(exc).__name__})", where) from None
