"""One validation pass over a glTF 2.0 document, before any of its data is touched.

`validate_gltf` checks what glphong's reader relies on: JSON types, required keys, index ranges (every
index a non-negative integer below the length of the array it names: a ``-1`` is refused, never read
as the last entry), enum values, finite numbers, and for every accessor and buffer view the byte
arithmetic (``byteStride`` from 4 to 252, a multiple of 4 and at least the element size; the last element
inside the view, the view inside the buffer's ``byteLength``).  An offset not aligned to the component size,
which the specification forbids, is read through a copy, with one warning naming the first (`_warn_unaligned`).
A node reached twice (the child of two nodes, twice in one ``children``, both a child and a scene root: not the
forest the specification asks for, but what three.js, Blender and trimesh draw once per path) is warned about;
a cycle, or more paths than ``Limits.nodes``, is an error (`glphong.formats.gltf_nodes.check_hierarchy`).
Each error is a `glphong.filesafety.SceneFileError` naming the file, the JSON path
(``accessors[3].byteStride``), what was found and what was expected.

Extensions whose JSON the reader relies on are checked too: ``EXT_``/``KHR_meshopt_compression`` buffer views (the
extension's rules on ``mode``, ``filter``, ``byteStride`` and ``count``, ``count * byteStride`` equal to the view's
``byteLength``, the compressed bytes inside their buffer), ``KHR_texture_basisu`` and ``EXT_texture_webp`` image
indices, ``KHR_materials_variants`` names and mappings.

glTF 1.0 documents are refused as such; the ``extensionsRequired`` list is returned to the reader, which
refuses the required extensions it cannot honour (`glphong.formats.gltf_data`).
"""
import math
import numbers
import warnings

from glphong.core.filesafety import SceneFileError
from glphong.formats.gltf_compressed import MESHOPT_FILTERS, meshopt_extension
from glphong.formats.gltf_material_extensions import check_material_extensions
from glphong.formats.gltf_nodes import check_hierarchy

__all__ = ["validate_gltf", "COMPONENT_BYTES", "TYPE_WIDTHS", "MODES"]

#: bytes per component, by ``componentType``
COMPONENT_BYTES = {5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4}
#: components per element, by accessor ``type``
TYPE_WIDTHS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}
#: primitive ``mode`` names
MODES = {0: "POINTS", 1: "LINES", 2: "LINE_LOOP", 3: "LINE_STRIP", 4: "TRIANGLES", 5: "TRIANGLE_STRIP",
         6: "TRIANGLE_FAN"}
_INDEX_TYPES = (5121, 5123, 5125)
_FILTERS = (9728, 9729, 9984, 9985, 9986, 9987)
_WRAPS = (33071, 33648, 10497)
_COLLECTIONS = ("accessors", "animations", "buffers", "bufferViews", "cameras", "images", "materials", "meshes",
                "nodes", "samplers", "scenes", "skins", "textures")


class _Checker:
    """Type and range checks that raise `SceneFileError` with the JSON path."""

    def __init__(self, path, document, limits):
        self.path, self.document, self.limits = path, document, limits
        self.unaligned = []  # (JSON path, byteOffset, view, view's byteOffset, component bytes) of unaligned data

    def fail(self, where, message):
        raise SceneFileError(self.path, message, where)

    def obj(self, value, where):
        if not isinstance(value, dict):
            self.fail(where, f"expected a JSON object, found {_kind(value)}")
        return value

    def array(self, value, where, minimum=0):
        if not isinstance(value, list):
            self.fail(where, f"expected a JSON array, found {_kind(value)}")
        if len(value) < minimum:
            self.fail(where, f"expected at least {minimum} entries, found {len(value)}")
        return value

    def integer(self, value, where, low=0, high=None):
        if isinstance(value, bool) or not isinstance(value, numbers.Integral) and not (
                isinstance(value, float) and value.is_integer()):
            self.fail(where, f"expected an integer, found {_kind(value)}")
        value = int(value)
        if value < low or high is not None and value > high:
            bounds = f"from {low} to {high}" if high is not None else f">= {low}"
            self.fail(where, f"expected an integer {bounds}, found {value}")
        return value

    def number(self, value, where, low=-math.inf, high=math.inf, low_open=False):
        if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value):
            self.fail(where, f"expected a finite number, found {_kind(value)}")
        if value < low or value > high or low_open and value == low:
            self.fail(where, f"expected a number {'>' if low_open else '>='} {low:g}"
                      + (f" and <= {high:g}" if high < math.inf else "") + f", found {value!r}")
        return float(value)

    def numbers(self, value, where, count, low=-math.inf, high=math.inf):
        self.array(value, where)
        if len(value) != count:
            self.fail(where, f"expected {count} numbers, found {len(value)} entries")
        return [self.number(v, f"{where}[{k}]", low, high) for k, v in enumerate(value)]

    def string(self, value, where):
        if not isinstance(value, str):
            self.fail(where, f"expected a string, found {_kind(value)}")
        return value

    def enum(self, value, where, allowed):
        if isinstance(value, bool) or value not in allowed:
            self.fail(where, f"expected one of {', '.join(map(str, allowed))}, found {value!r:.60}")
        return value

    def index(self, value, where, collection):
        entries = self.document.get(collection, [])
        if not entries:
            self.fail(where, f"refers to {collection}, but the document has none")
        return self.integer(value, where, 0, len(entries) - 1)

    def entries(self, collection):
        """``(k, entry, where)`` of every entry of a top-level array, each checked to be an object."""
        value = self.document.get(collection, [])
        self.array(value, collection)
        if len(value) > self.limits.nodes:
            self.fail(collection, f"{len(value)} entries, more than the limit of {self.limits.nodes} "
                      "(glphong.filesafety.Limits.nodes)")
        for k, entry in enumerate(value):
            yield k, self.obj(entry, f"{collection}[{k}]"), f"{collection}[{k}]"


def _kind(value):
    """A short description of a JSON value for messages (never its full content)."""
    if isinstance(value, bool):
        return f"the boolean {str(value).lower()}"
    if isinstance(value, (int, float)):
        return f"the number {value!r:.40}"
    if isinstance(value, str):
        return f"the string {value!r:.60}"
    return {dict: "an object", list: "an array", type(None): "null"}.get(type(value), type(value).__name__)


def _check_top(c):
    document = c.document
    c.obj(document, "(document)")
    asset = c.obj(document.get("asset"), "asset")
    version = str(asset.get("version", ""))
    if version.startswith("1.") or any(isinstance(document.get(k), dict) for k in _COLLECTIONS):
        c.fail("asset.version", f"a glTF 1.0 document (version {version or 'absent'!r}): glphong reads glTF 2.0; "
               "convert it first (for example with the Khronos glTF-Pipeline or Blender)")
    if not version.startswith("2."):
        c.fail("asset.version", f"expected a glTF 2.x version string, found {_kind(asset.get('version'))}")
    for key in ("extensionsUsed", "extensionsRequired"):
        for k, name in enumerate(c.array(document.get(key, []), key)):
            c.string(name, f"{key}[{k}]")
    for key in _COLLECTIONS:
        c.array(document.get(key, []), key)
    if "extensions" in document:
        c.obj(document["extensions"], "extensions")


def _check_buffers(c):
    for k, buffer, where in c.entries("buffers"):
        c.integer(buffer.get("byteLength"), f"{where}.byteLength", 1, c.limits.file_bytes)
        if "uri" in buffer:
            c.string(buffer["uri"], f"{where}.uri")
    buffers = c.document.get("buffers", [])
    for k, view, where in c.entries("bufferViews"):
        b = c.index(view.get("buffer"), f"{where}.buffer", "buffers")
        offset = c.integer(view.get("byteOffset", 0), f"{where}.byteOffset")
        length = c.integer(view.get("byteLength"), f"{where}.byteLength", 1)
        if offset + length > buffers[b]["byteLength"]:
            c.fail(where, f"bytes {offset} to {offset + length} lie outside buffer {b} of {buffers[b]['byteLength']} bytes")
        if "byteStride" in view:
            stride = c.integer(view["byteStride"], f"{where}.byteStride", 4, 252)
            if stride % 4:
                c.fail(f"{where}.byteStride", f"expected a multiple of 4 from 4 to 252, found {stride}")
        c.obj(view.get("extensions", {}), f"{where}.extensions")
        compressed = meshopt_extension(view)
        if compressed is not None:
            _check_meshopt(c, view, f"{where}.extensions.{compressed[0]}", *compressed)


def _check_meshopt(c, view, where, name, extension):
    """A meshopt-compressed view (``EXT_`` or ``KHR_meshopt_compression``): the extension's validity rules."""
    c.obj(extension, where)
    b = c.index(extension.get("buffer"), f"{where}.buffer", "buffers")
    offset = c.integer(extension.get("byteOffset", 0), f"{where}.byteOffset")
    length = c.integer(extension.get("byteLength"), f"{where}.byteLength", 1)
    size = c.document["buffers"][b]["byteLength"]
    if offset + length > size:
        c.fail(where, f"compressed bytes {offset} to {offset + length} lie outside buffer {b} of {size} bytes")
    stride = c.integer(extension.get("byteStride"), f"{where}.byteStride", 1, 256)
    count = c.integer(extension.get("count"), f"{where}.count", 1)
    mode = c.enum(extension.get("mode"), f"{where}.mode", ("ATTRIBUTES", "TRIANGLES", "INDICES"))
    filter_ = c.enum(extension.get("filter", "NONE"), f"{where}.filter", MESHOPT_FILTERS[name])
    if count * stride != view["byteLength"]:
        c.fail(where, f"count {count} times byteStride {stride} is {count * stride} bytes; the bufferView's "
               f"byteLength is {view['byteLength']} (they must be equal)")
    allowed = {"ATTRIBUTES": stride % 4 == 0, "TRIANGLES": stride in (2, 4) and count % 3 == 0,
               "INDICES": stride in (2, 4)}
    if not allowed[mode]:
        c.fail(where, f"mode {mode} with byteStride {stride} and count {count}: ATTRIBUTES needs a byteStride that is a "
               "multiple of 4, INDICES a byteStride of 2 or 4, TRIANGLES that and a count divisible by 3")
    strides = {"NONE": None, "OCTAHEDRAL": (4, 8), "QUATERNION": (8,), "COLOR": (4, 8)}
    if filter_ != "NONE" and mode != "ATTRIBUTES":
        c.fail(f"{where}.filter", f"filter {filter_} applies to mode ATTRIBUTES only, found mode {mode}")
    if strides.get(filter_) and stride not in strides[filter_]:
        c.fail(f"{where}.byteStride", f"filter {filter_} needs a byteStride of {' or '.join(map(str, strides[filter_]))}, "
               f"found {stride}")


def _element_bytes(component_type, kind):
    """Bytes of one element, with the column padding of MAT2/MAT3 of 1- and 2-byte components."""
    size = COMPONENT_BYTES[component_type]
    if kind in ("MAT2", "MAT3") and size < 4:
        columns = 2 if kind == "MAT2" else 3
        return columns * (-(-columns * size // 4) * 4)
    return size * TYPE_WIDTHS[kind]


def _check_view_range(c, where, view_index, offset, count, element, component, stride=None):
    """The bytes of ``count`` elements from ``offset`` in view ``view_index`` lie inside the view."""
    view = c.document["bufferViews"][view_index]
    stride = stride if stride is not None else view.get("byteStride") or element
    if stride < element:
        c.fail(f"bufferViews[{view_index}].byteStride", f"{stride} is less than the {element}-byte elements of {where}")
    if offset % component or (view.get("byteOffset", 0) + offset) % component:  # read through a copy, warned once
        c.unaligned.append((f"{where}.byteOffset", offset, view_index, view.get("byteOffset", 0), component))
    end = offset + stride * (count - 1) + element
    if end > view["byteLength"]:
        c.fail(where, f"its {count} elements end at byte {end} of bufferView {view_index}, which has "
               f"{view['byteLength']} bytes")


def _check_accessors(c):
    for k, accessor, where in c.entries("accessors"):
        component = c.enum(accessor.get("componentType"), f"{where}.componentType", tuple(COMPONENT_BYTES))
        kind = c.enum(accessor.get("type"), f"{where}.type", tuple(TYPE_WIDTHS))
        count = c.integer(accessor.get("count"), f"{where}.count", 1)
        offset = c.integer(accessor.get("byteOffset", 0), f"{where}.byteOffset")
        if not isinstance(accessor.get("normalized", False), bool):
            c.fail(f"{where}.normalized", f"expected a boolean, found {_kind(accessor['normalized'])}")
        elif accessor.get("normalized") and component in (5125, 5126):
            c.fail(f"{where}.normalized", "true for FLOAT or UNSIGNED_INT components, which the glTF specification "
                   "forbids (only 8- and 16-bit integers are normalized)")
        element = _element_bytes(component, kind)
        if "bufferView" in accessor:
            view = c.index(accessor["bufferView"], f"{where}.bufferView", "bufferViews")
            _check_view_range(c, where, view, offset, count, element, COMPONENT_BYTES[component])
        elif offset:
            c.fail(f"{where}.byteOffset", "an accessor without a bufferView has no byteOffset")
        elif count * element > c.limits.file_bytes:
            c.fail(f"{where}.count", f"{count} elements of zeros is more than the limit of {c.limits.file_bytes} bytes")
        if "sparse" in accessor:
            _check_sparse(c, accessor["sparse"], f"{where}.sparse", count, element, COMPONENT_BYTES[component])


def _warn_unaligned(c):
    """One warning for the accessors whose data does not start on a multiple of their component size (the
    specification requires it; trimesh's and the glTF-SDK's sample files break it): glphong reads them through an
    aligned copy (`glphong.formats.gltf_data.read_accessor`), their bounds checked as any other's."""
    if not c.unaligned:
        return
    where, offset, view, start, component = c.unaligned[0]
    more = f" (and {len(c.unaligned) - 1} more)" if len(c.unaligned) > 1 else ""
    warnings.warn(f"{c.path}: {where}: {offset}, at byte {start + offset} of its buffer (bufferViews[{view}] starts at "
                  f"{start}), is not a multiple of the {component}-byte component size the glTF specification requires"
                  f"{more}; read through an aligned copy", stacklevel=4)


def _check_sparse(c, sparse, where, count, element, component):
    c.obj(sparse, where)
    n = c.integer(sparse.get("count"), f"{where}.count", 1, count)
    indices = c.obj(sparse.get("indices"), f"{where}.indices")
    index_type = c.enum(indices.get("componentType"), f"{where}.indices.componentType", _INDEX_TYPES)
    view = c.index(indices.get("bufferView"), f"{where}.indices.bufferView", "bufferViews")
    size = COMPONENT_BYTES[index_type]
    _check_view_range(c, f"{where}.indices", view, c.integer(indices.get("byteOffset", 0), f"{where}.indices.byteOffset"),
                      n, size, size, stride=size)
    values = c.obj(sparse.get("values"), f"{where}.values")
    view = c.index(values.get("bufferView"), f"{where}.values.bufferView", "bufferViews")
    _check_view_range(c, f"{where}.values", view, c.integer(values.get("byteOffset", 0), f"{where}.values.byteOffset"),
                      n, element, component, stride=element)


def _check_textures(c):
    for k, image, where in c.entries("images"):
        if "uri" in image:
            c.string(image["uri"], f"{where}.uri")
        elif "bufferView" in image:
            c.index(image["bufferView"], f"{where}.bufferView", "bufferViews")
        else:
            c.fail(where, "an image needs a uri or a bufferView")
    for k, sampler, where in c.entries("samplers"):
        for key, allowed in (("magFilter", (9728, 9729)), ("minFilter", _FILTERS), ("wrapS", _WRAPS), ("wrapT", _WRAPS)):
            if key in sampler:
                c.enum(sampler[key], f"{where}.{key}", allowed)
    for k, texture, where in c.entries("textures"):
        if "source" in texture:
            c.index(texture["source"], f"{where}.source", "images")
        if "sampler" in texture:
            c.index(texture["sampler"], f"{where}.sampler", "samplers")
        extensions = c.obj(texture.get("extensions", {}), f"{where}.extensions")
        for name in ("KHR_texture_basisu", "EXT_texture_webp"):
            if name in extensions:
                c.index(c.obj(extensions[name], f"{where}.extensions.{name}").get("source"),
                        f"{where}.extensions.{name}.source", "images")


def _check_texture_ref(c, ref, where):
    c.obj(ref, where)
    c.index(ref.get("index"), f"{where}.index", "textures")
    c.integer(ref.get("texCoord", 0), f"{where}.texCoord")


def _check_materials(c):
    for k, material, where in c.entries("materials"):
        pbr = c.obj(material.get("pbrMetallicRoughness", {}), f"{where}.pbrMetallicRoughness")
        if "baseColorFactor" in pbr:
            c.numbers(pbr["baseColorFactor"], f"{where}.pbrMetallicRoughness.baseColorFactor", 4, 0.0)
        for key in ("metallicFactor", "roughnessFactor"):
            if key in pbr:
                c.number(pbr[key], f"{where}.pbrMetallicRoughness.{key}", 0.0)
        for key in ("baseColorTexture", "metallicRoughnessTexture"):
            if key in pbr:
                _check_texture_ref(c, pbr[key], f"{where}.pbrMetallicRoughness.{key}")
        for key in ("normalTexture", "occlusionTexture", "emissiveTexture"):
            if key in material:
                _check_texture_ref(c, material[key], f"{where}.{key}")
        if "emissiveFactor" in material:
            c.numbers(material["emissiveFactor"], f"{where}.emissiveFactor", 3, 0.0)
        if "alphaMode" in material:
            c.enum(material["alphaMode"], f"{where}.alphaMode", ("OPAQUE", "MASK", "BLEND"))
        if "alphaCutoff" in material:
            c.number(material["alphaCutoff"], f"{where}.alphaCutoff", 0.0)
        if "strength" in material.get("occlusionTexture", {}):
            c.number(material["occlusionTexture"]["strength"], f"{where}.occlusionTexture.strength", 0.0, 1.0)
        if "scale" in material.get("normalTexture", {}):
            c.number(material["normalTexture"]["scale"], f"{where}.normalTexture.scale")
        extensions = c.obj(material.get("extensions", {}), f"{where}.extensions")
        ior = extensions.get("KHR_materials_ior")
        if ior is not None:
            c.obj(ior, f"{where}.extensions.KHR_materials_ior")
            c.number(ior.get("ior", 1.5), f"{where}.extensions.KHR_materials_ior.ior", 0.0)
        check_material_extensions(c, extensions, where, _check_texture_ref)  # specular, clearcoat, sheen
        strength = extensions.get("KHR_materials_emissive_strength")
        if strength is not None:
            c.obj(strength, f"{where}.extensions.KHR_materials_emissive_strength")
            c.number(strength.get("emissiveStrength", 1.0),
                     f"{where}.extensions.KHR_materials_emissive_strength.emissiveStrength", 0.0)


def _check_meshes(c):
    for k, mesh, where in c.entries("meshes"):
        for p, primitive in enumerate(c.array(mesh.get("primitives"), f"{where}.primitives", 1)):
            pw = f"{where}.primitives[{p}]"
            c.obj(primitive, pw)
            attributes = c.obj(primitive.get("attributes"), f"{pw}.attributes")
            for name, accessor in attributes.items():
                c.index(accessor, f"{pw}.attributes.{name}", "accessors")
            if "indices" in primitive:
                c.index(primitive["indices"], f"{pw}.indices", "accessors")
            if "material" in primitive:
                c.index(primitive["material"], f"{pw}.material", "materials")
            c.enum(primitive.get("mode", 4), f"{pw}.mode", tuple(MODES))
            for t, target in enumerate(c.array(primitive.get("targets", []), f"{pw}.targets")):
                c.obj(target, f"{pw}.targets[{t}]")
            variants = c.obj(primitive.get("extensions", {}), f"{pw}.extensions").get("KHR_materials_variants")
            if variants is not None:
                _check_variant_mappings(c, variants, f"{pw}.extensions.KHR_materials_variants")


def _check_variant_mappings(c, block, where):
    """A primitive's ``KHR_materials_variants.mappings``: each a material and the variants that choose it."""
    names = c.document.get("extensions", {}).get("KHR_materials_variants", {}).get("variants", [])
    for m, mapping in enumerate(c.array(c.obj(block, where).get("mappings"), f"{where}.mappings", 1)):
        mw = f"{where}.mappings[{m}]"
        c.index(c.obj(mapping, mw).get("material"), f"{mw}.material", "materials")
        for v, variant in enumerate(c.array(mapping.get("variants"), f"{mw}.variants", 1)):
            if not names:
                c.fail(f"{mw}.variants[{v}]", "refers to a variant, but the document's "
                       "extensions.KHR_materials_variants.variants is empty or absent")
            c.integer(variant, f"{mw}.variants[{v}]", 0, len(names) - 1)


def _check_variants(c):
    block = c.document.get("extensions", {}).get("KHR_materials_variants")
    if block is None:
        return
    where = "extensions.KHR_materials_variants"
    for k, variant in enumerate(c.array(c.obj(block, where).get("variants"), f"{where}.variants", 1)):
        c.string(c.obj(variant, f"{where}.variants[{k}]").get("name"), f"{where}.variants[{k}].name")


def _check_cameras(c):
    for k, camera, where in c.entries("cameras"):
        kind = c.enum(camera.get("type"), f"{where}.type", ("perspective", "orthographic"))
        spec = c.obj(camera.get(kind), f"{where}.{kind}")
        if kind == "perspective":
            c.number(spec.get("yfov"), f"{where}.perspective.yfov", 0.0, math.pi, low_open=True)
            znear = c.number(spec.get("znear"), f"{where}.perspective.znear", 0.0, low_open=True)
            if "zfar" in spec and c.number(spec["zfar"], f"{where}.perspective.zfar") <= znear:
                c.fail(f"{where}.perspective.zfar", f"expected a number > znear ({znear:g}), found {spec['zfar']!r}")
        else:
            c.number(spec.get("xmag"), f"{where}.orthographic.xmag")
            c.number(spec.get("ymag"), f"{where}.orthographic.ymag", 0.0, low_open=True)
            znear = c.number(spec.get("znear"), f"{where}.orthographic.znear", 0.0)
            if c.number(spec.get("zfar"), f"{where}.orthographic.zfar") <= znear:
                c.fail(f"{where}.orthographic.zfar", f"expected a number > znear ({znear:g}), found {spec['zfar']!r}")


def _check_lights(c):
    extensions = c.document.get("extensions", {})
    block = extensions.get("KHR_lights_punctual")
    if block is None:
        return
    base = "extensions.KHR_lights_punctual"
    for k, light in enumerate(c.array(c.obj(block, base).get("lights", []), f"{base}.lights")):
        where = f"{base}.lights[{k}]"
        c.obj(light, where)
        kind = c.enum(light.get("type"), f"{where}.type", ("point", "directional", "spot"))
        if "color" in light:
            c.numbers(light["color"], f"{where}.color", 3, 0.0)
        if "intensity" in light:
            c.number(light["intensity"], f"{where}.intensity", 0.0)
        if "range" in light:
            c.number(light["range"], f"{where}.range", 0.0, low_open=True)
        if kind == "spot":
            spot = c.obj(light.get("spot", {}), f"{where}.spot")
            inner = c.number(spot.get("innerConeAngle", 0.0), f"{where}.spot.innerConeAngle", 0.0, math.pi / 2)
            outer = c.number(spot.get("outerConeAngle", math.pi / 4), f"{where}.spot.outerConeAngle", 0.0, math.pi / 2)
            if inner >= outer:
                c.fail(f"{where}.spot", f"innerConeAngle {inner:g} must be less than outerConeAngle {outer:g}")


def _check_nodes(c):
    lights = c.document.get("extensions", {}).get("KHR_lights_punctual", {}).get("lights", [])
    for k, node, where in c.entries("nodes"):
        for key, count in (("matrix", 16), ("translation", 3), ("rotation", 4), ("scale", 3)):
            if key in node:
                c.numbers(node[key], f"{where}.{key}", count)
        for key, collection in (("mesh", "meshes"), ("camera", "cameras"), ("skin", "skins")):
            if key in node:
                c.index(node[key], f"{where}.{key}", collection)
        for j, child in enumerate(c.array(node.get("children", []), f"{where}.children")):
            c.index(child, f"{where}.children[{j}]", "nodes")
        reference = c.obj(node.get("extensions", {}), f"{where}.extensions").get("KHR_lights_punctual")
        if reference is not None:
            c.obj(reference, f"{where}.extensions.KHR_lights_punctual")
            light = reference.get("light")
            if not lights:
                c.fail(f"{where}.extensions.KHR_lights_punctual.light", "refers to a light, but the document has none")
            c.integer(light, f"{where}.extensions.KHR_lights_punctual.light", 0, len(lights) - 1)
    for k, scene, where in c.entries("scenes"):
        for j, root in enumerate(c.array(scene.get("nodes", []), f"{where}.nodes")):
            c.index(root, f"{where}.nodes[{j}]", "nodes")
    if "scene" in c.document:
        c.index(c.document["scene"], "scene", "scenes")
    check_hierarchy(c)  # no cycle; the drawn scene's paths bounded, a shared node warned about


def validate_gltf(path, document, limits):
    """Check a glTF 2.0 document (see the module); returns None or raises.

    Parameters
    ----------
    path : path-like
        The file (for the errors).
    document : object
        The parsed JSON.
    limits : glphong.filesafety.Limits

    Raises
    ------
    glphong.filesafety.SceneFileError
        The first problem found, with its JSON path.

    Warns
    -----
    UserWarning
        Once each, for a file that passes: accessors not aligned to their component size (read through a copy) and
        nodes reached by several paths (drawn once per path).
    """
    c = _Checker(path, document, limits)
    _check_top(c)
    _check_buffers(c)
    _check_accessors(c)
    _check_textures(c)
    _check_materials(c)
    _check_variants(c)
    _check_meshes(c)
    _check_cameras(c)
    _check_lights(c)
    _check_nodes(c)
    _warn_unaligned(c)  # a file that passes: what it gets wrong and glphong reads all the same
