"""The lecture's four questions answered for every built-in model: the README's table.

For each entry of the gallery (`glphong.analysis.gallery.GALLERY`: every built-in model at the parameters of its
tile) `glphong.analysis.properties` measures, through the float64 twin, whether its BRDF is non-negative
(min ``f_r`` over 90,000 direction pairs), energy-conserving (the largest directional albedo over 15
incident angles, cos(theta_i) from 1 to 1e-3, with the quadrature's error estimate), reciprocal (largest
``|f(wi, wo) - f(wo, wi)|`` relative to the largest ``f_r``) and isotropic (largest change under a
rotation about n, relative), and compares each answer with what the model declares; `EXTRA` adds
parameters that meet a model's stated energy condition where the tile's do not.

Run:  python benchmarks/brdf_answers.py [--directions 300] [--markdown docs/brdf_answers.md] [--json out.json]
(about 8 s per model on 2 cores).
"""
import argparse
import json
import time

import numpy as np

import glphong
from glphong import analysis
from glphong.analysis.gallery import GALLERY

#: parameters that meet a model's stated energy condition where the gallery tile's do not, or that show where a
#: model declared not energy-conserving gains energy
#: (the tiles share a diffuse albedo of 0.6, which with a Fresnel factor reaching 1 exceeds 1)
EXTRA = (
    ("Cook-Torrance m=0.25, rho_d=0, F=1", lambda: glphong.CookTorrance(0.0, 0.25, fresnel=None)),
    ("Ward bounded, rho_d=0.3, rho_s=0.6", lambda: glphong.Ward(0.3, 0.6, 0.3, 0.06, normalization="bounded")),
    # where glTF's Fresnel mix gains energy (the specification says it does not conserve it): a white dielectric
    ("glTF white dielectric roughness 0.3", lambda: glphong.GltfPBR(1.0, 0.0, 0.3)),
)


def _yes(flag):
    return "yes" if flag else "**no**"


def row(label, record):
    """One markdown row of a `BrdfProperties` record: each answer, its figure, and where the model declares
    otherwise (energy conservation: the declared condition, which the tile's parameters may not meet)."""
    declared = record.declared

    def mark(name):
        if declared.get(name) is None or bool(declared[name]) == bool(getattr(record, name)):
            return ""
        if declared[name] and name == "energy_conserving" and declared.get("condition"):
            return " (declared under a condition these parameters miss)"
        return f" (declared {'yes' if declared[name] else 'no'})"

    albedo = (f"{_yes(record.energy_conserving)}: max {record.max_albedo:.4g} at "
              f"{np.degrees(record.max_albedo_theta_i):.2f} deg (+-{record.quadrature_error:.1g})")
    return (f"| {label} | {_yes(record.non_negative)}: min {record.min_value:.3g}{mark('non_negative')} | "
            f"{albedo}{mark('energy_conserving')} | {_yes(record.reciprocal)}: {record.reciprocity_error:.2g}"
            f"{mark('reciprocal')} | {_yes(record.isotropic)}: {record.isotropy_error:.2g}{mark('isotropic')} |")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--directions", type=int, default=300)
    parser.add_argument("--markdown", default=None, help="also write the table to this file")
    parser.add_argument("--json", default=None)
    args = parser.parse_args(argv)
    lines = ["| model (gallery tile) | non-negative | energy-conserving (directional albedo) | reciprocal | isotropic |",
             "|---|---|---|---|---|"]
    records = {}
    for label, factory in GALLERY + EXTRA:
        material = factory()
        start = time.perf_counter()
        record = analysis.properties(material, directions=args.directions)
        records[label] = record.to_dict() | {"seconds": time.perf_counter() - start}
        lines.append(row(label, record))
        print(lines[-1], f"  [{time.perf_counter() - start:.1f} s]", flush=True)
    table = "\n".join(lines)
    print()
    print(table)
    if args.markdown:
        with open(args.markdown, "w") as f:
            f.write(table + "\n")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(records, f, indent=1)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
