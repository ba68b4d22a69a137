"""Command line: ``glphong`` / ``python -m glphong``.

With no arguments it renders the lecture's "Phong Examples" figure from the built-in
default scene to ``phong_examples.png`` in the current directory.
"""
import argparse
import json
import sys
import time
import warnings

from glphong.analysis import plots
from glphong.analysis.figures import LIGHT_ANGLES, Q_VALUES, phong_examples, phong_examples_scene
from glphong.analysis.gallery import render_gallery
from glphong.analysis.questions import format_properties, properties
from glphong.batch import BatchError, orbit_scene, render_many
from glphong.bench import methods, quick_cases, run_bench, run_speed, standard_cases
from glphong.bench.matte import MATTE_SAMPLE_VALUES, format_matte, matte_points
from glphong.checks.stability import CASES, CaseExpectations, run_stability
from glphong.checks.verify import verify
from glphong.core.imaging import save_npy
from glphong.core.version import __version__
from glphong.datasets import save_exr, save_npz
from glphong.formats.load import load_scene
from glphong.gpu.contexts import BackendUnavailableError
from glphong.gpu.describe import describe, format_descriptions
from glphong.gpu.passes import GEOMETRY_PASSES
from glphong.gpu.renderer import Renderer
from glphong.lights import registered_lights
from glphong.materials import registered_models
from glphong.materials.blinn import BlinnPhong
from glphong.materials.phong import Phong
from glphong.tools.doctor import run_doctor
from glphong.tools.expressions import ExpressionError, parse_material

__all__ = ["main", "print_error", "EXIT_BAD_INPUT", "EXIT_INTERRUPTED"]

#: exit status of a command refused for its input (a file's content, an expression, a missing backend)
EXIT_BAD_INPUT = 2
#: exit status after Ctrl-C
EXIT_INTERRUPTED = 130
#: longest error message printed, in characters
MAX_MESSAGE_LENGTH = 500


def one_line(message, limit=MAX_MESSAGE_LENGTH):
    """``message`` as one line: its whitespace runs (newlines included) collapsed to single spaces, and
    cut to ``limit`` characters (ending in ``'...'``) where it is longer.

    Parameters
    ----------
    message : object
        The message (``str()`` of it is used, so an exception works).
    limit : int

    Returns
    -------
    str
    """
    text = " ".join(str(message).split())
    return text if len(text) <= limit else text[:limit - 3] + "..."


def print_error(command, message):
    """Print ``glphong <command>: <message>`` to stderr as one line (see `one_line`).

    Parameters
    ----------
    command : str
        The subcommand (``'render'``, ``'brdf'``, ...).
    message : object
        The message or exception.
    """
    print(f"glphong {command}: {one_line(message)}", file=sys.stderr)


def _render_file(args):
    """``glphong render FILE``: a scene file at the requested size (its camera and lights, or the defaults)."""
    from pathlib import Path

    try:
        scene = load_scene(args.file, light_units=args.light_units, camera_name=args.camera,
                           allow_outside=args.allow_outside)
    except ValueError as exc:
        print_error("render", exc)
        return EXIT_BAD_INPUT
    exposure = 1.0 if args.exposure is None else args.exposure
    if args.frames:
        folder = args.out if args.out is not None else f"{Path(args.file).stem}_frames"
        start = time.perf_counter()
        keywords = {"light_units": args.light_units, "camera_name": args.camera, "allow_outside": args.allow_outside}
        specs = [(str(Path(args.file).resolve()), 360.0 * k / args.frames, keywords) for k in range(args.frames)]
        paths = render_many(orbit_scene, specs, args.width, args.height, folder, fmt="png", backend=args.backend,
                            samples=args.samples, numerics=args.numerics)
        print(f"wrote {len(paths)} frames of a turntable of {args.file} to {folder} in "
              f"{time.perf_counter() - start:.1f} s")
        return 0
    out = args.out if args.out is not None else str(Path(args.file).with_suffix(".png").name)
    with Renderer(args.width, args.height, backend=args.backend, samples=args.samples,
                  numerics=args.numerics) as renderer:
        start = time.perf_counter()
        try:
            frame = renderer.render(scene, passes=("radiance", *(args.passes or ())))
        except ValueError as exc:  # a pass the file cannot give ('uv' on a mesh without uvs)
            print_error("render", exc)
            return EXIT_BAD_INPUT
        seconds = time.perf_counter() - start
        frame.save_png(out, exposure=exposure)
        if args.passes:
            passes_out = args.passes_out or str(Path(args.file).with_suffix(".npz").name)
            (save_exr if passes_out.lower().endswith(".exr") else save_npz)(passes_out, frame)
            print(f"wrote {passes_out}: {', '.join(frame.passes)}")
        if args.npy:
            frame.save_npy(args.npy)
        print(f"wrote {out}: {args.file}, {len(scene.objects)} object(s), {args.width}x{args.height} on "
              f"{renderer.backend} in {seconds:.2f} s")
        if args.verify:
            result = verify(scene, renderer, passes=args.passes)
            print(f"cross-check against the float64 twin: {result}")
            return 0 if result.passed else 1
    return 0


def _render(args):
    if args.file is not None:
        return _render_file(args)
    if args.out is None:
        args.out = "phong_examples.png"
    if args.exposure is None:
        args.exposure = 0.6

    with Renderer(args.tile, args.tile, backend=args.backend) as renderer:
        start = time.perf_counter()
        figure = phong_examples(renderer, tile=args.tile, verify=args.verify)
        seconds = time.perf_counter() - start
        figure.save_png(args.out, exposure=args.exposure)
        if args.npy:
            save_npy(args.npy, figure.radiance)
        tiles = len(figure.q_values) * len(figure.light_angles) * 2
        print(f"wrote {args.out}: {tiles} tiles of {args.tile}x{args.tile} on {renderer.backend} "
              f"({renderer.context.renderer_name}) in {seconds:.2f} s")
        if args.verify:
            failed = [r for r in figure.reports if not r.passed]
            worst = max(r.max_relative_error for r in figure.reports)
            print(f"cross-check against the float64 twin: {len(figure.reports) - len(failed)}/{len(figure.reports)} tiles "
                  f"inside the tolerance band, max relative error {worst:.3g}")
            return 1 if failed else 0
    return 0


def _gallery(args):
    with Renderer(args.tile, args.tile, backend=args.backend) as renderer:
        start = time.perf_counter()
        figure = render_gallery(renderer, tile=args.tile, columns=args.columns, verify=args.verify)
        seconds = time.perf_counter() - start
        figure.save_png(args.out, exposure=args.exposure)
        print(f"wrote {args.out}: {len(figure.labels)} models, tiles of {args.tile}x{args.tile} on {renderer.backend} "
              f"in {seconds:.2f} s")
        if args.verify:
            for label, report in zip(figure.labels, figure.reports):
                print(f"  {label:30s} {report}")
            return 0 if all(r.passed for r in figure.reports) else 1
    return 0


def _import_models(names):
    """Import modules (dotted names or .py paths) that define material models or light kinds; returns the new
    models and light kinds."""
    import importlib
    import importlib.util
    import os

    before = set(registered_models()) | set(registered_lights())
    for name in names:
        if name.endswith(".py") or os.sep in name:
            spec = importlib.util.spec_from_file_location(os.path.splitext(os.path.basename(name))[0], name)
            if spec is None or not os.path.isfile(name):
                raise SystemExit(f"glphong: --import {name!r}: no such file")
            module = importlib.util.module_from_spec(spec)
            sys.modules[spec.name] = module
            spec.loader.exec_module(module)
        else:
            importlib.import_module(name)
    return [m for m in registered_models() + registered_lights() if m not in before]


def _stability(args):
    cases = list(CASES)
    for definition in _import_models(args.imports):
        cases += list(definition.stability_cases())
    expectations = CaseExpectations()  # the twins, bands and oracles, once for both formulations
    reports = [run_stability(args.backend, "stable", cases=cases, numerics=args.numerics, expectations=expectations)]
    if args.naive:
        reports.append(run_stability(args.backend, "naive", cases=cases, expectations=expectations))
    if args.json:
        text = "[" + ",\n".join(r.to_json() for r in reports) + "]"
        if args.json == "-":
            print(text)
        else:
            with open(args.json, "w") as f:
                f.write(text)
    if args.json != "-":
        for report in reports:
            print(report.format_table())
            print()
    stable = reports[0]
    return 0 if stable.passed_count == len(stable.rows) and stable.nan_count == 0 else 1


def _describe(args):
    scenes = [phong_examples_scene(m, q, a) for a in LIGHT_ANGLES for m in (Phong, BlinnPhong) for q in Q_VALUES]
    print(f"the default scene ('Phong Examples', {len(scenes)} tiles) compiles:")
    print(format_descriptions(describe(scenes, gbuffer=args.gbuffer), source=args.source))
    return 0


def _doctor(args):
    return run_doctor(args.tile)


def _bench(args):
    import importlib.util

    if args.matte:
        rows = matte_points(samples=(4, 32) if args.quick else MATTE_SAMPLE_VALUES, repeats=args.repeats)
        print(format_matte(rows))
        path = f"{args.out}_matte.json"
        with open(path, "w") as f:
            json.dump(rows, f, indent=1)
        print(f"wrote {path}")
        return 0
    if args.speed:
        report = run_speed(sizes=(64,) if args.quick else (512, 1024), repeats=3 if args.quick else max(args.repeats, 9),
                           quick=args.quick, progress=not args.no_progress)
        print(report.format())
        path = f"{args.out}_speed.json"
        with open(path, "w") as f:
            f.write(report.to_json())
        print(f"wrote {path}")
        return 0

    missing = [m for m in ("matplotlib",) if importlib.util.find_spec(m) is None]
    if missing:  # say so at once, not after minutes of measuring
        print(f"glphong bench needs {', '.join(missing)} for its diagram: pip install 'glphong[bench]'", file=sys.stderr)
        return 2

    report = run_bench(args.width, args.height, cases=quick_cases() if args.quick else standard_cases(),
                       method_list=methods(quick=args.quick), repeats=args.repeats, progress=not args.no_progress,
                       reference_samples=3 if args.quick else 6)
    print(report.format_tables())
    for path in report.write(args.out):
        print(f"wrote {path}")
    return 0


def _material(command, text):
    """The material an expression such as ``"Phong(kd=0.2, ks=0.5, q=20)"`` describes, or None with the reason
    printed as one line to stderr (`glphong.tools.expressions.parse_material`: parsed, never evaluated)."""

    try:
        return parse_material(text)
    except ExpressionError as error:
        shown = text if len(text) <= 80 else text[:60] + f"... ({len(text)} characters)"
        print_error(command, f"cannot build a material from {shown!r}: {error}")
        return None


def _brdf(args):
    material = _material("brdf", args.material)
    if material is None:
        return EXIT_BAD_INPUT
    record = properties(material, gpu=args.gpu, backend=args.backend, directions=args.directions)
    print(record.to_json() if args.json else format_properties(record))
    return 0


def _plot(args):
    import importlib.util

    import numpy as np

    if importlib.util.find_spec("matplotlib") is None:
        print("glphong plot needs matplotlib: pip install 'glphong[bench]'", file=sys.stderr)
        return 2

    if args.kind == "gallery":
        curves = plots.plot_gallery(args.out, theta_i=np.radians(args.theta_i))
        print(f"wrote {args.out}: the lobes of {len(curves)} models at theta_i = {args.theta_i:g} deg")
        return 0
    if not args.materials:
        print(f"glphong plot {args.kind}: give one or more material expressions, e.g. \"Phong(kd=0, ks=0.5, q=20)\"",
              file=sys.stderr)
        return 2
    chosen = {}
    for text in args.materials:
        material = _material("plot", text)
        if material is None:
            return EXIT_BAD_INPUT
        chosen[text] = material
    if args.kind == "lobe":
        plots.plot_lobes(chosen, np.radians(args.theta_i), args.out)
    elif args.kind == "lobe3d":
        if len(chosen) != 1:
            print("glphong plot lobe3d: give exactly one material expression", file=sys.stderr)
            return 2
        text, material = next(iter(chosen.items()))
        plots.plot_lobe_3d(material, np.radians(args.theta_i), args.out, title=f"{text}, theta_i = {args.theta_i:g} deg")
    else:
        plots.plot_albedo(chosen, args.out)
    print(f"wrote {args.out}: {args.kind} of {len(chosen)} material(s)")
    return 0


def _incident_angle(text):
    value = float(text)
    if not 0.0 <= value < 90.0:
        raise argparse.ArgumentTypeError(f"--theta-i must be in [0, 90) degrees (got {text})")
    return value


def _writable(text):
    """An output path whose folder exists (checked before any work)."""
    import os

    folder = os.path.dirname(os.path.abspath(text))
    if not os.path.isdir(folder):
        raise argparse.ArgumentTypeError(f"the folder of {text!r} does not exist")
    return text


def _pass_list(text):
    """``--passes``: comma-separated frame pass names a single scene file can give (not 'radiance', always written,
    nor the flows, which need the next or previous scene)."""
    names = tuple(n.strip() for n in text.split(",") if n.strip())
    known = [n for n in GEOMETRY_PASSES if n not in ("flow", "backward_flow")]
    unknown = [n for n in names if n not in known]
    if not names or unknown:
        raise argparse.ArgumentTypeError(f"--passes takes {', '.join(known)}, comma-separated (got {text!r})")
    return names


def _passes_path(text):
    """``--passes-out``: a .npz or .exr path in an existing folder."""
    if not text.lower().endswith((".npz", ".exr")):
        raise argparse.ArgumentTypeError(f"--passes-out must end in .npz or .exr (got {text!r})")
    return _writable(text)


def _png_path(text):
    """``--out``: a path ending in .png, in an existing folder."""
    if not text.lower().endswith(".png"):
        raise argparse.ArgumentTypeError(f"--out must end in .png (got {text!r})")
    return _writable(text)


def _positive_float(text):
    """A finite number > 0."""
    import math

    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number > 0 (got {text!r})") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"must be a finite number > 0 (got {text!r})")
    return value


def _positive_int(text):
    """An integer >= 1."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be an integer >= 1 (got {text!r})") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be an integer >= 1 (got {value})")
    return value


def _image_side(text):
    """``--width``, ``--height``: an integer from 1 to 16384 (the renderer checks memory before work too)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"--width and --height must be integers from 1 to 16384 (got {text!r})") from None
    if not 1 <= value <= 16384:
        raise argparse.ArgumentTypeError(f"--width and --height must be from 1 to 16384 (got {value})")
    return value


def _tile_size(text):
    """``--tile``: an integer from 1 to 1024 (the figure is 8 x 5 tiles: 1024 makes 8192 x 5120 px, a
    0.5 GB float32 image in memory)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"--tile must be an integer from 1 to 1024 (got {text!r})") from None
    if not 1 <= value <= 1024:
        raise argparse.ArgumentTypeError(f"--tile must be from 1 to 1024 pixels (got {value}; the figure is "
                                         "8 x 5 tiles, held in memory as float32)")
    return value


def build_parser():
    """The argument parser (subcommands: render, stability, gallery, describe, bench, brdf, plot, doctor)."""

    parser = argparse.ArgumentParser(
        prog="glphong", description="Classic local-illumination shading (Lambert, Phong, Blinn-Torrance and your "
        "own materials) in GLSL, rendered offscreen (EGL or OSMesa) and cross-checked against a numpy float64 "
        "twin. With no command: render the lecture's 'Phong Examples' figure to phong_examples.png.")
    parser.add_argument("--version", action="version", version=f"glphong {__version__}")
    sub = parser.add_subparsers(dest="command")
    render = sub.add_parser("render", help="render the 'Phong Examples' figure (the default command), or a scene file")
    render.add_argument("file", nargs="?", default=None,
                        help="a scene file to render (.obj with its .mtl); without it, the default figure")
    render.add_argument("--out", default=None,
                        help="PNG path (default: phong_examples.png, or the file's name with .png); with "
                             "--frames, a folder")
    render.add_argument("--width", type=_image_side, default=512, help="with FILE: image width, 1 to 16384 (default 512)")
    render.add_argument("--height", type=_image_side, default=512, help="with FILE: image height, 1 to 16384 (default 512)")
    render.add_argument("--samples", type=int, choices=(1, 2, 4), default=1, help="with FILE: MSAA samples (default 1)")
    render.add_argument("--numerics", choices=("auto", "stable"), default="auto",
                        help="with FILE: 'auto' (default) the stable float32 arithmetic only where the scene's ranges "
                             "need it, 'stable' everywhere (docs/stability.md)")
    render.add_argument("--light-units", choices=("photometric", "radiometric"), default=None,
                        help="with a glTF FILE that has lights: candela and lux (the glTF specification) or W/sr "
                             "and W/m^2")
    render.add_argument("--camera", default=None, help="with a glTF FILE: the camera to look through (default the first)")
    render.add_argument("--allow-outside", action="store_true",
                        help="with FILE: let it name files outside its own folder (for files you trust)")
    render.add_argument("--frames", type=_positive_int, default=None,
                        help="with FILE: a turntable of N PNG frames (worker processes) into --out, a folder "
                             "(default FILE's name + _frames)")
    render.add_argument("--npy", default=None, type=_writable, help="also write the raw float32 radiance to this .npy path")
    render.add_argument("--passes", default=None, type=_pass_list,
                        help="with FILE: frame passes to write beside the PNG, comma-separated (depth, distance, "
                             "normal, normal_camera, uv, instance, category, object_coordinates, nocs; "
                             "docs/data_for_training.md), into --passes-out")
    render.add_argument("--passes-out", default=None, type=_passes_path,
                        help="with --passes: a .npz or .exr path (default the file's name with .npz)")
    render.add_argument("--backend", default="auto", choices=("auto", "egl", "osmesa"))
    render.add_argument("--tile", type=_tile_size, default=128, help="tile size in pixels, 1 to 1024 (default 128)")
    render.add_argument("--exposure", type=_positive_float, default=None,
                        help="linear exposure before sRGB encoding, > 0 (default 0.6 for the figure, 1 for a file)")
    render.add_argument("--verify", action="store_true", help="cross-check every tile against the float64 twin")
    render.set_defaults(func=_render)
    stability = sub.add_parser("stability", help="run the extreme-case suite: GPU vs float64 vs tolerance band")
    stability.add_argument("--backend", default="auto", choices=("auto", "egl", "osmesa"))
    stability.add_argument("--numerics", default="stable", choices=("stable", "auto"),
                           help="'auto': each case with the pieces Renderer(numerics='auto') specialises for its ranges "
                                "(listed per row); default: the stable formulation everywhere")
    stability.add_argument("--naive", action="store_true",
                           help="also run the cases through the textbook pow(dot(v, r), q) shader")
    stability.add_argument("--json", default=None, type=lambda t: t if t == "-" else _writable(t),
                           help="write the table(s) as JSON to this path ('-': stdout only)")
    stability.add_argument("--import", dest="imports", action="append", default=[], metavar="MODULE",
                           help="import a module (dotted name or .py path) defining material models or light kinds and add "
                                "their stability cases (repeatable)")
    stability.set_defaults(func=_stability)
    gallery = sub.add_parser("gallery", help="render one sphere per reflectance model under the same lights")
    gallery.add_argument("--out", default="gallery.png", type=_png_path, help="PNG path (default: gallery.png)")
    gallery.add_argument("--backend", default="auto", choices=("auto", "egl", "osmesa"))
    gallery.add_argument("--tile", type=_tile_size, default=160, help="tile size in pixels, 1 to 1024 (default 160)")
    gallery.add_argument("--columns", type=_positive_int, default=4, help="tiles per row (default 4)")
    gallery.add_argument("--exposure", type=_positive_float, default=1.0,
                         help="linear exposure before sRGB encoding, > 0 (default 1.0)")
    gallery.add_argument("--verify", action="store_true", help="cross-check every tile against the float64 twin")
    gallery.set_defaults(func=_gallery)
    describe = sub.add_parser("describe", help="list the default scene's programs: keys, chunks, what each leaves out")
    describe.add_argument("--source", action="store_true", help="print each program's effective fragment source")
    describe.add_argument("--gbuffer", action="store_true", help="include the G-buffer programs")
    describe.set_defaults(func=_describe)
    bench = sub.add_parser("bench", help="work-precision report: error against run time for every method")
    bench.add_argument("--width", type=_positive_int, default=256, help="image width in pixels (default 256)")
    bench.add_argument("--height", type=_positive_int, default=192, help="image height in pixels (default 192)")
    bench.add_argument("--repeats", type=_positive_int, default=5, help="timed repeats per point (median, >= 1)")
    bench.add_argument("--quick", action="store_true", help="a tiny configuration (2 scenes, 2 knob values; with "
                       "--speed: small sizes and stand-in meshes)")
    bench.add_argument("--speed", action="store_true", help="frame times on the scene family against the naive "
                       "floor and pyrender (glphong.bench.speed), instead of the work-precision report")
    bench.add_argument("--matte", action="store_true", help="the matte pass's error against the exact coverage, "
                       "against run time, for matte_samples 4 to 64 (glphong.bench.matte), instead of the "
                       "work-precision report; writes PREFIX_matte.json")
    bench.add_argument("--out", default="glphong_bench", type=_writable,
                       help="output prefix: PREFIX.csv, PREFIX.json, PREFIX.png")
    bench.add_argument("--no-progress", action="store_true", help="no progress bar")
    bench.set_defaults(func=_bench)
    brdf = sub.add_parser("brdf", help="is a material's BRDF non-negative, energy-conserving, reciprocal, isotropic?")
    brdf.add_argument("material", help='a material expression, e.g. "Phong(kd=0.2, ks=0.5, q=20)"')
    brdf.add_argument("--json", action="store_true", help="print the record as JSON")
    brdf.add_argument("--gpu", action="store_true", help="evaluate the GLSL on the GPU instead of the float64 twin")
    brdf.add_argument("--backend", default="auto", choices=("auto", "egl", "osmesa"))
    brdf.add_argument("--directions", type=_positive_int, default=300,
                      help="Fibonacci directions per side: their square is the number of pairs (default 300)")
    brdf.set_defaults(func=_brdf)
    plot = sub.add_parser("plot", help="lobe and albedo plots of materials (PNG; matplotlib, in the [test] and [bench] extras)")
    plot.add_argument("kind", choices=("lobe", "lobe3d", "albedo", "gallery"),
                      help="lobe: polar plot in the plane of incidence; lobe3d: one material's lobe over the "
                           "hemisphere as a surface; albedo: against the incident angle; "
                           "gallery: the lobe of every built-in model")
    plot.add_argument("materials", nargs="*", help='material expressions, e.g. "Phong(kd=0, ks=0.5, q=20)"')
    plot.add_argument("--theta-i", type=_incident_angle, default=45.0, help="incident angle [deg], 0 to 90 (default 45)")
    plot.add_argument("--out", default="plot.png", type=_png_path, help="PNG path (default: plot.png)")
    plot.set_defaults(func=_plot)
    doctor = sub.add_parser("doctor", help="why it does (not) render here: libraries, EGL devices, each backend "
                            "checked with a verified render, and what to install (exit 0 where one renders)")
    doctor.add_argument("--tile", type=_tile_size, default=32, help="verification render size in pixels (default 32)")
    doctor.set_defaults(func=_doctor)
    return parser


def main(argv=None):
    """Entry point; returns the process exit code."""
    parser = build_parser()
    argv = list(sys.argv[1:] if argv is None else argv)
    if not argv or argv[0].startswith("-") and argv[0] not in ("-h", "--help", "--version"):
        argv = ["render", *argv]
    args = parser.parse_args(argv)
    if args.func is _render:  # --out is a PNG path, or a folder with FILE --frames: checked before any work
        try:
            if args.out is not None and not (args.file is not None and args.frames):
                _png_path(args.out)
            elif args.out is not None:
                _writable(args.out)
        except argparse.ArgumentTypeError as exc:
            parser.error(f"argument --out: {exc}")
        if args.frames and args.file is None:
            parser.error("--frames needs a scene FILE (a turntable of it)")
    return _run_command(args)


def _run_command(args):
    """Run the parsed command; refused input becomes one line on stderr and exit status 2.

    A `ValueError` (glphong's convention for bad input: a scene file's content, an expression, a
    parameter), an `OSError` (a missing or unreadable file), a `glphong.batch.BatchError` (a worker's
    failure, reported by the parent) and a `glphong.gpu.contexts.BackendUnavailableError` are printed as
    ``glphong <command>: <message>``; Ctrl-C exits with 130.  Anything else is a bug and propagates
    with its traceback.

    Parameters
    ----------
    args : argparse.Namespace
        The parsed arguments, with ``func`` and ``command``.

    Returns
    -------
    int
        The exit status.
    """
    command = getattr(args, "command", None) or "render"

    def one_line_warning(message, category, filename, lineno, file=None, line=None):
        print(f"glphong {command}: warning: {one_line(str(message))}", file=sys.stderr)

    try:
        with warnings.catch_warnings():
            warnings.showwarning = one_line_warning  # a file's warnings as lines, not source excerpts
            return args.func(args)
    except KeyboardInterrupt:
        print_error(command, "interrupted")
        return EXIT_INTERRUPTED
    except (ValueError, OSError, BatchError, BackendUnavailableError) as error:
        print_error(command, error)
        return EXIT_BAD_INPUT
