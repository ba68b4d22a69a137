"""pyrender materials that draw with glphong's: `GlphongMaterial`, and `gltf_pbr_of` to convert pyrender's
metallic-roughness material to glTF's material as its specification writes it (`glphong.GltfPBR`)."""
import threading

import numpy as np
import pyrender

from glphong.core.validate import scalar
from glphong.formats.gltf_data import gl_sampling
from glphong.materials import GltfPBR, Material, NormalMap, Texture, TextureImage, VertexColors
from glphong.materials.gltf_transmission import transmissive

__all__ = ["GlphongMaterial", "gltf_pbr_of", "DRAWING"]


class GlphongMaterial(pyrender.Material):
    """A pyrender material that draws its primitives with a glphong material.

    Parameters
    ----------
    material : glphong.Material
        Any glphong material: `Lambert`, `Phong`, `BlinnPhong` or a user's `MaterialModel`/`MaterialSum`; not a blended
        one (``alpha_blend``: ValueError).
    exposure : float
        Linear scale before the sRGB encoding into pyrender's 8-bit framebuffer, > 0.
    name : str, optional
    """

    def __init__(self, material, exposure=1.0, name=None):
        if not isinstance(material, Material):
            raise TypeError(f"material must be a glphong material such as glphong.Phong (got {type(material).__name__})")
        if material.alpha_blend is not None:
            raise ValueError(f"{material!r} blends (alpha_blend): pyrender's passes draw glphong's materials opaque, so "
                             "the embedding refuses it rather than draw it wrong; composite it with glphong.Renderer "
                             "(depth peeling, docs/design.md section 16), or give the material alpha_mask= instead")
        if transmissive(material):
            names = " and ".join(f"KHR_materials_{name}" for name in material.extensions()
                                 if name in ("transmission", "diffuse_transmission"))
            raise ValueError(f"{material!r} transmits ({names}): pyrender's passes have no image of the opaque scene "
                             "to see through it, nor its lights behind the surface, so the embedding refuses it rather "
                             "than draw it wrong; draw it with glphong.Renderer (docs/transmission.md)")
        super().__init__(name=name, doubleSided=material.two_sided)
        self.glphong = material
        self.exposure = scalar("exposure", exposure, low=0.0, low_inclusive=False)

    def __repr__(self):
        return f"GlphongMaterial({self.glphong!r}, exposure={self.exposure:g})"

    @classmethod
    def from_pyrender(cls, material, exposure=1.0, vertex_colors=False):
        """The `GlphongMaterial` of a ``pyrender.MetallicRoughnessMaterial``: `gltf_pbr_of` it (glTF's Appendix B with
        its textures), to swap into a pyrender scene."""
        return cls(gltf_pbr_of(material, vertex_colors), exposure=exposure, name=material.name)

    @property
    def tex_flags(self):
        """pyrender reads this while drawing the primitive: only a renderer `enable` d may draw it."""
        if not getattr(DRAWING, "enabled", False):
            raise RuntimeError(
                f"{self!r} is drawn by a pyrender renderer that glphong was not enabled on (pyrender would "
                "draw it black or with garbage): call glphong.integrations.pyrender.enable(renderer) once "
                "after creating the OffscreenRenderer, or enable_everywhere() before it is created")
        return pyrender.Material.tex_flags.fget(self)


#: ``DRAWING.enabled``: set while a renderer glphong is enabled on draws (per thread)
DRAWING = threading.local()


def gltf_pbr_of(material, vertex_colors=False):
    """The `glphong.GltfPBR` of a ``pyrender.MetallicRoughnessMaterial`` (glTF's metallic-roughness, as pyrender holds
    it): ``baseColorFactor`` (rgb) times ``baseColorTexture`` (sRGB) times ``COLOR_0`` (``vertex_colors``: the
    primitive has them; glTF's rule, where pyrender 0.1.45 multiplies its whole result); ``metallicFactor`` and ``roughnessFactor``
    times the metallic-roughness texture's blue and green channels (pyrender keeps them as its two channels 'GB');
    ``emissiveFactor`` times ``emissiveTexture`` (sRGB); ``occlusionTexture``'s red channel; each texture's sampler
    (`glphong.formats.gltf_data.gl_sampling`); ``doubleSided`` as ``two_sided``; ``normalTexture`` as a
    `glphong.NormalMap` (pyrender keeps no normal scale: 1).  Alpha is not applied.

    Raises
    ------
    TypeError
        Another kind of pyrender material (a ``SpecularGlossinessMaterial``).
    """
    if not isinstance(material, pyrender.MetallicRoughnessMaterial):
        raise TypeError(f"glphong converts pyrender.MetallicRoughnessMaterial (glTF's metallic-roughness), not "
                        f"{type(material).__name__}")

    def image(texture, channels, srgb):
        if texture is None:
            return None
        pixels = np.asarray(texture.source)
        pixels = pixels[..., None] if pixels.ndim == 2 else pixels
        rgb = np.zeros(pixels.shape[:2] + (3,), pixels.dtype)
        for source, target in enumerate(channels):  # pyrender's channels, back in the places glTF gives them
            rgb[..., "rgb".index(target)] = pixels[..., source]
        wrap, filter_ = gl_sampling(texture.sampler.wrapS, texture.sampler.minFilter)
        return TextureImage(rgb, srgb=srgb, wrap=wrap, filter=filter_)

    base = tuple(np.clip(np.asarray(material.baseColorFactor, np.float64)[:3], 0.0, 1.0))
    texture = image(material.baseColorTexture, "rgb", True)
    base_color = Texture(texture, scale=base, vertex_colors=vertex_colors) if texture is not None else \
        VertexColors(scale=base) if vertex_colors else base
    metallic = min(float(material.metallicFactor), 1.0)
    roughness = min(float(material.roughnessFactor), 1.0)
    texture = image(material.metallicRoughnessTexture, "gb", False)
    if texture is not None:
        metallic, roughness = Texture(texture, metallic, channel="b"), Texture(texture, roughness, channel="g")
    emissive = tuple(np.asarray(material.emissiveFactor, np.float64))
    texture = image(material.emissiveTexture, "rgb", True) if any(emissive) else None
    emissive = Texture(texture, scale=emissive) if texture is not None else emissive
    texture = image(material.occlusionTexture, "r", False)
    occlusion = Texture(texture, channel="r") if texture is not None else 1.0
    texture = image(material.normalTexture, "rgb", False)
    return GltfPBR(base_color, metallic, roughness, emissive=emissive, occlusion=occlusion,
                   two_sided=bool(material.doubleSided), normal_map=NormalMap(texture) if texture is not None else None)
