"""GPU against twin per reflectance model, on every backend: the figures of `glphong.testing.assert_twin_matches`.

For every entry of the gallery (`glphong.analysis.gallery.GALLERY`) and each of its terms, the GLSL response is
evaluated on N seeded random direction pairs plus the 17 edge sets of `glphong.testing.direction_sets`
(the +z normal, a tangent along x for the anisotropic terms) and compared with the float64 twin under the
term's band: pairs, non-zero responses, the maximum relative error over the decided channels and the
number of pairs outside the band (assert_twin_matches raises on any; the count is then reported).

Run:  python benchmarks/twin_report.py [--n 2000] [--backends egl osmesa]
"""
import argparse

from glphong.analysis.gallery import GALLERY
from glphong.testing import TwinMismatch, assert_twin_matches


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=2000)
    parser.add_argument("--backends", nargs="+", default=["egl", "osmesa"])
    args = parser.parse_args(argv)
    print(f"{'entry':30s} {'term':24s} {'backend':8s} {'pairs':>6s} {'nonzero':>8s} {'max rel err':>12s} outside")
    for label, factory in GALLERY:
        try:
            material = factory()
        except AttributeError:
            continue
        for term in material.components:
            for backend in args.backends:
                try:
                    f = assert_twin_matches(term, n=args.n, seed=0, backend=backend)
                    outside = 0
                except TwinMismatch as exc:
                    f, outside = {"pairs": 0, "nonzero": 0, "max_relative_error": float("nan")}, str(exc).splitlines()[0]
                print(f"{label:30s} {term.name:24s} {backend:8s} {f['pairs']:6d} {f['nonzero']:8d} "
                      f"{f['max_relative_error']:12.3g} {outside}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
