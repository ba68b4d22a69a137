"""KHR_materials_clearcoat's own normal texture, ``clearcoatNormalTexture``, on `GltfPBR` (docs/gltf_extensions.md;
GLSL: ``glsl/materials/gltf_pbr.glsl`` under ``GLTF_PBR_CLEARCOAT_NORMAL``).  The extension gives the coat that texture's
normal, or the unperturbed normal where there is none, even where the base has a normal texture::

    m = 2 clearcoat_normal - 1,  n_c = normalize(t (s m.x) + b (s m.y) + n m.z)    s = clearcoatNormalTexture.scale
    f_r (n.l) (1 - w) + w D_c V_c (n_c.l),  w = clearcoat F_c(max(n_c.v, 0)),  D_c, V_c on n_c (0 where n_c.l <= 0 or
    n_c.v <= 0)

``(t, b, n)`` is the unperturbed frame: the interpolated normal and the tangent frame built on it, before the base's
``normal_map`` (whose own texel perturbs the base's ``n``, `f_r`'s).  Where the material has a ``normal_map`` the coat
has its own normal even at the default texel (the unperturbed normal itself, as the extension says and three.js
draws it), and the material needs ``'unperturbed'``: the radiance program keeps that frame (glsl/normal_map.glsl's
``unperturbed_frame``), the G-buffer its normal (the 'unperturbed' plane) and the twin reads it as ``f.unperturbed``
(`glphong.checks.reference.shade_inputs`).  The formula of ``n_c`` is the base normal map's
(`glphong.twin.functions.surface_normal`, glsl/normal_map.glsl).
"""
import numpy as np

from glphong.definitions.material_base import constant_part
from glphong.definitions.params import Param
from glphong.definitions.surface import SurfaceInput
from glphong.twin.functions import dot as _dot, microfacet_geometry, surface_normal

__all__ = ["COAT_NORMAL_PARAMS", "UNPERTURBED", "gltf_clearcoat_normal", "gltf_clearcoat_geometry",
           "uses_coat_normal", "coat_normal_oracle"]

#: the texel of an unperturbed normal: m = (0, 0, 1)
UNPERTURBED = (0.5, 0.5, 1.0)
_COAT_NORMAL = Param("clearcoat_normal", "rgb", low=0.0, high=1.0, default=UNPERTURBED, unit="", textureable=True,
                     doc="KHR_materials_clearcoat clearcoatNormalTexture's texel (linear): the coat's tangent-space "
                         "normal 2 texel - 1 on the unperturbed frame; (0.5, 0.5, 1): the unperturbed normal")
_COAT_NORMAL_SCALE = Param("clearcoat_normal_strength", "scalar", low=-1e4, high=1e4, default=1.0, unit="",
                           doc="KHR_materials_clearcoat clearcoatNormalTexture.scale: scales the normal's x and y")
#: the coat normal's parameters, appended to `GltfPBR`'s
COAT_NORMAL_PARAMS = (_COAT_NORMAL, _COAT_NORMAL_SCALE)


def uses_coat_normal(material):
    """True where a coated `GltfPBR`'s coat normal differs from its shading normal: a coat normal other than the
    unperturbed one (textured, or a constant texel other than `UNPERTURBED`), or a base ``normal_map`` (the coat then
    keeps the unperturbed normal, or its own on the unperturbed frame), also over KHR_materials_transmission (the coat
    weights the light let through on ``n_c``: transmission_thin.glsl)."""
    value = material.clearcoat_normal
    return isinstance(value, SurfaceInput) and value.texture is not None or material.normal_map is not None or \
        bool(np.any(np.asarray(constant_part(value), np.float64) != UNPERTURBED))


def unperturbed_frame(f):
    """The frame the coat's normal is taken on: ``f.unperturbed``, the frame before the base's normal map, where the
    twin has it (normal_map.glsl's ``unperturbed_frame``), else ``f`` itself (no normal map perturbed it)."""
    unperturbed = getattr(f, "unperturbed", None)
    return f if unperturbed is None else unperturbed


def gltf_clearcoat_normal(f, p, dtype):
    """The coat's own normal ``n_c`` (gltf_pbr.glsl's ``gltf_clearcoat_normal``): normal_map.glsl's
    `surface_normal` of the texel ``p.clearcoat_normal`` and scale ``p.clearcoat_normal_strength`` on
    `unperturbed_frame` ``(t, b, n)`` of ``f``, in ``dtype``; (N, 3) unit."""
    g = unperturbed_frame(f)
    n = np.asarray(g.n, dtype)
    texel = np.broadcast_to(np.asarray(p.clearcoat_normal, dtype), n.shape)
    return surface_normal(n, np.asarray(g.t, dtype), np.asarray(g.b, dtype), texel,
                          np.asarray(p.clearcoat_normal_strength, dtype)[()])


def gltf_clearcoat_geometry(f, wi, wo, p, dtype):
    """The coat's geometry on its own normal (gltf_pbr.glsl's order): ``(valid, n_c.l, n_c.v, tan2, fresnel_cos)``,
    each (N,): `microfacet_geometry` on ``n_c`` (`gltf_clearcoat_normal`; valid where ``n_c.l > 0``, ``n_c.v > 0``)
    and ``max(n_c.v, 0)``, the cosine of the coat's Fresnel (the extension's ``clampedDot``)."""
    n_c = gltf_clearcoat_normal(f, p, dtype)
    wi, wo = np.asarray(wi, dtype), np.asarray(wo, dtype)
    n_dot_l = _dot(n_c, wi).astype(dtype)
    valid, n_dot_v, _, _, tan2 = microfacet_geometry(n_c, wi, wo, n_dot_l)
    return valid, n_dot_l, n_dot_v, tan2, np.maximum(_dot(n_c, wo), dtype.type(0)).astype(dtype)


def coat_normal_oracle(f, wi, wo, p):
    """The coat's normal and dot products in mpmath from the extension's text: ``(n_c.l, n_c.v, n_c.h)`` with ``h =
    normalize(l + v)``, and ``n_c`` from the unperturbed frame of ``f`` (lists; `unperturbed_frame`) and the texel
    ``p.clearcoat_normal``."""
    import mpmath  # noqa: PLC0415 - the stability suite's, kept out of import time

    dot = lambda a, c: sum(x * y for x, y in zip(a, c))  # noqa: E731
    m = [2 * mpmath.mpf(float(c)) - 1 for c in np.broadcast_to(np.asarray(p.clearcoat_normal, np.float64), 3)]
    s = mpmath.mpf(float(p.clearcoat_normal_strength))
    g = unperturbed_frame(f)
    q = [tx * s * m[0] + bx * s * m[1] + nx * m[2] for tx, bx, nx in zip(g.t, g.b, g.n)]
    length = mpmath.sqrt(dot(q, q))
    n_c = [x / length for x in q] if length > 0 else list(g.n)
    h = [a + c for a, c in zip(wi, wo)]
    h = [x / mpmath.sqrt(dot(h, h)) for x in h]
    return dot(n_c, wi), dot(n_c, wo), dot(n_c, h)
