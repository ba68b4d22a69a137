"""Rough transmission below ior 1.5: the background's level of detail with and without the glTF Sample Viewer's ior
factor, against the specification's thin-walled lobe (docs/transmission.md, "Two roughness rules").

glphong blurs the background at ``lod = log2(W) r clamp(2 ior - 2, 0, 1)`` (the Sample Viewer's ``applyIorToRoughness``:
an ior of 1 bends no light, so it does not blur) while its lights behind take the specification's BTDF with ``alpha =
r^2`` whatever the ior.  This prints, for the geometry and the float64 integral of `benchmarks/transmission_rough.py`
(a 128 px orthographic view at normal incidence, the transmissive plane 0.1 m above a background image, ``F`` Schlick's
of ``f0 = ((ior - 1)/(ior + 1))^2``, 96 x 192 quadrature nodes), the relative RMS error of the method with the factor
(glphong's) and without it (``lod = log2(W) r``).  Run: ``python benchmarks/transmission_ior_lod.py`` (about a minute).
"""
import numpy as np

import transmission_rough as rough
from glphong.checks.transmission_twin import background_lookup
from glphong.materials.gltf_transmission import background_levels, gltf_transmission_weight

GAP = 0.1  # m
NODES = 96


def main():
    size = rough.SIZE
    j, i = np.mgrid[size // 4:3 * size // 4:4, size // 4:3 * size // 4:4]
    rows, columns = j.ravel(), i.ravel()
    xy = np.stack([(columns + 0.5) / size * 2 - 1, 1 - (rows + 0.5) / size * 2], axis=1)
    uv = np.stack([(columns + 0.5) / size, (size - 1 - rows + 0.5) / size], axis=1)
    images = rough.backgrounds(size)
    print("| background | ior | roughness | RMS, lod with the factor (glphong) | RMS, lod without it |")
    print("|-|-|-|-|-|")
    for name in ("gradient", "checker"):
        levels = background_levels(images[name][::-1])  # GL row order
        for ior in (1.0, 1.25):
            rough.F0 = ((ior - 1.0) / (ior + 1.0)) ** 2  # the integral's Schlick f0 (a module constant there)
            weight = gltf_transmission_weight(np.ones(len(rows)), np.ones(3), 0.0, 1.0, ior)
            for r in (0.2, 0.3, 0.5):
                exact = rough.exact(images[name], xy, GAP, r, NODES)
                errors = []
                for factor in (min(max(2.0 * ior - 2.0, 0.0), 1.0), 1.0):
                    lod = np.full(len(rows), np.float32(np.log2(size)) * np.float32(r) * np.float32(factor))
                    got = weight * background_lookup(levels, uv, lod.astype(np.float64))[0]
                    errors.append(np.sqrt(np.sum((got - exact) ** 2) / np.sum(exact ** 2)))
                print(f"| {name} | {ior:g} | {r:g} | {100 * errors[0]:.3g} % | {100 * errors[1]:.3g} % |", flush=True)


if __name__ == "__main__":
    main()
