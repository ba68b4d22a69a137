"""What each reflectance model costs: frame time relative to Lambert, and its error against the twin.

Every entry of the gallery (`glphong.analysis.gallery.GALLERY`: one sphere per model, the same lights, a key point
light, a rim directional light and ambient) is rendered at SIZE x SIZE (default 1024; the sphere covers
about 55 % of the image), alternating all models each round after a warm-up (`glphong.core.timing.alternating_medians`),
and reported as the median frame time (render + float32 readback), its ratio to Lambert measured in the
same process, and the cross-check against the float64 twin at that size (`glphong.verify`: covered
pixels, max relative error, pixels outside the band).

Run:  python benchmarks/models.py [--size 1024] [--repeats 9] [--backend egl] [--json out.json]
"""
import argparse
import json

import glphong
from glphong.analysis.gallery import GALLERY, gallery_scene
from glphong.core.timing import alternating_medians


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=int, default=1024)
    parser.add_argument("--repeats", type=int, default=9)
    parser.add_argument("--backend", default="egl", choices=("egl", "osmesa"))
    parser.add_argument("--json", default=None)
    args = parser.parse_args(argv)
    scenes = {}
    for label, factory in GALLERY:
        try:
            scenes[label] = gallery_scene(factory())
        except AttributeError:
            continue
    rows = []
    with glphong.Renderer(args.size, args.size, backend=args.backend) as renderer:
        times = alternating_medians({label: (lambda s=s: renderer.render(s)) for label, s in scenes.items()},
                                    repeats=args.repeats, warmup=2)
        for label, scene in scenes.items():
            report = glphong.verify(scene, renderer)
            rows.append({"model": label, "ms": 1e3 * times[label], "relative_to_lambert": times[label] / times["Lambert"],
                         "pixels": report.covered_pixels, "max_relative_error": report.max_relative_error,
                         "outside_band": report.outside_count, "passed": report.passed})
        print(f"{args.size}x{args.size} on {args.backend} ({renderer.context.renderer_name}), median of {args.repeats}")
    print(f"{'model':32s} {'ms':>8s} {'/ Lambert':>10s} {'pixels':>8s} {'max rel err':>12s} {'outside':>8s}")
    for r in rows:
        print(f"{r['model']:32s} {r['ms']:8.1f} {r['relative_to_lambert']:10.2f} {r['pixels']:8d} "
              f"{r['max_relative_error']:12.3g} {r['outside_band']:8d}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)
    return 0 if all(r["passed"] for r in rows) else 1


if __name__ == "__main__":
    raise SystemExit(main())
