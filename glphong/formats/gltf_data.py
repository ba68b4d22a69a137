"""The binary data of a glTF 2.0 file, read exactly and safely: accessors, mesh primitives and images.

`GltfFile` reads a ``.gltf`` or ``.glb`` file (a regular file within `glphong.filesafety.Limits`), parses
its JSON, validates the whole document before any data is touched (`glphong.formats.gltf_validate`), and refuses
the required extensions it cannot honour.  Buffers and images named by ``uri`` are read only from inside
the file's folder (`glphong.filesafety.resolve_reference`; ``allow_outside=True`` lifts that), ``data:``
URIs are decoded from base64, and every byte range is checked before it is read.

`read_gltf_primitives` returns every primitive of every node reachable from the file's scene as a
`glphong.scene.geometry.MeshData` with the file's own arrays: ``POSITION``, ``NORMAL`` (smooth normals where
absent), ``TEXCOORD_0`` (v flipped once, in float64, from glTF's top-left origin to glphong's
bottom-left), ``TANGENT``, ``COLOR_0`` (linear; normalised integers scaled to [0, 1]) and the indices.
Nothing is merged or reordered, so a file written by `glphong.save_gltf` reads back the very arrays it
holds.  Triangle strips and fans are triangulated (strips alternate their winding as the specification
says); points and lines are skipped with a warning; sparse accessors are applied; Draco-compressed
primitives (``KHR_draco_mesh_compression``) are decoded by ``DracoPy`` (the ``[draco]`` extra); morph
targets and skins are drawn in the rest pose, with one warning.

Extensions (``extensionsRequired``): `REQUIRED_OK` are read; `APPEARANCE_ONLY` cost appearance only
and are warned about; any other required extension (``EXT_meshopt_compression`` among them) is refused
by name.
"""
import base64
import binascii
import struct
import warnings
from pathlib import Path

import numpy as np

from glphong.core.filesafety import LIMITS, SceneFileError, decode_image, parse_json, read_bytes, resolve_reference
from glphong.formats.gltf_validate import COMPONENT_BYTES, TYPE_WIDTHS, validate_gltf
from glphong.scene.geometry import MeshData

__all__ = ["GltfFile", "glb_chunks", "node_matrices", "read_accessor", "read_gltf_primitives", "read_gltf_image",
           "texture_sampling", "gl_sampling", "REQUIRED_OK", "APPEARANCE_ONLY"]

_DTYPES = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
_TRIANGLES, _STRIP, _FAN = 4, 5, 6
_GLB_JSON, _GLB_BIN = 0x4E4F534A, 0x004E4942

#: required extensions glphong reads (Draco needs the ``[draco]`` extra)
REQUIRED_OK = ("KHR_lights_punctual", "KHR_mesh_quantization", "KHR_draco_mesh_compression",
               "KHR_materials_emissive_strength")
#: required extensions whose loss changes appearance only: read without them, with a warning
APPEARANCE_ONLY = ("KHR_texture_transform", "KHR_texture_basisu", "EXT_texture_webp", "EXT_texture_avif",
                   "KHR_materials_ior", "KHR_materials_specular", "KHR_materials_transmission", "KHR_materials_volume",
                   "KHR_materials_clearcoat", "KHR_materials_sheen", "KHR_materials_unlit", "KHR_materials_iridescence",
                   "KHR_materials_anisotropy", "KHR_materials_dispersion", "KHR_materials_variants",
                   "KHR_materials_pbrSpecularGlossiness")
#: what each refused extension does, for the message
_REFUSED_WHY = {"EXT_meshopt_compression": "meshopt-compressed buffers, which glphong does not decode (decompress the "
                "file first, for example with gltf-transform or gltfpack)",
                "KHR_meshopt_compression": "meshopt-compressed buffers, which glphong does not decode",
                "EXT_mesh_gpu_instancing": "GPU instancing, which glphong does not expand"}


def glb_chunks(path, data):
    """``(json bytes, binary bytes or None)`` of a ``.glb`` file's contents, every length checked.

    Raises
    ------
    SceneFileError
        A truncated header or chunk, a version other than 2, a first chunk that is not JSON.
    """
    if len(data) < 20:
        raise SceneFileError(path, f"a truncated glTF binary ({len(data)} bytes; the header needs 20)")
    magic, version, total = struct.unpack_from("<4sII", data, 0)
    if version == 1:
        raise SceneFileError(path, "a glTF 1.0 binary: glphong reads glTF 2.0; convert it first (for example with "
                             "the Khronos glTF-Pipeline or Blender)", "header")
    if version != 2:
        raise SceneFileError(path, f"a glTF binary of version {version}: glphong reads version 2", "header")
    if total > len(data):
        raise SceneFileError(path, f"the header says {total} bytes, the file has {len(data)} (truncated)", "header")
    length, kind = struct.unpack_from("<II", data, 12)
    if kind != _GLB_JSON:
        raise SceneFileError(path, "the first chunk of a glTF binary must be JSON", "chunk 0")
    start = 20 + length
    if start > total:
        raise SceneFileError(path, f"the JSON chunk of {length} bytes runs past the end of the file", "chunk 0")
    binary = None
    if total >= start + 8:
        size, kind = struct.unpack_from("<II", data, start)
        if kind == _GLB_BIN:
            if start + 8 + size > total:
                raise SceneFileError(path, f"the binary chunk of {size} bytes runs past the end of the file", "chunk 1")
            binary = data[start + 8:start + 8 + size]
    return data[20:start], binary


def _draco_available():
    try:
        import DracoPy  # noqa: F401 - optional dependency, probed only
    except ImportError:
        return False
    return True


class GltfFile:
    """A glTF 2.0 file, read and validated.

    Parameters
    ----------
    path : path-like
        A ``.gltf`` or ``.glb`` file.
    limits : glphong.filesafety.Limits, optional
    allow_outside : bool
        Read buffers and images named by ``uri`` outside the file's folder too.

    Attributes
    ----------
    path : pathlib.Path
    document : dict
        The validated JSON.
    binary : bytes or None
        A ``.glb``'s binary chunk.

    Raises
    ------
    SceneFileError
        Anything wrong with the file (`glphong.formats.gltf_validate`), or a required extension glphong cannot
        honour (named).
    """

    def __init__(self, path, limits=None, allow_outside=False):
        self.path, self.limits, self.allow_outside = Path(path), limits or LIMITS, allow_outside
        data = read_bytes(self.path, self.limits)
        self.binary = None
        if data[:4] == b"glTF":
            data, self.binary = glb_chunks(self.path, data)
        self.document = parse_json(self.path, data, "a glTF document")
        validate_gltf(self.path, self.document, self.limits)
        self._check_required()
        self._buffers, self._accessors, self._images, self._meshes = {}, {}, {}, {}
        self._warned = set()
        self._decoded = 0

    def _check_required(self):
        for name in self.document.get("extensionsRequired", []):
            if name in APPEARANCE_ONLY:
                warnings.warn(f"{self.path}: required extension {name} is not implemented by glphong; the file is "
                              "drawn without it (its appearance may differ)", stacklevel=4)
            elif name == "KHR_draco_mesh_compression" and not _draco_available():
                raise SceneFileError(self.path, "needs KHR_draco_mesh_compression, which glphong decodes with the "
                                     "optional DracoPy: pip install 'glphong[draco]'", "extensionsRequired")
            elif name not in REQUIRED_OK:
                why = _REFUSED_WHY.get(name, "an extension glphong does not implement")
                raise SceneFileError(self.path, f"requires {name}: {why}", "extensionsRequired")

    def warn_once(self, topic, message):
        """Warn ``message`` once per file and ``topic``."""
        if topic not in self._warned:
            self._warned.add(topic)
            warnings.warn(f"{self.path}: {message}", stacklevel=4)

    def charge(self, nbytes, where):
        """Count ``nbytes`` of decoded data against ``Limits.decoded_bytes`` before it is made."""
        self._decoded += int(nbytes)
        if self._decoded > self.limits.decoded_bytes:
            raise SceneFileError(self.path, f"decoding it would take more than {self.limits.decoded_bytes} bytes "
                                 "(glphong.filesafety.Limits.decoded_bytes)", where)

    def buffer(self, index):
        """Buffer ``index``'s bytes (at least its ``byteLength``), read once."""
        if index not in self._buffers:
            entry = self.document["buffers"][index]
            where = f"buffers[{index}]"
            uri = entry.get("uri")
            if uri is None:
                if index != 0 or self.binary is None:
                    raise SceneFileError(self.path, "a buffer without a uri must be the first buffer of a .glb with a "
                                         "binary chunk", where)
                blob = self.binary
            elif uri.startswith("data:"):
                blob = _data_uri(self.path, uri, f"{where}.uri")
            else:
                target = resolve_reference(self.path, uri, f"{where}.uri", self.allow_outside)
                blob = read_bytes(target, self.limits, self.path, f"{where}.uri")
            if len(blob) < entry["byteLength"]:
                raise SceneFileError(self.path, f"{len(blob)} bytes of data, the buffer declares {entry['byteLength']}",
                                     where)
            self._buffers[index] = blob
        return self._buffers[index]

    def view(self, index):
        """``(bytes, byteStride or None)`` of buffer view ``index`` (its range validated)."""
        view = self.document["bufferViews"][index]
        start = view.get("byteOffset", 0)
        return memoryview(self.buffer(view["buffer"]))[start:start + view["byteLength"]], view.get("byteStride")


def _data_uri(path, uri, where):
    """The bytes of a base64 ``data:`` URI."""
    head, _, payload = uri.partition(",")
    if not head.endswith(";base64"):
        raise SceneFileError(path, "a data: URI that is not base64 (glphong reads data:...;base64,...)", where)
    try:
        return base64.b64decode(payload, validate=True)
    except (binascii.Error, ValueError):
        raise SceneFileError(path, "a data: URI whose base64 payload is damaged", where) from None


def _strided(gltf, data, offset, count, element, stride, where):
    """(count, element) uint8 rows of ``data`` from ``offset`` every ``stride`` bytes, bounds checked."""
    end = offset + stride * (count - 1) + element
    if offset < 0 or stride < element or end > len(data):
        raise SceneFileError(gltf.path, f"elements end at byte {end} of a {len(data)}-byte view", where)
    raw = np.frombuffer(data, np.uint8, count=end - offset, offset=offset)
    return np.lib.stride_tricks.as_strided(raw, (count, element), (stride, 1), writeable=False)


def read_accessor(gltf, index):
    """Accessor ``index`` as a (count, width) read-only array of its component type (normalised integers as
    float64 in [0, 1] or [-1, 1]; sparse substitutions applied), decoded once per file and counted against
    ``Limits.decoded_bytes``.

    Raises
    ------
    SceneFileError
        A matrix accessor with padded columns (glphong reads none).
    """
    if index in gltf._accessors:
        return gltf._accessors[index]
    accessor = gltf.document["accessors"][index]
    where = f"accessors[{index}]"
    component, kind, count = accessor["componentType"], accessor["type"], accessor["count"]
    dtype = np.dtype(_DTYPES[component]).newbyteorder("<")
    width = TYPE_WIDTHS[kind]
    if kind in ("MAT2", "MAT3") and COMPONENT_BYTES[component] < 4:
        raise SceneFileError(gltf.path, "a padded-column matrix accessor, which glphong does not read", where)
    gltf.charge(count * width * 8, where)  # at its widest: float64 (normalised, or as the mesh converts it)
    row = dtype.itemsize * width
    if "bufferView" in accessor:
        data, stride = gltf.view(accessor["bufferView"])
        rows = _strided(gltf, data, accessor.get("byteOffset", 0), count, row, stride or row, where)
        values = np.ascontiguousarray(rows).view(dtype).reshape(count, width)
    else:
        values = np.zeros((count, width), dtype)
    if "sparse" in accessor:
        values = _apply_sparse(gltf, accessor["sparse"], values, dtype, width, f"{where}.sparse")
    if accessor.get("normalized") and dtype.kind in "ui":
        values = np.maximum(values / float(np.iinfo(dtype).max), -1.0)
    values.flags.writeable = False  # shared by every primitive that names the accessor
    gltf._accessors[index] = values
    return values


def _apply_sparse(gltf, sparse, values, dtype, width, where):
    n = sparse["count"]
    spec = sparse["indices"]
    index_dtype = np.dtype(_DTYPES[spec["componentType"]]).newbyteorder("<")
    data, _ = gltf.view(spec["bufferView"])
    rows = _strided(gltf, data, spec.get("byteOffset", 0), n, index_dtype.itemsize, index_dtype.itemsize, where)
    indices = np.ascontiguousarray(rows).view(index_dtype).reshape(n).astype(np.int64)
    if indices.max() >= len(values):
        raise SceneFileError(gltf.path, f"index {int(indices.max())} is beyond the accessor's {len(values)} elements",
                             f"{where}.indices")
    spec = sparse["values"]
    row = dtype.itemsize * width
    data, _ = gltf.view(spec["bufferView"])
    rows = _strided(gltf, data, spec.get("byteOffset", 0), n, row, row, f"{where}.values")
    values = values.copy()
    values[indices] = np.ascontiguousarray(rows).view(dtype).reshape(n, width)
    return values


def _local_matrix(node):
    if "matrix" in node:
        return np.asarray(node["matrix"], dtype=np.float64).reshape(4, 4).T  # column-major in glTF
    t = np.asarray(node.get("translation", (0.0, 0.0, 0.0)), dtype=np.float64)
    x, y, z, w = node.get("rotation", (0.0, 0.0, 0.0, 1.0))
    r = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                  [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                  [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])
    m = np.eye(4)
    m[:3, :3] = r * np.asarray(node.get("scale", (1.0, 1.0, 1.0)), dtype=np.float64)
    m[:3, 3] = t
    return m


def node_matrices(document):
    """World matrices of every node reachable from the default scene, by node index.

    The hierarchy is walked iteratively (a legal chain thousands of nodes deep loads); the document is
    validated (`glphong.formats.gltf_validate`), so it is a forest and each node is reached once.  Without a
    ``scenes`` array, every node without a parent is a root.
    """
    nodes = document.get("nodes", [])
    scenes = document.get("scenes")
    if scenes:
        roots = scenes[document.get("scene", 0)].get("nodes", [])
    else:
        children = {c for node in nodes for c in node.get("children", [])}
        roots = [k for k in range(len(nodes)) if k not in children]
    out = {}
    stack = [(root, np.eye(4)) for root in reversed(roots)]
    while stack:
        index, parent = stack.pop()
        if index in out:  # unreachable for a validated document; kept so a walk can never loop
            raise SceneFileError("(glTF document)", f"node {index} is reached twice", f"nodes[{index}]")
        world = parent @ _local_matrix(nodes[index])
        out[index] = world
        stack.extend((child, world) for child in reversed(nodes[index].get("children", [])))
    return out


def _triangles(gltf, mode, indices, where):
    """(T, 3) int64 triangles of a primitive's index list (or vertex order) in ``mode``."""
    if mode == _TRIANGLES:
        if len(indices) % 3:
            gltf.warn_once(("count", where), f"{where}: {len(indices)} indices is not a multiple of 3; the last "
                           f"{len(indices) % 3} are ignored")
        return indices[:len(indices) // 3 * 3].reshape(-1, 3)
    if len(indices) < 3:
        return np.zeros((0, 3), np.int64)
    k = np.arange(len(indices) - 2)
    if mode == _STRIP:  # triangle k is (k, k+1, k+2) for even k and (k+1, k, k+2) for odd k (winding kept)
        odd = k % 2 == 1
        first, second = np.where(odd, k + 1, k), np.where(odd, k, k + 1)
        return np.stack([indices[first], indices[second], indices[k + 2]], axis=1)
    return np.stack([np.full_like(k, indices[0]), indices[k + 1], indices[k + 2]], axis=1)  # a fan


def _draco_primitive(gltf, extension, where):
    """``{attribute name: (n, width) array, 'indices': (T*3,) array}`` of a Draco-compressed primitive."""
    try:
        import DracoPy
    except ImportError:
        raise SceneFileError(gltf.path, "a Draco-compressed primitive: glphong decodes it with the optional DracoPy: "
                             "pip install 'glphong[draco]'", where) from None
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


_ATTRIBUTE_TYPES = {"POSITION": ("VEC3",), "NORMAL": ("VEC3",), "TEXCOORD_0": ("VEC2",), "TANGENT": ("VEC4",),
                    "COLOR_0": ("VEC3", "VEC4")}


def _attribute(gltf, primitive, name, where):
    """The accessor of attribute ``name`` of a primitive (None where absent), its type checked."""
    if name not in primitive["attributes"]:
        return None
    index = primitive["attributes"][name]
    kind = gltf.document["accessors"][index]["type"]
    if kind not in _ATTRIBUTE_TYPES[name]:
        raise SceneFileError(gltf.path, f"{name} must be {' or '.join(_ATTRIBUTE_TYPES[name])}, found {kind}",
                             f"{where}.attributes.{name}")
    return read_accessor(gltf, index)


def _primitive_arrays(gltf, primitive, where):
    """``(positions, indices or None, other attributes)`` of a primitive, Draco-decoded where it is."""
    draco = primitive.get("extensions", {}).get("KHR_draco_mesh_compression")
    if draco is not None:
        decoded = _draco_primitive(gltf, draco, f"{where}.extensions.KHR_draco_mesh_compression")
        get = decoded.get
        return get("POSITION"), decoded["indices"], {k: get(k) for k in _ATTRIBUTE_TYPES if k != "POSITION"}
    positions = _attribute(gltf, primitive, "POSITION", where)
    indices = None
    if "indices" in primitive:
        accessor = gltf.document["accessors"][primitive["indices"]]
        if accessor["type"] != "SCALAR" or accessor["componentType"] not in (5121, 5123, 5125):
            raise SceneFileError(gltf.path, f"indices must be SCALAR unsigned integers, found {accessor['type']} of "
                                 f"componentType {accessor['componentType']}", f"{where}.indices")
        indices = read_accessor(gltf, primitive["indices"]).reshape(-1).astype(np.int64)
    return positions, indices, {k: _attribute(gltf, primitive, k, where) for k in _ATTRIBUTE_TYPES if k != "POSITION"}


def _primitive_mesh(gltf, primitive, where, key):
    """The `MeshData` of one primitive, or None (no triangles); made once per file and ``key`` (mesh index,
    primitive index), so every node that instances a mesh shares its arrays (and the renderer its buffers)."""
    if key not in gltf._meshes:
        gltf._meshes[key] = _new_primitive_mesh(gltf, primitive, where)
    return gltf._meshes[key]


def _new_primitive_mesh(gltf, primitive, where):

    mode = primitive.get("mode", _TRIANGLES)
    if mode not in (_TRIANGLES, _STRIP, _FAN):
        gltf.warn_once("mode", f"primitives of points or lines (e.g. {where}, mode {mode}) have no surface; skipped")
        return None
    if primitive.get("targets"):
        gltf.warn_once("morph", "morph targets are drawn in the rest pose (the base geometry)")
    positions, indices, attributes = _primitive_arrays(gltf, primitive, where)
    if positions is None:
        raise SceneFileError(gltf.path, "a primitive without POSITION", f"{where}.attributes")
    positions = positions.astype(np.float64)
    if not np.all(np.isfinite(positions)):
        raise SceneFileError(gltf.path, "POSITION holds NaN or infinite values", f"{where}.attributes.POSITION")
    count = len(positions)
    for name, values in attributes.items():
        if values is not None and len(values) != count:
            raise SceneFileError(gltf.path, f"{name} has {len(values)} elements, POSITION {count}",
                                 f"{where}.attributes.{name}")
    indices = np.arange(count, dtype=np.int64) if indices is None else indices
    if len(indices) and int(indices.max()) >= count:
        raise SceneFileError(gltf.path, f"index {int(indices.max())} is beyond the {count} vertices", f"{where}.indices")
    triangles = _triangles(gltf, mode, indices, where)
    if len(triangles) == 0:
        return None
    normals = attributes["NORMAL"]
    if normals is None:
        import trimesh

        normals = trimesh.Trimesh(positions, triangles, process=False).vertex_normals
    uvs = attributes["TEXCOORD_0"]
    if uvs is not None:
        uvs = uvs.astype(np.float64)  # a copy: the accessor's array is shared
        uvs[:, 1] = 1.0 - uvs[:, 1]  # glTF's origin is the image's top-left corner
    colors = attributes["COLOR_0"]
    return MeshData(positions, normals, triangles, uvs=uvs, tangents=attributes["TANGENT"],
                    colors=None if colors is None else np.clip(colors[:, :3], 0.0, 1.0))


def read_gltf_primitives(gltf):
    """Every primitive with triangles of the nodes of the file's scene.

    Parameters
    ----------
    gltf : GltfFile

    Returns
    -------
    list of (name, MeshData, world (4, 4) ndarray, material index or None)
        ``name`` is the node's (``node<i>`` where it has none), with ``.<k>`` for the k-th primitive of a
        mesh of several.
    """
    document = gltf.document
    out = []
    worlds = node_matrices(document)
    for index, node in enumerate(document.get("nodes", [])):
        if "mesh" not in node or index not in worlds:
            continue
        if "skin" in node:
            gltf.warn_once("skin", "skinned meshes are drawn in their rest pose (no animation is applied)")
        primitives = document["meshes"][node["mesh"]]["primitives"]
        for k, primitive in enumerate(primitives):
            name = node.get("name") if isinstance(node.get("name"), str) and node.get("name") else f"node{index}"
            name = name if len(primitives) == 1 else f"{name}.{k}"
            mesh = _primitive_mesh(gltf, primitive, f"meshes[{node['mesh']}].primitives[{k}]", (node["mesh"], k))
            if mesh is not None:
                out.append((name, mesh, worlds[index], primitive.get("material")))
    return out


_IMAGE_TYPES = {"image/png": "PNG", "image/jpeg": "JPEG"}


def read_gltf_image(gltf, index):
    """The pixels (H, W, 4) uint8 (rgba) of glTF texture ``index``, or None where the texture has no
    image glphong decodes (a KTX2 or WebP source only; warned once).

    The image comes from a buffer view, a base64 data URI, or a file inside the document's folder; it is
    decoded as PNG or JPEG only, after its size was checked against ``Limits.image_pixels``, once per file.
    """
    texture = gltf.document["textures"][index]
    if "source" not in texture:
        gltf.warn_once("texture source", f"texture {index} has no PNG or JPEG source (only an extension's); drawn "
                       "without it")
        return None
    if texture["source"] not in gltf._images:
        gltf._images[texture["source"]] = _decode_gltf_image(gltf, texture["source"])
    return gltf._images[texture["source"]]


def _decode_gltf_image(gltf, source):
    """The pixels of image ``source`` (see `read_gltf_image`), counted against ``Limits.decoded_bytes`` at the
    size of the float64 mip pyramid a texture builds from them (4/3 of the base level)."""
    where = f"images[{source}]"
    image = gltf.document["images"][source]
    if "bufferView" in image:
        mime = image.get("mimeType")
        if mime not in _IMAGE_TYPES:
            raise SceneFileError(gltf.path, f"mimeType {mime!r:.40}: glphong decodes image/png and image/jpeg",
                                 f"{where}.mimeType")
        payload = bytes(gltf.view(image["bufferView"])[0])
    elif image["uri"].startswith("data:"):
        payload = _data_uri(gltf.path, image["uri"], f"{where}.uri")
    else:
        target = resolve_reference(gltf.path, image["uri"], f"{where}.uri", gltf.allow_outside)
        payload = read_bytes(target, gltf.limits, gltf.path, f"{where}.uri")
    pixels = decode_image(payload, gltf.limits, gltf.path, where, mode="RGBA")  # alpha: an alpha mask's
    gltf.charge(pixels.size * 8 * 4 // 3, where)
    pixels.flags.writeable = False  # shared by every texture that names the image
    return pixels


def texture_sampling(document, index):
    """``(wrap, filter)`` of glTF texture ``index``: its sampler's ``wrapS`` and ``minFilter`` (`gl_sampling`)."""
    sampler = document.get("samplers", [])[document["textures"][index]["sampler"]] \
        if "sampler" in document["textures"][index] else {}
    return gl_sampling(sampler.get("wrapS"), sampler.get("minFilter"))


def gl_sampling(wrap_s, min_filter):
    """``(wrap, filter)`` of a glTF or pyrender sampler's GL ``wrapS`` and ``minFilter`` (None: the glTF defaults):
    10497 'repeat', 33071 'clamp' (mirrored repeat, 33648, is read as repeat, with a warning); a mipmapped or absent
    minification filter 'trilinear', 9728/9729 'bilinear'."""
    wrap_s = 10497 if wrap_s is None else int(wrap_s)
    wrap = {10497: "repeat", 33071: "clamp", 33648: "repeat"}.get(wrap_s, "repeat")
    if wrap_s == 33648:
        warnings.warn("a glTF sampler's MIRRORED_REPEAT is read as REPEAT (glphong has repeat and clamp)", stacklevel=3)
    return wrap, "bilinear" if min_filter in (9728, 9729) else "trilinear"