"""``KHR_materials_transmission``, ``KHR_materials_volume`` and ``KHR_materials_dispersion`` read from a glTF material
(`glphong.materials.gltf_transmission`, docs/transmission.md), as `glphong.GltfPBR` parameters:

- ``transmission = transmissionFactor * transmissionTexture.r`` (linear); ``transmissionFactor`` 0 (the default)
  leaves the material opaque;
- ``thickness = thicknessFactor * thicknessTexture.g`` (linear, the mesh's units), ``attenuation_distance =
  attenuationDistance`` (absent: the specification's +Infinity, held as FLT_MAX), ``attenuation_color =
  attenuationColor`` (linear); ``thicknessFactor`` 0 (the default) is a thin wall;
- ``dispersion`` (``20 / V_d``), which changes only a volume's refraction;
- ``KHR_materials_diffuse_transmission``: ``diffuse_transmission = diffuseTransmissionFactor *
  diffuseTransmissionTexture.a``, ``diffuse_transmission_color = diffuseTransmissionColorFactor *
  diffuseTransmissionColorTexture`` (sRGB; `glphong.materials.gltf_diffuse_transmission`); its factor 0 (the default)
  leaves the material opaque.

Validated with the other applied material extensions (`glphong.formats.gltf_material_extensions`: factors finite and in
range, with their JSON paths; texture references).
"""
from glphong.materials import Texture
from glphong.twin.band import FLT_MAX

__all__ = ["TRANSMISSION_TEXTURES", "TRANSMISSION_FACTORS", "transmission_arguments"]

#: the extensions' textures (extension -> (key, what glphong reads of it))
TRANSMISSION_TEXTURES = {"KHR_materials_transmission": (("transmissionTexture", "r"),),
                         "KHR_materials_volume": (("thicknessTexture", "g"),),
                         "KHR_materials_dispersion": (),
                         "KHR_materials_diffuse_transmission": (("diffuseTransmissionTexture", "alpha"),
                                                                ("diffuseTransmissionColorTexture", "srgb"))}
#: their factors (extension -> (key, components, low, high)); attenuationDistance above 0 (the least positive float32
#: normal number: glphong holds it in float32)
TRANSMISSION_FACTORS = {"KHR_materials_transmission": (("transmissionFactor", 1, 0.0, 1.0),),
                        "KHR_materials_volume": (("thicknessFactor", 1, 0.0, FLT_MAX),
                                                 ("attenuationDistance", 1, 1.1754943508222875e-38, FLT_MAX),
                                                 ("attenuationColor", 3, 0.0, 1.0)),
                        "KHR_materials_dispersion": (("dispersion", 1, 0.0, 1e4),),
                        "KHR_materials_diffuse_transmission": (("diffuseTransmissionFactor", 1, 0.0, 1.0),
                                                               ("diffuseTransmissionColorFactor", 3, 0.0, 1.0))}


def _textured(entry, key, factor, texture, channel):
    image = texture(entry[key], False) if key in entry else None
    return Texture(image, factor, channel=channel) if image is not None else factor


def transmission_arguments(extensions, texture):
    """`glphong.GltfPBR`'s keywords for a validated material's ``extensions`` object (dict: empty where the material
    does not transmit; a volume or a dispersion without transmission changes nothing glphong draws, and is not read);
    ``texture(info, srgb)`` the `TextureImage` of a ``textureInfo`` (None where it cannot be read)."""
    out = _diffuse_transmission_arguments(extensions.get("KHR_materials_diffuse_transmission"), texture)
    entry = extensions.get("KHR_materials_transmission")
    if entry is None or float(entry.get("transmissionFactor", 0.0)) <= 0.0:
        return out
    out["transmission"] = _textured(entry, "transmissionTexture", float(entry["transmissionFactor"]), texture, "r")
    volume = extensions.get("KHR_materials_volume")
    if volume is not None and float(volume.get("thicknessFactor", 0.0)) > 0.0:
        out["thickness"] = _textured(volume, "thicknessTexture", float(volume["thicknessFactor"]), texture, "g")
        out["attenuation_distance"] = float(volume.get("attenuationDistance", FLT_MAX))
        out["attenuation_color"] = tuple(float(c) for c in volume.get("attenuationColor", (1.0, 1.0, 1.0)))
        out["dispersion"] = float(extensions.get("KHR_materials_dispersion", {}).get("dispersion", 0.0))
    return out


def _diffuse_transmission_arguments(entry, texture):
    """KHR_materials_diffuse_transmission's `glphong.GltfPBR` keywords (dict; none where its factor is 0, the
    default): the factor times the texture's alpha (read as a grey image, channel r), the colour factor times the
    colour texture (sRGB)."""
    if entry is None or float(entry.get("diffuseTransmissionFactor", 0.0)) <= 0.0:
        return {}
    factor = float(entry["diffuseTransmissionFactor"])
    color = tuple(float(c) for c in entry.get("diffuseTransmissionColorFactor", (1.0, 1.0, 1.0)))
    key = "diffuseTransmissionTexture"
    image = texture(entry[key], False, True) if key in entry else None
    out = {"diffuse_transmission": Texture(image, factor, channel="r") if image is not None else factor}
    key = "diffuseTransmissionColorTexture"
    image = texture(entry[key], True) if key in entry else None
    out["diffuse_transmission_color"] = Texture(image, color) if image is not None else color
    return out
