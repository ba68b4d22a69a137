"""The binary data of a glTF 2.0 file, read exactly: accessors, mesh primitives and images.

`read_gltf_primitives` returns every triangle primitive of every node reachable from the file's scene
as a `glphong.geometry.MeshData` with the file's own arrays: ``POSITION``, ``NORMAL`` (smooth normals
where absent), ``TEXCOORD_0`` (v flipped once, in float64, from glTF's top-left origin to glphong's
bottom-left), ``TANGENT``, ``COLOR_0`` (linear; normalised integers scaled to [0, 1]) and the indices.
Nothing is merged or reordered, so a file written by `glphong.save_gltf` reads back the very arrays it
holds.  Sparse accessors and primitives other than triangles are refused or skipped, saying so.
"""
import base64
import struct
import warnings
from io import BytesIO
from pathlib import Path

import numpy as np

__all__ = ["glb_chunks", "node_matrices", "read_accessor", "read_gltf_primitives", "read_gltf_image", "texture_sampling"]

_COMPONENTS = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
_WIDTHS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
_TRIANGLES = 4


def glb_chunks(path, data):
    """``(json bytes, binary bytes or None)`` of a ``.glb`` file's contents."""
    if len(data) < 20:
        raise ValueError(f"{path}: truncated glTF binary ({len(data)} bytes)")
    length, kind = struct.unpack_from("<II", data, 12)
    if kind != 0x4E4F534A:  # 'JSON'
        raise ValueError(f"{path}: the first chunk of a glTF binary must be JSON")
    start = 20 + length
    binary = None
    if len(data) >= start + 8:
        size, kind = struct.unpack_from("<II", data, start)
        binary = data[start + 8:start + 8 + size] if kind == 0x004E4942 else None  # 'BIN'
    return data[20:start], binary


class _Buffers:
    """The file's buffers, read once each."""

    def __init__(self, path, document):
        self.path, self.document, self._cache = Path(path), document, {}

    def buffer(self, index):
        if index not in self._cache:
            uri = self.document["buffers"][index].get("uri")
            if uri is None:
                blob = glb_chunks(self.path, self.path.read_bytes())[1]
                if blob is None:
                    raise ValueError(f"{self.path}: buffer {index} has no uri and the file has no binary chunk")
            elif uri.startswith("data:"):
                blob = base64.b64decode(uri.split(",", 1)[1])
            else:
                blob = (self.path.parent / uri).read_bytes()
            self._cache[index] = blob
        return self._cache[index]

    def view(self, index):
        view = self.document["bufferViews"][index]
        start = view.get("byteOffset", 0)
        return self.buffer(view["buffer"])[start:start + view["byteLength"]], view.get("byteStride")


def read_accessor(buffers, index):
    """Accessor ``index`` as an (count, width) array of its component type (normalised integers as float64
    in [0, 1] or [-1, 1])."""
    accessor = buffers.document["accessors"][index]
    if "sparse" in accessor:
        raise ValueError(f"{buffers.path}: accessor {index} is sparse, which glphong does not read")
    dtype = np.dtype(_COMPONENTS[accessor["componentType"]]).newbyteorder("<")
    width, count = _WIDTHS[accessor["type"]], accessor["count"]
    data, stride = buffers.view(accessor["bufferView"])
    offset = accessor.get("byteOffset", 0)
    row = dtype.itemsize * width
    stride = stride or row
    raw = np.frombuffer(data, np.uint8, count=(count - 1) * stride + row, offset=offset) if count else np.zeros(0, np.uint8)
    rows = np.lib.stride_tricks.as_strided(raw, (count, row), (stride, 1)) if count else raw.reshape(0, row)
    values = np.ascontiguousarray(rows).view(dtype).reshape(count, width)
    if accessor.get("normalized") and dtype.kind in "ui":
        values = np.maximum(values / float(np.iinfo(dtype).max), -1.0)
    return values


def node_matrices(document):
    """World matrices of every node reachable from the default scene, by node index."""
    nodes = document.get("nodes", [])

    def local(node):
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

    out = {}

    def walk(index, parent):
        world = parent @ local(nodes[index])
        out[index] = world
        for child in nodes[index].get("children", []):
            walk(child, world)

    scenes = document.get("scenes", [{"nodes": list(range(len(nodes)))}])
    for root in scenes[document.get("scene", 0)].get("nodes", []):
        walk(root, np.eye(4))
    return out


def read_gltf_primitives(path, document):
    """Every triangle primitive of the nodes of the file's scene.

    Returns
    -------
    list of (name, MeshData, world (4, 4) ndarray, material index or None)
        ``name`` is the node's (``node<i>`` where it has none), with ``.<k>`` for the k-th primitive of a
        mesh of several.
    """
    from .geometry import MeshData
    buffers = _Buffers(path, document)
    out = []
    worlds = node_matrices(document)
    for index, node in enumerate(document.get("nodes", [])):
        if "mesh" not in node or index not in worlds:
            continue
        primitives = document["meshes"][node["mesh"]].get("primitives", [])
        for k, primitive in enumerate(primitives):
            name = node.get("name") or f"node{index}"
            name = name if len(primitives) == 1 else f"{name}.{k}"
            if primitive.get("mode", _TRIANGLES) != _TRIANGLES:
                warnings.warn(f"{path}: {name} is not made of triangles (mode {primitive['mode']}); skipped", stacklevel=3)
                continue
            attributes = primitive["attributes"]
            get = lambda key: read_accessor(buffers, attributes[key]) if key in attributes else None  # noqa: E731
            positions = get("POSITION").astype(np.float64)
            indices = read_accessor(buffers, primitive["indices"]).reshape(-1, 3) if "indices" in primitive else \
                np.arange(len(positions)).reshape(-1, 3)
            normals = get("NORMAL")
            if normals is None:
                import trimesh

                normals = trimesh.Trimesh(positions, indices, process=False).vertex_normals
            uvs = get("TEXCOORD_0")
            if uvs is not None:
                uvs = uvs.astype(np.float64)
                uvs[:, 1] = 1.0 - uvs[:, 1]  # glTF's origin is the image's top-left corner
            colors = get("COLOR_0")
            mesh = MeshData(positions, normals, indices.astype(np.int64), uvs=uvs, tangents=get("TANGENT"),
                            colors=None if colors is None else np.clip(colors[:, :3], 0.0, 1.0))
            out.append((name, mesh, worlds[index], primitive.get("material")))
    return out


def read_gltf_image(path, document, index):
    """The pixels (H, W, 3) uint8 (or uint16) of glTF texture ``index``: from a buffer view (a ``.glb``'s binary
    chunk or a data-URI buffer), a data URI, or an image file beside the document."""
    from PIL import Image

    image = document["images"][document["textures"][index]["source"]]
    if "bufferView" in image:
        payload = BytesIO(_Buffers(path, document).view(image["bufferView"])[0])
    elif image.get("uri", "").startswith("data:"):
        payload = BytesIO(base64.b64decode(image["uri"].split(",", 1)[1]))
    else:
        payload = Path(path).parent / image["uri"]
    with Image.open(payload) as opened:
        return np.asarray(opened.convert("RGB"))


def texture_sampling(document, index):
    """``(wrap, filter)`` of glTF texture ``index``: its sampler's ``wrapS`` (10497 repeat, 33071 clamp;
    mirrored repeat is read as repeat, with a warning) and ``minFilter`` (a mipmapped or absent one:
    'trilinear'; 9728/9729: 'bilinear')."""
    sampler = document.get("samplers", [])[document["textures"][index]["sampler"]] \
        if "sampler" in document["textures"][index] else {}
    wrap = {10497: "repeat", 33071: "clamp", 33648: "repeat"}.get(sampler.get("wrapS", 10497), "repeat")
    if sampler.get("wrapS") == 33648:
        warnings.warn("a glTF sampler's MIRRORED_REPEAT is read as REPEAT (glphong has repeat and clamp)", stacklevel=3)
    return wrap, "bilinear" if sampler.get("minFilter") in (9728, 9729) else "trilinear"
