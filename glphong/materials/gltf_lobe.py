"""The GGX specular lobe glTF's material forms twice, for its base and for KHR_materials_clearcoat's coat (GLSL:
``glsl/materials/gltf_pbr.glsl``'s functions of the same names; docs/gltf_extensions.md)::

    gltf_pbr_visibility_cos(n.l, n.v, a2) = V (n.l) = n.l / (2 (n.v r_l + n.l r_v)),  r_x = sqrt((n.x)^2 + a2 (1 - (n.x)^2))
    gltf_pbr_specular(a2, tan2, n.l, n.v) = min(D V (n.l), FLT_MAX) for a2 > 0, 0 for a2 = 0 (roughness 0: a delta)

``D`` is the library's GGX (`glphong.twin.functions.microfacet_ggx`, ``tan2 = tan^2(theta_h)`` from the chord).
The coat's Fresnel, ``gltf_clearcoat_fresnel(n.v) = 0.04 + 0.96 (1 - n.v)^5``, is here too: the coat weights both the
base's reflection (`glphong.materials.gltf_extensions`) and the light a transmissive base lets through
(`glphong.materials.gltf_transmission`).
"""
import numpy as np

from glphong.twin.band import FLT_MAX
from glphong.twin.functions import microfacet_ggx

__all__ = ["gltf_pbr_visibility_cos", "gltf_pbr_specular", "gltf_clearcoat_fresnel", "CLEARCOAT_F0"]

#: the coat's f0: ((1 - 1.5)/(1 + 1.5))^2, fresnel_coat's fixed ior 1.5
CLEARCOAT_F0 = 0.04


def gltf_pbr_visibility_cos(n_dot_l, n_dot_v, a2):
    """``V (n.l) = n.l / (2 (n.v r_l + n.l r_v))``, ``r_x = sqrt((n.x)^2 + a2 (1 - (n.x)^2))`` (gltf_pbr.glsl).
    (...) each -> (...), dimensionless; the response's ``n.l`` cancels V's ``1/(n.l)``."""
    n_dot_l = np.asarray(n_dot_l)
    dtype = np.result_type(n_dot_l, n_dot_v)
    n_dot_l, n_dot_v, a2 = n_dot_l.astype(dtype), np.asarray(n_dot_v).astype(dtype), np.asarray(a2).astype(dtype)
    one = dtype.type(1)
    r_l = np.sqrt(n_dot_l * n_dot_l + a2 * (one - n_dot_l * n_dot_l))
    r_v = np.sqrt(n_dot_v * n_dot_v + a2 * (one - n_dot_v * n_dot_v))
    with np.errstate(divide="ignore", invalid="ignore"):
        return (n_dot_l / (dtype.type(2) * (n_dot_v * r_l + n_dot_l * r_v))).astype(dtype)


def gltf_pbr_specular(a2, tan2, n_dot_l, n_dot_v):
    """The GGX lobe ``D V (n.l)`` of the base and of the coat (gltf_pbr.glsl): ``min(D V (n.l), FLT_MAX)`` where ``a2 =
    alpha^2 > 0``, 0 where ``a2 = 0`` (D is a delta that a point light meets with zero measure, and V's ``r_x`` would
    underflow to 0/0 for grazing l and v).  a2 () or (N,), tan2, n_dot_l, n_dot_v (N,) -> (N,) [1/sr], in tan2's dtype."""
    tan2 = np.asarray(tan2)
    dtype = tan2.dtype
    a2 = np.asarray(a2).astype(dtype)
    n_dot_l = np.asarray(n_dot_l).astype(dtype)
    with np.errstate(over="ignore", under="ignore", invalid="ignore", divide="ignore"):
        value = np.minimum(microfacet_ggx(tan2, a2) * gltf_pbr_visibility_cos(n_dot_l, n_dot_v, a2), dtype.type(FLT_MAX))
        return np.where(a2 > 0, value, dtype.type(0)).astype(dtype)


def gltf_clearcoat_fresnel(n_dot_v):
    """KHR_materials_clearcoat's ``F_c = 0.04 + 0.96 (1 - n.v)^5`` (gltf_pbr.glsl; fresnel_coat with ior 1.5, on n.v).
    (...) -> (...), dimensionless."""
    n_dot_v = np.asarray(n_dot_v)
    dtype = n_dot_v.dtype if n_dot_v.dtype.kind == "f" else np.float64
    y1 = np.maximum(dtype.type(1) - n_dot_v.astype(dtype), dtype.type(0))
    y = ((y1 * y1) * (y1 * y1) * y1).astype(dtype)
    return (dtype.type(CLEARCOAT_F0) + dtype.type(1 - CLEARCOAT_F0) * y).astype(dtype)
