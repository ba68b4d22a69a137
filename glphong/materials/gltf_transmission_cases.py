"""Stability cases of KHR_materials_transmission, _volume, _dispersion and _diffuse_transmission, with their
specification's formulas in mpmath (docs/transmission.md, "Stability"; issue 41).

`transmission_stability_cases`: the stability suite's (`glphong.checks.stability`, registered by
``GltfPBR.stability_cases``) under a light in front.  `transmission_cases`: the scalar pieces the suite's points
program does not hold (the light behind the surface is the radiance programs' alone).

The background lookups (``gltf_transmission_background``, ``gltf_transmission_sample``, ``gltf_volume_light``) read a
texture and are checked by `glphong.checks.transmission_twin`; what they are given and weighted by is covered here,
one function of ``glsl/transmission_thin.glsl`` and ``glsl/materials/gltf_pbr.glsl`` at a time (the twins of the same
names in `glphong.materials.gltf_transmission` and `glphong.materials.gltf_diffuse_transmission`):

============================ =========================================================================================
function                     the specification's formula the oracle evaluates (60 digits, inputs rounded to float32)
============================ =========================================================================================
gltf_transmission_fresnel    ``f0 + (1 - f0) (1 - clamp(c, 0, 1))^5``, ``f0 = ((ior - 1)/(ior + 1))^2``
gltf_transmission_weight     ``(1 - m) t (1 - F(n.v)) c``
gltf_transmission_response   the thin wall's BTDF times ``n.l'``: ``l' = wi - 2 (n.wi) n``, ``h = normalize(l' + v)``,
                             ``(1 - m) t c (1 - F(v.h)) D V (n.l')``, Appendix B's GGX ``D = a^2 / (pi ((n.h)^2 (a^2 -
                             1) + 1)^2)``, ``V = 1 / (2 (n.l' sqrt(a^2 + (1 - a^2) (n.v)^2) + n.v sqrt(a^2 + (1 - a^2)
                             (n.l')^2)))``, ``a = r^2``; 0 for ``r = 0`` (a delta a point light meets with zero
                             measure) and where ``n.v <= 0``
gltf_diffuse_transmission_   ``(1 - m) (1 - t) dt (c_dt / pi) (1 - F(v.h')) n.l'``
response
gltf_volume_attenuation      Beer-Lambert ``color^(d / distance)`` (1 for ``distance`` = FLT_MAX, the specification's
                             +Infinity; ``color^0 = 1``: no path, no attenuation)
gltf_volume_uv               ``((P p).xy / (P p).w + 1) / 2``, ``P`` a perspective camera's view-projection
gltf_volume_ray              Snell's law: the refracted direction of ``-v`` into the medium of ``eta`` times
                             ``thickness`` (a unit scale)
============================ =========================================================================================

Each `TransmissionCase` is data; `transmission_oracle` is its expected value, `transmission_twin_value` the float64
twin's.  The GPU's side (the real chunks run on the case's float32 inputs by `glphong.testing.glsl_function` in the
fragment stage, where ``gl_FragCoord`` exists) is in tests/test_transmission_stability.py.
"""
from dataclasses import dataclass, field

import numpy as np

from glphong.definitions.cases import Case, _mirror_eye, _unit
from glphong.materials.gltf_diffuse_transmission import gltf_diffuse_transmission_response
from glphong.materials.gltf_transmission import (gltf_transmission_fresnel, gltf_transmission_response,
                                                 gltf_transmission_weight, gltf_volume_attenuation, gltf_volume_ray,
                                                 gltf_volume_uv)
from glphong.twin.band import FLT_MAX

__all__ = ["transmission_stability_cases", "TransmissionCase", "TRANSMISSION_FUNCTIONS", "transmission_cases", "transmission_oracle",
           "transmission_twin_value", "KNOWN", "VIEW_PROJECTION"]

#: the GLSL functions the cases call, by case kind
TRANSMISSION_FUNCTIONS = {"fresnel": "gltf_transmission_fresnel", "weight": "gltf_transmission_weight",
                          "response": "gltf_transmission_response",
                          "diffuse": "gltf_diffuse_transmission_response",
                          "attenuation": "gltf_volume_attenuation", "ray": "gltf_volume_ray", "uv": "gltf_volume_uv"}


@dataclass(frozen=True)
class TransmissionCase:
    """One extreme input of one transmission function.

    Attributes
    ----------
    name : str
    kind : str
        A key of `TRANSMISSION_FUNCTIONS`.
    n, wi, wo : tuple of 3 float
        Normal (unit up to float32 rounding), direction toward the light (behind: ``n.wi < 0``) and toward the viewer.
    material : dict
        ``c`` (base colour), ``m``, ``t``, ``r`` (roughness), ``ior``, ``dt``, ``c_dt`` (as GltfPBR's parameters).
    d, color, distance : float, tuple of 3 float, float
        Beer-Lambert's path length [m], attenuation colour and distance [m] (kind 'attenuation').
    eta, thickness : float
        The volume ray's index of refraction and thickness (kind 'ray').
    point : tuple of 3 float
        The exit point projected (kind 'uv'), by `VIEW_PROJECTION`.
    note : str
    known : str
        Non-empty where the case shows a known instability of the GLSL or its twin (what it is); reported, not yet
        fixed (docs/transmission.md, "Stability").
    """

    name: str
    kind: str
    n: tuple = (0.0, 0.0, 1.0)
    wi: tuple = (0.0, 0.0, -1.0)
    wo: tuple = (0.0, 0.0, 1.0)
    material: dict = field(default_factory=dict)
    d: float = 0.0
    color: tuple = (1.0, 1.0, 1.0)
    distance: float = 1.0
    eta: float = 1.5
    thickness: float = 1.0
    point: tuple = (0.0, 0.0, 0.0)
    note: str = ""
    known: str = ""


#: the instabilities the cases found, by case name prefix (docs/transmission.md, "Stability")
KNOWN = {"ray ": "outside gltf_volume_ray's domain (eta >= 1: gltf_transmission_radiance keeps a dispersed channel's "
                 "ior at 1 or above): total internal reflection at grazing view, refract() gives 0 and normalize(0) "
                 "NaN, on the GPU and in the twin; ior 0 exactly: 1/0"}


def transmission_stability_cases(cls):
    """The stability suite's cases (`glphong.checks.stability`, ``GltfPBR.stability_cases``) of a transmissive
    `GltfPBR` ``cls`` under a light in front, whose diffuse the transmission weights by ``1 - t`` and the diffuse
    transmission by ``1 - dt`` (gltf_pbr.glsl; the oracle `glphong.materials.gltf_extensions.gltf_extensions_oracle`):
    transmission 0.5 and 1, metallic 0 and 1, roughness 0, 1e-4 and 0.3 at the peak and off it, grazing view, ior 1
    and 1e4, a volume whose attenuation distance is tiny, huge or FLT_MAX and colour 0 or 1, dispersion 0 and 1e4,
    diffuse transmission 1 (list of Case).  The light behind the surface and the background are not the points
    program's (`transmission_cases` covers their scalar pieces)."""
    e_one = 4 * np.pi  # a point light at 1 m: E = 1 W/m^2
    light = (("point", _unit(30.0), e_one),)
    c = (0.8, 0.5, 0.2)
    cases = []
    for t in (0.5, 1.0):
        for m in (0.0, 1.0):
            for r in (0.0, 1e-4, 0.3):
                for where, theta_h in (("peak", 0.0), ("off", 0.2)):
                    cases.append(Case(f"gltf_pbr transmission={t:g} metallic={m:g} roughness={r:g} {where}",
                                      "gltf transmission", cls(c, m, r, transmission=t), eye=_mirror_eye(30.0, 2 * theta_h),
                                      lights=light))
    for nv in (1e-3, 1e-8):
        for ior in (1.0, 1.5, 1e4):
            cases.append(Case(f"gltf_pbr transmission grazing view n.v={nv:g} ior={ior:g}", "gltf transmission",
                              cls(c, 0.0, 0.3, ior=ior, transmission=0.9), eye=(-float(np.sqrt(1.0 - nv * nv)), 0.0, nv),
                              lights=(("point", _unit(40.0), e_one),)))
    for label, volume in (("distance 1e-30 colour 0", {"attenuation_distance": 1e-30, "attenuation_color": 0.0}),
                          ("distance 1e30 colour 1", {"attenuation_distance": 1e30, "attenuation_color": 1.0}),
                          ("distance FLT_MAX", {"attenuation_distance": float(FLT_MAX)}),
                          ("dispersion 1e4", {"dispersion": 1e4})):
        cases.append(Case(f"gltf_pbr transmission volume {label}", "gltf transmission",
                          cls(c, 0.0, 0.3, transmission=0.9, thickness=0.2, **volume), eye=_mirror_eye(30.0, 0.2),
                          lights=light, note="the volume changes nothing under a light in front"))
    for dt, t, m in ((1.0, 0.0, 0.0), (1.0, 0.5, 0.0), (0.5, 0.0, 1.0)):
        cases.append(Case(f"gltf_pbr diffuse_transmission={dt:g} transmission={t:g} metallic={m:g}",
                          "gltf transmission", cls(c, m, 0.3, transmission=t, diffuse_transmission=dt,
                                                   diffuse_transmission_color=(0.9, 0.6, 0.3)),
                          eye=_mirror_eye(30.0, 0.2), lights=light))
    return cases


#: the uv cases' view-projection: ``PerspectiveCamera.look_at((0, 0, 2), (0, 0, 0), znear=1e-4)`` at aspect 1.25, in
#: float32, (4, 4) applied to column vectors
VIEW_PROJECTION = ((1.9313709, 0.0, 0.0, 0.0), (0.0, 2.4142137, 0.0, 0.0), (0.0, 0.0, -1.000002, 1.999804),
                   (0.0, 0.0, -1.0, 2.0))


_GLASS = {"c": (0.8, 0.5, 0.2), "m": 0.0, "t": 0.9, "r": 0.3, "ior": 1.5, "dt": 0.0, "c_dt": (1.0, 1.0, 1.0)}


def _view(cosine, azimuth_deg=0.0):
    """Unit view direction with the given cosine to +z (float64)."""
    s, p = np.sqrt(max(1.0 - cosine * cosine, 0.0)), np.radians(azimuth_deg)
    return (float(s * np.cos(p)), float(s * np.sin(p)), float(cosine))


def _behind(wo, offset_rad=0.0):
    """The light behind the surface whose mirror ``l'`` is ``wo`` reflected about n (the peak, ``h' = n``), turned
    by ``offset_rad`` about +y: ``-wo`` for offset 0."""
    x, y, z = -wo[0], -wo[1], -wo[2]
    c, s = np.cos(offset_rad), np.sin(offset_rad)
    return (float(c * x + s * z), float(y), float(-s * x + c * z))


def _glass(**over):
    return dict(_GLASS, **over)


def transmission_cases():
    """The cases, in report order (list of TransmissionCase): grazing and over-unit ``n.v``, ior 1 and 1e4, metallic
    1, roughness 0, 1e-4, 1e-2 and 1 at the thin wall's peak (the light straight behind along the view line), off it
    and with the mirrored light exactly along the view; diffuse transmission 0 and 1; Beer-Lambert's distance tiny,
    huge and FLT_MAX, colour 0 and 1, path 0; dispersion's per-channel iors (``ior -+ (ior - 1) 0.025
    dispersion``) at dispersion 0, 1, 39, 60, 120 (red ior 0) and 1e4 (red ior negative): above 40 the red ior falls below 1
    and a grazing view meets total internal reflection (`KNOWN`)."""
    cases = []
    for cosine, label in ((1.0, "1"), (float(np.nextafter(np.float32(1), np.float32(2))), "1+ulp"), (0.5, "0.5"),
                          (1e-3, "1e-3"), (1e-8, "1e-8"), (0.0, "0"), (-1e-3, "-1e-3")):
        n = (0.0, 0.0, 1.0)
        wo = _view(min(cosine, 1.0)) if cosine <= 1.0 else (0.0, 0.0, cosine)  # n.v above 1 from rounding
        for ior in (1.0, 1.5, 1e4):
            cases.append(TransmissionCase(f"weight n.v={label} ior={ior:g}", "weight", n=n, wo=wo,
                                          material=_glass(ior=ior)))
        cases.append(TransmissionCase(f"fresnel c={label}", "fresnel", wo=wo, material=_glass()))
    cases.append(TransmissionCase("weight metallic=1", "weight", wo=_view(0.5), material=_glass(m=1.0)))
    cases.append(TransmissionCase("weight t=1 c=1", "weight", wo=_view(0.5), material=_glass(t=1.0, c=(1.0,) * 3)))
    for r in (0.0, 1e-4, 1e-2, 0.3, 1.0):
        for cosine in (1.0, 0.5, 1e-3):
            wo = _view(cosine)
            cases.append(TransmissionCase(f"response r={r:g} n.v={cosine:g} peak (light behind along the view line)",
                                          "response", wi=_behind(wo), wo=wo, material=_glass(r=r),
                                          note="h' = n" + ("; r = 0: a delta, 0" if r == 0 else "")))
            offset = 3.0 * max(r, 1e-3) ** 2
            if cosine > 0.1:
                cases.append(TransmissionCase(f"response r={r:g} n.v={cosine:g} tail", "response",
                                              wi=_behind(wo, offset), wo=wo, material=_glass(r=r),
                                              note=f"l turned {offset:.3g} rad off the peak"))
        wo = _view(0.6)
        cases.append(TransmissionCase(f"response r={r:g} mirrored light along the view (l' = v)", "response",
                                      wi=(wo[0], wo[1], -wo[2]), wo=wo, material=_glass(r=r), note="h' = v"))
    wo = _view(0.5)
    for label, over in (("ior=1", {"ior": 1.0}), ("ior=1e4", {"ior": 1e4}), ("metallic=1", {"m": 1.0}),
                        ("t=0", {"t": 0.0}), ("colour 0", {"c": (0.0, 0.0, 0.0)})):
        cases.append(TransmissionCase(f"response {label}", "response", wi=_behind(wo, 0.05), wo=wo,
                                      material=_glass(**over)))
    for label, wi, view in (("grazing light n.l=1e-6", (float(np.sqrt(1 - 1e-12)), 0.0, -1e-6), _view(0.5)),
                            ("grazing view n.v=1e-6", _behind(_view(1e-6)), _view(1e-6)),
                            ("n.v=1+ulp", (0.0, 0.0, -1.0), (0.0, 0.0, float(np.nextafter(np.float32(1),
                                                                                          np.float32(2)))))):
        cases.append(TransmissionCase(f"response {label}", "response", wi=wi, wo=view, material=_glass(r=0.2)))
    for dt, t, m in ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (1.0, 0.5, 0.0), (0.5, 0.0, 1.0)):
        for cosine in (1.0, 1e-6):
            wo = _view(cosine)
            for ior in (1.0, 1.5, 1e4):
                cases.append(TransmissionCase(f"diffuse dt={dt:g} t={t:g} m={m:g} n.v={cosine:g} ior={ior:g}",
                                              "diffuse", wi=_behind(wo, 0.4 if cosine == 1.0 else 0.0), wo=wo,
                                              material=_glass(dt=dt, t=t, m=m, ior=ior, c_dt=(0.9, 0.6, 0.3))))
    for label, d, color, distance in (("path 0 (thickness 0)", 0.0, (0.5, 0.6, 0.7), 0.5),
                                      ("distance 1e-30", 0.1, (0.5, 0.6, 0.7), 1e-30),
                                      ("distance 1e30", 0.1, (0.5, 0.6, 0.7), 1e30),
                                      ("distance FLT_MAX", 0.1, (0.5, 0.6, 0.7), float(FLT_MAX)),
                                      ("colour 1", 3.0, (1.0, 1.0, 1.0), 0.5),
                                      ("colour 0", 0.1, (0.0, 0.0, 0.0), 0.5),
                                      ("colour 0, path 0", 0.0, (0.0, 0.5, 1.0), 0.5),
                                      ("colour (0, 1e-6, 1) far", 10.0, (0.0, 1e-6, 1.0), 1e-3)):
        cases.append(TransmissionCase(f"attenuation {label}", "attenuation", d=d, color=color, distance=distance))
    for cosine in (1.0, 0.5, 1e-3, 0.0):
        for dispersion in (0.0, 1.0, 39.0, 60.0, 120.0, 1e4):
            for k, sign in enumerate((-1.0, 1.0)):
                ior = 1.5
                eta = ior + sign * (ior - 1.0) * 0.025 * dispersion
                sin2_t = (1.0 - cosine * cosine) / eta ** 2 if eta else np.inf
                cases.append(TransmissionCase(f"ray n.v={cosine:g} dispersion={dispersion:g} {'rb'[k]} eta={eta:g}",
                                              "ray", wo=_view(cosine, 30.0), eta=eta, thickness=0.3,
                                              known=KNOWN["ray "] if sin2_t > 1.0 else "",
                                              note="eta < 0: past the specification's range" if eta < 0 else ""))
    for eta, thickness in ((1.0, 1e-3), (1e4, 1e-3), (1.5, 0.0)):
        cases.append(TransmissionCase(f"ray n.v=0.5 eta={eta:g} thickness={thickness:g}", "ray", wo=_view(0.5), eta=eta,
                                      thickness=thickness))
    for label, point in (("on the axis", (0.0, 0.0, 0.3)), ("off the axis", (0.4, -0.3, -0.2)),
                         ("far, 1e6 m", (1e5, -2e5, -1e6)), ("1e-4 m before the eye", (1e-5, 2e-5, 2.0 - 1e-4)),
                         ("behind the eye", (0.1, 0.2, 2.5))):
        cases.append(TransmissionCase(f"uv {label}", "uv", point=point,
                                      note="w < 0: projected through the eye" if point[2] > 2 else ""))
    return cases


def _f32(x):
    return float(np.float32(x))


def transmission_oracle(case, digits=60):
    """The specification's value of ``case`` in mpmath with ``digits`` digits, from its inputs rounded to float32
    (the GPU's input precision; directions then normalised, as the suite's oracle does); (3,) float64 (module
    docstring's table; kind 'fresnel': F at ``c = wo.z``; kind 'uv': ``(u, v, 0)``)."""
    import mpmath  # noqa: PLC0415 - the stability suite's, kept out of import time

    mpmath.mp.dps = digits
    f = lambda x: mpmath.mpf(_f32(x))  # noqa: E731
    vec = lambda a: [f(x) for x in np.broadcast_to(np.asarray(a, np.float64), 3)]  # noqa: E731
    dot = lambda a, b: sum(x * y for x, y in zip(a, b))  # noqa: E731
    p = {k: (vec(v) if isinstance(v, tuple) else f(v)) for k, v in case.material.items()}

    def fresnel(ior, c):
        f0 = ((ior - 1) / (ior + 1)) ** 2
        return f0 + (1 - f0) * (1 - min(max(c, 0), 1)) ** 5

    unit = lambda a: [x / mpmath.sqrt(dot(a, a)) for x in a]  # noqa: E731 - the directions the float32 ones mean
    n, wi, wo = (unit(vec(a)) for a in (case.n, case.wi, case.wo))
    if case.kind == "fresnel":
        wo = vec(case.wo)  # the cosine itself
        return np.array([float(fresnel(p["ior"], wo[2]))] * 3)
    if case.kind == "weight":
        scale = (1 - p["m"]) * p["t"] * (1 - fresnel(p["ior"], dot(n, wo)))
        return np.array([float(c * scale) for c in p["c"]])
    if case.kind == "attenuation":
        color, d, distance = vec(case.color), f(case.d), f(case.distance)
        if distance >= mpmath.mpf(float(FLT_MAX)) or d == 0:
            return np.ones(3)
        return np.array([float(c ** (d / distance)) for c in color])
    if case.kind == "uv":
        clip = [sum(f(a) * b for a, b in zip(row, vec(case.point) + [1])) for row in VIEW_PROJECTION]
        return np.array([float((clip[0] / clip[3] + 1) / 2), float((clip[1] / clip[3] + 1) / 2), 0.0])
    if case.kind == "ray":
        eta, thickness = f(case.eta), f(case.thickness)
        cos_i = dot(n, wo)
        sin2_t = (1 - cos_i ** 2) / eta ** 2 if eta != 0 else mpmath.inf
        if eta == 0 or sin2_t > 1:  # total internal reflection: no refracted ray
            return np.full(3, np.nan)
        cos_t = mpmath.sqrt(1 - sin2_t)
        tangential = [w - cos_i * q for w, q in zip(wo, n)]  # wo's part along the surface
        return np.array([float((-t / eta - cos_t * q) * thickness) for t, q in zip(tangential, n)])
    n_dot_l = -dot(n, wi)
    mirrored = [w + 2 * n_dot_l * q for w, q in zip(wi, n)]
    n_dot_v = dot(n, wo)
    s = [a + b for a, b in zip(mirrored, wo)]
    if n_dot_v <= 0 or n_dot_l <= 0 or dot(s, s) == 0:
        return np.zeros(3)
    h = [x / mpmath.sqrt(dot(s, s)) for x in s]
    one_minus_f = 1 - fresnel(p["ior"], dot(wo, h))
    if case.kind == "diffuse":
        scale = (1 - p["m"]) * (1 - p["t"]) * p["dt"] / mpmath.pi * one_minus_f * n_dot_l
        return np.array([float(c * scale) for c in p["c_dt"]])
    alpha = p["r"] ** 2
    if alpha == 0:
        return np.zeros(3)
    a2 = alpha * alpha
    n_dot_h = dot(n, h)
    d = a2 / (mpmath.pi * (n_dot_h ** 2 * (a2 - 1) + 1) ** 2)
    v = 1 / (2 * (n_dot_l * mpmath.sqrt(a2 + (1 - a2) * n_dot_v ** 2) + n_dot_v * mpmath.sqrt(a2 + (1 - a2)
                                                                                              * n_dot_l ** 2)))
    scale = (1 - p["m"]) * p["t"] * one_minus_f * d * v * n_dot_l
    return np.array([float(c * scale) for c in p["c"]])


def transmission_twin_value(case):
    """The float64 twin's value of ``case`` (the functions of the same names; inputs rounded to float32); (3,)."""
    a = lambda x: np.asarray([x], np.float32).astype(np.float64)  # noqa: E731
    p = {k: np.float64(np.float32(v)) if not isinstance(v, tuple) else np.float32(v).astype(np.float64)
         for k, v in case.material.items()}
    n, wi, wo = a(case.n), a(case.wi), a(case.wo)
    if case.kind == "fresnel":
        return gltf_transmission_fresnel(p["ior"], wo[:, 2])[0]
    if case.kind == "weight":
        return gltf_transmission_weight(np.einsum("ij,ij->i", n, wo), p["c"], p["m"], p["t"], p["ior"])[0]
    if case.kind == "attenuation":
        return gltf_volume_attenuation(a(case.d), np.float32(case.color).astype(np.float64),
                                       _f32(case.distance))[0]
    if case.kind == "uv":
        return np.append(gltf_volume_uv(a(case.point), np.float32(VIEW_PROJECTION).astype(np.float64))[0], 0.0)
    if case.kind == "ray":
        with np.errstate(divide="ignore", invalid="ignore"):  # eta = 0 (`KNOWN`): 1/eta, inf 0
            return gltf_volume_ray(n, wo, a(case.eta)[0], a(case.thickness)[0], np.ones(3))[0]
    n_dot_l = -np.einsum("ij,ij->i", n, wi)
    if case.kind == "diffuse":
        return gltf_diffuse_transmission_response(n, wi, wo, n_dot_l, p["c_dt"], p["m"], p["t"], p["dt"], p["ior"])[0]
    return gltf_transmission_response(n, wi, wo, n_dot_l, p["c"], p["m"], p["t"], p["r"], p["ior"])[0]
