"""KHR_materials_anisotropy on `GltfPBR` (docs/gltf_extensions.md; GLSL: ``glsl/materials/gltf_pbr.glsl`` under
``GLTF_PBR_ANISOTROPY``): the twin's functions, the specification's formulas in mpmath for the stability suite, and
the stability cases.  With ``alpha = roughness^2``, ``s`` the strength, ``(t, b, n)`` the shading frame::

    d = rotate(normalize(2 texel.rg - 1), rotation)            the direction in tangent space ((1, 0) untextured)
    T = normalize(d.x t + d.y b),  B = normalize(n x T)        the rotated frame
    alpha_t = mix(alpha, 1, s^2),  alpha_b = alpha
    D = 1 / (pi alpha_t alpha_b ((T.h/alpha_t)^2 + (B.h/alpha_b)^2 + (n.h)^2)^2)         anisotropic GGX
    V = clamp(0.5 / (n.l |(alpha_t T.v, alpha_b B.v, n.v)| + n.v |(alpha_t T.l, alpha_b B.l, n.l)|), 0, 1)
    the base's specular lobe D V replaces the isotropic one (dielectric and metal alike; the coat keeps its own)

``D`` is the specification's ``a2 w2^2 / pi``, ``w2 = a2 / |(alpha_b T.h, alpha_t B.h, a2 n.h)|^2``, ``a2 = alpha_t
alpha_b``, divided through by ``a2^2``: a sum of positive terms, no cancellation.  ``alpha_t alpha_b = 0`` (roughness
0): the lobe is a delta along B that a point light meets with zero measure: 0, as the core's roughness 0.  A texel
whose direction is 0 (``rg = 0.5``) takes the tangent.  ``V``'s clamp at 1 is the specification's (Appendix B's
isotropic V has none): it acts where ``n.l |.| + n.v |.| < 1/2``, smooth and grazing.
"""
import numpy as np

from glphong.definitions.cases import Case, _mirror_eye, _unit
from glphong.definitions.params import Param
from glphong.twin.band import FLT_MAX
from glphong.twin.functions import dot as _dot, safe_normalize

__all__ = ["ANISOTROPY_PARAMS", "gltf_anisotropy_frame", "gltf_anisotropy_ggx", "gltf_anisotropy_visibility_cos",
           "gltf_anisotropy_specular", "gltf_anisotropy_layer", "gltf_anisotropy_oracle", "anisotropy_cases"]

_STRENGTH = Param("anisotropy_strength", "scalar", low=0.0, high=1.0, default=0.0, unit="", textureable=True,
                  doc="KHR_materials_anisotropy anisotropyStrength (times anisotropyTexture.b): alpha_t = mix(alpha, 1, "
                      "strength^2)")
_ROTATION = Param("anisotropy_rotation", "scalar", low=-1e4, high=1e4, default=0.0, unit="rad",
                  doc="KHR_materials_anisotropy anisotropyRotation: the direction's angle from the tangent, "
                      "counter-clockwise toward the bitangent")
_DIRECTION = Param("anisotropy_direction", "rgb", low=0.0, high=1.0, default=(1.0, 0.5, 1.0), unit="",
                   textureable=True,
                   doc="KHR_materials_anisotropy anisotropyTexture's texel (linear): r, g the direction in tangent space "
                       "mapped from [0, 1] to [-1, 1] (b unused: the strength reads it); (1, 0.5): the tangent")
#: the anisotropy's parameters, appended to `GltfPBR`'s
ANISOTROPY_PARAMS = (_STRENGTH, _ROTATION, _DIRECTION)


def gltf_anisotropy_frame(n, t, b, texel, rotation):
    """``(T, B)``, each (N, 3): the direction ``d = rotate(normalize(2 texel.rg - 1), rotation)`` in the frame ``(t, b,
    n)``, ``T = normalize(d.x t + d.y b)``, ``B = normalize(n x T)`` (gltf_pbr.glsl).  ``d = (1, 0)`` where the texel's
    direction is 0, ``T = t``, ``B = b`` where they do not normalise.  texel (3,) or (N, 3), rotation [rad] ()."""
    n = np.asarray(n)
    dtype = n.dtype
    one, two = dtype.type(1), dtype.type(2)
    texel = np.broadcast_to(np.asarray(texel, dtype), n.shape)
    raw = np.concatenate([texel[..., :2] * two - one, np.zeros_like(texel[..., :1])], axis=-1).astype(dtype)
    ok, d, _ = safe_normalize(raw)
    dx = np.where(ok, d[..., 0], one).astype(dtype)
    dy = np.where(ok, d[..., 1], dtype.type(0)).astype(dtype)
    rotation = np.asarray(rotation).astype(dtype)
    c, s = np.cos(rotation).astype(dtype), np.sin(rotation).astype(dtype)
    rx, ry = (c * dx - s * dy).astype(dtype), (s * dx + c * dy).astype(dtype)
    ok, tt, _ = safe_normalize((t * rx[..., None] + b * ry[..., None]).astype(dtype))
    tt = np.where(ok[..., None], tt, t).astype(dtype)
    ok, bb, _ = safe_normalize(np.cross(n, tt).astype(dtype))
    return tt, np.where(ok[..., None], bb, b).astype(dtype)


def gltf_anisotropy_ggx(n_dot_h, t_dot_h, b_dot_h, at, ab):
    """The specification's ``D_GGX_anisotropic`` as ``1 / (pi at ab s^2)``, ``s = (T.h/at)^2 + (B.h/ab)^2 + (n.h)^2``
    (gltf_pbr.glsl); not finite where ``at ab = 0`` (the caller's gate).  (...) each -> (...) [1/sr]."""
    n_dot_h = np.asarray(n_dot_h)
    dtype = n_dot_h.dtype
    with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
        x = (np.asarray(t_dot_h, dtype) / at).astype(dtype)
        y = (np.asarray(b_dot_h, dtype) / ab).astype(dtype)
        s = (x * x + y * y + n_dot_h * n_dot_h).astype(dtype)
        return (dtype.type(1 / np.pi) / ((at * ab) * (s * s))).astype(dtype)


def _length(x, y, z):
    """GLSL's ``length(vec3(x, y, z))``."""
    return np.sqrt(x * x + y * y + z * z)


def gltf_anisotropy_visibility_cos(n_dot_l, n_dot_v, t_dot_l, b_dot_l, t_dot_v, b_dot_v, at, ab):
    """The specification's ``V_GGX_anisotropic`` times ``n.l``: ``min(0.5 n.l / (n.l |(at T.v, ab B.v, n.v)| + n.v
    |(at T.l, ab B.l, n.l)|), n.l)`` (its ``clamp(V, 0, 1)``; gltf_pbr.glsl).  (...) each -> (...), dimensionless."""
    n_dot_l = np.asarray(n_dot_l)
    dtype = n_dot_l.dtype
    with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
        ggx_v = n_dot_l * _length(at * t_dot_v, ab * b_dot_v, n_dot_v)
        ggx_l = n_dot_v * _length(at * t_dot_l, ab * b_dot_l, n_dot_l)
        return np.minimum(dtype.type(0.5) * n_dot_l / (ggx_v + ggx_l), n_dot_l).astype(dtype)


def gltf_anisotropy_specular(t, b, wi, wo, n_dot_l, n_dot_v, n_dot_h, v_dot_h, alpha, strength):
    """The base's anisotropic lobe ``D V (n.l)`` (gltf_pbr.glsl): ``alpha_t = mix(alpha, 1, s^2)``, ``alpha_b =
    alpha``, ``T.h = (T.l + T.v)/(2 v.h)``, ``B.h`` likewise (``|l + v| = 2 v.h`` from `microfacet_geometry`, as its
    ``n.h``); ``min(., FLT_MAX)`` where ``alpha_t alpha_b > 0``, 0 where it is 0 (a delta).  t, b, wi, wo (N, 3);
    n_dot_l, n_dot_v, n_dot_h, v_dot_h (N,); alpha, strength () or (N,) -> (N,) [1/sr]."""
    n_dot_h = np.asarray(n_dot_h)
    dtype = n_dot_h.dtype
    t_dot_l, b_dot_l, t_dot_v, b_dot_v = (_dot(x, y).astype(dtype) for x, y in ((t, wi), (b, wi), (t, wo), (b, wo)))
    h_len = (dtype.type(2) * np.asarray(v_dot_h).astype(dtype)).astype(dtype)  # |l + v| (1 where invalid)
    alpha, strength = np.asarray(alpha).astype(dtype), np.asarray(strength).astype(dtype)
    at = (alpha * (dtype.type(1) - strength * strength) + strength * strength).astype(dtype)  # GLSL's mix
    ab = alpha
    a2 = (at * ab).astype(dtype)
    with np.errstate(over="ignore", invalid="ignore"):
        d = gltf_anisotropy_ggx(n_dot_h, ((t_dot_l + t_dot_v) / h_len).astype(dtype),
                                ((b_dot_l + b_dot_v) / h_len).astype(dtype), at, ab)
        v_cos = gltf_anisotropy_visibility_cos(np.asarray(n_dot_l).astype(dtype), np.asarray(n_dot_v).astype(dtype),
                                               t_dot_l, b_dot_l, t_dot_v, b_dot_v, at, ab)
        value = np.minimum(d * v_cos, dtype.type(FLT_MAX))
        return np.where(a2 > 0, value, dtype.type(0)).astype(dtype)


def gltf_anisotropy_layer(f, wi, wo, n_dot_l, n_dot_v, n_dot_h, v_dot_h, alpha, p):
    """`GltfPBR`'s twin with KHR_materials_anisotropy: the base's lobe ``D V (n.l)``, (N,), from the shading frame
    ``f`` (its ``t``, ``b``: the material needs 'tangent') and the parameters ``p`` (gltf_pbr.glsl's order)."""
    dtype = np.asarray(n_dot_h).dtype
    n, t, b = (np.asarray(a).astype(dtype) for a in (f.n, f.t, f.b))
    tt, bb = gltf_anisotropy_frame(n, t, b, p.anisotropy_direction, p.anisotropy_rotation)
    return gltf_anisotropy_specular(tt, bb, np.asarray(wi, dtype), np.asarray(wo, dtype), n_dot_l, n_dot_v, n_dot_h,
                                    v_dot_h, alpha, p.anisotropy_strength)


def gltf_anisotropy_oracle(f, wi, wo, h, p):
    """The specification's ``V D`` of the base in mpmath (its ``D_GGX_anisotropic`` and ``V_GGX_anisotropic`` as
    written, the direction rotated by ``mat2(cos, sin, -sin, cos)``), from the frame ``f`` (lists: ``f.n``, ``f.t``,
    ``f.b``) and the half vector ``h``; an mpmath number [1/sr] (0 where ``alpha_t alpha_b = 0``)."""
    import mpmath  # noqa: PLC0415 - the stability suite's, kept out of import time

    def dot(a, c):
        return sum(x * y for x, y in zip(a, c))

    texel = [mpmath.mpf(float(c)) for c in np.broadcast_to(np.asarray(p.anisotropy_direction, np.float64), 3)]
    dx, dy = 2 * texel[0] - 1, 2 * texel[1] - 1
    length = mpmath.sqrt(dx * dx + dy * dy)
    dx, dy = (dx / length, dy / length) if length > 0 else (mpmath.mpf(1), mpmath.mpf(0))
    rotation = mpmath.mpf(float(p.anisotropy_rotation))
    c, s = mpmath.cos(rotation), mpmath.sin(rotation)
    rx, ry = c * dx - s * dy, s * dx + c * dy
    t = [rx * a + ry * b for a, b in zip(f.t, f.b)]
    t = [x / mpmath.sqrt(dot(t, t)) for x in t]
    n = f.n
    b = [n[1] * t[2] - n[2] * t[1], n[2] * t[0] - n[0] * t[2], n[0] * t[1] - n[1] * t[0]]
    b = [x / mpmath.sqrt(dot(b, b)) for x in b]
    alpha = mpmath.mpf(float(p.roughness)) ** 2
    strength = mpmath.mpf(float(p.anisotropy_strength))
    at = alpha * (1 - strength ** 2) + strength ** 2
    ab = alpha
    a2 = at * ab
    if a2 == 0:
        return mpmath.mpf(0)
    fv = [ab * dot(t, h), at * dot(b, h), a2 * dot(n, h)]
    w2 = a2 / dot(fv, fv)
    d = a2 * w2 * w2 / mpmath.pi
    n_dot_l, n_dot_v = dot(n, wi), dot(n, wo)
    ggx_v = n_dot_l * mpmath.sqrt((at * dot(t, wo)) ** 2 + (ab * dot(b, wo)) ** 2 + n_dot_v ** 2)
    ggx_l = n_dot_v * mpmath.sqrt((at * dot(t, wi)) ** 2 + (ab * dot(b, wi)) ** 2 + n_dot_l ** 2)
    return d * min(max(mpmath.mpf("0.5") / (ggx_v + ggx_l), 0), 1)


def anisotropy_cases(cls):
    """Stability cases of the anisotropy on `GltfPBR` ``cls``: strength 0.5 and 1 at roughness 0, 1e-2, 0.3 and 1, at
    the peak and off it along T and along B; rotated directions; grazing view and light (V's clamp acts)."""
    e_one = 4 * np.pi  # a point light at 1 m: E = 1 W/m^2
    light = (("point", _unit(30.0), e_one),)
    cases = []
    for strength in (0.5, 1.0):
        for roughness in (0.0, 1e-2, 0.3, 1.0):
            for where, theta_h in (("peak", 0.0), ("off", 0.2)):
                cases.append(Case(f"gltf_pbr anisotropy={strength:g} roughness={roughness:g} {where}",
                                  "gltf anisotropy",
                                  cls((0.8, 0.5, 0.2), 0.5, roughness, anisotropy_strength=strength),
                                  eye=_mirror_eye(30.0, 2 * theta_h), lights=light, note=f"theta_h = {theta_h:.3g} rad"))
    for rotation in (0.7, -np.pi / 2, 3.0):
        cases.append(Case(f"gltf_pbr anisotropy rotation={rotation:.3g}", "gltf anisotropy",
                          cls((0.8, 0.5, 0.2), 1.0, 0.2, anisotropy_strength=0.8, anisotropy_rotation=rotation,
                              anisotropy_direction=(0.2, 0.9, 1.0)),
                          eye=_mirror_eye(30.0, 0.3), lights=light))
    for nv in (1e-3, 1e-8, 1e-20):
        cases.append(Case(f"gltf_pbr anisotropy grazing view n.v={nv:g}", "gltf anisotropy",
                          cls(0.5, 0.5, 0.05, anisotropy_strength=1.0, clearcoat=0.5, clearcoat_roughness=0.1),
                          eye=(-float(np.sqrt(1.0 - nv * nv)), 0.0, nv), lights=(("point", _unit(40.0), e_one),),
                          note="V (n.l) finite"))
    cases.append(Case("gltf_pbr anisotropy grazing light", "gltf anisotropy",
                      cls(0.5, 1.0, 0.1, anisotropy_strength=0.9, anisotropy_rotation=0.4),
                      eye=_mirror_eye(89.0, 0.0), lights=(("point", _unit(89.99), e_one),),
                      note="l and v grazing, smooth: V clamped at 1"))
    return cases
