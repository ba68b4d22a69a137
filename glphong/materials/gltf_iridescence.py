"""KHR_materials_iridescence on `GltfPBR` (docs/gltf_extensions.md; GLSL: ``glsl/materials/gltf_iridescence.glsl``,
read before ``gltf_pbr.glsl`` under ``GLTF_PBR_IRIDESCENCE``): the twin's functions, the extension's formulas in mpmath
for the stability suite, and the stability cases.  The thin-film Fresnel of Belcour & Barla (2017) as the extension's
README writes it, at ``cos1 = v.h``, ``eta1 = 1``, ``eta2 = iridescence_ior``, thickness ``d`` [nm]::

    d = mix(iridescence_thickness_minimum, iridescence_thickness_maximum, iridescence_thickness_mix)
    cos2 = sqrt(1 - (eta1/eta2)^2 (1 - cos1^2));  R12 = Schlick(((eta2 - eta1)/(eta2 + eta1))^2, cos1), T121 = 1 - R12
    eta3 = (1 + sqrt(f))/(1 - sqrt(f)), f = min(base_f0 + 1e-4, 0.9999);  R23 = Schlick(((eta3 - eta2)/(eta3 + eta2))^2, cos2)
    phi = (pi - phi12) + phi23 (pi where the next medium's ior is lower, else 0);  OPD = 2 eta2 d cos2
    R123 = clamp(R12 R23, 1e-5, 0.9999), Rs = T121^2 R23/(1 - R123)
    F_iridescence = max(R12 + Rs + sum_{m=1,2} (Rs - T121) R123^(m/2) 2 S(m OPD, m phi), 0)            rgb
    dielectric: F_d' = mix(F_d, F_iridescence(base_f0 = dielectric f0), iridescence), diffuse weight 1 - max(F_d')
    metal: mix(c + (1 - c) x, F_iridescence(base_f0 = c), iridescence)

``S`` is the README's ``evalSensitivity``: a fit of the CIE 1931 XYZ sensitivities' Fourier transforms by Gaussians,
turned to linear Rec. 709 RGB.  Its error against a float64 spectral integral of the same Airy reflectance against
the CIE 1931 colour matching functions is measured by ``benchmarks/gltf_iridescence_spectral.py``
(docs/gltf_extensions.md).

=================================== ====== =========== ======= ==============================================================
parameter                           kind   range       neutral meaning
=================================== ====== =========== ======= ==============================================================
iridescence                         scalar [0, 1]      0       ``iridescenceFactor`` times ``iridescenceTexture.r``
iridescence_ior                     scalar [1, 1e4]    1.3     ``iridescenceIor``: the film's index of refraction
iridescence_thickness_minimum       scalar [0, 1e5]    100     ``iridescenceThicknessMinimum`` [nm]
iridescence_thickness_maximum       scalar [0, 1e5]    400     ``iridescenceThicknessMaximum`` [nm]
iridescence_thickness_mix           scalar [0, 1]      1       ``iridescenceThicknessTexture.g`` (1 where there is none)
=================================== ====== =========== ======= ==============================================================
"""
import warnings

import numpy as np

from glphong.definitions.cases import Case, _mirror_eye, _unit
from glphong.definitions.material_base import constant_part
from glphong.definitions.params import Param
from glphong.definitions.surface import SurfaceInput

__all__ = ["IRIDESCENCE_PARAMS", "gltf_iridescence_sensitivity", "gltf_iridescence_fresnel", "gltf_iridescence_parts",
           "gltf_iridescence_oracle", "iridescence_cases", "iridescence_gltf_fields"]

_IRIDESCENCE = Param("iridescence", "scalar", low=0.0, high=1.0, default=0.0, unit="", textureable=True,
                     doc="KHR_materials_iridescence iridescenceFactor (times iridescenceTexture.r): the film's weight")
_IOR = Param("iridescence_ior", "scalar", low=1.0, high=1e4, default=1.3, unit="",
             doc="KHR_materials_iridescence iridescenceIor: the thin film's index of refraction")
_MINIMUM = Param("iridescence_thickness_minimum", "scalar", low=0.0, high=1e5, default=100.0, unit="nm",
                 doc="KHR_materials_iridescence iridescenceThicknessMinimum: the film's thickness where the texture is 0")
_MAXIMUM = Param("iridescence_thickness_maximum", "scalar", low=0.0, high=1e5, default=400.0, unit="nm",
                 doc="KHR_materials_iridescence iridescenceThicknessMaximum: the film's thickness where the texture is 1")
_MIX = Param("iridescence_thickness_mix", "scalar", low=0.0, high=1.0, default=1.0, unit="", textureable=True,
             doc="KHR_materials_iridescence iridescenceThicknessTexture.g (1 without it): thickness = mix(minimum, "
                 "maximum, it)")
#: the iridescence's parameters, appended to `GltfPBR`'s
IRIDESCENCE_PARAMS = (_IRIDESCENCE, _IOR, _MINIMUM, _MAXIMUM, _MIX)
#: the README's Gaussian fit: amplitudes, positions [rad/m], variances [rad^2/m^2] of x, y, z, and x's fourth Gaussian
_VAL, _POS, _VAR = (5.4856e-13, 4.4201e-13, 5.2481e-13), (1.6810e+06, 1.7953e+06, 2.2084e+06), \
    (4.3278e+09, 9.3046e+09, 6.6121e+09)
_X4 = (9.7470e-14, 2.2399e+06, 4.5282e+09)
#: the README's XYZ_TO_REC709 (GLSL's column-major mat3, as rows)
XYZ_TO_REC709 = np.array([[3.2404542, -1.5371385, -0.4985314], [-0.9692660, 1.8760108, 0.0415560],
                          [0.0556434, -0.2040259, 1.0572252]])


def _mix(a, b, t):
    """GLSL's ``mix``: ``a (1 - t) + b t``."""
    return a * (t.dtype.type(1) - t) + b * t


def gltf_iridescence_sensitivity(opd, shift):
    """The README's ``evalSensitivity``: ``XYZ_TO_REC709 xyz``, ``xyz_i = val_i sqrt(2 pi var_i) cos(pos_i t +
    shift_i) exp(-var_i t^2) / 1.0685e-7`` (and x's fourth Gaussian), ``t = 2 pi OPD 1e-9``.  opd (...) [nm], shift
    (..., 3) [rad] -> (..., 3) linear RGB."""
    opd = np.asarray(opd)
    dtype = opd.dtype if opd.dtype.kind == "f" else np.float64
    f = dtype.type
    pi = f(np.pi)
    shift = np.asarray(shift).astype(dtype)
    phase = (f(2) * pi * opd.astype(dtype) * f(1e-9)).astype(dtype)[..., None]
    val, pos, var = (np.asarray(v, dtype) for v in (_VAL, _POS, _VAR))
    xyz = val * np.sqrt(f(2) * pi * var) * np.cos(pos * phase + shift) * np.exp(-(phase * phase) * var)
    a, p, v = (f(q) for q in _X4)
    xyz[..., 0] += (a * np.sqrt(f(2) * pi * v) * np.cos(p * phase[..., 0] + shift[..., 0])
                    * np.exp(-v * (phase[..., 0] * phase[..., 0])))
    xyz = xyz / f(1.0685e-7)
    return (xyz @ XYZ_TO_REC709.T.astype(dtype)).astype(dtype)


def gltf_iridescence_fresnel(outside_ior, film_ior, base_f0, thickness, cos_theta1):
    """The README's ``iridescent_fresnel`` (module docstring; gltf_iridescence.glsl's order).  outside_ior, film_ior,
    thickness [nm], cos_theta1: (...) or (); base_f0 (..., 3) or (3,) -> (..., 3), dimensionless."""
    cos_theta1 = np.asarray(cos_theta1)
    dtype = cos_theta1.dtype if cos_theta1.dtype.kind == "f" else np.float64
    f = dtype.type
    one, pi = f(1), f(np.pi)
    cos_theta1 = cos_theta1.astype(dtype)
    outside_ior, film_ior, thickness = (np.asarray(a).astype(dtype) for a in (outside_ior, film_ior, thickness))
    base_f0 = np.asarray(base_f0).astype(dtype)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore", under="ignore"):
        ratio = outside_ior / film_ior
        cos2_theta2 = ((one - ratio * ratio) + ratio * ratio * (cos_theta1 * cos_theta1)).astype(dtype)
        cos_theta2 = np.sqrt(np.maximum(cos2_theta2, f(0)))
        q0 = (film_ior - outside_ior) / (film_ior + outside_ior)
        y1 = np.maximum(one - cos_theta1, f(0))
        r12 = (q0 * q0 + (one - q0 * q0) * ((y1 * y1) * (y1 * y1) * y1)).astype(dtype)
        t121 = one - r12
        phi21 = pi - np.where(film_ior < outside_ior, pi, f(0))
        s = np.sqrt(np.minimum(base_f0 + f(0.0001), f(0.9999)))
        base_ior = (one + s) / (one - s)
        film3 = film_ior[..., None]
        q1 = (base_ior - film3) / (base_ior + film3)
        y2 = np.maximum(one - cos_theta2, f(0))[..., None]
        r23 = (q1 * q1 + (one - q1 * q1) * ((y2 * y2) * (y2 * y2) * y2)).astype(dtype)
        phi23 = np.where(base_ior < film3, pi, f(0))
        opd = (f(2) * film_ior * thickness * cos_theta2).astype(dtype)
        phi = (phi21[..., None] + phi23).astype(dtype)
        r12_3, t121_3 = r12[..., None], t121[..., None]
        r123 = np.clip(r12_3 * r23, f(1e-5), f(0.9999))
        r123_sqrt = np.sqrt(r123)
        rs = (t121_3 * t121_3) * r23 / (one - r123)
        out = r12_3 + rs
        cm = (rs - t121_3) * r123_sqrt
        out = out + cm * (f(2) * gltf_iridescence_sensitivity(opd, phi))
        cm = cm * r123_sqrt
        out = out + cm * (f(2) * gltf_iridescence_sensitivity(f(2) * opd, f(2) * phi))
        return np.where((cos2_theta2 < 0)[..., None], one, np.maximum(out, f(0))).astype(dtype)


def gltf_iridescence_parts(c, m, x, film_f0, fd, v_dot_h, p):
    """``(fd_max (N,), fresnel (N, 3))`` of `GltfPBR`'s twin with KHR_materials_iridescence (gltf_iridescence.glsl's
    ``gltf_iridescence_parts``): ``F_d' = mix(F_d, F_iridescence(base_f0 = film_f0), iridescence)`` (``F_d`` the
    dielectric's, (N, 3) or (N, 1); ``film_f0`` (..., 3) its base, `gltf_specular_fresnel` at ``x = 0`` or ``f0``),
    ``fd_max = max F_d'`` (the response's diffuse weight ``1 - fd_max``), ``fresnel = F_d' (1 - m) + mix(c + (1 - c) x,
    F_iridescence(base_f0 = c), iridescence) m``."""
    dtype = np.asarray(x).dtype
    one = dtype.type(1)
    thickness = _mix(np.asarray(p.iridescence_thickness_minimum).astype(dtype),
                     np.asarray(p.iridescence_thickness_maximum).astype(dtype),
                     np.asarray(p.iridescence_thickness_mix).astype(dtype))
    film_f0 = np.asarray(film_f0).astype(dtype)
    w = np.asarray(p.iridescence).astype(dtype)[..., None]
    ior = np.asarray(p.iridescence_ior).astype(dtype)
    fd = np.asarray(fd).astype(dtype)  # (N, 3), or (N, 1) where F_d is one number
    c = np.asarray(c, dtype)
    fd_i = _mix(fd, gltf_iridescence_fresnel(one, ior, film_f0, thickness, v_dot_h), w)
    fm_i = _mix(c + (one - c) * x[..., None], gltf_iridescence_fresnel(one, ior, c, thickness, v_dot_h), w)
    fresnel = fd_i * (one - m) + fm_i * m
    return np.max(fd_i, axis=-1).astype(dtype), fresnel.astype(dtype)


def gltf_iridescence_oracle(fr, base_color, x, f0_film, p, v_dot_h):
    """The dielectric's and the metal's Fresnel with the iridescence, in mpmath from the README's text (its
    ``iridescent_fresnel`` with the ``pow``, ``if`` and loop as written): ``(dielectric, metal)``, each 3 mpmath
    numbers; ``fr`` the dielectric's Fresnel without it (3 numbers, ``specular`` times ``fresnel_mix``'s),
    ``f0_film`` its ``base_f0`` (3 numbers)."""
    import mpmath  # noqa: PLC0415 - the stability suite's, kept out of import time

    mp = mpmath.mpf
    pi = mpmath.pi
    eta1, eta2 = mp(1), mp(float(p.iridescence_ior))
    lo, hi, t = (mp(float(getattr(p, name))) for name in ("iridescence_thickness_minimum",
                                                           "iridescence_thickness_maximum", "iridescence_thickness_mix"))
    d = lo + (hi - lo) * t
    cos1 = mp(v_dot_h)

    def schlick(r0, c):
        return r0 + (1 - r0) * (1 - c) ** 5

    def sensitivity(opd, shift):
        phase = 2 * pi * opd * mp("1e-9")
        xyz = [mp(v) * mpmath.sqrt(2 * pi * mp(s2)) * mpmath.cos(mp(q) * phase + sh) * mpmath.exp(-phase ** 2 * mp(s2))
               for v, q, s2, sh in zip(_VAL, _POS, _VAR, shift)]
        a, q, s2 = (mp(v) for v in _X4)
        xyz[0] += a * mpmath.sqrt(2 * pi * s2) * mpmath.cos(q * phase + shift[0]) * mpmath.exp(-s2 * phase ** 2)
        xyz = [v / mp("1.0685e-7") for v in xyz]
        return [sum(mp(XYZ_TO_REC709[i, j]) * xyz[j] for j in range(3)) for i in range(3)]

    def fresnel(base_f0):
        cos2_sq = 1 - (eta1 / eta2) ** 2 * (1 - cos1 ** 2)
        if cos2_sq < 0:
            return [mp(1)] * 3
        cos2 = mpmath.sqrt(cos2_sq)
        r12 = schlick(((eta2 - eta1) / (eta2 + eta1)) ** 2, cos1)
        t121 = 1 - r12
        phi21 = pi - (pi if eta2 < eta1 else 0)
        base_ior = [(1 + mpmath.sqrt(min(mp(b) + mp("0.0001"), mp("0.9999")))) /
                    (1 - mpmath.sqrt(min(mp(b) + mp("0.0001"), mp("0.9999")))) for b in base_f0]
        r23 = [schlick(((n - eta2) / (n + eta2)) ** 2, cos2) for n in base_ior]
        phi = [phi21 + (pi if n < eta2 else 0) for n in base_ior]
        opd = 2 * eta2 * d * cos2
        out = []
        for k in range(3):
            r123 = min(max(r12 * r23[k], mp("1e-5")), mp("0.9999"))
            rs = t121 ** 2 * r23[k] / (1 - r123)
            total, cm = r12 + rs, rs - t121
            for m in (1, 2):
                cm *= mpmath.sqrt(r123)
                total += cm * 2 * sensitivity(m * opd, [m * q for q in phi])[k]
            out.append(max(total, mp(0)))
        return out

    w = mp(float(p.iridescence))
    dielectric = [(1 - w) * a + w * b for a, b in zip(fr, fresnel(f0_film))]
    metal = [(1 - w) * (c + (1 - c) * x) + w * b for c, b in zip(base_color, fresnel(base_color))]
    return dielectric, metal


def iridescence_cases(cls):
    """Stability cases of the iridescence on `GltfPBR` ``cls``: thickness 0, 400 nm and 1e5 nm; iridescence 0 (the
    texture's weight) and 1; a film of ior 1 (the outside's: no first interface) and 2.5 (above the base's); a white
    metal (base_f0 = 1: the guard); grazing view and light."""
    e_one = 4 * np.pi  # a point light at 1 m: E = 1 W/m^2
    light = (("point", _unit(30.0), e_one),)
    cases = []
    for name, kwargs in (("thickness 0", dict(iridescence_thickness_maximum=0.0)),
                         ("thickness 400 nm", dict()),
                         ("thickness 1e5 nm", dict(iridescence_thickness_maximum=1e5)),
                         ("film ior 1", dict(iridescence_ior=1.0)),
                         ("film ior 2.5", dict(iridescence_ior=2.5, iridescence_thickness_maximum=250.0)),
                         ("iridescence 0.5 specular", dict(iridescence=0.5, specular=0.5, specular_color=(1.0, 2.0, 30.0)))):
        for metallic, color in ((0.0, (0.8, 0.5, 0.2)), (1.0, (1.0, 0.9, 0.0))):
            arguments = dict(iridescence=1.0) | kwargs
            for theta_h in (0.0, 0.7):
                cases.append(Case(f"gltf_pbr iridescence {name} metallic={metallic:g} theta_h={theta_h:g}",
                                  "gltf iridescence", cls(color, metallic, 0.3, **arguments),
                                  eye=_mirror_eye(30.0, 2 * theta_h), lights=light))
    for nv in (1e-3, 1e-8, 1e-20):
        cases.append(Case(f"gltf_pbr iridescence grazing view n.v={nv:g}", "gltf iridescence",
                          cls(0.5, 0.5, 0.3, iridescence=1.0, iridescence_ior=1.8),
                          eye=(-float(np.sqrt(1.0 - nv * nv)), 0.0, nv), lights=(("point", _unit(40.0), e_one),),
                          note="v.h -> 0: R12 -> 1"))
    cases.append(Case("gltf_pbr iridescence grazing light", "gltf iridescence",
                      cls(0.5, 0.0, 0.5, iridescence=1.0), eye=_mirror_eye(30.0, 0.2),
                      lights=(("point", _unit(89.99), e_one),)))
    return cases


def iridescence_gltf_fields(material, texture_index):
    """``{"KHR_materials_iridescence": {...}}`` for a `GltfPBR` that uses the extension, else ``{}``: the factor, the
    film's ior, the thicknesses, ``iridescenceTexture`` (a texture read on its red channel) and
    ``iridescenceThicknessTexture`` (read on its green channel, unscaled, as the loader makes it; another thickness
    texture is kept in glphong's extras only, with a warning).  An untextured
    ``iridescence_thickness_mix`` below 1 is written as the maximum it gives, ``mix(minimum, maximum, it)`` (the file
    has no such factor); the minimum is written with the thickness texture only (without it the file's thickness is
    the maximum, and the Khronos validator notes a minimum as having no effect)."""
    if "iridescence" not in material.extensions():
        return {}
    lo, hi = float(material.iridescence_thickness_minimum), float(material.iridescence_thickness_maximum)
    weight = material.iridescence_thickness_mix
    fields = {"iridescenceFactor": float(constant_part(material.iridescence)),
              "iridescenceIor": float(material.iridescence_ior), "iridescenceThicknessMinimum": lo,
              "iridescenceThicknessMaximum": hi}
    value = material.iridescence
    if isinstance(value, SurfaceInput) and value.texture is not None and value.channel == "r":
        fields["iridescenceTexture"] = {"index": texture_index(value.texture)}
    if isinstance(weight, SurfaceInput) and weight.texture is not None and weight.channel == "g" and weight.scale == 1.0:
        fields["iridescenceThicknessTexture"] = {"index": texture_index(weight.texture)}
    elif isinstance(weight, SurfaceInput) and weight.texture is not None:  # the file reads .g, unscaled
        warnings.warn(f"GltfPBR's iridescence_thickness_mix texture (channel {weight.channel!r}, scale "
                      f"{float(np.max(weight.scale)):g}) is written in glphong's extras only: other viewers read "
                      "iridescenceThicknessTexture's green channel unscaled, which does not carry it", stacklevel=7)
    elif not isinstance(weight, SurfaceInput):
        fields["iridescenceThicknessMaximum"] = lo + (hi - lo) * float(weight)
    if "iridescenceThicknessTexture" not in fields:  # the minimum only acts through the texture (the validator's info)
        del fields["iridescenceThicknessMinimum"]
    return {"KHR_materials_iridescence": fields}
