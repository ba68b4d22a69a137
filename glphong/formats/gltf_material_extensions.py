"""The KHR_materials extensions glphong applies to a glTF material, read from a file's JSON (`extension_arguments`) and
validated with their JSON paths (`check_material_extensions`): ``KHR_materials_specular``,
``KHR_materials_clearcoat`` and ``KHR_materials_sheen`` as `glphong.GltfPBR`'s parameters
(`glphong.materials.gltf_extensions`, `glphong.materials.gltf_sheen`, docs/gltf_extensions.md).

- ``specular = specularFactor * specularTexture.a`` (linear), ``specular_color = specularColorFactor *
  specularColorTexture.rgb`` (sRGB);
- ``clearcoat = clearcoatFactor * clearcoatTexture.r``, ``clearcoat_roughness = clearcoatRoughnessFactor *
  clearcoatRoughnessTexture.g`` (linear); ``clearcoatNormalTexture``: glphong's coat takes the material's shading
  normal, so a coat normal other than the base's normal texture is named in a warning;
- ``sheen_color = sheenColorFactor * sheenColorTexture.rgb`` (sRGB), ``sheen_roughness = sheenRoughnessFactor *
  sheenRoughnessTexture.a`` (linear); ``sheenColorFactor`` 0 (the default) disables the layer.
"""
import numpy as np

from glphong.materials import Texture

__all__ = ["MATERIAL_EXTENSIONS", "extension_arguments", "check_material_extensions", "extension_texture_infos"]

#: the material extensions read here, each with its textures (key, what glphong reads of it)
MATERIAL_EXTENSIONS = {
    "KHR_materials_specular": (("specularTexture", "alpha"), ("specularColorTexture", "srgb")),
    "KHR_materials_clearcoat": (("clearcoatTexture", "r"), ("clearcoatRoughnessTexture", "g"),
                                ("clearcoatNormalTexture", "normal")),
    "KHR_materials_sheen": (("sheenColorTexture", "srgb"), ("sheenRoughnessTexture", "alpha")),
}
_FACTORS = {"KHR_materials_specular": (("specularFactor", 1, 0.0, 1.0), ("specularColorFactor", 3, 0.0, np.inf)),
            "KHR_materials_clearcoat": (("clearcoatFactor", 1, 0.0, 1.0), ("clearcoatRoughnessFactor", 1, 0.0, 1.0)),
            "KHR_materials_sheen": (("sheenColorFactor", 3, 0.0, 1.0), ("sheenRoughnessFactor", 1, 0.0, 1.0))}


def check_material_extensions(c, extensions, where, texture_ref):
    """Validate the extensions of `MATERIAL_EXTENSIONS` in a material's ``extensions`` object: objects, factors finite
    and in range, texture references (``texture_ref(c, ref, where)``); ``c`` the validator (its ``fail`` names the file
    and the JSON path)."""
    for name, textures in MATERIAL_EXTENSIONS.items():
        entry = extensions.get(name)
        if entry is None:
            continue
        path = f"{where}.extensions.{name}"
        c.obj(entry, path)
        for key, count, low, high in _FACTORS[name]:
            if key in entry:
                if count == 1:
                    c.number(entry[key], f"{path}.{key}", low, high)
                else:
                    c.numbers(entry[key], f"{path}.{key}", count, low, high)
        for key, _ in textures:
            if key in entry:
                texture_ref(c, entry[key], f"{path}.{key}")
        if "scale" in entry.get("clearcoatNormalTexture", {}):
            c.number(entry["clearcoatNormalTexture"]["scale"], f"{path}.clearcoatNormalTexture.scale")


def extension_texture_infos(entry):
    """The ``textureInfo`` objects of a material's applied extensions (list of dict), for what all its textures share
    (their texture transform)."""
    extensions = entry.get("extensions", {})
    return [extensions[name][key] for name, textures in MATERIAL_EXTENSIONS.items() if name in extensions
            for key, _ in textures if isinstance(extensions[name].get(key), dict)]


def extension_arguments(entry, texture, warn):
    """`glphong.GltfPBR`'s keyword arguments for the extensions of a validated glTF material ``entry`` (dict).

    Parameters
    ----------
    entry : dict
        The material's JSON entry.
    texture : callable
        ``texture(info, srgb, alpha=False)``: the `TextureImage` of a ``textureInfo`` (None where it cannot be read).
    warn : callable
        ``warn(message)``: what the file asks that glphong draws otherwise.
    """
    extensions = entry.get("extensions", {})
    out = {}
    specular = extensions.get("KHR_materials_specular")
    if specular is not None:
        factor = float(specular.get("specularFactor", 1.0))
        color = tuple(float(c) for c in specular.get("specularColorFactor", (1.0, 1.0, 1.0)))
        image = texture(specular["specularTexture"], False, True) if "specularTexture" in specular else None
        out["specular"] = Texture(image, factor, channel="r") if image is not None else factor
        image = texture(specular["specularColorTexture"], True) if "specularColorTexture" in specular else None
        out["specular_color"] = Texture(image, color) if image is not None else color
    coat = extensions.get("KHR_materials_clearcoat")
    if coat is not None and float(coat.get("clearcoatFactor", 0.0)) > 0:  # 0: the whole layer is disabled
        for name, key, factor_key, channel in (("clearcoat", "clearcoatTexture", "clearcoatFactor", "r"),
                                               ("clearcoat_roughness", "clearcoatRoughnessTexture",
                                                "clearcoatRoughnessFactor", "g")):
            factor = float(coat.get(factor_key, 0.0))
            image = texture(coat[key], False) if key in coat else None
            out[name] = Texture(image, factor, channel=channel) if image is not None else factor
        base_normal = entry.get("normalTexture", {}).get("index")
        coat_normal = coat.get("clearcoatNormalTexture", {}).get("index")
        if base_normal != coat_normal:
            warn("KHR_materials_clearcoat: glphong's coat takes the material's shading normal ("
                 + ("its normalTexture" if base_normal is not None else "the unperturbed normal") + "), the file's coat "
                 + (f"normal is texture {coat_normal}" if coat_normal is not None else "the unperturbed normal"))
    sheen = extensions.get("KHR_materials_sheen")
    if sheen is not None and any(float(c) > 0 for c in sheen.get("sheenColorFactor", (0.0, 0.0, 0.0))):
        color = tuple(float(c) for c in sheen["sheenColorFactor"])  # all 0 (the default): the layer is disabled
        factor = float(sheen.get("sheenRoughnessFactor", 0.0))
        image = texture(sheen["sheenColorTexture"], True) if "sheenColorTexture" in sheen else None
        out["sheen_color"] = Texture(image, color) if image is not None else color
        image = texture(sheen["sheenRoughnessTexture"], False, True) if "sheenRoughnessTexture" in sheen else None
        out["sheen_roughness"] = Texture(image, factor, channel="r") if image is not None else factor
    return out
