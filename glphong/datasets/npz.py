"""A frame's passes as a NumPy ``.npz`` archive, and the pieces every per-pixel format shares.

`save_npz` writes each pass the frame holds (``frame.passes``, `glphong.gpu.passes`) as an array named by the pass,
with its dtype and shape unchanged (float32 or uint32, so a round trip is bit-exact, NaN flow included), plus
``coverage`` (H, W) float32 where the frame has it (``frame.mask`` is ``coverage > 0``), compressed
(``numpy.savez_compressed``).  `load_npz` reads one back as a dict, bounded and checked: each member's name, dtype
and shape are read from its header and checked before its pixels are decompressed, and nothing is unpickled.

`LAYOUT` and `frame_arrays` are shared with `glphong.datasets.exr`: what each array of a frame looks like, and a
frame's arrays checked against it.  Files are written whole or not at all (`glphong.core.atomic_files`).
"""
import io
import zipfile
import zlib

import numpy as np

from glphong.core.atomic_files import write_atomically
from glphong.core.filesafety import LIMITS, SceneFileError, read_bytes
from glphong.gpu.matte import MAX_MATTE_K
from glphong.gpu.passes import PASSES

__all__ = ["LAYOUT", "PASS_ARRAYS", "MAX_MATTE_K", "pass_arrays", "frame_arrays", "save_npz", "load_npz"]

_F4, _U4 = np.dtype(np.float32), np.dtype(np.uint32)
#: each array a frame file may hold: name -> (components, dtype); components None for an (H, W) array, an int c for
#: (H, W, c), "k" for the matte's (H, W, k) with any k from 1 to `MAX_MATTE_K` (both matte arrays the same k).  The
#: passes of `glphong.gpu.passes.PASSES` in its order (the 'matte' pass as its two arrays), then ``coverage``.
LAYOUT = {
    "radiance": (3, _F4), "depth": (None, _F4), "distance": (None, _F4), "normal": (3, _F4),
    "normal_camera": (3, _F4), "uv": (2, _F4), "instance": (None, _U4), "category": (None, _U4),
    "object_coordinates": (3, _F4), "nocs": (3, _F4), "flow": (2, _F4), "backward_flow": (2, _F4),
    "matte_ids": ("k", _U4), "matte_fractions": ("k", _F4), "coverage": (None, _F4),
}
#: the arrays of each pass that is not one array of its own name
PASS_ARRAYS = {"matte": ("matte_ids", "matte_fractions")}
assert tuple(LAYOUT)[:-1] == tuple(a for p in PASSES for a in PASS_ARRAYS.get(p, (p,)))


def pass_arrays(names):
    """The array names of the passes ``names`` (tuple of str, `LAYOUT`'s order)."""
    arrays = {a for p in names for a in PASS_ARRAYS.get(p, (p,))}
    return tuple(n for n in LAYOUT if n in arrays)


def _components_ok(components, shape):
    """Whether an array of ``shape`` has `LAYOUT`'s ``components``."""
    if components is None:
        return len(shape) == 2
    if len(shape) != 3:
        return False
    return 1 <= shape[2] <= MAX_MATTE_K if components == "k" else shape[2] == components


def _shape_text(components):
    return "(H, W)" if components is None else f"(H, W, {components})" + (
        f" with k from 1 to {MAX_MATTE_K}" if components == "k" else "")


def frame_arrays(frame):
    """The arrays of ``frame`` that frame files hold, checked against `LAYOUT`.

    Parameters
    ----------
    frame : glphong.gpu.frame.Frame
        A render (``renderer.render(scene, passes=...)``).

    Returns
    -------
    dict of str to ndarray
        Each pass in ``frame.passes`` (`LAYOUT`'s order) and ``coverage`` (H, W) float32 where ``frame.coverage`` is
        not None; the frame's own arrays where already C-contiguous, else C-ordered copies (the radiance is a view
        with a negative row stride).

    Raises
    ------
    TypeError
        ``frame`` has no ``passes``.
    ValueError
        A listed pass is None, an array has another dtype or shape than `LAYOUT`'s, or the arrays differ in
        height and width (the message names the pass).
    """
    names = getattr(frame, "passes", None)
    if names is None or isinstance(names, str):
        raise TypeError(f"expected a glphong Frame (renderer.render(...)), got {type(frame).__name__}")
    arrays, size = {}, None
    for name in list(pass_arrays([n for n in names if n in PASSES])) + ["coverage"]:
        value = getattr(frame, name, None)
        if value is None:
            if name == "coverage":
                continue
            raise ValueError(f"frame.passes lists {name!r} but frame.{name} is None")
        value = np.asarray(value)
        components, dtype = LAYOUT[name]
        if value.dtype != dtype or not _components_ok(components, value.shape):
            raise ValueError(f"frame.{name} is {value.dtype} {value.shape}; expected {dtype} {_shape_text(components)}")
        if size is None:
            size = value.shape[:2]
        elif value.shape[:2] != size:
            raise ValueError(f"frame.{name} is {value.shape[0]} x {value.shape[1]} pixels (H x W), the frame's other "
                             f"passes {size[0]} x {size[1]}")
        arrays[name] = np.ascontiguousarray(value)
    if "matte_ids" in arrays and arrays["matte_ids"].shape != arrays["matte_fractions"].shape:
        raise ValueError(f"frame.matte_ids is {arrays['matte_ids'].shape}, frame.matte_fractions "
                         f"{arrays['matte_fractions'].shape}; expected the same (H, W, k)")
    unknown = [n for n in names if n not in PASSES]
    if unknown:
        raise ValueError(f"frame.passes lists unknown passes {unknown}; the passes are {', '.join(PASSES)}")
    if not arrays:
        raise ValueError("the frame holds no pass to write")
    return arrays


def save_npz(path, frame):
    """Write every pass of ``frame`` (and its coverage) to a compressed ``.npz`` archive, atomically.

    Parameters
    ----------
    path : path-like
        The archive (written as named: NumPy's ``.npz`` suffix is not added).
    frame : glphong.gpu.frame.Frame
        Each pass in ``frame.passes`` is stored under its name with its dtype and shape, e.g. ``depth`` (H, W)
        float32 [m], ``instance`` (H, W) uint32, ``flow`` (H, W, 2) float32 [px] (`glphong.gpu.passes`), and
        ``coverage`` (H, W) float32 where the frame has it.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    ValueError
        The frame's arrays are not those of a render (`frame_arrays`).
    """
    arrays = frame_arrays(frame)

    def write(temporary):
        with open(temporary, "wb") as stream:
            np.savez_compressed(stream, **arrays)

    return write_atomically(path, write)


def _read_header(path, member, stream):
    """``(shape, fortran_order, dtype)`` of a ``.npy`` member's header, without reading its data."""
    try:
        version = np.lib.format.read_magic(stream)
        if version not in ((1, 0), (2, 0)):
            raise SceneFileError(path, f".npy format version {version[0]}.{version[1]}; expected 1.0 or 2.0", member)
        read = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
        return read(stream)
    except SceneFileError:
        raise
    except Exception as exc:  # NumPy's header parser (ast.literal_eval) raises ValueError, SyntaxError, TokenError ...
        raise SceneFileError(path, f"not a .npy header ({type(exc).__name__}: {str(exc)[:120]})", member) from None


def _check_member(path, member, name, header, size, limits):
    shape, _, dtype = header
    components, expected = LAYOUT[name]
    if (dtype.kind, dtype.itemsize) != (expected.kind, expected.itemsize) or dtype.hasobject or \
            not _components_ok(components, shape):
        raise SceneFileError(path, f"{dtype} {shape}; expected {expected} {_shape_text(components)}", member)
    if min(shape) < 1:
        raise SceneFileError(path, f"shape {shape}; expected every dimension >= 1", member)
    if size is not None and tuple(shape[:2]) != size:
        raise SceneFileError(path, f"{shape[0]} x {shape[1]} pixels (H x W), the archive's other arrays "
                             f"{size[0]} x {size[1]}", member)
    pixels = int(shape[0]) * int(shape[1])
    if not 0 < pixels <= limits.image_pixels:
        raise SceneFileError(path, f"{shape[0]} x {shape[1]} pixels; expected 1 to {limits.image_pixels} "
                             "(glphong.filesafety.Limits.image_pixels)", member)
    return tuple(shape[:2]), pixels * (shape[2] if len(shape) == 3 else 1) * 8


def load_npz(path, passes=None, limits=None):
    """Read an archive `save_npz` wrote: a dict of name to array.

    Only arrays named in `LAYOUT` are read, each with `LAYOUT`'s dtype and shape, all of one height and width
    within ``limits.image_pixels``; each member's header is checked before its data is decompressed, the file
    must be a regular file within ``limits.file_bytes``, and nothing is unpickled (``allow_pickle=False``).

    Parameters
    ----------
    path : path-like
    passes : sequence of str, optional
        Names the archive must hold (a `SceneFileError` naming the missing ones otherwise).
    limits : glphong.core.filesafety.Limits, optional
        Default `glphong.core.filesafety.LIMITS`; ``decoded_bytes`` bounds the arrays' total size.

    Returns
    -------
    dict of str to ndarray
        In `LAYOUT`'s order: e.g. ``radiance`` (H, W, 3) float32, ``instance`` (H, W) uint32, ``coverage`` (H, W)
        float32, native byte order.

    Raises
    ------
    SceneFileError
        Missing, not a regular file, too large, not a zip archive, an unexpected member name, dtype or shape,
        truncated or corrupt data, or a name of ``passes`` missing (the message names the file and the member).
    ValueError
        An unknown name in ``passes``.
    """
    limits = limits or LIMITS
    for name in passes or ():
        if name not in LAYOUT:
            raise ValueError(f"unknown name {name!r}; the names are {', '.join(LAYOUT)}")
    data = read_bytes(path, limits)
    try:
        archive = zipfile.ZipFile(io.BytesIO(data))
        members = archive.namelist()
    except (zipfile.BadZipFile, zipfile.LargeZipFile, ValueError, EOFError) as exc:
        raise SceneFileError(path, f"not a .npz (zip) archive ({exc})") from None
    names = [m[:-4] if m.endswith(".npy") else m for m in members]
    unexpected = [m for m, n in zip(members, names) if not m.endswith(".npy") or n not in LAYOUT]
    if unexpected:
        raise SceneFileError(path, f"unexpected members {unexpected[:8]}; expected <name>.npy with the names "
                             f"{', '.join(LAYOUT)}")
    if len(set(names)) != len(names):
        raise SceneFileError(path, f"members named twice: {sorted({n for n in names if names.count(n) > 1})}")
    missing = [n for n in (passes or ()) if n not in names]
    if missing:
        raise SceneFileError(path, f"holds no {missing}; it holds {[n for n in LAYOUT if n in names]}")
    if not names:
        raise SceneFileError(path, "holds no arrays")
    size, total = None, 0
    try:
        for member, name in zip(members, names):  # every header first: nothing decompressed beyond the limits
            with archive.open(member) as stream:
                size, decoded = _check_member(path, member, name, _read_header(path, member, stream), size, limits)
            total += decoded
            if total > limits.decoded_bytes:
                raise SceneFileError(path, f"arrays of more than {limits.decoded_bytes} bytes "
                                     "(glphong.filesafety.Limits.decoded_bytes)", member)
        out = {}
        for member, name in zip(members, names):
            with archive.open(member) as stream:
                array = np.lib.format.read_array(stream, allow_pickle=False)
                if stream.read(1):  # read to the end, where zipfile checks the CRC-32
                    raise SceneFileError(path, "data beyond the array its header describes", member)
            out[name] = np.ascontiguousarray(array, dtype=LAYOUT[name][1])
        if ("matte_ids" in out) != ("matte_fractions" in out) or (
                "matte_ids" in out and out["matte_ids"].shape != out["matte_fractions"].shape):
            raise SceneFileError(path, "matte_ids and matte_fractions: expected both, of the same (H, W, k)")
    except SceneFileError:
        raise
    except (zipfile.BadZipFile, zlib.error, ValueError, EOFError, OSError, NotImplementedError, RuntimeError) as exc:
        raise SceneFileError(path, f"corrupt or truncated archive ({type(exc).__name__}: {exc})") from None
    return {name: out[name] for name in LAYOUT if name in out}
