"""The environment light's defaults on the error-against-time front (issue 40): a sky with a sun of 5 degrees.

The map: 256 x 512 texels (H x W), z up: a sky brightening toward the zenith (0.25 at the horizon to 1.0 at the
zenith, a 0.15 ground) stepped in blocks of 8 x 8 texels, plus a sun disc of 5 degrees angular diameter at 35 degrees
elevation whose irradiance at normal incidence is 10 times the sky's on a horizontal plane (a real sun's share: it
carries most of the irradiance). The sky is constant over 8 x 8 texel blocks so that its exact integral is that of a
32 x 64 map (the lat-long blocks are exactly that map's texels), and the exact integral of the whole map is the sum
of the coarse sky's and of the sun-only map's (whose zero texels the quadrature skips): the Phong lobe's exact
integral, a quadrature over every texel above the horizon, is then affordable (``--check-split`` checks the split
against the quadrature over the whole map at a few pixels).

Measured, per knob setting of `glphong.EnvironmentLight`, each with the bright blocks (``bright`` = K, the default)
and without (K = 0, the whole map by the cube map and the harmonics, the way before them), and at the default knob
every K of ``--brights`` and every threshold T of ``--thresholds`` (besides the automatic one):

- Lambert (``Lambert(0.8)``) against ``resolution`` R of the irradiance cube map: the error of the GPU render against
  the exact integral (`glphong.checks.verify.exact_image`: the map's closed forms) at ``--score`` x ``--score`` pixels;
- the Phong lobe alone (``Phong(0, 1, q)``, q = 10, 50, 100) against ``order`` of the harmonics: the error against
  the exact integral (the quadrature, split as above) at ``--lobe-score`` x ``--lobe-score`` pixels;
- frame time: median and quartiles of ``--repeats`` frames (after 2 warm-up) at ``--size`` x ``--size``, EGL,
  readback included, every setting once in each round (interleaved: the machine's load drifts alike for all), for
  the Lambert sphere, the lobe sphere and a Phong sphere with both terms (``Phong(0.5, 0.3, q)``);
- the light's one-time host cost, measured once: the bright blocks, and the cube map's exact irradiances (R) or the
  harmonics' projection (order).

The exact images do not depend on the knobs: ``--cache DIR`` keeps them between runs (the lobe's take minutes).

Errors (`errors`): the bench's relative RMS ``sqrt(sum |err|^2 / sum |exact|^2)`` over the covered pixels
(`glphong.bench.continuous`), and per pixel ``|err| / |exact|`` over the covered pixels whose exact radiance is above
1e-2 of the image's largest (the bench's rule; RMS, p99, worst) and above ``--threshold`` (default 1e-3: the dim
side and the sky's reflection in the lobe included).

    python benchmarks/environment_defaults.py [--resolutions 5,7,9,13,24] [--orders 2,4,8,16,24]
        [--sh-orders 4,8] [--qs 10,50,100] [--brights 0,8,16,32,64,128] [--thresholds 0.6,2.4,9.6] [--size 256]
        [--score 128] [--lobe-score 48] [--repeats 15] [--backend egl] [--cache DIR] [--json out.json]
        [--error-maps out.png]

``--error-maps`` draws the signed relative error (render / exact - 1) of Lambert and of the lobe at the largest q:
the old defaults (R = 9, order 8, no blocks, `OLD`), the finest settings run without blocks, and the new defaults,
pixels below ``--threshold`` blank (matplotlib).
"""
import argparse
import dataclasses
import json
import sys
import time

import numpy as np

SUN_ELEVATION = np.radians(35.0)
SUN_AZIMUTH = np.radians(-30.0)
SUN_DIAMETER = np.radians(5.0)
BLOCK = 8
#: the defaults before the bright blocks (R = 9, order 8, no blocks), kept in the table and the figure
OLD = {"resolution": 9, "order": 8}


def sun_direction():
    return np.array([np.cos(SUN_ELEVATION) * np.cos(SUN_AZIMUTH), np.cos(SUN_ELEVATION) * np.sin(SUN_AZIMUTH),
                     np.sin(SUN_ELEVATION)])


def maps(H=256, W=512, sun_ratio=10.0):
    """``(whole, coarse sky (H/8 x W/8), sun only)`` [W/(m^2 sr)], grey (H, W) arrays, and the sun's share."""
    from glphong.twin import environment as env
    h, w = H // BLOCK, W // BLOCK
    up = env.texel_directions(h, w)[..., 2]
    coarse = np.where(up > 0.0, 0.25 + 0.75 * np.maximum(up, 0.0) ** 0.5, 0.15)
    sky = np.repeat(np.repeat(coarse, BLOCK, axis=0), BLOCK, axis=1)
    d = env.texel_directions(H, W)
    disc = d @ sun_direction() > np.cos(SUN_DIAMETER / 2)
    omega = env.texel_solid_angles(H, W)[disc].sum()
    sky_e = env.irradiance(sky, np.array([[0.0, 0.0, 1.0]]))[0][0]
    sun_radiance = sun_ratio * sky_e / omega  # irradiance at normal incidence: sun_ratio x the sky's on the ground
    sun = np.where(disc, sun_radiance - sky, 0.0)   # added to the sky: the disc's texels hold sun_radiance
    return sky + sun, coarse, sun, {"sun_texels": int(disc.sum()), "sun_solid_angle_sr": float(omega),
                                    "sun_radiance": float(sun_radiance), "sky_irradiance_up": float(sky_e)}


def scene(material, light):
    import glphong
    from glphong import primitives
    camera = glphong.PerspectiveCamera.look_at((0.0, -2.4, 0.7), (0.0, 0.0, 0.0), up=(0.0, 0.0, 1.0), yfov=0.6)
    sc = glphong.Scene(camera, [light])
    sc.add(primitives.sphere(5, 0.6), material)
    return sc


def errors(image, exact, mask, threshold):
    """The relative errors over the covered pixels: ``energy`` the bench's relative RMS (``sqrt(sum |err|^2 / sum
    |exact|^2)``, `glphong.bench.continuous`), ``worst`` and ``p99`` per pixel over the pixels above 1e-2 of the
    largest exact radiance (the bench's), ``rms_pixel`` and ``worst_dim`` per pixel over those above ``threshold``."""
    mag = np.linalg.norm(exact, axis=-1)
    err = np.linalg.norm(image - exact, axis=-1)
    out = {"energy": float(np.sqrt(np.sum(err[mask] ** 2) / np.sum(mag[mask] ** 2)))}
    for name, t in (("", 1e-2), ("_dim", threshold)):
        lit = mask & (mag > t * mag[mask].max())
        rel = err[lit] / mag[lit]
        out |= {f"rms_pixel{name}": float(np.sqrt(np.mean(rel ** 2))), f"worst{name}": float(rel.max()),
                f"p99{name}": float(np.percentile(rel, 99)), f"pixels{name}": int(lit.sum())}
    return out


def signed_error(image, exact, mask, threshold):
    mag = np.linalg.norm(exact, axis=-1)
    lit = mask & (mag > threshold * mag[mask].max())
    return np.where(lit, np.linalg.norm(image, axis=-1) / np.where(lit, mag, 1.0) - 1.0, np.nan)


def save_error_maps(path, maps_):
    import matplotlib  # noqa: PLC0415 - optional
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415
    fig, axes = plt.subplots(1, len(maps_), figsize=(2.6 * len(maps_), 2.9), squeeze=False)
    for ax, (title, image) in zip(axes[0], maps_):
        shown = ax.imshow(image, cmap="RdBu_r", vmin=-0.1, vmax=0.1)
        ax.set_title(f"{title}\n[{np.nanmin(image):+.1%}, {np.nanmax(image):+.1%}]", fontsize=8)
        ax.axis("off")
    fig.colorbar(shown, ax=axes[0].tolist(), shrink=0.8, label="render / exact - 1 (clipped to 10 %)")
    fig.savefig(path, dpi=110)


def alternating_times(runs, repeats):
    from glphong.core.timing import alternating_times as times  # noqa: PLC0415
    return times(runs, repeats)


def exact_lambert(sc, renderer, cache):
    """The exact Lambert image (the map's closed forms), from ``cache`` (an .npz path or None) where it is there."""
    from glphong.checks.verify import exact_image
    return _cached(cache, "lambert", lambda: exact_image(sc, renderer.gbuffer(sc))[0])


def exact_lobe(lobe, sc, renderer, cache, q):
    """The exact Phong lobe image, split as the module docstring says (coarse sky + sun only), cached likewise."""
    import glphong
    from glphong.checks.verify import exact_image
    _, coarse, sun, _ = maps()

    def compute():
        gb = renderer.gbuffer(sc)
        return (exact_image(scene(lobe, glphong.EnvironmentLight(coarse, order=2, bright=0)), gb)[0]
                + exact_image(scene(lobe, glphong.EnvironmentLight(sun, order=2, bright=0)), gb)[0])
    return _cached(cache, f"lobe_q{q:g}", compute)


def _cached(cache, name, compute):
    import os  # noqa: PLC0415
    path = None if cache is None else os.path.join(cache, f"{name}.npy")
    if path is not None and os.path.exists(path):
        return np.load(path)
    start = time.perf_counter()
    value = compute()
    print(json.dumps({f"{name}_exact_s": time.perf_counter() - start}), flush=True)
    if path is not None:
        os.makedirs(cache, exist_ok=True)
        np.save(path, value)
    return value


def settings(args, knob, values):
    """``(knob value, bright K, threshold)`` rows: each ``values`` with the old way (K = 0) and the default K, and at
    the default knob every K of ``--brights`` and every threshold of ``--thresholds``."""
    import glphong
    default = dict(zip(("resolution", "order"), (glphong.lights.environment.RESOLUTION.default,
                                                  glphong.lights.environment.ORDER.default)))[knob]
    k0 = int(glphong.lights.environment.BRIGHT.default)
    rows = [(v, k, None) for v in values for k in (0, k0)] + [(OLD[knob], 0, None)]
    rows += [(default, k, None) for k in args.brights if k not in (0, k0)]
    rows += [(default, k0, t) for t in args.thresholds]
    return list(dict.fromkeys(rows))


def run(args):
    import glphong
    whole, coarse, sun, info = maps()
    print(json.dumps({"map": info}), flush=True)
    rows, error_maps = [], []

    def light(**kw):
        return glphong.EnvironmentLight(whole, **kw)

    big = glphong.Renderer(args.size, args.size, backend=args.backend)
    small = glphong.Renderer(args.score, args.score, backend=args.backend)
    lobe_small = glphong.Renderer(args.lobe_score, args.lobe_score, backend=args.backend)
    default_r = int(glphong.lights.environment.RESOLUTION.default)
    default_order = int(glphong.lights.environment.ORDER.default)
    default_k = int(glphong.lights.environment.BRIGHT.default)

    timed = {}                          # (row index, column) -> the scene whose frame time that column holds

    def measure(term, knob, value, k, t, lt, build, frame, exact, scenes):
        row = {"term": term, "knob": knob, "value": value, "bright": k, "threshold": t,
               "blocks": lt.bright_count(), "T": lt.bright_threshold(), "build_s": build,
               **errors(frame.radiance.astype(np.float64), exact, frame.mask, args.threshold)}
        print(json.dumps(row), flush=True)
        timed.update({(len(rows), column): sc for column, sc in scenes.items()})
        rows.append(row)

    # ---- Lambert against R, with and without the bright blocks
    lambert = glphong.Lambert(0.8)
    exact = None
    for R, k, t in settings(args, "resolution", args.resolutions):
        lt, build = built(light(resolution=R, bright=k, threshold=t), "irradiance")
        sc = scene(lambert, lt)
        frame = small.render(sc)
        exact = exact_lambert(sc, small, args.cache) if exact is None else exact
        measure("lambert", "resolution", R, k, t, lt, build, frame, exact, {"frame_ms": sc})
        if t is None and (R, k) in ((OLD["resolution"], 0), (max(args.resolutions), 0), (default_r, default_k)):
            error_maps.append((f"Lambert, R = {R}, K = {k}",
                               signed_error(frame.radiance, exact, frame.mask, args.threshold)))
    for order in args.sh_orders:  # Lambert by the harmonics (irradiance='sh')
        for k in (0, default_k):
            lt, build = built(light(order=order, irradiance="sh", bright=k), "sh")
            sc = scene(lambert, lt)
            measure("lambert sh", "order", order, k, None, lt, build, small.render(sc), exact, {"frame_ms": sc})

    # ---- the Phong lobe against order, with and without the bright blocks
    for q in args.qs:
        lobe = glphong.Phong(0.0, 1.0, q)
        exact = None
        for order, k, t in settings(args, "order", args.orders):
            lt, build = built(light(order=order, bright=k, threshold=t), "sh")
            sc = scene(lobe, lt)
            frame = lobe_small.render(sc)
            exact = exact_lobe(lobe, sc, lobe_small, args.cache, q) if exact is None else exact
            measure(f"lobe q={q:g}", "order", order, k, t, lt, build, frame, exact,
                    {"frame_ms": sc, "phong_frame_ms": scene(glphong.Phong(0.5, 0.3, q), lt)})
            if q == args.qs[-1] and t is None and (order, k) in ((OLD["order"], 0), (max(args.orders), 0),
                                                                  (default_order, default_k)):
                error_maps.append((f"lobe q = {q:g}, order {order}, K = {k}",
                                   signed_error(frame.radiance, exact, frame.mask, args.threshold)))
    if args.error_maps:  # per term: the old defaults, the new, the finest without blocks
        old = (f"R = {OLD['resolution']}, K = 0", f"order {OLD['order']}, K = 0")
        rank = [(title.startswith("lobe"), 0 if title.endswith(old) else 2 if title.endswith(", K = 0") else 1)
                for title, _ in error_maps]
        save_error_maps(args.error_maps, [m for _, m in sorted(zip(rank, error_maps), key=lambda x: x[0])])
    # frame times last, every setting in each round (interleaved, so the load's drift hits all alike)
    times = alternating_times({key: (lambda sc=sc: big.render(sc)) for key, sc in timed.items()}, args.repeats)
    for (i, column), t in times.items():
        rows[i][column] = 1e3 * float(np.median(t))
        rows[i][column + "_spread"] = [1e3 * float(np.percentile(t, 25)), 1e3 * float(np.percentile(t, 75))]
    for row in rows:
        print(json.dumps(row), flush=True)
    return rows


def check_split(args):
    """The split exact integral (coarse sky + sun only) against the quadrature over the whole map at a few pixels."""
    import glphong
    from glphong.checks.verify import exact_image
    whole, coarse, sun, _ = maps()
    with glphong.Renderer(args.lobe_score, args.lobe_score, backend=args.backend) as r:
        lobe = glphong.Phong(0.0, 1.0, 100.0)
        sc = scene(lobe, glphong.EnvironmentLight(whole, order=2))
        gb = r.gbuffer(sc)
        picks = np.flatnonzero(gb.mask.ravel())
        picks = np.random.default_rng(1).choice(picks, 3, replace=False)
        keep = np.zeros(gb.mask.size, bool)
        keep[picks] = True
        mask = gb.mask & keep.reshape(gb.mask.shape)
        gb = dataclasses.replace(gb, mask=mask, object_index=np.where(mask, gb.object_index, -1))
        start = time.perf_counter()
        full = exact_image(sc, gb)[0]
        full_s = time.perf_counter() - start
        split = (exact_image(scene(lobe, glphong.EnvironmentLight(coarse, order=2)), gb)[0]
                 + exact_image(scene(lobe, glphong.EnvironmentLight(sun, order=2)), gb)[0])
        print(json.dumps({"full_s": full_s, "full": full[gb.mask].tolist(), "split": split[gb.mask].tolist(),
                          "max_relative": float(np.max(np.abs(full - split)[gb.mask] / np.abs(full[gb.mask])))}))


def built(light_, uniform):
    """``(light, seconds)``: the light with its host-side tables built (the bright blocks and ``uniform``: the
    one-time cost, timed)."""
    start = time.perf_counter()
    light_.uniform_value(uniform)
    return light_, time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ints = lambda s: [int(v) for v in s.split(",")]  # noqa: E731
    parser.add_argument("--resolutions", type=ints, default=[5, 7, 9, 13, 24])
    parser.add_argument("--orders", type=ints, default=[2, 4, 8, 16, 24])
    parser.add_argument("--sh-orders", type=ints, default=[4, 8], help="Lambert by the harmonics")
    parser.add_argument("--qs", type=lambda s: [float(v) for v in s.split(",")], default=[10.0, 50.0, 100.0])
    parser.add_argument("--size", type=int, default=256)
    parser.add_argument("--score", type=int, default=128)
    parser.add_argument("--lobe-score", type=int, default=48)
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--threshold", type=float, default=1e-3)
    parser.add_argument("--backend", default="egl")
    parser.add_argument("--brights", type=ints, default=[0, 8, 16, 32, 64, 128], help="K, at the default R and order")
    parser.add_argument("--thresholds", type=lambda s: [float(v) for v in s.split(",")] if s else [],
                        default=[0.6, 2.4, 9.6], help="T [W/(m^2 sr)] besides the automatic one, at the defaults")
    parser.add_argument("--cache", help="a folder keeping the exact images between runs")
    parser.add_argument("--json")
    parser.add_argument("--error-maps")
    parser.add_argument("--check-split", action="store_true")
    args = parser.parse_args()
    if args.check_split:
        check_split(args)
        return
    rows = run(args)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)


if __name__ == "__main__":
    sys.exit(main())
