"""The binary data of a glTF 2.0 file, read exactly and safely: accessors, mesh primitives and images.

`GltfFile` reads a ``.gltf`` or ``.glb`` file (a regular file within `glphong.filesafety.Limits`), parses
its JSON, validates the whole document before any data is touched (`glphong.formats.gltf_validate`), and refuses
the required extensions it cannot honour.  Buffers and images named by ``uri`` are read only from inside
the file's folder (`glphong.filesafety.resolve_reference`; ``allow_outside=True`` lifts that), ``data:``
URIs are decoded from base64, and every byte range is checked before it is read.

`read_gltf_primitives` returns every primitive of every node reachable from the file's scene as a
`glphong.scene.geometry.MeshData` with the file's own arrays: ``POSITION``, ``NORMAL`` (smooth normals where
absent), the ``TEXCOORD_<n>`` its material's textures read (`glphong.formats.gltf_choices`; v flipped once, in
float64, from glTF's top-left origin to glphong's bottom-left), ``TANGENT``, ``COLOR_0`` (linear; normalised
integers scaled to [0, 1]) and the indices, with the material a ``KHR_materials_variants`` variant chooses.
Nothing is merged or reordered, so a file written by `glphong.save_gltf` reads back the very arrays it
holds; only a primitive without ``TANGENT`` whose material reads the tangent frame (a normal texture, anisotropy, a
coat normal texture) gets MikkTSpace tangents from its uvs, as the specification asks (`glphong.scene.mikktspace`),
with a copy of each vertex whose triangles' tangents differ appended.  Triangle strips and fans are triangulated
(strips alternate their winding as the specification says); points and lines are skipped with a warning; sparse
accessors are applied; Draco-compressed primitives and meshopt-compressed buffer views are decoded by optional
packages (`glphong.formats.gltf_compressed`); morph targets and skins are drawn in the rest pose, with one warning.
Images are PNG, JPEG, WebP (``EXT_texture_webp``) or KTX2 (``KHR_texture_basisu``).

Extensions: `REQUIRED_OK` are read; `APPEARANCE_ONLY` cost appearance only and are warned about where required;
any other required extension is refused by name; one a file uses (``extensionsUsed``) that glphong does not apply
(`APPLIED`) is named in a warning.
"""
import base64
import binascii
import functools
import struct
import warnings
from pathlib import Path

import numpy as np
import PIL.features

from glphong.core.filesafety import LIMITS, SceneFileError, decode_image, parse_json, read_bytes, resolve_reference
from glphong.formats.gltf_compressed import (MESHOPT, OPTIONAL_DECODERS, decode_ktx2, decode_meshopt_view,
                                             decoder_available, draco_primitive, meshopt_extension)
from glphong.formats.gltf_choices import (APPEARANCE_ONLY, APPLIED, REQUIRED_OK, check_attribute_type,
                                          material_uv_set, primitive_material, variant_index)
from glphong.formats.gltf_nodes import node_worlds
from glphong.formats.gltf_validate import COMPONENT_BYTES, TYPE_WIDTHS, validate_gltf
from glphong.scene.geometry import MeshData
from glphong.scene.mikktspace import mikktspace_vertices

__all__ = ["GltfFile", "glb_chunks", "node_worlds", "read_accessor", "read_gltf_primitives", "read_gltf_image",
           "texture_sampling", "gl_sampling", "REQUIRED_OK", "APPEARANCE_ONLY", "APPLIED"]

_DTYPES = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
_TRIANGLES, _STRIP, _FAN = 4, 5, 6
_GLB_JSON, _GLB_BIN = 0x4E4F534A, 0x004E4942

#: what each refused extension does, for the message
_REFUSED_WHY = {"EXT_mesh_gpu_instancing": "GPU instancing, which glphong does not expand"}


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
        self._buffers, self._accessors, self._images, self._meshes, self._views = {}, {}, {}, {}, {}
        self._warned = set()
        self._decoded = 0

    def _check_required(self):
        required = self.document.get("extensionsRequired", [])
        for name in required:
            if name in APPEARANCE_ONLY:
                warnings.warn(f"{self.path}: required extension {name} is not implemented by glphong; the file is "
                              "drawn without it (its appearance may differ)", stacklevel=4)
            elif name not in REQUIRED_OK:
                why = _REFUSED_WHY.get(name, "an extension glphong does not implement")
                raise SceneFileError(self.path, f"requires {name}: {why}", "extensionsRequired")
            elif not decoder_available(name):
                module, extra = OPTIONAL_DECODERS[name]
                raise SceneFileError(self.path, f"needs {name}, which glphong decodes with the optional {module}: "
                                     f"pip install 'glphong[{extra}]'", "extensionsRequired")
        ignored = [n for n in self.document.get("extensionsUsed", []) if n not in APPLIED and n not in required]
        if ignored:
            warnings.warn(f"{self.path}: glphong does not apply {', '.join(sorted(set(ignored)))} (extensionsUsed); "
                          "the file is drawn without them (its appearance may differ)", stacklevel=4)

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

    def _meshopt_fallback(self, view):
        """Whether a meshopt-compressed view's parent buffer holds plain data a reader without the decoder may read
        (the extension's rule: a buffer marked ``fallback: true`` holds none)."""
        parent = self.document["buffers"][view["buffer"]]
        marks = parent.get("extensions") if isinstance(parent.get("extensions"), dict) else {}
        return not any(isinstance(marks.get(name), dict) and marks[name].get("fallback") is True for name in MESHOPT)

    def view(self, index):
        """``(bytes, byteStride or None)`` of buffer view ``index`` (its range validated; a meshopt-compressed view
        decoded once, `glphong.formats.gltf_compressed.decode_meshopt_view`)."""
        view = self.document["bufferViews"][index]
        compressed = meshopt_extension(view)
        if compressed is not None and not decoder_available(compressed[0]) and self._meshopt_fallback(view):
            compressed = None  # the parent view's plain data, which a reader without the decoder may read
        if compressed is not None:
            if index not in self._views:
                self._views[index] = decode_meshopt_view(self, index, *compressed)
            return memoryview(self._views[index]), view.get("byteStride")
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
        values = values if values.flags.aligned else values.copy()  # an unaligned accessor (validate_gltf warns)
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


_ATTRIBUTE_TYPES = {"POSITION": ("VEC3",), "NORMAL": ("VEC3",), "TEXCOORD": ("VEC2",), "TANGENT": ("VEC4",),
                    "COLOR_0": ("VEC3", "VEC4")}


def _attribute(gltf, primitive, name, where):
    """The accessor of attribute ``name`` of a primitive (None where absent), its type and component type checked
    (`glphong.formats.gltf_choices.check_attribute_type`)."""
    if name not in primitive["attributes"]:
        return None
    index = primitive["attributes"][name]
    accessor = gltf.document["accessors"][index]
    kinds = _ATTRIBUTE_TYPES["TEXCOORD" if name.startswith("TEXCOORD_") else name]
    if accessor["type"] not in kinds:
        raise SceneFileError(gltf.path, f"{name} must be {' or '.join(kinds)}, found {accessor['type']}",
                             f"{where}.attributes.{name}")
    check_attribute_type(gltf.path, accessor, name, f"{where}.attributes.{name}")
    return read_accessor(gltf, index)


def _primitive_arrays(gltf, primitive, where, uv_set):
    """``(positions, indices or None, other attributes)`` of a primitive, Draco-decoded where it is; its uvs are
    ``TEXCOORD_<uv_set>`` (under the key ``'uv'``)."""
    names = {"NORMAL": "NORMAL", "uv": f"TEXCOORD_{uv_set}", "TANGENT": "TANGENT", "COLOR_0": "COLOR_0"}
    draco = primitive.get("extensions", {}).get("KHR_draco_mesh_compression")
    if draco is not None:
        decoded = draco_primitive(gltf, draco, f"{where}.extensions.KHR_draco_mesh_compression")
        return decoded.get("POSITION"), decoded["indices"], {k: decoded.get(n) for k, n in names.items()}
    positions = _attribute(gltf, primitive, "POSITION", where)
    indices = None
    if "indices" in primitive:
        accessor = gltf.document["accessors"][primitive["indices"]]
        if accessor["type"] != "SCALAR" or accessor["componentType"] not in (5121, 5123, 5125):
            raise SceneFileError(gltf.path, f"indices must be SCALAR unsigned integers, found {accessor['type']} of "
                                 f"componentType {accessor['componentType']}", f"{where}.indices")
        indices = read_accessor(gltf, primitive["indices"]).reshape(-1).astype(np.int64)
    return positions, indices, {k: _attribute(gltf, primitive, n, where) for k, n in names.items()}


def _primitive_mesh(gltf, primitive, where, key, uv_set, mikktspace):
    """The `MeshData` of one primitive, or None (no triangles); made once per file and ``key`` (mesh index,
    primitive index, uv set, whether it takes MikkTSpace tangents), so every node that instances a mesh shares its
    arrays (and the renderer its buffers)."""
    if key not in gltf._meshes:
        gltf._meshes[key] = _new_primitive_mesh(gltf, primitive, where, uv_set, mikktspace)
    return gltf._meshes[key]


#: what `glphong.scene.mikktspace.mikktspace_vertices` holds at its peak per triangle [bytes] (tracemalloc: 970 on an
#: icosphere of 81,920 triangles), charged to ``Limits.decoded_bytes`` before a primitive's tangents are made
MIKKTSPACE_BYTES_PER_TRIANGLE = 1024


def _reads_tangents(entry):
    """Whether a glTF material entry reads the tangent frame: a ``normalTexture``, ``KHR_materials_anisotropy`` or
    ``KHR_materials_clearcoat``'s ``clearcoatNormalTexture``."""
    extensions = entry.get("extensions", {}) if isinstance(entry, dict) else {}
    coat = extensions.get("KHR_materials_clearcoat")
    return isinstance(entry, dict) and ("normalTexture" in entry or "KHR_materials_anisotropy" in extensions
                                        or (isinstance(coat, dict) and "clearcoatNormalTexture" in coat))


def _with_mikktspace(positions, normals, triangles, uvs, colors):
    """The arrays of a primitive without ``TANGENT`` given MikkTSpace tangents from its (glphong, v-up) uvs, as the
    specification asks: ``(positions, normals, triangles, uvs, colors, tangents)``, a vertex split where its
    triangles' tangents differ (`glphong.scene.mikktspace`).  A tangent made of non-finite normals or uvs is 0 (the
    shader's basis around n)."""
    with np.errstate(all="ignore"):
        source, triangles, tangents = mikktspace_vertices(positions, normals, triangles, uvs)
    tangents[~np.all(np.isfinite(tangents), axis=1)] = (0.0, 0.0, 0.0, 1.0)
    return (positions[source], normals[source], triangles, uvs[source], None if colors is None else colors[source],
            tangents)


def _new_primitive_mesh(gltf, primitive, where, uv_set, mikktspace):

    mode = primitive.get("mode", _TRIANGLES)
    if mode not in (_TRIANGLES, _STRIP, _FAN):
        gltf.warn_once("mode", f"primitives of points or lines (e.g. {where}, mode {mode}) have no surface; skipped")
        return None
    if primitive.get("targets"):
        gltf.warn_once("morph", "morph targets are drawn in the rest pose (the base geometry)")
    positions, indices, attributes = _primitive_arrays(gltf, primitive, where, uv_set)
    if positions is None:
        raise SceneFileError(gltf.path, "a primitive without POSITION", f"{where}.attributes")
    positions = positions.astype(np.float64)
    if not np.all(np.isfinite(positions)):
        raise SceneFileError(gltf.path, "POSITION holds NaN or infinite values", f"{where}.attributes.POSITION")
    count = len(positions)
    for name, values in attributes.items():
        if values is not None and len(values) != count:
            name = f"TEXCOORD_{uv_set}" if name == "uv" else name
            raise SceneFileError(gltf.path, f"{name} has {len(values)} elements, POSITION {count}",
                                 f"{where}.attributes.{name}")
    for name in ("TANGENT", "uv", "COLOR_0"):  # NORMAL may hold them: such a vertex is shaded ambient only
        if attributes[name] is not None and not np.all(np.isfinite(attributes[name])):
            name = f"TEXCOORD_{uv_set}" if name == "uv" else name
            raise SceneFileError(gltf.path, f"{name} holds NaN or infinite values", f"{where}.attributes.{name}")
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
    uvs = attributes["uv"]
    if uvs is not None:
        uvs = uvs.astype(np.float64)  # a copy: the accessor's array is shared
        uvs[:, 1] = 1.0 - uvs[:, 1]  # glTF's origin is the image's top-left corner
    colors = attributes["COLOR_0"]
    colors = None if colors is None else np.clip(colors[:, :3], 0.0, 1.0)
    tangents = attributes["TANGENT"]
    if mikktspace and tangents is None and uvs is not None:
        # MikkTSpace's working arrays, counted against the decoded-bytes limit before they are made
        gltf.charge(MIKKTSPACE_BYTES_PER_TRIANGLE * len(triangles), f"{where}.attributes (MikkTSpace tangents)")
        positions, normals, triangles, uvs, colors, tangents = _with_mikktspace(positions, normals, triangles, uvs,
                                                                                colors)
    return MeshData(positions, normals, triangles, uvs=uvs, tangents=tangents, colors=colors)


def read_gltf_primitives(gltf, variant=None):
    """Every primitive with triangles of the nodes of the file's scene.

    Parameters
    ----------
    gltf : GltfFile
    variant : str, optional
        A ``KHR_materials_variants`` variant's name: each primitive gets the material its mappings give that variant
        (`glphong.formats.gltf_choices.primitive_material`).

    Returns
    -------
    list of (name, MeshData, world (4, 4) ndarray, material index or None)
        ``name`` is the node's (``node<i>`` where it has none), with ``.<k>`` for the k-th primitive of a
        mesh of several; a node reached by several paths gives one entry per path (`glphong.formats.gltf_nodes`).
        The mesh's uvs are the ``TEXCOORD_<n>`` its material's textures read
        (`glphong.formats.gltf_choices.material_uv_set`; ``TEXCOORD_0`` without a material or textures).

    Raises
    ------
    ValueError
        ``variant`` is not one of the file's variants (the message lists them).
    """
    document = gltf.document
    chosen = variant_index(document, variant, gltf.path)
    out = []
    worlds = node_worlds(document, gltf.limits)  # one world per path: a shared node is drawn per path
    materials = document.get("materials", [])
    for index, node in enumerate(document.get("nodes", [])):
        if "mesh" not in node or index not in worlds:
            continue
        if "skin" in node:
            gltf.warn_once("skin", "skinned meshes are drawn in their rest pose (no animation is applied)")
        primitives = document["meshes"][node["mesh"]]["primitives"]
        for k, primitive in enumerate(primitives):
            name = node.get("name") if isinstance(node.get("name"), str) and node.get("name") else f"node{index}"
            name = name if len(primitives) == 1 else f"{name}.{k}"
            where = f"meshes[{node['mesh']}].primitives[{k}]"
            material = primitive_material(primitive, chosen)
            uv_set = (material_uv_set(materials[material]) or 0) if material is not None else 0
            mikktspace = material is not None and _reads_tangents(materials[material])
            mesh = _primitive_mesh(gltf, primitive, where, (node["mesh"], k, uv_set, mikktspace), uv_set, mikktspace)
            if mesh is not None and uv_set and mesh.uvs is None:
                gltf.warn_once(("uv set", where), f"{where}: material {material}'s textures read TEXCOORD_{uv_set}, "
                               "which the primitive lacks: drawn without its textures")
            if mesh is not None:
                out.extend((name, mesh, world, material) for world in worlds[index])
    return out


_IMAGE_TYPES = {"image/png": ("PNG",), "image/jpeg": ("JPEG",), "image/webp": ("WEBP",)}
#: a texture's image sources, most preferred first: the extension's (where glphong decodes it), then ``source``
_SOURCES = ("KHR_texture_basisu", "EXT_texture_webp")


@functools.lru_cache(maxsize=None)
def _webp_available():
    """Whether this Pillow decodes WebP (asked once a process)."""
    return bool(PIL.features.check("webp"))


def _texture_source(gltf, index):
    """``(image index, kind)`` of glTF texture ``index``: its ``KHR_texture_basisu`` (kind ``'ktx2'``) or
    ``EXT_texture_webp`` (``'webp'``) image where glphong decodes it, else its ``source`` (``'core'``: PNG or JPEG),
    or None where none of these is there."""
    texture = gltf.document["textures"][index]
    for name in _SOURCES:
        extension = texture.get("extensions", {}).get(name)
        if extension is None:
            continue
        ktx2 = name == "KHR_texture_basisu"
        if decoder_available(name) if ktx2 else _webp_available():
            return extension["source"], "ktx2" if ktx2 else "webp"
        how = f"the optional {OPTIONAL_DECODERS[name][0]}: pip install 'glphong[{OPTIONAL_DECODERS[name][1]}]'" if ktx2 \
            else "Pillow, which was built without WebP here (Pillow's own wheels include it)"
        if "source" not in texture:
            raise SceneFileError(gltf.path, f"a {name} texture without a PNG or JPEG fallback: glphong decodes it with "
                                 f"{how}", f"textures[{index}]")
        gltf.warn_once(("fallback", name), f"{name} textures are drawn from their PNG or JPEG fallback (glphong "
                       f"decodes {name} with {how})")
    return (texture["source"], "core") if "source" in texture else None


def read_gltf_image(gltf, index):
    """The pixels (H, W, 4) uint8 (rgba) of glTF texture ``index``, or None where the texture names no image (warned
    once).

    The image is the texture's ``KHR_texture_basisu`` KTX2 image (transcoded, `glphong.formats.gltf_compressed`) or
    ``EXT_texture_webp`` WebP image where the file has one, else its ``source`` (PNG or JPEG).  It comes from a buffer
    view, a base64 data URI, or a file inside the document's folder; its size is checked against
    ``Limits.image_pixels`` before it is decoded, once per file.
    """
    chosen = _texture_source(gltf, index)
    if chosen is None:
        gltf.warn_once("texture source", f"texture {index} names no image glphong decodes; drawn without it")
        return None
    if chosen not in gltf._images:
        gltf._images[chosen] = _decode_gltf_image(gltf, *chosen)
    return gltf._images[chosen]


def _decode_gltf_image(gltf, source, kind):
    """The pixels of image ``source`` (see `read_gltf_image`) as ``kind`` ('core', 'webp' or 'ktx2'), counted against
    ``Limits.decoded_bytes`` at the size of the float64 mip pyramid a texture builds from them (4/3 of the base
    level)."""
    where = f"images[{source}]"
    image = gltf.document["images"][source]
    if "bufferView" in image:
        mime = image.get("mimeType")
        expected = {"core": ("image/png", "image/jpeg"), "webp": ("image/webp",), "ktx2": ("image/ktx2",)}[kind]
        if mime not in expected:
            raise SceneFileError(gltf.path, f"mimeType {mime!r:.40}: expected {' or '.join(expected)}",
                                 f"{where}.mimeType")
        payload = bytes(gltf.view(image["bufferView"])[0])
    elif image["uri"].startswith("data:"):
        payload = _data_uri(gltf.path, image["uri"], f"{where}.uri")
    else:
        target = resolve_reference(gltf.path, image["uri"], f"{where}.uri", gltf.allow_outside)
        payload = read_bytes(target, gltf.limits, gltf.path, f"{where}.uri")
    if kind == "ktx2":
        pixels = decode_ktx2(gltf, payload, where)
    else:
        formats = _IMAGE_TYPES["image/webp"] if kind == "webp" else _IMAGE_TYPES["image/png"] + _IMAGE_TYPES["image/jpeg"]
        pixels = decode_image(payload, gltf.limits, gltf.path, where, formats=formats, mode="RGBA")  # alpha: a mask's
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