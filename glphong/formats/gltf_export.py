"""Writing a `glphong.Scene` as glTF 2.0 (``.glb`` or ``.gltf``), so that `glphong.load_scene` reads it back.

What is written:
- every object as a node (its pose as the node ``matrix``, left out where it is the identity) with a mesh of its
  `MeshData` (positions, normals, ``TEXCOORD_0`` with v flipped to glTF's top-left origin, ``COLOR_0`` as linear
  floats, given tangents as ``TANGENT``, or the derived ones glphong draws with where the material reads a tangent
  frame; one glTF mesh per distinct MeshData and material).  glTF asks for unit normals and
  tangents and a tangent w of +-1: those off unit length are rescaled (glphong renormalises per fragment anyway), w
  written as its sign, and a zero tangent (a sphere's poles) as the shader's fallback there, the basis vector around
  the normal (`glphong.twin.functions.frame_from_tangent`);
- every material as a glTF metallic-roughness material for other viewers (``baseColorFactor`` from the
  diffuse albedo ``rho_d``/``rho``, or ``pi kd`` clipped to 1, its texture as ``baseColorTexture``;
  metallic 0, roughness 1: an approximation; a `GltfPBR` as itself: its base colour, metallic and roughness
  factors, a metallic-roughness texture that both read (blue, green), its emissive with
  ``KHR_materials_emissive_strength``; any material's normal map as ``normalTexture``, alpha mask as
  ``alphaMode`` MASK and alpha blend as ``alphaMode`` BLEND; a volume's ``doubleSided`` false, which glTF says
  has no effect on a volume's boundary and the validator asks for) and, exactly, in the material's
  ``extras: {"glphong": ...}`` (`glphong.definitions.as_json`), which `load_scene` prefers;
- textures as PNG images (8-bit sources, re-encoded losslessly) with their samplers;
- the camera (perspective: ``yfov``, ``znear``, ``zfar``; orthographic: ``ymag``; an `IntrinsicsCamera`'s
  principal point is not representable: written as its perspective frustum, with a warning);
- point, spot and directional lights (``KHR_lights_punctual``, each kind's ``to_gltf``; ``range`` where given) in
  radiometric units (W/sr, W/m^2), declared in
  the asset's ``extras: {"glphong": {"light_units": "radiometric"}}`` together with the ambient light,
  which glTF has no place for.  A kind without a glTF equivalent (`UnattenuatedPointLight`, a user's kind
  without ``to_gltf``) is skipped, with a warning.

A scene without objects has no accessors, buffer views nor buffer (glTF refuses empty arrays and 0-byte buffers).
The 72 files of ``benchmarks/gltf_validate.py`` pass the Khronos glTF validator without an error or a warning (the
rules in Python: tests/test_gltf_conformance.py); a mesh whose normals hold a zero vector is written as it is, which
the validator reports (``ACCESSOR_VECTOR3_NON_UNIT``): glphong draws such a vertex with its emission terms only, and
no unit vector would keep that.

Nothing is written compressed: a scene loaded from a Draco- or meshopt-compressed file, or with KTX2 or WebP textures,
is written with plain buffers and PNG images (its decoded arrays and pixels, so it reads back equal).
"""
import base64
import json
import struct
import warnings
from io import BytesIO
from pathlib import Path

import numpy as np
from glphong.materials import SurfaceInput
from glphong.definitions.as_json import material_to_json
from glphong.scene.camera import IntrinsicsCamera, OrthographicCamera
from glphong.scene.scene import Scene
from glphong.twin.functions import frame_from_tangent, safe_normalize

__all__ = ["save_gltf"]

_FLOAT, _UINT = 5126, 5125
_ARRAY_BUFFER, _ELEMENT_ARRAY_BUFFER = 34962, 34963
_REPEAT, _CLAMP = 10497, 33071
_LINEAR, _LINEAR_MIPMAP_LINEAR = 9729, 9987
_ROUNDING = 1e-6  # a float32 unit vector's length is 1 within a few 6e-8


class _Builder:
    """The JSON document and the one binary buffer of a glTF file being written."""

    def __init__(self):
        self.doc = {"asset": {"version": "2.0", "generator": "glphong"}, "buffers": [], "bufferViews": [],
                    "accessors": []}
        self.data = bytearray()

    def view(self, payload, target=None):
        while len(self.data) % 4:
            self.data.append(0)
        view = {"buffer": 0, "byteOffset": len(self.data), "byteLength": len(payload)}
        if target is not None:
            view["target"] = target
        self.data += payload
        self.doc["bufferViews"].append(view)
        return len(self.doc["bufferViews"]) - 1

    def accessor(self, array, kind, target=_ARRAY_BUFFER, bounds=False):
        array = np.ascontiguousarray(array)
        component = _UINT if array.dtype == np.uint32 else _FLOAT
        accessor = {"bufferView": self.view(array.tobytes(), target), "componentType": component,
                    "count": int(array.shape[0]), "type": kind}
        if bounds:
            accessor["min"] = [float(v) for v in array.min(axis=0)]
            accessor["max"] = [float(v) for v in array.max(axis=0)]
        self.doc["accessors"].append(accessor)
        return len(self.doc["accessors"]) - 1

    def append(self, field, entry):
        self.doc.setdefault(field, []).append(entry)
        return len(self.doc[field]) - 1


def _unit_normals(normals):
    """``normals`` (V, 3) at unit length, as glTF's ``NORMAL`` must be (glphong renormalises per fragment): those off
    1 by more than float32 rounding (`_ROUNDING`) rescaled, the others as they are; a zero or non-finite one stays as it
    is (nothing to scale)."""
    normals = np.asarray(normals, np.float64)
    valid, unit, length = safe_normalize(normals)
    return np.where((valid & (np.abs(length - 1.0) > _ROUNDING))[:, None], unit, normals).astype(np.float32)


def _unit_tangents(normals, tangents):
    """``tangents`` (V, 4) as glTF's ``TANGENT`` must be: xyz at unit length (rescaled as in `_unit_normals`), w
    exactly +-1 (its sign; 0 as +1, the shader's reading); a zero or non-finite xyz (a sphere's poles) is the tangent
    the shader falls back to there (`frame_from_tangent`'s basis around the normal), w kept."""
    tangents = np.asarray(tangents, np.float64)
    valid, unit, length = safe_normalize(tangents[:, :3])
    fallback, _ = frame_from_tangent(np.asarray(normals, np.float64), np.zeros_like(tangents))
    xyz = np.where((valid & (np.abs(length - 1.0) > _ROUNDING))[:, None], unit, tangents[:, :3])
    xyz = np.where(valid[:, None], xyz, fallback)
    return np.concatenate([xyz, np.where(tangents[:, 3:] < 0, -1.0, 1.0)], axis=1).astype(np.float32)


def _mesh(builder, mesh, material, material_index):
    normals = _unit_normals(mesh.normals)
    attributes = {"POSITION": builder.accessor(mesh.positions, "VEC3", bounds=True),
                  "NORMAL": builder.accessor(normals, "VEC3")}
    if mesh.uvs is not None:
        uv = np.array(mesh.uvs, dtype=np.float32)
        uv[:, 1] = 1.0 - uv[:, 1]  # glTF's v runs down from the image's top-left corner
        attributes["TEXCOORD_0"] = builder.accessor(uv, "VEC2")
    if mesh.colors is not None:
        attributes["COLOR_0"] = builder.accessor(mesh.colors, "VEC3")
    # the mesh's own tangents, else those glphong derives and draws with, where the material reads a tangent frame
    # (a loader would derive others: MikkTSpace); none otherwise, whether or not a draw derived them already
    reads_frame = material.normal_map is not None or any("tangent" in term.needs for term in material.components)
    tangents = mesh.given_tangents if mesh.given_tangents is not None or not reads_frame else mesh.tangents
    if tangents is not None:
        attributes["TANGENT"] = builder.accessor(_unit_tangents(normals, tangents), "VEC4")
    indices = builder.accessor(mesh.indices.reshape(-1), "SCALAR", _ELEMENT_ARRAY_BUFFER)
    return {"primitives": [{"attributes": attributes, "indices": indices, "material": material_index}]}


def _texture(builder, image, cache, alpha=None):
    """The index of the glTF texture of ``image`` (written once); ``alpha`` ('r', 'g' or 'b'): an RGBA image whose
    alpha (and colour) is that channel, for a field glTF reads from the alpha (``diffuseTransmissionTexture``)."""
    from PIL import Image

    name = image.digest if alpha is None else (image.digest, alpha)
    if name in cache:
        return cache[name]
    pixels = image.pixels8()
    if alpha is not None:
        grey = pixels[..., "rgb".index(alpha)]
        pixels = np.stack([grey, grey, grey, grey], axis=-1)
    png = BytesIO()
    Image.fromarray(pixels).save(png, format="PNG")
    source = builder.append("images", {"bufferView": builder.view(png.getvalue()), "mimeType": "image/png"})
    sampler = builder.append("samplers", {
        "wrapS": _REPEAT if image.wrap == "repeat" else _CLAMP, "wrapT": _REPEAT if image.wrap == "repeat" else _CLAMP,
        "magFilter": _LINEAR, "minFilter": _LINEAR_MIPMAP_LINEAR if image.filter == "trilinear" else _LINEAR})
    index = cache[name] = builder.append("textures", {"source": source, "sampler": sampler})
    return index


def _base_color(material):
    """``(baseColorFactor rgb, TextureImage or None)`` of the PBR approximation (see the module)."""

    for term in material.components:
        for name, scale in (("base_color", 1.0), ("rho_d", 1.0), ("rho", 1.0), ("kd", np.pi)):
            value = getattr(term, name, None) if name in {p.name for p in term.params} else None
            if value is None:
                continue
            if isinstance(value, SurfaceInput):
                return np.clip(np.asarray(value.scale) * scale, 0, 1), value.texture
            return np.clip(np.asarray(value) * scale, 0, 1), None
    return np.full(3, 0.5), None


def _material(builder, material, cache):
    stored = material_to_json(material, texture_index=lambda image: _texture(builder, image, cache))
    (term,) = material.components if len(material.components) == 1 else (None,)
    fields = term.gltf_fields(lambda image, alpha=None: _texture(builder, image, cache, alpha)) \
        if term is not None else None
    if fields is not None:  # a glTF material (GltfPBR): its own fields, as they are, for other viewers
        pbr, out = fields
    else:
        base, texture = _base_color(material)
        pbr = {"baseColorFactor": [float(c) for c in base] + [1.0], "metallicFactor": 0.0, "roughnessFactor": 1.0}
        if texture is not None:
            pbr["baseColorTexture"] = {"index": _texture(builder, texture, cache)}
        out = {}
    if material.normal_map is not None:
        out["normalTexture"] = {"index": _texture(builder, material.normal_map.texture, cache),
                                "scale": float(material.normal_map.scale)}
    if material.alpha_mask is not None:
        out.update(alphaMode="MASK", alphaCutoff=float(material.alpha_mask.cutoff))
    elif material.alpha_blend is not None:
        out.update(alphaMode="BLEND")
    alpha = material.alpha_mask or material.alpha_blend
    if alpha is not None and not alpha.textured:
        pbr["baseColorFactor"][3] = float(alpha.alpha)
    elif alpha is not None:
        warnings.warn(f"{type(material).__name__}'s textured alpha is written in glphong's extras only: other viewers "
                      "read the glTF alpha, baseColorFactor.a (1) times the base-colour texture's, which does not "
                      "carry it", stacklevel=4)
    name = f"{type(material).__name__}{len(builder.doc.get('materials', []))}"  # unique: readers key materials by name
    # a volume's boundary is one-sided to glTF (doubleSided "has no effect on volume boundaries", and the validator
    # warns of it); glphong's two_sided is kept in the extras
    two_sided = bool(material.two_sided) and "KHR_materials_volume" not in out.get("extensions", {})
    return {"name": name, "pbrMetallicRoughness": pbr, **out, "extras": {"glphong": stored}, "doubleSided": two_sided}


def _column_major(matrix):
    return [float(v) for v in np.asarray(matrix, dtype=np.float64).T.ravel()]


def _posed(node, pose):
    """``node`` with its ``matrix`` (column-major), left out where ``pose`` is the identity (glTF's default)."""
    if not np.array_equal(np.asarray(pose, dtype=np.float64), np.eye(4)):
        node["matrix"] = _column_major(pose)
    return node


def _camera(camera):
    if isinstance(camera, OrthographicCamera):
        return {"type": "orthographic", "orthographic": {"xmag": float(camera.ymag), "ymag": float(camera.ymag),
                                                         "znear": float(camera.znear), "zfar": float(camera.zfar)}}
    if isinstance(camera, IntrinsicsCamera):
        warnings.warn("an IntrinsicsCamera's principal point has no glTF equivalent: written as a centred "
                      "perspective camera of the same vertical field of view", stacklevel=3)
    return {"type": "perspective", "perspective": {"yfov": float(camera.yfov), "znear": float(camera.znear),
                                                   "zfar": float(camera.zfar)}}


def _light_node(builder, light, index):
    entry, pose = light.to_gltf()
    lights = builder.doc.setdefault("extensions", {}).setdefault("KHR_lights_punctual", {"lights": []})["lights"]
    lights.append(entry)
    return _posed({"name": f"light{index}", "extensions": {"KHR_lights_punctual": {"light": len(lights) - 1}}}, pose)


def save_gltf(scene, path):
    """Write ``scene`` to ``path`` (``.glb``: binary; ``.gltf``: JSON with the buffer as a data URI).

    Parameters
    ----------
    scene : glphong.Scene
    path : str or path-like

    Returns
    -------
    pathlib.Path

    Raises
    ------
    ValueError
        Another suffix, a material with a table argument, or a texture made from a 16-bit or float image
        (PNG at 8 bits cannot hold it exactly).
    """

    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a glphong.Scene (got {type(scene).__name__})")
    path = Path(path)
    if path.suffix.lower() not in (".glb", ".gltf"):
        raise ValueError(f"{path}: save_gltf writes .glb or .gltf files (got {path.suffix or 'no suffix'!r})")
    builder = _Builder()
    doc = builder.doc
    nodes, meshes, materials, textures = [], {}, {}, {}
    for obj in scene.objects:
        if obj.material not in materials:
            materials[obj.material] = builder.append("materials", _material(builder, obj.material, textures))
        key = (id(obj.mesh), materials[obj.material])
        if key not in meshes:
            meshes[key] = builder.append("meshes", _mesh(builder, obj.mesh, obj.material, materials[obj.material]))
        nodes.append(_posed({"name": obj.name, "mesh": meshes[key]}, obj.pose))
    doc["cameras"] = [_camera(scene.camera)]
    nodes.append(_posed({"name": "camera", "camera": 0}, scene.camera.pose))
    for index, light in enumerate(scene.lights):
        if light.to_gltf() is None:
            warnings.warn(f"light {index}: a {type(light).__name__} has no glTF equivalent; not written", stacklevel=2)
            continue
        nodes.append(_light_node(builder, light, index))
    if "extensions" in doc:
        doc["extensionsUsed"] = ["KHR_lights_punctual"]
    # every material extension written (emissive strength, specular, clearcoat, sheen, anisotropy...), as glTF asks
    used = sorted({name for m in doc.get("materials", []) for name in m.get("extensions", {})})
    if used:
        doc["extensionsUsed"] = doc.get("extensionsUsed", []) + used
    doc["nodes"] = nodes
    doc["scenes"] = [{"nodes": list(range(len(nodes)))}]
    doc["scene"] = 0
    doc["asset"]["extras"] = {"glphong": {"light_units": "radiometric",
                                          "ambient": None if scene.ambient is None else list(scene.ambient.radiance)}}
    while len(builder.data) % 4:
        builder.data.append(0)
    for field in ("accessors", "bufferViews"):  # a scene without objects: none (glTF refuses empty arrays)
        if not doc[field]:
            del doc[field]
    if builder.data:  # nor a buffer of 0 bytes
        doc["buffers"] = [{"byteLength": len(builder.data)}]
    else:
        del doc["buffers"]
    if path.suffix.lower() == ".gltf":
        if builder.data:
            doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + base64.b64encode(builder.data).decode()
        path.write_text(json.dumps(doc), encoding="utf-8")
        return path
    text = json.dumps(doc).encode("utf-8")
    text += b" " * (-len(text) % 4)
    body = struct.pack("<II", len(text), 0x4E4F534A) + text
    if builder.data:
        body += struct.pack("<II", len(builder.data), 0x004E4942) + bytes(builder.data)
    path.write_bytes(struct.pack("<III", 0x46546C67, 2, 12 + len(body)) + body)
    return path
