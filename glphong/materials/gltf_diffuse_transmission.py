"""KHR_materials_diffuse_transmission on `glphong.GltfPBR` (docs/gltf_extensions.md; GLSL: ``glsl/materials/
gltf_pbr.glsl`` under the structural define ``GLTF_PBR_DIFFUSE_TRANSMISSION``).  The extension's dielectric::

    fresnel_mix(ior, base = mix(diffuse_brdf(c), diffuse_btdf(diffuse_transmission_color), dt), layer = specular_brdf)

``dt`` the diffuse transmission, ``diffuse_btdf(color) = color / pi`` for light on the far side, 0 on the viewer's.
So a light in front (``n.l > 0``) sees the core's diffuse times ``1 - dt``; a point, spot or directional light behind
the surface (``n.wi < 0``) sends, with its irradiance ``E`` and ``n_dot_l = -n.wi``::

    (1 - m) (1 - t) dt (c_dt / pi) (1 - F(v.h')) n_dot_l E,   l' = wi + 2 n_dot_l n (the light mirrored),
    h' = normalize(l' + v),  F = f0 + (1 - f0) (1 - v.h')^5,  f0 = ((ior - 1)/(ior + 1))^2

(``t`` KHR_materials_transmission's weight, which overrides the diffuse transmission: the extension's combined
formula; the Fresnel at the mirrored half vector is the glTF Sample Viewer's).  With KHR_materials_specular the
diffuse BTDF sits in ``fresnel_mix``'s base under the specular's ``F`` (`gltf_transmission_fresnel`), so ``1 - F``
becomes ``1 - max3(F_specular(v.h'))``; KHR_materials_sheen and _clearcoat multiply it by
`gltf_transmission_layers` ``(n.v, n_dot_l)``, as they weight the transmission's lights behind, and
KHR_materials_iridescence replaces ``F`` by the film's ``F' = mix(F, F_iridescence, iridescence)`` (``1 - max3(F')``,
as the specification's rgb_mix weights its base; docs/transmission.md, "Layers over transmission").  It is added by the light loops of
the transmissive programs (`glphong.shaders.generated.lights_chunk`, glphong/gpu/transmission.py) and their twin
(`glphong.checks.transmission_twin`).

=========================== ====== ======= ======= ==================================================================
parameter                   kind   range   neutral meaning
=========================== ====== ======= ======= ==================================================================
diffuse_transmission        scalar [0, 1]  0       ``diffuseTransmissionFactor`` times ``diffuseTransmissionTexture.a``
diffuse_transmission_color  rgb    [0, 1]  1       ``diffuseTransmissionColorFactor`` times its texture (sRGB)
=========================== ====== ======= ======= ==================================================================
"""
import numpy as np

from glphong.definitions.material_base import constant_part
from glphong.definitions.params import Param
from glphong.definitions.surface import SurfaceInput
from glphong.materials.gltf_transmission import _coat_cosine, gltf_transmission_fresnel, gltf_transmission_layers
from glphong.twin.functions import microfacet_geometry

__all__ = ["DIFFUSE_TRANSMISSION_PARAMS", "gltf_diffuse_transmission_response",
           "diffuse_transmission_gltf_fields"]

_DT = Param("diffuse_transmission", "scalar", low=0.0, high=1.0, default=0.0, unit="", textureable=True,
            doc="KHR_materials_diffuse_transmission diffuseTransmissionFactor (times diffuseTransmissionTexture.a): "
                "the diffuse's share transmitted to the far side")
_DT_COLOR = Param("diffuse_transmission_color", "rgb", low=0.0, high=1.0, default=1.0, unit="", textureable=True,
                  doc="KHR_materials_diffuse_transmission diffuseTransmissionColorFactor (times its texture, sRGB): "
                      "the colour of the diffusely transmitted light")
#: the extension's parameters, appended to `GltfPBR`'s (`glphong.materials.gltf_extensions`)
DIFFUSE_TRANSMISSION_PARAMS = (_DT, _DT_COLOR)


def gltf_diffuse_transmission_response(n, wi, wo, n_dot_l, c_dt, m, t, dt, ior, specular=None, layers=None,
                                       film=None):
    """The diffuse BTDF of a punctual light behind the surface times ``n_dot_l = -n.wi > 0`` (gltf_pbr.glsl's
    ``gltf_diffuse_transmission_response``): ``(1 - m) (1 - t) dt (c_dt / pi) (1 - max3(F(v.h'))) n_dot_l keep``
    (module docstring), ``F`` `glphong.materials.gltf_transmission.gltf_transmission_fresnel` (with
    KHR_materials_specular its ``fresnel_mix`` F, with KHR_materials_iridescence the film's F'), ``keep`` `glphong.materials.gltf_transmission.gltf_transmission_layers`
    ``(n.v, n_dot_l)`` (the sheen's and the coat's).

    Parameters
    ----------
    n, wi, wo : (N, 3) ndarray
        Unit normal, direction toward the light (behind: ``n.wi < 0``) and toward the viewer.
    n_dot_l : (N,) ndarray
        ``-n.wi``.
    c_dt : (N, 3) or (3,) ndarray
        The diffuse transmission colour.
    m, t, dt, ior : (N,) ndarray or float
        Metallic, transmission, diffuse transmission, index of refraction.
    specular : tuple, optional
        ``(specular, specular_color)``, (N,) and (N, 3) or (3,): KHR_materials_specular's; None without it.
    layers : dict, optional
        `gltf_transmission_layers`' keywords (the coat's own normal as ``coat_normal`` (N, 3)); None: no layers.
    film : dict, optional
        KHR_materials_iridescence's (`gltf_transmission_fresnel`'s ``film``); None without it.

    Returns
    -------
    (N, 3) float64 ndarray [1/sr]
    """
    n_dot_l = np.asarray(n_dot_l, np.float64)
    mirrored = wi + (2.0 * n_dot_l)[:, None] * n
    valid, n_dot_v, _, v_dot_h, _ = microfacet_geometry(n, mirrored, wo, n_dot_l)
    fresnel = np.max(gltf_transmission_fresnel(ior, v_dot_h, *(specular or (None, None)), film), axis=-1)
    scale = (1.0 - np.asarray(m, np.float64)) * (1.0 - np.asarray(t, np.float64)) * np.asarray(dt, np.float64)
    value = np.asarray(c_dt, np.float64) * ((scale * (1.0 / np.pi)) * (1.0 - fresnel) * n_dot_l)[:, None]
    keep = gltf_transmission_layers(n_dot_v, n_dot_l, **_coat_cosine(layers, wo))
    return np.where(valid[:, None], value * keep[:, None], 0.0)


def diffuse_transmission_gltf_fields(material, texture_index):
    """``{"KHR_materials_diffuse_transmission": {...}}`` for a `GltfPBR` that uses the extension, else ``{}``: the
    factors, ``diffuseTransmissionTexture`` where the weight is textured (``texture_index(image, alpha=channel)``: an
    image whose alpha holds the channel the weight reads, as glTF reads it) and ``diffuseTransmissionColorTexture``
    where the colour is (sRGB)."""
    if "diffuse_transmission" not in material.extensions():
        return {}
    weight, color = material.diffuse_transmission, material.diffuse_transmission_color
    fields = {"diffuseTransmissionFactor": float(constant_part(weight)),
              "diffuseTransmissionColorFactor": [float(c) for c in np.broadcast_to(constant_part(color), 3)]}
    if isinstance(weight, SurfaceInput) and weight.texture is not None:
        fields["diffuseTransmissionTexture"] = {"index": texture_index(weight.texture, alpha=weight.channel)}
    if isinstance(color, SurfaceInput) and color.texture is not None:
        fields["diffuseTransmissionColorTexture"] = {"index": texture_index(color.texture)}
    return {"KHR_materials_diffuse_transmission": fields}
