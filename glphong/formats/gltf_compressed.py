"""Compressed glTF data, decoded through optional packages and bounded like every other input (docs/files.md).

- ``EXT_meshopt_compression`` and ``KHR_meshopt_compression``: a buffer view whose bytes are stored compressed
  (modes ATTRIBUTES, TRIANGLES, INDICES; filters OCTAHEDRAL, QUATERNION, EXPONENTIAL and, for the KHR extension,
  COLOR) is decoded by ``meshopt`` (the ``[meshopt]`` extra; meshoptimizer's own C++ decoder, MIT) into the bytes
  its parent view declares, and read from there like any other view.  The JSON is validated first
  (`glphong.formats.gltf_validate`: the extension's rules on ``mode``, ``filter``, ``byteStride`` and ``count``, and
  ``count * byteStride`` equal to the parent view's ``byteLength``), so the decoded size is known and counted
  against ``Limits.decoded_bytes`` before the decoder allocates it; a stream the decoder rejects is a
  `glphong.filesafety.SceneFileError` naming the view.
- ``KHR_texture_basisu``: a KTX2 image with a Basis Universal payload (ETC1S or UASTC LDR) is transcoded to RGBA8
  by ``opengl_basisu`` (the ``[ktx2]`` extra; Binomial's basis_universal transcoder, Apache-2.0).  Its header is
  read here first: the 2D size is checked against ``Limits.image_pixels`` before the transcoder allocates a pixel,
  and cube maps, arrays, 3D textures and HDR payloads are refused by name.  Level 0 is read (glphong builds its own
  mip pyramid); rows run from the top, as glTF's images do.

Without the package, a file that needs it is refused with the ``pip install`` line of its extra.
"""
import struct

import numpy as np

from glphong.core.filesafety import SceneFileError

__all__ = ["MESHOPT", "MESHOPT_FILTERS", "KTX2_IDENTIFIER", "OPTIONAL_DECODERS", "decoder_available",
           "meshopt_extension", "decode_meshopt_view", "decode_ktx2", "draco_primitive"]

#: the two names of the meshopt extension (the KHR one adds the COLOR filter and the v1 attribute stream)
MESHOPT = ("EXT_meshopt_compression", "KHR_meshopt_compression")
#: filters each meshopt extension allows
MESHOPT_FILTERS = {"EXT_meshopt_compression": ("NONE", "OCTAHEDRAL", "QUATERNION", "EXPONENTIAL"),
                   "KHR_meshopt_compression": ("NONE", "OCTAHEDRAL", "QUATERNION", "EXPONENTIAL", "COLOR")}
#: the 12 bytes a KTX2 file starts with
KTX2_IDENTIFIER = b"\xabKTX 20\xbb\r\n\x1a\n"
#: extension -> (module that decodes it, the extra that installs the module)
OPTIONAL_DECODERS = {"KHR_draco_mesh_compression": ("DracoPy", "draco"),
                     "EXT_meshopt_compression": ("meshopt", "meshopt"),
                     "KHR_meshopt_compression": ("meshopt", "meshopt"),
                     "KHR_texture_basisu": ("opengl_basisu", "ktx2")}
_BASIS_MODELS = {163: "ETC1S", 166: "UASTC LDR 4x4"}  # the KTX2 colour models KHR_texture_basisu allows


def decoder_available(extension):
    """Whether the optional module that decodes ``extension`` imports (True for extensions that need none)."""
    if extension not in OPTIONAL_DECODERS:
        return True
    try:
        __import__(OPTIONAL_DECODERS[extension][0])
    except ImportError:
        return False
    return True


def _module(gltf, extension, where):
    """The decoder module of ``extension``, or a `SceneFileError` naming its extra."""
    module, extra = OPTIONAL_DECODERS[extension]
    try:
        return __import__(module)
    except ImportError:
        raise SceneFileError(gltf.path, f"{extension} data: glphong decodes it with the optional {module} package: "
                             f"pip install 'glphong[{extra}]'", where) from None


def meshopt_extension(view):
    """``(extension name, its object)`` of a buffer view compressed by meshopt, or None."""
    extensions = view.get("extensions")
    if isinstance(extensions, dict):
        for name in MESHOPT:
            if name in extensions:
                return name, extensions[name]
    return None


def decode_meshopt_view(gltf, index, name, extension):
    """The decoded bytes of buffer view ``index`` (``count * byteStride`` of them, the parent view's ``byteLength``).

    Parameters
    ----------
    gltf : glphong.formats.gltf_data.GltfFile
    index : int
        The buffer view.
    name : str
        ``EXT_meshopt_compression`` or ``KHR_meshopt_compression``.
    extension : dict
        Its validated object (`glphong.formats.gltf_validate`).

    Returns
    -------
    bytes

    Raises
    ------
    SceneFileError
        The decoder is not installed (naming the extra), the decoded size is beyond ``Limits.decoded_bytes``, or the
        stream is malformed (truncated, of another mode, bytes left over).
    """
    where = f"bufferViews[{index}].extensions.{name}"
    meshopt = _module(gltf, name, where)
    count, stride, mode = extension["count"], extension["byteStride"], extension["mode"]
    gltf.charge(count * stride, where)  # before the decoder allocates its output
    start = extension.get("byteOffset", 0)
    source = bytes(memoryview(gltf.buffer(extension["buffer"]))[start:start + extension["byteLength"]])
    try:
        decoded = meshopt.decode_gltf_buffer(source, count, stride, mode, extension.get("filter", "NONE"))
    except Exception as exc:  # noqa: BLE001 - the decoder reports a malformed stream as ValueError; others alike
        raise SceneFileError(gltf.path, f"a {mode} stream of {len(source)} bytes that does not decode to {count} "
                             f"elements of {stride} bytes ({type(exc).__name__}: {str(exc)[:80]})", where) from None
    decoded = np.ascontiguousarray(decoded)
    if decoded.nbytes != count * stride:
        raise SceneFileError(gltf.path, f"decoded {decoded.nbytes} bytes, expected {count * stride}", where)
    return decoded.astype(decoded.dtype.newbyteorder("<"), copy=False).tobytes()


def draco_primitive(gltf, extension, where):
    """``{attribute name: (n, width) array, 'indices': (T*3,) array}`` of a Draco-compressed primitive."""
    DracoPy = _module(gltf, "KHR_draco_mesh_compression", where)
    view = extension.get("bufferView")
    if isinstance(view, bool) or not isinstance(view, int) or not 0 <= view < len(gltf.document.get("bufferViews", [])):
        raise SceneFileError(gltf.path, f"expected a bufferView index, found {view!r:.40}", f"{where}.bufferView")
    data, _ = gltf.view(view)
    try:
        mesh = DracoPy.decode(bytes(data))
    except Exception as exc:  # noqa: BLE001 - the decoder's own exception types vary by version
        raise SceneFileError(gltf.path, f"Draco data that cannot be decoded ({type(exc).__name__})", where) from None
    gltf.charge(8 * (np.asarray(mesh.faces).size + sum(np.asarray(a["data"]).size for a in mesh.attributes)), where)
    out = {"indices": np.asarray(mesh.faces, dtype=np.int64).reshape(-1)}
    for name, unique_id in extension.get("attributes", {}).items():
        attribute = mesh.get_attribute_by_unique_id(unique_id) if isinstance(unique_id, int) else None
        if attribute is None:
            raise SceneFileError(gltf.path, f"no Draco attribute with id {unique_id!r:.20}", f"{where}.attributes.{name}")
        out[name] = np.asarray(attribute["data"]).reshape(len(mesh.points), -1)
    return out


def _ktx2_header(gltf, payload, where):
    """``(width, height, colour model)`` of a KTX2 file's header, every field glphong relies on checked."""
    if len(payload) < 80 or payload[:12] != KTX2_IDENTIFIER:
        raise SceneFileError(gltf.path, f"expected a KTX2 file (80 bytes of header at least, starting with its "
                             f"identifier), found {len(payload)} bytes starting {bytes(payload[:4])!r}", where)
    (vk_format, _type_size, width, height, depth, layers, faces, levels,
     scheme) = struct.unpack_from("<9I", payload, 12)
    dfd_offset, dfd_length = struct.unpack_from("<II", payload, 48)
    if vk_format != 0:
        raise SceneFileError(gltf.path, f"a KTX2 image of vkFormat {vk_format}: KHR_texture_basisu images hold a "
                             "Basis Universal payload (vkFormat 0, VK_FORMAT_UNDEFINED)", where)
    if depth > 1 or layers > 1 or faces != 1:
        raise SceneFileError(gltf.path, f"a KTX2 image of depth {depth}, {layers} layers and {faces} faces: glTF "
                             "textures are one 2D image (depth 0, 0 or 1 layers, 1 face)", where)
    if width < 1 or height < 1 or levels > 32:
        raise SceneFileError(gltf.path, f"a KTX2 image of {width} x {height} pixels and {levels} levels", where)
    if width * height > gltf.limits.image_pixels:
        raise SceneFileError(gltf.path, f"a {width} x {height} KTX2 image is more than "
                             f"{gltf.limits.image_pixels} pixels (glphong.filesafety.Limits.image_pixels)", where)
    if dfd_length < 16 or dfd_offset + dfd_length > len(payload):
        raise SceneFileError(gltf.path, f"its data format descriptor (bytes {dfd_offset} to "
                             f"{dfd_offset + dfd_length}) lies outside the {len(payload)}-byte file", where)
    model = payload[dfd_offset + 12]
    if model not in _BASIS_MODELS:
        raise SceneFileError(gltf.path, f"a KTX2 image of colour model {model}: KHR_texture_basisu images are ETC1S "
                             "(163) or UASTC LDR 4x4 (166)", where)
    if scheme not in (0, 1, 2):
        raise SceneFileError(gltf.path, f"KTX2 supercompression scheme {scheme}: expected 0 (none), 1 (BasisLZ) or "
                             "2 (Zstandard)", where)
    _ktx2_levels(gltf, payload, width, height, levels, model, scheme, where)
    return width, height, model


def _ktx2_levels(gltf, payload, width, height, levels, model, scheme, where):
    """Check the KTX2 level index (24 bytes a level after the 80-byte header: byteOffset, byteLength,
    uncompressedByteLength, uint64 each) before the transcoder reads it: no more levels than the size has, every level
    inside the file and after the index, and level 0's uncompressed size what a UASTC 4x4 image of this size holds
    (16 bytes a block: the size a Zstandard stream may ask to be inflated to), BasisLZ's 0 as the specification says."""
    count = max(levels, 1)
    if count > max(width, height).bit_length():
        raise SceneFileError(gltf.path, f"{levels} levels for a {width} x {height} KTX2 image (at most "
                             f"{max(width, height).bit_length()})", where)
    end_of_index = 80 + 24 * count
    if end_of_index > len(payload):
        raise SceneFileError(gltf.path, f"its level index ({count} levels, to byte {end_of_index}) lies outside the "
                             f"{len(payload)}-byte file", where)
    for level in range(count):
        offset, length, uncompressed = struct.unpack_from("<3Q", payload, 80 + 24 * level)
        if offset < end_of_index or offset + length > len(payload):
            raise SceneFileError(gltf.path, f"KTX2 level {level} (bytes {offset} to {offset + length}) lies outside "
                                 f"the {len(payload)}-byte file's data after its index", where)
    blocks = -(-width // 4) * -(-height // 4)
    expected = 0 if scheme == 1 else blocks * 16 if model == 166 else None
    _, length, uncompressed = struct.unpack_from("<3Q", payload, 80)
    if expected is not None and uncompressed != expected or scheme == 0 and uncompressed != length:
        raise SceneFileError(gltf.path, f"KTX2 level 0 declares {uncompressed} uncompressed bytes; a "
                             f"{_BASIS_MODELS[model]} {width} x {height} image with supercompression {scheme} has "
                             f"{expected if expected is not None else length}", where)


def decode_ktx2(gltf, payload, where):
    """The level-0 pixels (H, W, 4) uint8 (rgba, top row first) of a ``KHR_texture_basisu`` KTX2 image.

    Parameters
    ----------
    gltf : glphong.formats.gltf_data.GltfFile
    payload : bytes
        The image's bytes.
    where : str
        Its JSON path (for errors).

    Raises
    ------
    SceneFileError
        The transcoder is not installed (naming the extra), a header beyond the limits or of a kind glTF does not
        allow (see `_ktx2_header`), or a payload the transcoder rejects.
    """
    basisu = _module(gltf, "KHR_texture_basisu", where)
    width, height, model = _ktx2_header(gltf, payload, where)
    gltf.charge(width * height * 4 + -(-width // 4) * -(-height // 4) * 16, where)  # the rgba8 image, level 0 inflated
    try:
        texture = basisu.open(bytes(payload))
        if (texture.width, texture.height) != (width, height) or texture.is_video:
            raise ValueError("the transcoder reads another size, or a video")
        image = texture.transcode("rgba8", level=0)
    except (ValueError, IndexError) as exc:  # opengl_basisu.BasisuError is a ValueError
        raise SceneFileError(gltf.path, f"a {_BASIS_MODELS[model]} KTX2 image of {width} x {height} pixels that "
                             f"cannot be transcoded ({type(exc).__name__}: {str(exc)[:80]})", where) from None
    pixels = np.asarray(image.data, dtype=np.uint8)
    if pixels.shape != (height, width, 4):
        raise SceneFileError(gltf.path, f"transcoded to {pixels.shape}, expected ({height}, {width}, 4)", where)
    return pixels
