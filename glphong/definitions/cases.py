"""A material's extreme cases for the stability suite, as data (`Case`), and the geometry every model is
tried on (`generic_cases`, `lobe_cases`).

A model lists its cases in ``stability_cases()`` with these; `glphong.checks.stability` turns each into a
one-point scene, evaluates it on the GPU, in the twin and in a 60-digit oracle, and reports.
"""
from dataclasses import dataclass

import numpy as np

__all__ = ["Case", "generic_cases", "lobe_cases", "cases_for"]


@dataclass(frozen=True)
class Case:
    """One extreme shading configuration.

    Attributes
    ----------
    name, group : str
    material : glphong.materials.Material
        Any material, built-in or user-defined.
    normal : tuple of 3 float
        Raw normal at the origin (renormalised by the shader; may be zero or non-finite).
    eye : tuple of 3 float
        Camera centre [m].
    lights : tuple of glphong.lights.LightModel or of (kind, where, value)
        Lights, any kind (`glphong.lights.SpotLight(...)`, a user's), or the short form of the kinds made of
        two values: ``('point', position, power)``, ``('unattenuated', position, radiance)`` or
        ``('directional', direction of travel, irradiance)``.
    ambient : float or None
        ``L_a``.
    in_range : bool
        Whether the case lies inside `VALID_RANGES` (expected value representable).
    note : str
    tangent : tuple of 4 float
        Raw tangent (handedness in w) at the point, for terms that need a tangent frame.
    uv : tuple of 2 float
        Texture coordinates at the point, for terms that need them.
    """

    name: str
    group: str
    material: object = None
    normal: tuple = (0.0, 0.0, 1.0)
    eye: tuple = (0.0, 0.0, 1.0)
    lights: tuple = (("point", (0.0, 0.0, 1.0), 4 * np.pi),)
    ambient: float = None
    in_range: bool = True
    note: str = ""
    tangent: tuple = (1.0, 0.0, 0.0, 1.0)
    uv: tuple = (0.5, 0.5)


def _unit(angle_deg, azimuth_deg=0.0):
    """Unit vector at polar angle ``angle_deg`` from +z, azimuth ``azimuth_deg`` from +x."""
    t, p = np.radians(angle_deg), np.radians(azimuth_deg)
    return (float(np.sin(t) * np.cos(p)), float(np.sin(t) * np.sin(p)), float(np.cos(t)))


def _mirror_eye(light_angle, offset_rad):
    """Eye direction at the lobe peak of a light ``light_angle`` deg off the normal +z, turned by ``offset_rad``.

    The mirror direction of ``l`` is the peak of both lobes (Phong: ``v = r``; Blinn: ``h = n``);
    the offset rotates it about +y, away from the peak.
    """
    v = np.array(_unit(light_angle, 180.0))
    c, s = np.cos(offset_rad), np.sin(offset_rad)
    return (float(c * v[0] + s * v[2]), float(v[1]), float(-s * v[0] + c * v[2]))


def _grazing(n_dot_l):
    """Unit light direction with exactly the given cosine to +z (in float64)."""
    return (float(np.sqrt(1.0 - n_dot_l * n_dot_l)), 0.0, float(n_dot_l))


def generic_cases(label, material):
    """The geometry every model is tried on: grazing light and view, light behind, ``l = -v``, and
    ``l`` and ``v`` grazing and mirrored (list of Case).

    Parameters
    ----------
    label : str
        Prefix of the case names (the model's name).
    material : glphong.materials.Material
    """
    e_one = 4 * np.pi  # a point light at 1 m with E = 1 W/m^2
    light = _unit(30.0)
    cases = []
    for cosine in (1e-2, 1e-4, 1e-6, 0.0, -1e-6):
        cases.append(Case(f"{label} grazing light n.l={cosine:g}", "grazing", material,
                          eye=_unit(20.0, 90.0), lights=(("point", _grazing(cosine), e_one),)))
    cases.append(Case(f"{label} grazing view n.v=1e-5", "grazing", material,
                      eye=_unit(90 - np.degrees(1e-5), 180.0), lights=(("point", _unit(60.0), e_one),)))
    cases.append(Case(f"{label} light behind the surface", "behind", _with_ka(material, 0.01),
                      eye=_unit(30.0, 180.0), lights=(("point", _unit(120.0), e_one),),
                      note="k_a only: the n.l gate removes every term, specular too"))
    cases.append(Case(f"{label} l = -v", "opposite", material, eye=tuple(-c for c in light),
                      lights=(("point", light, e_one),), note="n.v < 0: a half vector is undefined"))
    cases.append(Case(f"{label} l, v grazing and mirrored, |l + v| = 6e-6", "opposite", material,
                      eye=(-1.0, 0.0, 3e-6), lights=(("directional", (-1.0, 0.0, -3e-6), 1.0),),
                      note="n.l = n.v = 3e-6: the half vector is n, just above Blinn's |l + v| floor"))
    return cases


def _with_ka(material, ka):
    """``material`` with the constant term ``ka`` (same class, same parameters)."""
    values = material.parameter_values()
    values["ka"] = ka
    return type(material)(**values)


def lobe_cases(label, material_class):
    """A cosine-power lobe's exponent sweep, at, near and in the tail of its peak, and ``q = 0`` off
    the peak (list of Case).

    Parameters
    ----------
    label : str
    material_class : type
        Called as ``material_class(kd, ks, q)`` (`Phong`, `BlinnPhong`).
    """
    e_one = 4 * np.pi
    light = _unit(30.0)
    cases = []
    for q in (0.0, 0.5, 1.0, 1e3, 1e4, 1e5, 1e6, 1e7):
        width = 1.0 / np.sqrt(max(q, 1.0))
        for where, offset in (("peak", 0.0), ("near", 0.7 * width), ("tail", 3.0 * width)):
            cases.append(Case(f"{label} q={q:g} {where}", "lobe", material_class(0.1, 1.0, q),
                              eye=_mirror_eye(30.0, offset), lights=(("point", light, e_one),)))
    cases.append(Case(f"{label} q=0 with v.r < 0", "lobe", material_class(0.2, 0.5, 0.0), eye=_unit(60.0, 90.0),
                      lights=(("point", light, e_one),), note="0^0 := 1 convention, no pow(0, 0)"))
    return cases


def cases_for(model):
    """The stability cases of a model (its ``stability_cases()``), a list of Case.

    Parameters
    ----------
    model : MaterialModel subclass or instance
    """
    return list((model if isinstance(model, type) else type(model)).stability_cases())
