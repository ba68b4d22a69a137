"""The KHR_materials extensions glphong applies to a glTF material, read from a file's JSON (`extension_arguments`) and
validated with their JSON paths (`check_material_extensions`): ``KHR_materials_specular``,
``KHR_materials_clearcoat`` and ``KHR_materials_sheen`` as `glphong.GltfPBR`'s parameters
(`glphong.materials.gltf_extensions`, `glphong.materials.gltf_sheen`, docs/gltf_extensions.md).

- ``specular = specularFactor * specularTexture.a`` (linear), ``specular_color = specularColorFactor *
  specularColorTexture.rgb`` (sRGB);
- ``clearcoat = clearcoatFactor * clearcoatTexture.r``, ``clearcoat_roughness = clearcoatRoughnessFactor *
  clearcoatRoughnessTexture.g`` (linear); ``clearcoatNormalTexture`` (linear, its ``scale``) is the coat's own normal
  on the unperturbed frame, also over a ``normalTexture``, which perturbs the base alone (without it the coat keeps
  the unperturbed normal; `glphong.materials.gltf_coat_normal`);
- ``sheen_color = sheenColorFactor * sheenColorTexture.rgb`` (sRGB), ``sheen_roughness = sheenRoughnessFactor *
  sheenRoughnessTexture.a`` (linear); ``sheenColorFactor`` 0 (the default) disables the layer;
- ``iridescence = iridescenceFactor * iridescenceTexture.r``, ``iridescence_thickness_mix = iridescenceThicknessTexture.g``
  (linear; `glphong.materials.gltf_iridescence`); ``iridescenceFactor`` 0 (the default) disables the film;
- ``anisotropy_strength = anisotropyStrength * anisotropyTexture.b``, ``anisotropy_direction = anisotropyTexture.rgb``
  (linear; the material maps rg to [-1, 1]), ``anisotropy_rotation = anisotropyRotation`` (reduced to [-pi, pi];
  `glphong.materials.gltf_anisotropy`); ``anisotropyStrength`` 0 (the default) is isotropic.  The mesh's tangent frame
  is its ``TANGENT``, or computed from its UVs where it has none (as the specification asks of the normal texture's).
"""
import math

import numpy as np

from glphong.formats.gltf_transmission import TRANSMISSION_FACTORS, TRANSMISSION_TEXTURES, transmission_arguments
from glphong.core.filesafety import SceneFileError
from glphong.materials import Texture
from glphong.materials.gltf_coat_normal import COAT_NORMAL_PARAMS
from glphong.materials.gltf_extensions import EXTENSIONS

__all__ = ["MATERIAL_EXTENSIONS", "extension_arguments", "check_material_extensions", "extension_texture_infos",
           "tangent_frame_error"]

#: the material extensions read here, each with its textures (key, what glphong reads of it)
MATERIAL_EXTENSIONS = {
    "KHR_materials_specular": (("specularTexture", "alpha"), ("specularColorTexture", "srgb")),
    "KHR_materials_clearcoat": (("clearcoatTexture", "r"), ("clearcoatRoughnessTexture", "g"),
                                ("clearcoatNormalTexture", "normal")),
    "KHR_materials_sheen": (("sheenColorTexture", "srgb"), ("sheenRoughnessTexture", "alpha")),
    "KHR_materials_anisotropy": (("anisotropyTexture", "rgb"),),
    "KHR_materials_iridescence": (("iridescenceTexture", "r"), ("iridescenceThicknessTexture", "g")),
} | TRANSMISSION_TEXTURES  # KHR_materials_transmission, _volume, _dispersion: glphong.formats.gltf_transmission
_FACTORS = {"KHR_materials_specular": (("specularFactor", 1, 0.0, 1.0), ("specularColorFactor", 3, 0.0, np.inf)),
            "KHR_materials_clearcoat": (("clearcoatFactor", 1, 0.0, 1.0), ("clearcoatRoughnessFactor", 1, 0.0, 1.0)),
            "KHR_materials_sheen": (("sheenColorFactor", 3, 0.0, 1.0), ("sheenRoughnessFactor", 1, 0.0, 1.0)),
            "KHR_materials_anisotropy": (("anisotropyStrength", 1, 0.0, 1.0), ("anisotropyRotation", 1, -np.inf, np.inf)),
            "KHR_materials_iridescence": (("iridescenceFactor", 1, 0.0, 1.0), ("iridescenceIor", 1, 1.0, 1e4),
                                          ("iridescenceThicknessMinimum", 1, 0.0, 1e5),
                                          ("iridescenceThicknessMaximum", 1, 0.0, 1e5)),
} | TRANSMISSION_FACTORS
_COAT_NORMAL_SCALE = next(p for p in COAT_NORMAL_PARAMS if p.name == "clearcoat_normal_strength")


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
        if "scale" in entry.get("clearcoatNormalTexture", {}):  # the bounds of glphong's clearcoat_normal_strength
            c.number(entry["clearcoatNormalTexture"]["scale"], f"{path}.clearcoatNormalTexture.scale",
                     _COAT_NORMAL_SCALE.low, _COAT_NORMAL_SCALE.high)


def extension_texture_infos(entry):
    """The ``textureInfo`` objects of a material's applied extensions (list of dict), for what all its textures share
    (their texture transform)."""
    extensions = entry.get("extensions", {})
    return [extensions[name][key] for name, textures in MATERIAL_EXTENSIONS.items() if name in extensions
            for key, _ in textures if isinstance(extensions[name].get(key), dict)]


def tangent_frame_error(path, error, material, mesh, name, index):
    """The `SceneFileError` for the scene's refusal ``error`` (ValueError: `glphong.Scene.add`'s check of what the
    mesh serves) of primitive ``name`` where the mesh has no tangent frame (neither ``TANGENT`` nor texture coordinates
    to compute it from) and the material's extensions need it (KHR_materials_anisotropy, KHR_materials_clearcoat's
    ``clearcoatNormalTexture``: those whose structural define reads 'tangent'): it names them, with their JSON paths
    under ``materials[index]``.  ``error`` itself otherwise (its refusal is not an extension's)."""
    needing = [f"materials[{index}].extensions.{EXTENSIONS[short][0]}"
               + (".clearcoatNormalTexture" if short == "clearcoat_normal" else "")
               for term in material.components if hasattr(term, "structural_needs")
               for short in term.extensions()
               if "tangent" in term.structural_needs.get(f"{term.name.upper()}_{short.upper()}", ())]
    if mesh.has_tangents or not needing:
        return error
    return SceneFileError(path, f"primitive {name!r} uses {', '.join('.'.join(p.split('.')[2:]) for p in needing)} "
                          f"(materials[{index}]), which needs the mesh's tangent frame, but the mesh has neither "
                          "TANGENT nor TEXCOORD to compute it from (the extensions ask for TANGENT, or a normal texture "
                          f"and its texture coordinates): {error}", ", ".join(needing))


def _anisotropy_arguments(entry, texture):
    """KHR_materials_anisotropy's `glphong.GltfPBR` arguments (dict; none where ``anisotropyStrength`` is 0, the
    default: isotropic): the strength times the texture's blue channel, the texture's texel as the direction (its rg
    mapped to [-1, 1] by the material), the rotation reduced to [-pi, pi] (the same angle)."""
    if entry is None or float(entry.get("anisotropyStrength", 0.0)) == 0.0:
        return {}
    strength = float(entry["anisotropyStrength"])
    out = {"anisotropy_rotation": math.remainder(float(entry.get("anisotropyRotation", 0.0)), 2.0 * math.pi)}
    image = texture(entry["anisotropyTexture"], False) if "anisotropyTexture" in entry else None
    out["anisotropy_strength"] = Texture(image, strength, channel="b") if image is not None else strength
    if image is not None:
        out["anisotropy_direction"] = Texture(image, 1.0)
    return out


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
        image = texture(coat["clearcoatNormalTexture"], False) if "clearcoatNormalTexture" in coat else None
        if image is not None:  # the coat's own normal on the unperturbed frame, a normal-mapped base's too: exact
            out["clearcoat_normal"] = Texture(image, 1.0)
            out["clearcoat_normal_strength"] = float(coat["clearcoatNormalTexture"].get("scale", 1.0))
    sheen = extensions.get("KHR_materials_sheen")
    if sheen is not None and any(float(c) > 0 for c in sheen.get("sheenColorFactor", (0.0, 0.0, 0.0))):
        color = tuple(float(c) for c in sheen["sheenColorFactor"])  # all 0 (the default): the layer is disabled
        factor = float(sheen.get("sheenRoughnessFactor", 0.0))
        image = texture(sheen["sheenColorTexture"], True) if "sheenColorTexture" in sheen else None
        out["sheen_color"] = Texture(image, color) if image is not None else color
        image = texture(sheen["sheenRoughnessTexture"], False, True) if "sheenRoughnessTexture" in sheen else None
        out["sheen_roughness"] = Texture(image, factor, channel="r") if image is not None else factor
    out |= _anisotropy_arguments(extensions.get("KHR_materials_anisotropy"), texture)
    film = extensions.get("KHR_materials_iridescence")
    if film is not None and float(film.get("iridescenceFactor", 0.0)) > 0:  # 0 (the default): no film
        factor = float(film["iridescenceFactor"])  # iridescence = factor * texture.r, thickness = mix(min, max, .g)
        image = texture(film["iridescenceTexture"], False) if "iridescenceTexture" in film else None
        out["iridescence"] = Texture(image, factor, channel="r") if image is not None else factor
        image = texture(film["iridescenceThicknessTexture"], False) if "iridescenceThicknessTexture" in film else None
        out["iridescence_thickness_mix"] = Texture(image, 1.0, channel="g") if image is not None else 1.0
        out |= {"iridescence_ior": float(film.get("iridescenceIor", 1.3)),
                "iridescence_thickness_minimum": float(film.get("iridescenceThicknessMinimum", 100.0)),
                "iridescence_thickness_maximum": float(film.get("iridescenceThicknessMaximum", 400.0))}
    return out | transmission_arguments(extensions, texture)  # every layer is drawn over transmission too

