"""Soak (issue 42): frames by the hundred thousand, renderers, contexts and batches, sampling what could grow.

Phases (each count an option, 0 skips it; docs/long_runs.md has the figures):

- ``--frames`` (default 100000): one renderer in this process; after a warm-up of the `CYCLE` scene structures
  (each rendered and cross-checked once; a few more programs follow, for the parameter ranges `numerics='auto'`
  meets later: the GL objects held stopped growing by frame 400 in runs sampled every 100 frames), a new scene
  every frame: the
  material (seven models, their parameters changing), one to three lights of four kinds at moving positions, the
  object's pose, the camera, the sphere's mesh (a new one); every ``--resize-every`` frames (default 1000) the
  image size changes (a cycle of four sizes); every 7th frame with depth and normals; at every sample the frame's
  scene is cross-checked against the twin (`glphong.verify`).  At the end the first scene is rendered again at the
  first size, by the same renderer and by a new one: both must be bit-identical to the first render.
- ``--renderers`` (default 1000): renderers made, rendering one frame and released, alternating the backends
  (``--backends``); every tenth dropped without ``release()`` (the next glphong call releases it).
- ``--contexts`` (default 1000): contexts made by `glphong.gpu.contexts.create_context`, alternating the backends,
  drawn on and destroyed (``release()``, not recycled as a renderer's is): what the driver keeps per context.
- ``--workers`` (default 10000): frames through `glphong.batch.render_many`'s 'spawn' pool of 2 workers;
  ``--dask`` (default 10000): through ``render_many(executor="dask")``, a 2-worker local cluster; tasks of `CYCLE`
  frames.  Frame 0 of each batch must be bit-identical to this process's first render (same size and backend).
  ``--batches`` (default 1) such batches in a row from this process: its resident memory after each and its largest
  during each (read every 0.2 s), against its memory before the first.

Sampled after ``gc.collect()`` every ``--sample-every`` frames (and ten times per renderer and context phase):
resident memory (/proc/self/statm), open descriptors (/proc/self/fd), threads (/proc/self/task), what glphong holds
(`glphong.gpu.counters.gl_objects_alive`: live renderers, their GL objects, pooled contexts, orphans), and the
median, 99th percentile and largest render time of the interval's frames (`Renderer.render` alone) [ms].  The batch workers sample themselves the
same way from their scene function, at the first frame of a task every ``--sample-every`` frames (rounded to a
multiple of `CYCLE`), and are judged from their second sample on.  "After warm-up": from the
sample at ``--warmup`` frames (default 2000) on.

Run:  python benchmarks/soak.py [--frames 100000] [--size 32 24] [--json soak.json]   (the full soak, about 20 minutes
      on 2 cores); tests/test_soak.py runs it with --frames 10000 --size 16 16 --workers 0 --dask 0 and others.
"""
import argparse
import gc
import json
import os
import tempfile
import threading
import time
import warnings

import numpy as np

import glphong
from glphong import primitives
from glphong.gpu.contexts import BACKENDS, create_context
from glphong.gpu.counters import gl_objects_alive
from glphong.scene.geometry import MeshData


# --------------------------------------------------------------------------- what is sampled
def probe():
    """Resident memory [MiB], open descriptors, threads and `gl_objects_alive` of this process, after a collection."""
    gc.collect()
    with open("/proc/self/statm") as f:
        rss = int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20
    counts = gl_objects_alive()
    return {"rss_mib": round(rss, 3), "fds": len(os.listdir("/proc/self/fd")),
            "threads": len(os.listdir("/proc/self/task")), "renderers": counts.renderers,
            "gl_objects": counts.objects, "pooled_contexts": counts.pooled_contexts, "orphans": counts.orphans}


def growth(samples, start=0):
    """What changed from ``samples[start]`` to the end: RSS band (max - min) and end - start [MiB], descriptors,
    threads and GL objects end - start, and the RSS slope by least squares [MiB per 10^4 frames]."""
    kept = samples[start:]
    rss = np.array([s["rss_mib"] for s in kept])
    x = np.array([s.get("frame", k) for k, s in enumerate(kept)], dtype=float)
    slope = float(np.polyfit(x, rss, 1)[0]) * 1e4 if len(kept) > 2 and np.ptp(x) > 0 else 0.0
    first, last = kept[0], kept[-1]
    return {"rss_band_mib": round(float(np.ptp(rss)), 3), "rss_end_minus_start_mib": round(last["rss_mib"] - first["rss_mib"], 3),
            "rss_slope_mib_per_1e4": round(slope, 3), "fds_change": last["fds"] - first["fds"],
            "threads_change": last["threads"] - first["threads"],
            "gl_objects_change": last["gl_objects"] - first["gl_objects"],
            "renderers_change": last["renderers"] - first["renderers"]}


# --------------------------------------------------------------------------- the scenes
#: the scenes' structure (material model, light kinds and count, ambient or not, passes) repeats every CYCLE
#: frames (7 x 4 x 3): their programs are all made in the first CYCLE frames; the numbers change every frame
CYCLE = 84

def _material(i):
    """The i-th frame's material: seven models in turn, parameters changing with ``i``."""
    t = (i * 0.618034) % 1.0
    return (lambda: glphong.Lambert(0.1 + 0.8 * t),
            lambda: glphong.Phong(0.2, 0.5, 5.0 + i % 200),
            lambda: glphong.BlinnPhong((0.2, 0.1 + 0.5 * t, 0.3), 0.6, 10.0 + 3 * (i % 97)),
            lambda: glphong.materials.PhongLobe(0.8, 10.0 ** (1 + i % 5)),
            lambda: glphong.CookTorrance((0.3, 0.2, 0.1), 0.05 + 0.5 * t),
            lambda: glphong.OrenNayar(0.6, 0.05 + 1.2 * t),
            lambda: glphong.GltfPBR((0.8, 0.3, 0.2), metallic=t, roughness=0.1 + 0.8 * t))[i % 7]()


def _lights(i):
    """One to three lights of four kinds, positions moving with ``i``."""
    a = 0.37 * i
    kinds = (lambda: glphong.PointLight((1.5 + np.cos(a), 2.0, 2.0 + np.sin(a)), 40.0 + i % 50),
             lambda: glphong.DirectionalLight((0.3 * np.cos(a), -1.0, -0.4), 0.5),
             lambda: glphong.SpotLight((0.0, 3.0, 1.0), (0.1 * np.sin(a), -1.0, -0.3), 30.0,
                                       outer_cone_angle=0.6),
             lambda: glphong.UnattenuatedPointLight((-2.0, 1.0 + np.sin(a), 1.0), 0.3))
    return [kinds[(i + k) % 4]() for k in range(1 + i % 3)]


def _pose(i):
    """A rotation about a tilted axis by ``0.41 i`` rad and a small translation (4x4, metres)."""
    axis = np.array([np.sin(0.1 * i), 1.0, 0.3])
    axis /= np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    angle = 0.41 * i
    pose = np.eye(4)
    pose[:3, :3] = np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k
    pose[:3, 3] = (0.2 * np.sin(i), 0.1 * np.cos(0.5 * i), 0.0)
    return pose


def _sphere(i):
    """A new mesh every frame (its buffers uploaded, and released when the frame's scene is gone): a sphere of 1 to 3
    subdivisions and a radius changing with ``i`` (`glphong.primitives.sphere` caches its meshes: scaled copies)."""
    base = primitives.sphere(1 + i % 3)
    radius = 0.8 + 0.2 * ((i * 0.381966) % 1.0)
    return MeshData(base.positions * radius, base.normals, base.indices, uvs=base.uvs)


def scene(i):
    """The i-th scene: a sphere (`_sphere`, a new mesh) of `_material` at `_pose` on a Lambert floor,
    `_lights`, an ambient term every other frame, the camera orbiting."""
    camera = glphong.PerspectiveCamera.look_at((np.sin(0.2 * i), 0.6, 3.0 + 0.5 * np.cos(0.3 * i)), (0.0, 0.0, 0.0))
    s = glphong.Scene(camera, lights=_lights(i), ambient=glphong.AmbientLight(0.02) if i % 2 else None)
    s.add(_sphere(i), _material(i), pose=_pose(i))
    floor = np.eye(4)
    floor[1, 3] = -0.6
    s.add(primitives.plane(4.0, 4), glphong.Lambert(0.1), pose=floor)
    return s


def worker_scene(spec):
    """`scene` for a batch worker; ``spec = (i, stats_path, every)``: every ``every`` frames it appends the
    worker's `probe` to ``stats_path`` (one JSON line), before building the scene."""
    i, stats_path, every = spec
    if stats_path and i % every == 0:
        with open(stats_path, "a") as f:
            f.write(json.dumps({"pid": os.getpid(), "frame": i, **probe()}) + "\n")
    return scene(i)


# --------------------------------------------------------------------------- the phases
def _sizes(width, height):
    return [(width, height), (width + 5, height + 3), (2 * width, 2 * height), (max(1, width // 2), max(1, height // 2))]


def frames_phase(n, width, height, backend, every, resize_every, warmup, log, first):
    """One renderer, ``n`` frames of a new scene each; the first scene again at the end by it and by a new renderer,
    each compared bit for bit with ``first`` (scene 0 rendered before, by another renderer)."""
    sizes = _sizes(width, height)
    renderer = glphong.Renderer(width, height, backend=backend)
    for i in range(CYCLE):  # warm-up: the programs and targets of every scene structure, made once
        renderer.render(scene(i), depth=i % 7 == 0, normals=i % 7 == 0)
        glphong.verify(scene(i), renderer)
    samples, times, failed, checks, compared, differed = [], [], 0, 0, 0, 0
    start = time.perf_counter()
    for i in range(n):
        if resize_every and i % resize_every == 0:
            renderer.resize(*sizes[(i // resize_every) % len(sizes)])
        s = scene(i)
        t = time.perf_counter()
        renderer.render(s, depth=i % 7 == 0, normals=i % 7 == 0)
        times.append(time.perf_counter() - t)
        if (i + 1) % every == 0 or i + 1 == n:
            ms = np.array(times) * 1e3
            checks += 1
            failed += not glphong.verify(s, renderer).passed
            # scene 0 again, this frame's scene dropped: the GL objects counted are then those of one scene at the
            # size of the moment (its meshes' vertex arrays, its passes' and the cross-check's targets), whatever
            # the frames before; and at the first size its frame is compared with the first
            s = None
            again = renderer.render(scene(0), depth=True, normals=True)
            if (renderer.width, renderer.height) == (width, height):
                compared += 1
                differed += not _same(first, again)
            samples.append({"frame": i + 1, "seconds": round(time.perf_counter() - start, 1), **probe(),
                            "renderer_gl_objects": renderer.gl_object_count(), "size": [renderer.width, renderer.height],
                            "frame_ms_median": round(float(np.median(ms)), 3),
                            "frame_ms_p99": round(float(np.percentile(ms, 99)), 3), "frame_ms_max": round(float(ms.max()), 3)})
            times = []
            log(f"frames {i + 1:7d}  {samples[-1]['seconds']:7.1f} s  rss {samples[-1]['rss_mib']:8.2f} MiB  "
                f"fds {samples[-1]['fds']}  threads {samples[-1]['threads']}  gl {samples[-1]['gl_objects']}  "
                f"median {samples[-1]['frame_ms_median']:.2f} ms")
    renderer.resize(width, height)
    again = renderer.render(scene(0), depth=True, normals=True)
    name = renderer.backend
    renderer.release()
    with glphong.Renderer(width, height, backend=backend) as fresh:
        other = fresh.render(scene(0), depth=True, normals=True)
    warm = next((k for k, s in enumerate(samples) if s["frame"] >= warmup), max(0, len(samples) - 1))
    return {"frames": n, "backend": name, "size": [width, height], "sizes": sizes,
            "seconds": samples[-1]["seconds"] if samples else 0.0, "cross_checks": checks, "cross_checks_failed": failed,
            "warmup_frames": samples[warm]["frame"] if samples else 0,
            "after_warmup": growth(samples, warm) if samples else {},
            "first_frame_identical": _same(first, again), "first_frame_identical_new_renderer": _same(first, other),
            "first_frame_compared_at_samples": compared, "first_frame_differed_at_samples": differed,
            "samples": samples}


def _same(a, b):
    """Bit-identical radiance, coverage and mask."""
    return bool(np.array_equal(a.radiance.view(np.uint32), b.radiance.view(np.uint32))
                and np.array_equal(a.coverage.view(np.uint32), b.coverage.view(np.uint32))
                and np.array_equal(a.mask, b.mask))


def renderers_phase(n, width, height, backends, log):
    """``n`` renderers made, rendering one frame and released (every tenth dropped), alternating ``backends``."""
    for backend in backends:  # each backend's one-time set-up (OSMesa's first context: threads and +57 MB) before
        with glphong.Renderer(width, height, backend=backend) as r:  # the first sample
            r.render(scene(0))
    samples, start = [probe()], time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ResourceWarning)  # the dropped ones are deliberate
        for j in range(n):
            r = glphong.Renderer(width, height, backend=backends[j % len(backends)])
            r.render(scene(j))
            if j % 10 != 9:
                r.release()
            del r
            if (j + 1) % max(1, n // 10) == 0:
                samples.append({"frame": j + 1, **probe()})
                log(f"renderers {j + 1:5d}  rss {samples[-1]['rss_mib']:8.2f} MiB  fds {samples[-1]['fds']}  "
                    f"threads {samples[-1]['threads']}  gl {samples[-1]['gl_objects']}")
    glphong.Renderer(1, 1, backend=backends[0]).release()  # a glphong call releases the last orphan
    samples.append({"frame": n, **probe()})
    return {"renderers": n, "backends": list(backends), "seconds": round(time.perf_counter() - start, 1),
            "whole": growth(samples), "after_first_tenth": growth(samples, 1), "samples": samples}


def contexts_phase(n, backends, log):
    """``n`` contexts made alternating ``backends``, each drawn on (a 4x4 clear read back) and destroyed."""
    for backend in backends:
        create_context(backend).release()
    samples, start = [probe()], time.perf_counter()
    for j in range(n):
        ctx = create_context(backends[j % len(backends)])
        with ctx:
            fbo = ctx.mgl.simple_framebuffer((4, 4))
            fbo.use()
            ctx.mgl.clear(0.25, 0.5, 0.75, 1.0)
            if fbo.read(components=4)[:4] != bytes((64, 128, 191, 255)):
                raise AssertionError(f"context {j} ({ctx.backend}) read back the wrong clear colour")
            fbo.release()
        ctx.release()
        if (j + 1) % max(1, n // 10) == 0:
            samples.append({"frame": j + 1, **probe()})
            log(f"contexts {j + 1:5d}  rss {samples[-1]['rss_mib']:8.2f} MiB  fds {samples[-1]['fds']}  "
                f"threads {samples[-1]['threads']}")
    whole = growth(samples)
    return {"contexts": n, "backends": list(backends), "seconds": round(time.perf_counter() - start, 1),
            "whole": whole, "mib_per_context": round(whole["rss_end_minus_start_mib"] / max(n, 1), 4), "samples": samples}


def _rss_mib():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20


class _PeakRss(threading.Thread):
    """This process's largest resident memory [MiB] while it runs, read every ``interval`` seconds."""

    def __init__(self, interval=0.2):
        super().__init__(daemon=True)
        self.interval, self.peak, self.halt = interval, _rss_mib(), threading.Event()

    def run(self):
        while not self.halt.wait(self.interval):
            self.peak = max(self.peak, _rss_mib())


def batch_phase(n, width, height, backend, every, first, executor, log, batches=1):
    """``n`` frames through `render_many` (``executor`` None: the 'spawn' pool; 'dask'), 2 workers; ``batches``
    such batches in a row (each its own pool or cluster), the workers' samples those of the first, this process's
    resident memory after each and its largest during each."""
    from glphong.batch import render_many

    # tasks of CYCLE frames, samples at the first frame of a task: the frame a worker rendered before each sample is
    # then always the last of a cycle (its meshes, not yet released, are counted), and after its first task a worker
    # has made every program
    every = max(1, round(every / CYCLE)) * CYCLE
    before, after_each, peaks = probe(), [], []
    for b in range(batches):
        with tempfile.TemporaryDirectory(prefix="glphong-soak-") as tmp:
            stats = os.path.join(tmp, "workers.jsonl")
            watch = _PeakRss()
            watch.start()
            start = time.perf_counter()
            paths = render_many(worker_scene, [(i, stats if b == 0 else None, every) for i in range(n)], width,
                                height, os.path.join(tmp, "frames"), executor=executor, workers=2,
                                frames_per_task=CYCLE, progress=False, backend=backend)
            elapsed = time.perf_counter() - start
            watch.halt.set()
            watch.join()
            peaks.append(round(watch.peak - before["rss_mib"], 3))
            if b == 0:  # the first batch's time, frame 0 and worker samples are the ones reported
                seconds = elapsed
                identical = bool(np.array_equal(np.load(paths[0]).view(np.uint32),
                                                np.ascontiguousarray(first.radiance).view(np.uint32)))
                with open(stats) as f:
                    rows = [json.loads(line) for line in f]
        after_each.append(round(probe()["rss_mib"] - before["rss_mib"], 3))
        log(f"{executor or 'spawn pool'} batch {b + 1}: parent rss {after_each[-1]:+.2f} MiB after, "
            f"{peaks[-1]:+.2f} MiB at most during")
    after = probe()
    workers = {}
    for row in sorted(rows, key=lambda r: r["frame"]):
        workers.setdefault(row["pid"], []).append(row)
    per_worker = {str(pid): {"frames_sampled": [s[0]["frame"], s[-1]["frame"]],
                             "after_first_sample": growth(s, 1) if len(s) > 2 else None, "samples": s}
                  for pid, s in workers.items()}
    log(f"{executor or 'spawn pool'}: {n} frames in {seconds:.1f} s, frame 0 identical: {identical}")
    return {"frames": n, "executor": executor or "spawn", "seconds": round(seconds, 1),
            "frames_per_second": round(n / seconds, 1), "frame0_identical": identical,
            "parent": {"rss_change_mib": round(after["rss_mib"] - before["rss_mib"], 3),
                       "rss_change_after_each_batch_mib": after_each, "rss_peak_change_during_each_batch_mib": peaks,
                       "fds_change": after["fds"] - before["fds"], "threads_change": after["threads"] - before["threads"]},
            "workers": per_worker}


# --------------------------------------------------------------------------- the report
def markdown(report):
    """The summary as markdown tables."""
    lines = ["| phase | count | seconds | RSS band after warm-up [MiB] | RSS end - start [MiB] | descriptors | "
             "threads | GL objects | identical |", "|---|---|---|---|---|---|---|---|---|"]
    f = report.get("frames")
    if f:
        g = f["after_warmup"]
        lines.append(f"| frames, one renderer ({f['backend']}) | {f['frames']} | {f['seconds']} | {g['rss_band_mib']} | "
                     f"{g['rss_end_minus_start_mib']:+} | {g['fds_change']:+d} | {g['threads_change']:+d} | "
                     f"{g['gl_objects_change']:+d} | {f['first_frame_identical'] and f['first_frame_identical_new_renderer']} |")
    for key, label in (("renderers", "renderers made and released"), ("contexts", "contexts made and destroyed")):
        p = report.get(key)
        if p:
            g = p["whole"]
            lines.append(f"| {label} ({', '.join(p['backends'])}) | {p[key]} | {p['seconds']} | "
                         f"{p.get('after_first_tenth', g)['rss_band_mib']} | {g['rss_end_minus_start_mib']:+} | "
                         f"{g['fds_change']:+d} | {g['threads_change']:+d} | {g['gl_objects_change']:+d} | |")
    for key in ("workers", "dask"):
        p = report.get(key)
        if p:
            grown = [w["after_first_sample"] for w in p["workers"].values() if w["after_first_sample"]]

            def worst(key, form):
                return format(max(w[key] for w in grown), form) if grown else "n/a"

            lines.append(f"| render_many, {p['executor']} (2 workers; worker figures) | {p['frames']} | {p['seconds']} | "
                         f"{worst('rss_band_mib', '')} | {worst('rss_end_minus_start_mib', '+')} | "
                         f"{worst('fds_change', '+d')} | {worst('threads_change', '+d')} | "
                         f"{worst('gl_objects_change', '+d')} | {p['frame0_identical']} |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=100_000)
    parser.add_argument("--renderers", type=int, default=1000)
    parser.add_argument("--contexts", type=int, default=1000)
    parser.add_argument("--workers", type=int, default=10_000, help="frames through render_many's spawn pool")
    parser.add_argument("--dask", type=int, default=10_000, help="frames through render_many(executor='dask')")
    parser.add_argument("--batches", type=int, default=1,
                        help="batches of --workers and of --dask frames in a row from this process (its memory after each)")
    parser.add_argument("--size", type=int, nargs=2, default=(32, 24), metavar=("W", "H"))
    parser.add_argument("--backend", default="auto", choices=("auto", "egl", "osmesa"), help="of the frames and batches")
    parser.add_argument("--backends", default=",".join(BACKENDS),
                        help="comma-separated, alternated by the renderer and context phases (default: egl,osmesa)")
    parser.add_argument("--sample-every", type=int, default=1000)
    parser.add_argument("--resize-every", type=int, default=1000)
    parser.add_argument("--warmup", type=int, default=2000)
    parser.add_argument("--json", default=None, help="write every sample and the summary here")
    parser.add_argument("--quiet", action="store_true", help="no progress lines")
    args = parser.parse_args(argv)
    log = (lambda message: None) if args.quiet else (lambda message: print(message, flush=True))
    backends = [b for b in args.backends.split(",") if b]
    width, height = args.size
    report = {"glphong": glphong.__version__, "started": time.strftime("%Y-%m-%d %H:%M:%S"), "cpus": os.cpu_count(),
              "start": probe(), "counts": {k: getattr(args, k) for k in ("frames", "renderers", "contexts", "workers", "dask")}}
    with glphong.Renderer(width, height, backend=args.backend) as r:
        report["gl_renderer"], report["backend"] = r.context.renderer_name, r.backend
        first = r.render(scene(0), depth=True, normals=True)
    if args.frames:
        report["frames"] = frames_phase(args.frames, width, height, args.backend, args.sample_every,
                                        args.resize_every, args.warmup, log, first)
    if args.renderers:
        report["renderers"] = renderers_phase(args.renderers, width, height, backends, log)
    if args.contexts:
        report["contexts"] = contexts_phase(args.contexts, backends, log)
    if args.workers:
        report["workers"] = batch_phase(args.workers, width, height, args.backend, args.sample_every, first, None, log,
                                        args.batches)
    if args.dask:
        report["dask"] = batch_phase(args.dask, width, height, args.backend, args.sample_every, first, "dask", log,
                                     args.batches)
    report["end"] = probe()
    if args.json:
        with open(args.json, "w") as f:
            json.dump(report, f, indent=1)
    print(markdown(report), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
