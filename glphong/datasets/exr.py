"""A frame's passes as one OpenEXR file, every pass in named channels (the optional extra ``exr``: OpenEXR >= 3.3).

The channels (`EXR_CHANNELS`), one scanline part, ZIP compression (lossless), 32-bit ``FLOAT`` for the float passes
and ``UINT`` for the ids, so that a round trip is bit-exact (NaN flow included):

- ``radiance``: ``R``, ``G``, ``B`` [W/(m^2 sr)], linear, FLOAT;
- the coverage: ``A``, FLOAT (the radiance is coverage-weighted: premultiplied alpha; ``frame.mask`` is ``A > 0``);
- ``depth``: ``Z`` [m], along the camera's viewing axis (OpenEXR's depth channel), FLOAT;
- ``distance``: ``distance.Z`` [m], along the pixel's ray, FLOAT;
- ``normal``, ``normal_camera``, ``object_coordinates`` [m], ``nocs``: ``<pass>.X``, ``<pass>.Y``, ``<pass>.Z``,
  FLOAT;
- ``uv``: ``uv.U``, ``uv.V``, FLOAT;
- ``instance``, ``category``: ``instance.id``, ``category.id`` (0 the background), UINT;
- ``flow``, ``backward_flow`` [px], x right, y down: ``flow.X``, ``flow.Y``, ``backward_flow.X``,
  ``backward_flow.Y``, FLOAT;
- the ``matte`` pass's k entries: ``matte.id0`` to ``matte.id<k-1>`` (UINT) and ``matte.fraction0`` to
  ``matte.fraction<k-1>`` (FLOAT), entry 0 the largest share (`MATTE_CHANNELS`).

The radiance, alpha and depth take the channel names every EXR reader knows (``R G B A Z``); every other pass is a
layer named by the pass, its components the axes (``X Y Z``, ``U V`` for texture coordinates), as Blender's
multilayer files name theirs.  The flow is glphong's (Kubric's) convention, y down: not Nuke's ``forward.u/v``
(y up), hence its own layer name.  Ids are ``UINT`` rather than float (Cryptomatte's hashes in float) so that
every id up to ``2^32 - 1`` survives.

`load_exr` reads such a file back into a dict of pass name to array (the layout of `glphong.datasets.npz.LAYOUT`),
bounded: a regular file within ``Limits.file_bytes``, its data window and channels checked from the header before
a pixel is decoded.
"""
import io
from pathlib import Path

import numpy as np

from glphong.core.filesafety import LIMITS, SceneFileError, read_bytes
from glphong.core.atomic_files import write_atomically
from glphong.datasets.npz import LAYOUT, MAX_MATTE_K, frame_arrays

__all__ = ["EXR_CHANNELS", "MATTE_CHANNELS", "save_exr", "load_exr"]

_AXES = ("X", "Y", "Z")
#: each array's channels in the file, in component order
EXR_CHANNELS = {
    "radiance": ("R", "G", "B"), "depth": ("Z",), "distance": ("distance.Z",),
    "normal": tuple(f"normal.{a}" for a in _AXES),
    "normal_camera": tuple(f"normal_camera.{a}" for a in _AXES), "uv": ("uv.U", "uv.V"), "instance": ("instance.id",),
    "category": ("category.id",), "object_coordinates": tuple(f"object_coordinates.{a}" for a in _AXES),
    "nocs": tuple(f"nocs.{a}" for a in _AXES), "flow": ("flow.X", "flow.Y"),
    "backward_flow": ("backward_flow.X", "backward_flow.Y"), "coverage": ("A",),
}
#: the prefix of each matte array's channels, followed by the entry's number 0 to k - 1
MATTE_CHANNELS = {"matte_ids": "matte.id", "matte_fractions": "matte.fraction"}
_MAGIC = b"\x76\x2f\x31\x01"


def _matte_count(prefix, present):
    """How many channels ``prefix0``, ``prefix1``, ... the file has in a row from 0."""
    k = 0
    while k < MAX_MATTE_K and f"{prefix}{k}" in present:
        k += 1
    return k


def _channels_of(name, present=None, k=None):
    """The channels of array ``name``: `EXR_CHANNELS`'s, or a matte array's ``k`` (given, or as many as ``present``
    holds in a row from 0)."""
    if name in EXR_CHANNELS:
        return EXR_CHANNELS[name]
    prefix = MATTE_CHANNELS[name]
    return tuple(f"{prefix}{j}" for j in range(_matte_count(prefix, present) if k is None else k))


def _openexr(path):
    try:
        import OpenEXR  # noqa: PLC0415 - the optional extra
    except ImportError:
        raise ImportError(f"{path}: OpenEXR files need the optional extra 'exr' (pip install 'glphong[exr]', which "
                          "installs OpenEXR)") from None
    return OpenEXR


def save_exr(path, frame):
    """Write every pass of ``frame`` (and its coverage as alpha) to one OpenEXR file, atomically.

    Parameters
    ----------
    path : path-like
        The file (its folder must exist); replaced whole or left as it was.
    frame : glphong.gpu.frame.Frame
        Each pass in ``frame.passes`` goes to the channels `EXR_CHANNELS` names (module docstring): float32 passes
        as FLOAT, ``instance`` and ``category`` (uint32) as UINT; ``frame.coverage`` as ``A``.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    ImportError
        OpenEXR is not installed (the extra 'exr').
    ValueError
        The frame's arrays are not those of a render (`glphong.datasets.npz.frame_arrays`).
    """
    OpenEXR = _openexr(path)
    channels = {}
    for name, array in frame_arrays(frame).items():
        names = _channels_of(name, k=array.shape[2] if array.ndim == 3 else None)
        planes = [array] if array.ndim == 2 else [array[..., i] for i in range(array.shape[2])]
        channels.update({channel: np.ascontiguousarray(plane) for channel, plane in zip(names, planes)})
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}

    def write(temporary):
        with OpenEXR.File(header, channels) as exr:
            exr.write(temporary)

    return write_atomically(path, write)


def _header(OpenEXR, path, data, limits):
    """``(height, width, channel names)`` from the header, checked before a pixel is decoded."""
    try:
        with OpenEXR.File(io.BytesIO(data), header_only=True) as exr:  # its header is emptied when it closes
            header = exr.header()
            kind = header.get("type")
            window, listed = header.get("dataWindow"), header.get("channels")
            if window is None or listed is None:
                raise SceneFileError(path, "header: no dataWindow or no channels")
            low, high = (np.asarray(corner, np.int64) for corner in window)
            names = [str(c.name) for c in listed]
            sampling = {str(c.name): (int(c.xSampling), int(c.ySampling)) for c in listed}
    except SceneFileError:
        raise
    except Exception as exc:  # OpenEXR raises RuntimeError, ValueError, IndexError ... on a malformed header
        raise SceneFileError(path, f"unreadable OpenEXR header ({type(exc).__name__}: {exc})") from None
    if kind not in (None, OpenEXR.scanlineimage, OpenEXR.tiledimage):  # absent: a flat image
        raise SceneFileError(path, f"header: a {kind} part; expected a flat (scanline or tiled) image")
    width, height = (int(v) for v in high - low + 1)
    if width < 1 or height < 1 or width * height > limits.image_pixels:
        raise SceneFileError(path, f"header: a data window of {width} x {height} pixels; expected 1 to "
                             f"{limits.image_pixels} (glphong.filesafety.Limits.image_pixels)")
    if width * height * len(names) * 8 > limits.decoded_bytes:
        raise SceneFileError(path, f"header: {len(names)} channels of {width} x {height} pixels, more than "
                             f"{limits.decoded_bytes} bytes (glphong.filesafety.Limits.decoded_bytes)")
    ours = [n for group in EXR_CHANNELS.values() for n in group] + [
        n for n in names if any(n.startswith(prefix) for prefix in MATTE_CHANNELS.values())]
    subsampled = [n for n in ours if n in sampling and sampling[n] != (1, 1)]
    if subsampled:
        raise SceneFileError(path, f"header: channels {subsampled} are subsampled; expected one sample per pixel")
    return height, width, set(names)


def load_exr(path, passes=None, limits=None):
    """Read the passes of an OpenEXR file (as `save_exr` names them, `EXR_CHANNELS`): a dict of name to array.

    A name is read where all its channels are in the file (other channels are ignored); one with some of its
    channels only is an error.  Float channels (FLOAT, or HALF widened exactly) give float32, the id channels
    (UINT only) uint32.

    Parameters
    ----------
    path : path-like
    passes : sequence of str, optional
        Names the file must hold (names of `EXR_CHANNELS`); a `SceneFileError` naming their channels otherwise.
    limits : glphong.core.filesafety.Limits, optional
        Default `glphong.core.filesafety.LIMITS`: ``file_bytes`` bounds the file, ``image_pixels`` its data window,
        ``decoded_bytes`` its channels' pixels, all checked before a pixel is decoded.

    Returns
    -------
    dict of str to ndarray
        In `glphong.datasets.npz.LAYOUT`'s order: e.g. ``radiance`` (H, W, 3) float32, ``depth`` (H, W) float32
        [m], ``instance`` (H, W) uint32, ``coverage`` (H, W) float32 (the ``A`` channel).

    Raises
    ------
    ImportError
        OpenEXR is not installed (the extra 'exr').
    SceneFileError
        Missing, not a regular file, too large, not an OpenEXR file, truncated or corrupt, a channel missing or of
        another pixel type (the message names the file and the channel).
    ValueError
        An unknown name in ``passes``.
    """
    limits = limits or LIMITS
    path = Path(path)
    for name in passes or ():
        if name not in LAYOUT:
            raise ValueError(f"unknown name {name!r}; the names are {', '.join(LAYOUT)}")
    OpenEXR = _openexr(path)
    data = read_bytes(path, limits)
    if data[:4] != _MAGIC:
        raise SceneFileError(path, "not an OpenEXR file (its first bytes are not the magic number 76 2f 31 01)")
    height, width, present = _header(OpenEXR, path, data, limits)
    wanted = set(passes or ())
    chosen = []
    groups = {name: _channels_of(name, present) for name in LAYOUT}
    for name, group in groups.items():
        if name in MATTE_CHANNELS and not group:
            if name in wanted:
                raise SceneFileError(path, f"no {name!r}: expected the channels {MATTE_CHANNELS[name]}0 to "
                                     f"{MATTE_CHANNELS[name]}<k-1>; the file has {sorted(present)[:24]}")
            continue
        found = [c for c in group if c in present]
        if found and len(found) < len(group):
            raise SceneFileError(path, f"channels {found} of {name!r} without {[c for c in group if c not in found]}; "
                                 f"expected all of {list(group)}")
        if len(found) == len(group):
            chosen.append(name)
        elif name in wanted:
            raise SceneFileError(path, f"no {name!r}: expected the channels {list(group)}; the file has "
                                 f"{sorted(present)[:24]}")
    if not chosen:
        raise SceneFileError(path, f"no channel glphong knows; the file has {sorted(present)[:24]}")
    try:
        with OpenEXR.File(io.BytesIO(data), separate_channels=True) as exr:
            channels = exr.channels()
            out = {name: _pass(OpenEXR, path, channels, name, groups[name], height, width) for name in chosen}
    except SceneFileError:
        raise
    except Exception as exc:  # OpenEXR's errors on truncated or corrupt pixel data
        raise SceneFileError(path, f"unreadable OpenEXR pixels ({type(exc).__name__}: {exc})") from None
    if ("matte_ids" in out) != ("matte_fractions" in out) or (
            "matte_ids" in out and out["matte_ids"].shape != out["matte_fractions"].shape):
        raise SceneFileError(path, f"channels {', '.join(MATTE_CHANNELS.values())}: expected both, with the same "
                             "number of entries")
    return out


def _pass(OpenEXR, path, channels, name, group, height, width):
    """One name's array from its channels ``group``, each checked for pixel type and size."""
    components, dtype = LAYOUT[name]
    planes = []
    for channel in group:
        if channel not in channels:  # listed in the header, but no pixels read (a truncated file)
            raise SceneFileError(path, f"channel {channel!r}: no pixel data (a truncated or corrupt file)")
        kind = channels[channel].type()
        allowed = (OpenEXR.UINT,) if dtype == np.uint32 else (OpenEXR.FLOAT, OpenEXR.HALF)
        if kind not in allowed:
            raise SceneFileError(path, f"channel {channel!r}: pixel type {kind.name}; expected "
                                 f"{' or '.join(k.name for k in allowed)}")
        pixels = np.asarray(channels[channel].pixels)
        if pixels.shape != (height, width):
            raise SceneFileError(path, f"channel {channel!r}: {pixels.shape} pixels; expected ({height}, {width})")
        planes.append(pixels.astype(dtype, copy=False))
    return np.ascontiguousarray(planes[0] if components is None else np.stack(planes, axis=-1))
