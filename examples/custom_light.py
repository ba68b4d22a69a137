"""A light glphong does not ship, defined with the same public mechanism as the built-in lights.

A Phong luminaire (the lecture's light-emission slide: a light is what it emits toward a point): a point
source whose intensity falls off about its axis ``a`` as a cosine power,

    I(theta) = I0 max(cos(theta), 0)^n   [W/sr],   cos(theta) = -wi . a,

so the irradiance it delivers at distance ``d`` on a surface facing it is ``E = I(theta) / d^2`` [W/m^2].
``n = 0`` is a hemisphere emitter, ``n = 1`` a Lambertian panel, large ``n`` a narrow beam.  Its GLSL gives, at a
surface point, whether the light reaches it, the direction toward it and ``E``; its numpy twin does the same
in float64, function for function.

The script defines the kind, lights a floor and a sphere with it next to a built-in SpotLight, cross-checks every
pixel against the float64 twin (``glphong.verify``), and checks the floor against the closed form of ``E``.

Run:  python examples/custom_light.py [out.png]
      glphong stability --import examples/custom_light.py     (its cases next to the built-ins')
Its tests: tests/lights/test_custom_light_example.py.
"""
import sys

import numpy as np

import glphong
from glphong import primitives
from glphong.lights import LightModel
from glphong.materials import Param


class PhongLuminaire(LightModel):
    """A point source of intensity ``I0 max(cos(theta), 0)^n`` about its axis."""

    name = "luminaire"
    params = (Param("position", "vec3", low=-np.inf, unit="m", doc="world-space position"),
              Param("axis", "direction", low=-1.0, high=1.0, doc="direction of peak emission"),
              Param("peak", "rgb", low=0.0, unit="W/sr", doc="I0, the intensity along the axis"),
              Param("n", "scalar", low=0.0, high=1e4, default=1.0, doc="the cosine power"))
    glsl = """
    bool luminaire_incident(vec3 x, int j, out vec3 wi, out vec3 irradiance)
    {
        float d;
        bool valid = safe_normalize(u_luminaire_position[j] - x, wi, d);
        float c = -dot(wi, u_luminaire_axis[j]);
        // pow(c, n) is undefined for c <= 0: the select keeps only c > 0 (a cosine power of 0 there);
        // a lobe below FLT_MIN is flushed to 0 by float32 arithmetic (the twin says so too)
        float lobe = c > 0.0 ? pow(max(c, 1e-30), u_luminaire_n[j]) : 0.0;
        irradiance = min((u_luminaire_peak[j] * (lobe / d)) / d, vec3(FLT_MAX));
        return valid;
    }
    """

    def incident(self, x, p):
        """The twin of luminaire_incident, the same formulation in numpy."""
        to_light = p.position - x
        d = np.sqrt(np.sum(to_light * to_light, axis=-1))
        valid = d > 0
        with np.errstate(divide="ignore", invalid="ignore"):
            wi = to_light / d[..., None]
            c = -np.sum(wi * p.axis, axis=-1)
            lobe = np.where(c > 0, np.maximum(c, 1e-30) ** p.n, 0.0)
            # float32 flushes a lobe below FLT_MIN to 0 before the division by d^2 could lift it back into range
            # (glphong.testing.assert_light_matches found this: 14 of 2000 points near the light, n = 30)
            lobe = np.where(lobe < np.finfo(np.float32).tiny, 0.0, lobe)
            irradiance = np.minimum((p.peak * (lobe / d)[..., None]) / d[..., None], np.finfo(np.float32).max)
        return valid, wi, irradiance


    def band(self, x, p, constants):
        """The generic band (the twin's sensitivity to a few ulps of its inputs), widened by the precision GLSL
        gives ``pow(c, n) = exp2(n log2 c)``: ``log2`` within ``2^-21`` absolute on [0.5, 2] (3 ulp elsewhere),
        ``exp2`` within ``3 + 2|t|`` ulp of ``t = n log2 c``, so a relative error of ``ln(2) dt + (3 + 2|t|) eps``."""
        low, high = super().band(x, p, constants)
        to_light = p.position - x
        with np.errstate(divide="ignore", invalid="ignore"):
            c = -np.sum(to_light * p.axis, axis=-1) / np.sqrt(np.sum(to_light * to_light, axis=-1))
            log2c = np.log2(np.clip(c, 1e-30, 1.0))
        eps = 2.0 ** -24
        t = p.n * log2c
        dt = p.n * np.where(c >= 0.5, 2.0 ** -21, 3 * eps * np.abs(log2c)) + eps * np.abs(t)
        rel = (np.log(2.0) * dt + (3 + 2 * np.abs(t)) * eps)[..., None]
        return low * (1 - rel), high * (1 + rel)


def closed_form(light, points):
    """``E = I0 cos(theta)^n / d^2`` on a surface facing the light, straight from the definition (float64)."""
    to_light = np.asarray(light.position) - points
    d = np.linalg.norm(to_light, axis=-1)
    cos_theta = np.clip(-(to_light / d[:, None]) @ np.asarray(light.axis), 0.0, None)
    return np.asarray(light.peak) * (cos_theta ** light.n / d ** 2)[:, None]


def scene():
    """A floor and a sphere under the luminaire and a built-in spot light."""
    camera = glphong.PerspectiveCamera.look_at((0.0, -3.2, 2.4), (0.0, 0.0, 0.3))
    lights = [PhongLuminaire((-0.6, 0.0, 1.5), (0.3, 0.0, -1.0), 6.0, n=8.0),
              glphong.SpotLight((0.9, 0.3, 1.6), (-0.3, -0.1, -1.0), 4.0, inner_cone_angle=0.25, outer_cone_angle=0.45)]
    out = glphong.Scene(camera, lights, ambient=glphong.AmbientLight(0.02))
    out.add(primitives.plane(4.0, segments=8), glphong.Lambert(0.6))
    out.add(primitives.sphere(4, radius=0.4), glphong.Phong(0.3, 0.4, 40.0), pose=np.array(
        [[1, 0, 0, 0.1], [0, 1, 0, 0.2], [0, 0, 1, 0.4], [0, 0, 0, 1]], dtype=float))
    return out


def main(out_path=None, size=(320, 240)):
    lit = scene()
    with glphong.Renderer(*size) as renderer:
        report = glphong.verify(lit, renderer)
        print("verify against the float64 twin:", report.summary())
        # the luminaire alone on the floor, against the closed form: the lecture's Lambert k_d E (n . wi), n = +z
        alone = glphong.Scene(lit.camera, [lit.lights[0]])
        alone.add(primitives.plane(4.0, segments=8), glphong.Lambert(1.0))
        gbuffer = renderer.gbuffer(alone)
        frame = renderer.render(alone)
        covered = gbuffer.mask
        points = gbuffer.position[covered].astype(np.float64)
        to_light = np.asarray(lit.lights[0].position) - points
        n_dot_wi = to_light[:, 2] / np.linalg.norm(to_light, axis=-1)
        expected = closed_form(lit.lights[0], points) * n_dot_wi[:, None]
        got = frame.radiance[covered]
        bright = expected > 1e-3 * expected.max()
        worst = float(np.max(np.abs(got[bright] - expected[bright]) / expected[bright]))
        print(f"floor against E = I0 cos(theta)^n / d^2: {int(bright.sum())} values, largest relative error {worst:.2g}")
        if out_path:
            renderer.render(lit).save_png(out_path, exposure=1.0)
            print("wrote", out_path)
    return report, worst


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else None)
