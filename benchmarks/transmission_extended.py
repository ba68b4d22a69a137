"""The method error of area and environment lights behind a transmissive surface (issue 41, docs/transmission.md
"Lights"): the generated loops' sum over the kind's weighted directions against the float64 integral over the back
hemisphere.

Scene (the twin's arithmetic, no GPU: the GPU equals the twin of the method within its band, `glphong.verify`, and
tests/test_transmission_extended.py): a thin quad of 1.2 m (normal +z) at z = 0, seen from ``EYE``, its points a
``GRID x GRID`` grid over it; behind it either a RectLight (1 m square 0.6 m below the quad, emitting up, radiance 1)
or an EnvironmentLight (`EnvironmentLight.example`'s sky turned upside down, its sun below the quad), at their
default sample counts (4 x 4 cells; 2 x 4^2 = 32 averaged texels).  Materials: KHR_materials_transmission
(transmission 1, metallic 0, ior 1.5, base colour 1) at roughness 0.3 and 0.6, and KHR_materials_diffuse_transmission
(diffuse transmission 1, transmission 0, roughness 0.5).

- the method: ``sum_k [n.wi_k < 0] <response>(n, wi_k, wo, -n.wi_k) E_k`` over the kind's ``sample`` (what
  `glphong.checks.transmission_extended` twins and the GLSL computes);
- the integral: ``integral <response>(n, w, wo, -n.w) L(w) [-n.w > 0] dw``, the kind's float64 ``exact`` quadrature
  (rtol 1e-9) over the hemisphere about ``-n`` (the responses' twins, `gltf_transmission_response` and
  `gltf_diffuse_transmission_response`, are the specification's BTDFs with the light mirrored through the surface).

Printed per light and material: the relative RMS error over the grid ``sqrt(sum |err|^2 / sum |exact|^2)`` and the
largest per-point relative error (of the point's largest channel).  Roughness 0 is not measured: its BTDF is a delta
that the samples meet with zero measure (0 by the method, 0 by the integral's quadrature too).  Run: ``python
benchmarks/transmission_extended.py`` (about a minute on one core; ``--samples 16``: each light's
samples raised, about two).
"""
import argparse

import numpy as np

import glphong
from glphong.lights.environment import EnvironmentLight
from glphong.materials.gltf_diffuse_transmission import gltf_diffuse_transmission_response
from glphong.materials.gltf_transmission import gltf_transmission_response

EYE = np.array([0.3, -0.4, 2.0])
GRID = 12


def responses():
    """``{name: response(n, wi, wo, n_dot_l)}`` of the materials measured, each (N, 3) [1/sr]."""
    out = {}
    for r in (0.3, 0.6):
        out[f"transmission 1, roughness {r}"] = (lambda n, wi, wo, c, r=r: gltf_transmission_response(
            n, wi, wo, c, np.ones(3), 0.0, 1.0, r, 1.5))
    out["diffuse transmission 1, roughness 0.5"] = (lambda n, wi, wo, c: gltf_diffuse_transmission_response(
        n, wi, wo, c, np.ones(3), 0.0, 0.0, 1.0, 1.5))
    return out


def lights(samples=None):
    """The lights behind the quad, at their default sample counts (or ``samples`` each)."""
    flip = np.diag([1.0, -1.0, -1.0])  # the map's zenith (its sun and its bright sky) below the quad
    more = {} if samples is None else {"samples": samples}
    return {"RectLight": glphong.RectLight((0.1, 0.05, -0.6), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), radiance=1.0, **more),
            "EnvironmentLight": EnvironmentLight.example(rotation=flip, **more)}


def measure(light, response, grid=GRID):
    """``(rms, worst, own)``: the method's relative RMS error over the grid, its largest per-point relative error, and
    the quadrature's own error estimate (relative, its largest)."""
    s = np.linspace(-0.55, 0.55, grid)
    x = np.stack([*np.meshgrid(s, s, indexing="ij"), np.zeros((grid, grid))], axis=-1).reshape(-1, 3)
    n = np.tile([0.0, 0.0, 1.0], (len(x), 1))
    wo = EYE - x
    wo /= np.linalg.norm(wo, axis=1)[:, None]
    p = light.values()
    sampled = np.zeros((len(x), 3))
    for k in range(light.sample_count()):
        valid, wi, e = light.sample(x, n, k, p)
        n_dot_wi = wi @ np.array([0.0, 0.0, 1.0])
        gate = valid & (n_dot_wi < 0.0)
        with np.errstate(divide="ignore", invalid="ignore"):
            term = response(n, wi, wo, -n_dot_wi) * e
        sampled += np.where(gate[:, None], term, 0.0)

    def integrand(index, w):
        with np.errstate(divide="ignore", invalid="ignore"):
            return np.nan_to_num(response(n[index], w, wo[index], -(w @ np.array([0.0, 0.0, 1.0]))))

    exact, error, converged = light.exact(x, -n, p, integrand)
    assert converged.all(), "the quadrature did not converge"
    err = np.max(np.abs(sampled - exact), axis=1)
    size = np.max(np.abs(exact), axis=1)
    rms = np.sqrt(np.sum(np.abs(sampled - exact) ** 2) / np.sum(exact ** 2))
    return rms, float(np.max(err / size)), float(np.max(error / size))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--grid", type=int, default=GRID, help="points per side of the quad")
    parser.add_argument("--samples", type=int, default=None, help="the lights' samples (default: their defaults)")
    args = parser.parse_args()
    print("| light | samples | material | relative RMS | worst point | quadrature's own |")
    print("|---|---|---|---|---|---|")
    for light_name, light in lights(args.samples).items():
        for name, response in responses().items():
            rms, worst, own = measure(light, response, args.grid)
            print(f"| {light_name} | {light.sample_count()} | {name} | {rms:.2e} | {worst:.2e} | {own:.0e} |",
                  flush=True)


if __name__ == "__main__":
    main()
