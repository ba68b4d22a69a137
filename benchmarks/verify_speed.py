"""What `glphong.verify` costs against one render of the same scene (issue 40).

Scenes (a sphere of tessellation 4 and radius 0.5 seen from 3 m, filling about a fifth of the image):

- Phong sphere, 1 point light; Phong sphere, 8 point lights;
- GltfPBR sphere, a spot light;
- Phong sphere over a Lambert plane, a point light with ``shadows=True``;
- Lambert sphere, a RectLight; Phong sphere, a RectLight (closed forms: irradiance and the whole-q lobe).

For each image size, in one process: one render (`Renderer.render`: draw and float32 readback) timed as the median
of ``--repeats`` runs after a warm-up, and one `glphong.verify` as the median of ``--verify-repeats`` runs after one
warm-up; printed: both medians and their ratio.

``--save DIR`` writes each verify's arrays (reference, low, high, exact, outside, mask, shadow band, relative
error) to ``DIR/<scene>_<size>.npz``; ``--compare DIR`` checks the arrays against such a directory with
``np.array_equal`` (bit for bit, NaN equal to NaN) and prints the verdict per scene; ``--profile SCENE`` runs
cProfile over one verify of that scene at the first size instead.

``--against BEFORE`` compares two versions of glphong interleaved: BEFORE (the root of a checkout or an export of
another commit, e.g. ``git archive <commit> | tar -x -C /tmp/before``) and ``--tree`` (default: this checkout), each
imported in a worker process of its own (``PYTHONPATH`` and ``GLPHONG_GLSL_DIR`` set to its root) that runs this
script's scenes on request.  Per scene and size, after a warm-up, ``--rounds`` rounds alternate the workers (before,
after, before, after, ...); each round times ``--repeats`` renders (their median) and one verify in each worker.
Printed per version: the medians over the rounds of the render, the verify and their ratio, with the ratio's spread
(25th to 75th percentile); each round's verify after over before, in wall time and in the worker's CPU time
(``time.process_time``: less moved by other jobs on the machine than wall time, but llvmpipe's threads count in it);
and whether the two versions' verify arrays are equal bit for bit.

``--shadow-step BEFORE`` times the shadow step alone (`glphong.checks.shadows.shadow_visibility` of every receiver
and shadowing light, on the G-buffer of each scene), BEFORE's ``glphong/checks/shadows.py`` loaded under another
name in this process against this checkout's, interleaved over ``--rounds`` rounds: wall and CPU time, their ratios
and whether the arrays are equal bit for bit.

Run:  python benchmarks/verify_speed.py [--backend egl] [--sizes 64 256] [--repeats 7] [--verify-repeats 3]
      [--scenes ...] [--save DIR | --compare DIR] [--profile SCENE]
      python benchmarks/verify_speed.py --against /tmp/before [--tree DIR] [--rounds 5] [--sizes ...] [--scenes ...]
      python benchmarks/verify_speed.py --shadow-step /tmp/before [--rounds 5] [--sizes ...] [--scenes ...]
"""
import argparse
import cProfile
import importlib.util
import os
import pstats
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import glphong
from glphong import primitives
from glphong.checks import shadows
from glphong.core.timing import median_seconds
from glphong.shaders.binding import binding
from glphong.twin.functions import safe_normalize

ARRAYS = ("reference", "low", "high", "exact", "outside", "mask", "shadow_band", "relative_error")
LIGHTS8 = [(1.5 * np.cos(a), 1.5 * np.sin(a), 1.0 + 0.5 * np.sin(3 * a))
           for a in np.linspace(0, 2 * np.pi, 8, endpoint=False)]


def _scene(material, lights, plane=False):
    camera = glphong.PerspectiveCamera.look_at((0.0, -1.2, 1.5), (0.0, 0.0, 0.45), up=(0.0, 0.0, 1.0))
    scene = glphong.Scene(camera, lights)
    pose = np.eye(4)
    pose[2, 3] = 0.5
    scene.add(primitives.sphere(4, radius=0.5), material, pose=pose)
    if plane:
        scene.add(primitives.plane(4.0, segments=8), glphong.Lambert(0.6))
    return scene


SCENES = {
    "phong_point": lambda: _scene(glphong.Phong(0.3, 0.4, 30.0), [glphong.PointLight((0.8, -1.0, 2.0), 20.0)]),
    "phong_8_points": lambda: _scene(glphong.Phong(0.3, 0.4, 30.0),
                                     [glphong.PointLight(p, 5.0) for p in LIGHTS8]),
    "gltf_spot": lambda: _scene(glphong.GltfPBR((0.8, 0.5, 0.2), 0.3, 0.4),
                                [glphong.SpotLight((0.8, -1.0, 2.0), (-0.8, 1.0, -1.5), 20.0, 0.3, 0.6)]),
    "phong_plane_shadow": lambda: _scene(glphong.Phong(0.3, 0.4, 30.0),
                                         [glphong.PointLight((0.3, 0.2, 2.0), 20.0, shadows=True)], plane=True),
    "lambert_rect": lambda: _scene(glphong.Lambert(0.6),
                                   [glphong.RectLight((0.3, -0.5, 1.6), (0.0, 0.6, 0.3), (1.0, 0.0, 0.0), 5.0)]),
    "phong_rect": lambda: _scene(glphong.Phong(0.3, 0.4, 20.0),
                                 [glphong.RectLight((0.3, -0.5, 1.6), (0.0, 0.6, 0.3), (1.0, 0.0, 0.0), 5.0)]),
}


def _arrays(report):
    return {name: getattr(report, name) for name in ARRAYS if getattr(report, name) is not None}


def _worker(backend):
    """Serve ``render|verify|save <scene> <size> [path]`` lines from stdin: seconds (or 'ok') on stdout."""
    renderers, scenes = {}, {}
    print(Path(glphong.__file__).parent.parent, flush=True)  # the version this worker imported
    for line in sys.stdin:
        command, name, size, *rest = line.split()
        size = int(size)
        if size not in renderers:
            renderers[size] = glphong.Renderer(size, size, backend=backend)
        scene = scenes.setdefault(name, SCENES[name]())
        start, cpu = time.perf_counter(), time.process_time()
        if command == "render":
            renderers[size].render(scene)
        else:
            report = glphong.verify(scene, renderers[size])
            if command == "save":
                np.savez(rest[0], **_arrays(report))
        print(time.perf_counter() - start, time.process_time() - cpu, flush=True)


class _Version:
    """A worker process importing glphong from ``root``."""

    def __init__(self, root, backend):
        env = dict(os.environ, PYTHONPATH=str(root), GLPHONG_GLSL_DIR=str(Path(root) / "glsl"))
        self.process = subprocess.Popen([sys.executable, __file__, "--worker", "--backend", backend], cwd=root,
                                        env=env, stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        self.root = self.process.stdout.readline().strip()

    def ask(self, *words):
        """Seconds the request took: ``(wall, CPU of the worker process)``."""
        self.process.stdin.write(" ".join(str(w) for w in words) + "\n")
        self.process.stdin.flush()
        answer = self.process.stdout.readline()
        if not answer:
            raise RuntimeError(f"the worker of {self.process.args} stopped")
        wall, cpu = answer.split()
        return float(wall), float(cpu)

    def close(self):
        self.process.stdin.close()
        self.process.wait()


def _against(args):
    """``--against``: the two versions interleaved, one worker each."""
    versions = {"before": _Version(args.against, args.backend), "after": _Version(args.tree, args.backend)}
    print(f"before: glphong from {versions['before'].root}; after: from {versions['after'].root}; {args.rounds} rounds, "
          f"render: median of {args.repeats}\n")
    print("| scene | size | render before [ms] | verify before [ms] | before / render | render after [ms] | "
          "verify after [ms] | after / render | verify after / before: wall, CPU | same arrays |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as folder:
        for size in args.sizes:
            for name in args.scenes:
                times = {v: {"render": [], "verify": [], "ratio": [], "cpu": []} for v in versions}
                for v, worker in versions.items():  # warm-up, and the arrays
                    worker.ask("render", name, size)
                    worker.ask("save", name, size, f"{folder}/{v}.npz")
                for _ in range(args.rounds):
                    for v, worker in versions.items():
                        render = float(np.median([worker.ask("render", name, size)[0] for _ in range(args.repeats)]))
                        check, cpu = worker.ask("verify", name, size)
                        times[v]["render"].append(render)
                        times[v]["verify"].append(check)
                        times[v]["cpu"].append(cpu)
                        times[v]["ratio"].append(check / render)
                before, after = (np.load(f"{folder}/{v}.npz") for v in versions)
                differ = [k for k in set(before.files) | set(after.files) if k not in before.files
                          or k not in after.files or not np.array_equal(before[k], after[k], equal_nan=True)]
                cells = []
                for v in versions:
                    ratio = times[v]["ratio"]
                    cells.append(f"{1000 * np.median(times[v]['render']):.1f} | {1000 * np.median(times[v]['verify']):.0f} | "
                                 f"{np.median(ratio):.0f}x ({np.percentile(ratio, 25):.0f}-{np.percentile(ratio, 75):.0f})")
                same = "yes" if not differ else f"no: {', '.join(sorted(differ))}"
                # each round's after over the same round's before: wall, and the CPU time of the worker
                wall, cpu = (np.array(times["after"][k]) / np.array(times["before"][k]) for k in ("verify", "cpu"))
                cells.append(f"{np.median(wall):.2f} ({np.percentile(wall, 25):.2f}-{np.percentile(wall, 75):.2f}), "
                             f"{np.median(cpu):.2f} ({np.percentile(cpu, 25):.2f}-{np.percentile(cpu, 75):.2f})")
                print(f"| {name} | {size} | {' | '.join(cells)} | {same} |", flush=True)
    for worker in versions.values():
        worker.close()


def _shadow_inputs(scene, renderer):
    """``(setup, position, normal, receiver index)`` of each shadowing light at each object's pixels, as the twin
    passes them to `shadow_visibility` (`glphong.checks.reference.shade_inputs`)."""
    gbuffer = renderer.gbuffer(scene)
    out = []
    for index, obj in enumerate(scene.objects):
        selection = gbuffer.object_index == index
        key = renderer.program_key(scene, obj)
        if not key.shadow_slots or not selection.any():
            continue
        position = gbuffer.position[selection].astype(np.float64)
        normal = safe_normalize(gbuffer.face[selection].astype(np.float64))[1]
        out += [(setup, position, normal, index) for setup in binding(scene).shadow_setups(key.lights, key.shadow_size)]
    return out


def _shadow_step(args):
    """``--shadow-step BEFORE``: the shadow step alone (`shadow_visibility` of every receiver and shadowing light),
    BEFORE's glphong/checks/shadows.py (loaded under another name, on this checkout's glphong) against this
    checkout's, interleaved in one process: wall and CPU time, and whether their arrays are equal bit for bit."""
    spec = importlib.util.spec_from_file_location("shadows_before", args.shadow_step / "glphong/checks/shadows.py")
    before = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(before)
    versions = {"before": before, "after": shadows}
    print(f"shadow step: before {spec.origin}, after {shadows.__file__}; {args.rounds} rounds\n")
    print("| scene | size | points | before wall [ms] | after wall [ms] | after / before wall | before CPU [ms] | "
          "after CPU [ms] | after / before CPU | same arrays |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for size in args.sizes:
        with glphong.Renderer(size, size, backend=args.backend) as renderer:
            for name in args.scenes:
                scenes = {v: SCENES[name]() for v in versions}  # each version caches its casters on its own scene
                inputs = _shadow_inputs(scenes["after"], renderer)
                if not inputs:
                    continue
                radius = renderer.shadow_settings[1]

                def step(v):
                    return [versions[v].shadow_visibility(scenes[v], setup, x, n, radius, scenes[v].objects[index])
                            for setup, x, n, index in inputs]

                arrays = {v: step(v) for v in versions}  # warm-up (the casters' intersectors), and the arrays
                same = all(np.array_equal(a, b) and a.dtype == b.dtype for one, other in
                           zip(arrays["before"], arrays["after"]) for a, b in zip(one, other))
                times = {v: {"wall": [], "cpu": []} for v in versions}
                for _ in range(args.rounds):
                    for v in versions:
                        start, cpu = time.perf_counter(), time.process_time()
                        step(v)
                        times[v]["wall"].append(time.perf_counter() - start)
                        times[v]["cpu"].append(time.process_time() - cpu)
                cells = []
                for k in ("wall", "cpu"):
                    ratio = np.array(times["after"][k]) / np.array(times["before"][k])
                    cells.append(f"{1000 * np.median(times['before'][k]):.0f} | {1000 * np.median(times['after'][k]):.0f} "
                                 f"| {np.median(ratio):.2f} ({np.percentile(ratio, 25):.2f}-{np.percentile(ratio, 75):.2f})")
                print(f"| {name} | {size} | {sum(len(x) for _, x, _, _ in inputs)} | {' | '.join(cells)} | "
                      f"{'yes' if same else 'NO'} |", flush=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--backend", default="egl")
    parser.add_argument("--sizes", type=int, nargs="+", default=[64, 256])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--verify-repeats", type=int, default=3)
    parser.add_argument("--scenes", nargs="+", default=list(SCENES), choices=list(SCENES))
    parser.add_argument("--save", type=Path)
    parser.add_argument("--compare", type=Path)
    parser.add_argument("--profile", choices=list(SCENES))
    parser.add_argument("--against", type=Path, help="root of the version to compare with (before)")
    parser.add_argument("--tree", type=Path, default=Path(__file__).resolve().parent.parent,
                        help="root of the version compared (after; default: this checkout)")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--shadow-step", type=Path, help="root of the version whose shadow step to compare with")
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        _worker(args.backend)
        return
    if args.against:
        _against(args)
        return
    if args.shadow_step:
        _shadow_step(args)
        return
    if args.profile:
        size = args.sizes[0]
        with glphong.Renderer(size, size, backend=args.backend) as renderer:
            scene = SCENES[args.profile]()
            glphong.verify(scene, renderer)
            profile = cProfile.Profile()
            profile.enable()
            glphong.verify(scene, renderer)
            profile.disable()
        pstats.Stats(profile).sort_stats("cumulative").print_stats(45)
        return
    if args.save:
        args.save.mkdir(parents=True, exist_ok=True)
    with glphong.Renderer(8, 8, backend=args.backend) as probe:
        print(f"backend: {probe.backend} ({probe.context.renderer_name})\n")
    print("| scene | size | render [ms] | verify [ms] | verify / render | passed |"
          + (" same arrays |" if args.compare else ""))
    print("|---|---|---|---|---|---|" + ("---|" if args.compare else ""))
    for size in args.sizes:
        with glphong.Renderer(size, size, backend=args.backend) as renderer:
            for name in args.scenes:
                scene = SCENES[name]()
                render = median_seconds(lambda: renderer.render(scene), repeats=args.repeats, warmup=2)
                reports = []
                check = median_seconds(lambda: reports.append(glphong.verify(scene, renderer)),
                                       repeats=args.verify_repeats, warmup=1)
                report = reports[-1]
                same = ""
                if args.save:
                    np.savez(args.save / f"{name}_{size}.npz", **_arrays(report))
                if args.compare:
                    before = np.load(args.compare / f"{name}_{size}.npz")
                    now = _arrays(report)
                    differ = [k for k in set(before.files) | set(now) if k not in before.files or k not in now
                              or not np.array_equal(before[k], now[k], equal_nan=True)]
                    same = " yes |" if not differ else f" NO: {', '.join(sorted(differ))} |"
                print(f"| {name} | {size} | {1000 * render:.1f} | {1000 * check:.0f} | {check / render:.0f}x | "
                      f"{report.passed} |{same}", flush=True)


if __name__ == "__main__":
    main()
