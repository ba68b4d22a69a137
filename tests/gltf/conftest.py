"""Small glTF files made by the tests of tests/gltf: one triangle-pair primitive whose attributes, indices, views
(plain or meshopt-compressed), materials and images each test chooses."""
import json

import numpy as np
import pytest

_COMPONENTS = {np.dtype(np.int8): 5120, np.dtype(np.uint8): 5121, np.dtype(np.int16): 5122,
               np.dtype(np.uint16): 5123, np.dtype(np.uint32): 5125, np.dtype(np.float32): 5126}
_TYPES = {1: "SCALAR", 2: "VEC2", 3: "VEC3", 4: "VEC4"}


class GltfBuilder:
    """Build one glTF document and its single buffer.

    ``attribute(name, values, normalized=False, stride=None, compress=None)`` adds an accessor over its own buffer
    view (rows padded to ``stride`` bytes, a multiple of 4); ``compress(rows)`` (rows: (count, stride) uint8)
    returns ``(mode, filter, encoded bytes)`` to store the view meshopt-compressed, its parent view then over a
    placeholder buffer without data.  ``image(payload, mime)`` adds an image in a buffer view.
    """

    def __init__(self):
        self.blob = bytearray()
        self.document = {"asset": {"version": "2.0"}, "buffers": [{"byteLength": 0}], "bufferViews": [],
                         "accessors": [], "meshes": [{"primitives": [{"attributes": {}}]}], "nodes": [{"mesh": 0}],
                         "scenes": [{"nodes": [0]}], "scene": 0}
        self.placeholder = None

    @property
    def primitive(self):
        return self.document["meshes"][0]["primitives"][0]

    def _append(self, data):
        self.blob += bytes(-len(self.blob) % 4)
        offset = len(self.blob)
        self.blob += data
        return offset

    def view(self, rows, stride=None, compress=None, extension="EXT_meshopt_compression"):
        rows = np.ascontiguousarray(rows)
        count = len(rows)
        raw = rows.reshape(count, -1).view(np.uint8)
        stride = stride or raw.shape[1]
        padded = np.zeros((count, stride), np.uint8)
        padded[:, :raw.shape[1]] = raw
        view = {"buffer": 0, "byteLength": count * stride}
        if stride != raw.shape[1]:
            view["byteStride"] = stride
        if compress is None:
            view["byteOffset"] = self._append(padded.tobytes())
        else:
            mode, filter_, encoded = compress(padded)
            if self.placeholder is None:
                self.document["buffers"].append({"byteLength": 0, "extensions": {extension: {"fallback": True}}})
                self.placeholder = len(self.document["buffers"]) - 1
            holder = self.document["buffers"][self.placeholder]
            view.update(buffer=self.placeholder, byteOffset=holder["byteLength"])
            holder["byteLength"] += count * stride
            view["extensions"] = {extension: {"buffer": 0, "byteOffset": self._append(encoded),
                                              "byteLength": len(encoded), "byteStride": stride, "count": count,
                                              "mode": mode, "filter": filter_}}
        self.document["bufferViews"].append(view)
        return len(self.document["bufferViews"]) - 1

    def accessor(self, values, normalized=False, stride=None, compress=None, extension="EXT_meshopt_compression"):
        values = np.asarray(values)
        width = 1 if values.ndim == 1 else values.shape[1]
        accessor = {"bufferView": self.view(values, stride, compress, extension),
                    "componentType": _COMPONENTS[values.dtype], "count": len(values), "type": _TYPES[width]}
        if normalized:
            accessor["normalized"] = True
        self.document["accessors"].append(accessor)
        return len(self.document["accessors"]) - 1

    def attribute(self, name, values, **keywords):
        self.primitive["attributes"][name] = self.accessor(values, **keywords)

    def indices(self, values, **keywords):
        self.primitive["indices"] = self.accessor(values, **keywords)

    def image(self, payload, mime):
        view = {"buffer": 0, "byteOffset": self._append(payload), "byteLength": len(payload)}
        self.document["bufferViews"].append(view)
        self.document.setdefault("images", []).append({"bufferView": len(self.document["bufferViews"]) - 1,
                                                       "mimeType": mime})
        return len(self.document["images"]) - 1

    def write(self, folder, name="scene.gltf"):
        """The ``.gltf`` file (its buffer beside it, ``scene.bin``)."""
        folder.mkdir(parents=True, exist_ok=True)
        self.blob += bytes(-len(self.blob) % 4)
        self.document["buffers"][0].update(uri="scene.bin", byteLength=len(self.blob))
        (folder / "scene.bin").write_bytes(bytes(self.blob))
        path = folder / name
        path.write_text(json.dumps(self.document))
        return path


@pytest.fixture
def builder():
    """A fresh `GltfBuilder`."""
    return GltfBuilder()
