"""Which material, which texture coordinates and which attribute types a glTF primitive gets.

- ``KHR_materials_variants``: `variant_index` finds a variant by name (an unknown name is a ``ValueError`` listing the
  file's variants) and `primitive_material` gives the material a primitive's ``mappings`` choose for it (the
  primitive's own ``material`` where no mapping names the variant, as the extension says).
- Texture coordinate sets: glphong draws one set of uvs per primitive.  `material_uv_set` is the set every texture
  of a material reads (``textureInfo.texCoord``, or the ``texCoord`` of its ``KHR_texture_transform``, which
  overrides it); the primitive then carries ``TEXCOORD_<set>`` as its uvs, so a material whose textures all read
  ``TEXCOORD_1`` is drawn exactly.  A material whose textures read different sets is refused by name
  (`check_one_uv_set`): drawing one set for all would put some textures in the wrong place.
- Extensions: `REQUIRED_OK` (read where required), `APPEARANCE_ONLY` (warned about where required), `APPLIED` (read
  where used; any other a file uses is named in a warning).
- ``KHR_mesh_quantization``: `check_attribute_type` holds each attribute to the extension's table of component types.
"""
from glphong.core.filesafety import SceneFileError

__all__ = ["REQUIRED_OK", "APPEARANCE_ONLY", "APPLIED", "ATTRIBUTE_COMPONENTS", "variant_index", "primitive_material",
           "texture_infos", "material_uv_set", "check_one_uv_set", "check_attribute_type"]

#: required extensions glphong reads (the compressed ones need their extra: `OPTIONAL_DECODERS`)
REQUIRED_OK = ("KHR_lights_punctual", "KHR_mesh_quantization", "KHR_draco_mesh_compression",
               "KHR_materials_emissive_strength", "KHR_texture_transform", "KHR_materials_ior",
               "EXT_meshopt_compression", "KHR_meshopt_compression", "KHR_texture_basisu", "EXT_texture_webp",
               "KHR_materials_variants", "KHR_materials_specular", "KHR_materials_clearcoat",
               "KHR_materials_sheen", "KHR_materials_anisotropy", "KHR_materials_iridescence", "KHR_materials_transmission",
               "KHR_materials_volume", "KHR_materials_dispersion", "KHR_materials_diffuse_transmission")
#: required extensions whose loss changes appearance only: read without them, with a warning
APPEARANCE_ONLY = ("EXT_texture_avif",
                   "KHR_materials_unlit", "KHR_materials_pbrSpecularGlossiness")
#: extensions glphong applies where a file uses them (`extensionsUsed`); any other is warned about, by name
APPLIED = REQUIRED_OK

_FLOAT, _BYTE, _UBYTE, _SHORT, _USHORT = 5126, 5120, 5121, 5122, 5123
_ANY_INTEGER = tuple((t, n) for t in (_BYTE, _UBYTE, _SHORT, _USHORT) for n in (False, True))
#: (componentType, normalized) pairs each attribute may have: the core specification's, widened by
#: KHR_mesh_quantization's table (POSITION and TEXCOORD_n any 8- or 16-bit integer, normalized or not; NORMAL and
#: TANGENT signed normalized 8- or 16-bit)
ATTRIBUTE_COMPONENTS = {"POSITION": ((_FLOAT, False),) + _ANY_INTEGER,
                        "NORMAL": ((_FLOAT, False), (_BYTE, True), (_SHORT, True)),
                        "TANGENT": ((_FLOAT, False), (_BYTE, True), (_SHORT, True)),
                        "TEXCOORD": ((_FLOAT, False),) + _ANY_INTEGER}
_TYPE_NAMES = {_FLOAT: "float", _BYTE: "byte", _UBYTE: "unsigned byte", _SHORT: "short", _USHORT: "unsigned short",
               5125: "unsigned int"}


def check_attribute_type(path, accessor, name, where):
    """Raise `SceneFileError` where accessor ``accessor`` (JSON) has a component type attribute ``name`` may not have
    (`ATTRIBUTE_COMPONENTS`); attributes outside the table (``COLOR_0``, ...) pass."""
    key = "TEXCOORD" if name.startswith("TEXCOORD_") else name
    if key not in ATTRIBUTE_COMPONENTS:
        return
    found = (accessor["componentType"], bool(accessor.get("normalized", False)))
    if found not in ATTRIBUTE_COMPONENTS[key]:
        allowed = sorted({("normalized " if n else "") + _TYPE_NAMES[t] for t, n in ATTRIBUTE_COMPONENTS[key]})
        raise SceneFileError(path, f"{name} of {'normalized ' if found[1] else ''}{_TYPE_NAMES[found[0]]} components: "
                             f"the glTF specification and KHR_mesh_quantization allow {', '.join(allowed)}", where)


def variant_index(document, variant, source):
    """The index of ``KHR_materials_variants`` variant ``variant`` (a name), or None for ``variant=None``.

    Raises
    ------
    ValueError
        The file has no variant of that name (the message lists those it has), or no variants at all.
    """
    if variant is None:
        return None
    names = [v["name"] for v in document.get("extensions", {}).get("KHR_materials_variants", {}).get("variants", [])]
    if variant not in names:
        having = f"its variants are {', '.join(map(repr, names))}" if names else "it has no KHR_materials_variants"
        raise ValueError(f"{source}: no material variant named {variant!r}: {having}")
    return names.index(variant)


def primitive_material(primitive, variant):
    """The material index a primitive is drawn with: the mapping of ``variant`` (an index, `variant_index`) where one
    names it, else the primitive's own ``material`` (or None)."""
    if variant is not None:
        block = primitive.get("extensions", {}).get("KHR_materials_variants", {})
        for mapping in block.get("mappings", []):
            if variant in mapping["variants"]:
                return mapping["material"]
    return primitive.get("material")


def texture_infos(entry, where):
    """``(JSON path, textureInfo)`` of every texture glphong reads from a material entry: any ``...Texture`` object
    with an ``index`` in the entry, its ``pbrMetallicRoughness`` and the extensions it applies (`APPLIED`; the
    textures of an extension it does not apply are not drawn, whatever their set)."""
    out, stack = [], [(entry, where)]
    while stack:
        holder, path = stack.pop()
        for key, value in holder.items():
            if not isinstance(value, dict):
                continue
            if key.endswith("Texture") and "index" in value:
                out.append((f"{path}.{key}", value))
            elif key in ("pbrMetallicRoughness", "extensions") or key in APPLIED:
                stack.append((value, f"{path}.{key}"))
    return sorted(out, key=lambda item: item[0])


def _uv_set(info):
    """The texture coordinate set a textureInfo reads (its KHR_texture_transform's ``texCoord`` overrides its own)."""
    transform = info.get("extensions", {}).get("KHR_texture_transform")
    chosen = transform.get("texCoord") if isinstance(transform, dict) else None
    chosen = info.get("texCoord", 0) if chosen is None else chosen
    return chosen if isinstance(chosen, int) and not isinstance(chosen, bool) and chosen >= 0 else 0


def material_uv_set(entry):
    """The set every texture of a material entry reads (0 where it has none), or None where they differ."""
    sets = {_uv_set(info) for _, info in texture_infos(entry, "")}
    return sets.pop() if len(sets) == 1 else 0 if not sets else None


def check_one_uv_set(path, entry, where):
    """Raise `SceneFileError` where a material's textures read different texture coordinate sets (naming them)."""
    if material_uv_set(entry) is None:
        listed = ", ".join(f"{p.lstrip('.')} TEXCOORD_{_uv_set(info)}" for p, info in texture_infos(entry, ""))
        raise SceneFileError(path, f"its textures read different texture coordinate sets ({listed}): glphong draws "
                             "one set per material; give this material with load_scene(..., materials={name: ...})",
                             where)
