"""Many frames: one render per spec, in worker processes, resumable (``glphong.batch.render_many``).

A batch is a list of small picklable specs (a camera angle, a material parameter, a file name) and a
picklable top-level function ``scene_fn(spec) -> Scene`` that builds each frame's scene in the worker (a
pickled scene would carry and re-upload its meshes).  Frames are written to ``out_dir`` as float32
radiance ``.npy`` (or PNG) files named by their index; each is written to a temporary file and renamed, so
a frame file is whole or absent.  ``manifest.json`` records the batch (the spec hashes, glphong's version,
the image size and format, the GL renderer): a rerun with the same batch renders only the frames that are
missing, and a different batch in the same folder is refused rather than mixed.

The default executor is a ``concurrent.futures.ProcessPoolExecutor`` started with 'spawn' (a forked child
of a process that made a context would hang: `glphong.contexts.ForkedProcessError`), one renderer per
worker made on first use and kept, and ``LP_NUM_THREADS`` set in each worker before its first context so
that the workers do not oversubscribe the cores.  Any ``concurrent.futures.Executor`` works, a Dask
client's included (``client.get_executor()``, for a real cluster ``Client("tcp://scheduler:8786")`` or
dask-jobqueue's), and ``executor="dask"`` starts a local Dask cluster.  A worker that dies mid-batch costs
no frame: the pool is made again and the frames not yet on disk are rendered again (Dask reschedules the
task itself).
"""
import hashlib
import json
import os
import pickle
import tempfile
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

import numpy as np

__all__ = ["render_many", "turntable_scene", "orbit_scene", "BatchError"]

_WORKER = {}


class BatchError(RuntimeError):
    """A batch cannot run as asked (another batch's frames in the folder, a spec that cannot be pickled)."""


def _spec_hash(spec):
    try:
        data = pickle.dumps(spec, protocol=4)
    except Exception as exc:  # noqa: BLE001 - whatever pickling raises, say which spec
        raise BatchError(f"spec {spec!r} cannot be pickled ({exc}): specs travel to the workers") from None
    return hashlib.sha256(data).hexdigest()[:16]


def _frame_name(index, fmt):
    return f"frame_{index:06d}.{fmt}"


def _set_threads(threads):
    """Worker initialiser: llvmpipe's rasterizer threads per worker, before the worker's first context."""
    if threads:
        os.environ.setdefault("LP_NUM_THREADS", str(threads))


def _local_dask(workers):
    """``((client, cluster), executor)``: a local Dask cluster of ``workers`` single-threaded processes."""
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise ImportError("executor='dask' needs dask.distributed: pip install 'glphong[dask]'") from None
    threads = max(1, (os.cpu_count() or 1) // workers)
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                           env={"LP_NUM_THREADS": str(threads)})
    client = Client(cluster)
    return (client, cluster), client.get_executor()


def _remove_partials(out):
    """Remove the temporary files of writers that died (``.partial-*``; a frame is renamed when whole)."""
    for leftover in Path(out).glob(".partial-*"):
        try:
            leftover.unlink()
        except OSError:
            pass


def _render_chunk(scene_fn, items, width, height, out_dir, fmt, options):
    """In a worker: render ``items`` (``(index, spec)`` pairs) with the worker's renderer, write each frame
    atomically; returns the written paths and the worker's GL renderer name."""
    from .renderer import Renderer

    key = (width, height, tuple(sorted(options.items())))
    renderer = _WORKER.get(key)
    if renderer is None or renderer.context is None:
        renderer = _WORKER[key] = Renderer(width, height, **options)
    written = []
    for index, spec in items:
        frame = renderer.render(scene_fn(spec))
        final = Path(out_dir) / _frame_name(index, fmt)
        handle, temporary = tempfile.mkstemp(dir=out_dir, prefix=".partial-", suffix=f".{fmt}")
        os.close(handle)
        try:
            if fmt == "npy":
                np.save(temporary, np.ascontiguousarray(frame.radiance, dtype=np.float32))
            else:
                frame.save_png(temporary)
            os.replace(temporary, final)
        finally:
            if os.path.exists(temporary):
                os.remove(temporary)
        written.append(str(final))
    return written, renderer.context.renderer_name


def render_many(scene_fn, specs, width, height, out_dir, executor=None, fmt="npy", frames_per_task=1,
                workers=None, progress=True, **options):
    """Render one frame per spec into ``out_dir`` and return the frame paths in spec order.

    Parameters
    ----------
    scene_fn : callable
        A picklable top-level function ``scene_fn(spec) -> glphong.Scene``, called in the workers.
    specs : sequence
        Picklable specs, one frame each.
    width, height : int
    out_dir : str or path-like
        Made if missing.  Holds the frames and ``manifest.json``.
    executor : concurrent.futures.Executor or 'dask', optional
        Default: a 'spawn' process pool of ``workers`` processes (default: the CPU count), shut down at
        the end; a given executor is used as it is and left running (a Dask client's:
        ``client.get_executor()``).  ``'dask'``: a local Dask cluster of ``workers`` single-threaded
        worker processes (``dask.distributed.LocalCluster``, from the ``[dask]`` extra), closed at the end.
    fmt : {'npy', 'png'}
        float32 radiance ``.npy`` (default) or an 8-bit sRGB PNG at exposure 1.
    frames_per_task : int
        Frames a task renders in a row (fewer round trips for small frames).
    progress : bool
        A tqdm progress bar where tqdm is installed.
    **options
        `glphong.Renderer` options (``backend``, ``samples``, ...).

    Returns
    -------
    list of str
        The frame paths, ``out_dir/frame_NNNNNN.npy``, in spec order.

    Raises
    ------
    BatchError
        ``out_dir`` holds another batch's manifest, or a spec cannot be pickled.
    """
    from . import __version__, _validate
    from .timing import progress_bar

    specs = list(specs)
    width = _validate.positive_int("width", width, 1, 16384)
    height = _validate.positive_int("height", height, 1, 16384)
    fmt = _validate.choice("fmt", fmt, ("npy", "png"))
    frames_per_task = _validate.positive_int("frames_per_task", frames_per_task)
    if not callable(scene_fn):
        raise TypeError(f"scene_fn must be a callable spec -> Scene (got {type(scene_fn).__name__})")
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    batch = {"glphong": __version__, "width": width, "height": height, "format": fmt,
             "options": {k: repr(v) for k, v in sorted(options.items())}, "specs": [_spec_hash(s) for s in specs]}
    manifest = out / "manifest.json"
    if manifest.exists():
        previous = json.loads(manifest.read_text())
        previous.pop("renderer", None)
        if previous != batch:
            differ = sorted(k for k in batch if previous.get(k) != batch[k])
            raise BatchError(f"{out} holds another batch (its {', '.join(differ)} differ): glphong never mixes two "
                             "batches in one folder; use another out_dir or remove it")
    paths = [str(out / _frame_name(i, fmt)) for i in range(len(specs))]
    missing = [i for i in range(len(specs)) if not os.path.exists(paths[i])]
    workers = workers or os.cpu_count() or 1
    cluster = None
    if isinstance(executor, str):
        _validate.choice("executor", executor, ("dask",))
        cluster, executor = _local_dask(workers)
    own = executor is None
    bar = progress_bar(len(missing), progress, unit="frame")
    renderer_name = None
    try:
        while missing:
            if executor is None:
                import multiprocessing

                threads = max(1, (os.cpu_count() or 1) // workers)
                executor = ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"),
                                               initializer=_set_threads, initargs=(threads,))
            chunks = [missing[k:k + frames_per_task] for k in range(0, len(missing), frames_per_task)]
            futures = [executor.submit(_render_chunk, scene_fn, [(i, specs[i]) for i in chunk], width, height,
                                       str(out), fmt, options) for chunk in chunks]
            broken = False
            for future in futures:
                try:
                    written, renderer_name = future.result()
                    if bar:
                        bar.update(len(written))
                except BrokenProcessPool:
                    broken = True  # a worker died: its frames are not on disk, and are rendered again below
            if renderer_name is not None and not manifest.exists():
                manifest.write_text(json.dumps(batch | {"renderer": renderer_name}, indent=1))
            missing = [i for i in range(len(specs)) if not os.path.exists(paths[i])]
            if broken and own:
                executor.shutdown(wait=True, cancel_futures=True)  # every worker gone: none is writing now
                executor = None
                _remove_partials(out)  # a worker killed with its pool may have left a half-written file
            elif missing and not broken:
                raise BatchError(f"{len(missing)} frame(s) were not written, e.g. {paths[missing[0]]}")
    finally:
        if bar:
            bar.close()
        if own and executor is not None:
            executor.shutdown()
        if cluster is not None:
            for closing in cluster:
                closing.close()
    if own:
        _remove_partials(out)
    if not manifest.exists():  # every frame was already there
        manifest.write_text(json.dumps(batch, indent=1))
    return paths


def turntable_scene(angle):
    """A built-in scene for batches and examples: a Phong and a Blinn-Phong sphere on a plane under a point
    light and ambient light, seen from ``angle`` degrees of azimuth (a picklable top-level ``scene_fn``)."""
    import math

    from . import primitives
    from .camera import PerspectiveCamera
    from .lights import AmbientLight, PointLight
    from .materials import BlinnPhong, Lambert, Phong
    from .scene import Scene

    a = math.radians(float(angle))
    camera = PerspectiveCamera.look_at((3.5 * math.sin(a), 1.6, 3.5 * math.cos(a)), (0.0, 0.0, 0.0),
                                       yfov=math.radians(40.0))
    scene = Scene(camera, [PointLight((2.0, 3.0, 2.0), 250.0)], ambient=AmbientLight(0.03))
    for x, material in ((-0.7, Phong((0.20, 0.06, 0.04), 0.5, 60.0)), (0.7, BlinnPhong((0.04, 0.08, 0.20), 0.5, 240.0))):
        pose = np.diag([0.6, 0.6, 0.6, 1.0])
        pose[:3, 3] = (x, 0.0, 0.0)
        scene.add(primitives.sphere(4), material, pose=pose)
    floor = np.eye(4)
    floor[:3, :3] = [[1, 0, 0], [0, 0, 1], [0, -1, 0]]
    floor[1, 3] = -0.6
    scene.add(primitives.plane(6.0, 4), Lambert(0.08), pose=floor)
    return scene


def orbit_scene(spec):
    """``spec = (path, angle[, load_scene keywords])``: the scene file at ``path`` (`glphong.load_scene`) with the
    camera turned by ``angle`` degrees about the vertical axis through the geometry's centre (a picklable
    ``scene_fn`` for turntables of files: ``glphong render FILE --frames N``)."""
    import math

    from .camera import PerspectiveCamera
    from .loaders import load_scene, scene_bounds

    path, angle = spec[:2]
    scene = load_scene(path, **(spec[2] if len(spec) > 2 else {}))
    camera = scene.camera
    target = camera.position - camera.pose[:3, 2] * np.linalg.norm(camera.position - scene_bounds(scene)[0])
    a = math.radians(float(angle))
    turn = np.array([[math.cos(a), 0.0, math.sin(a)], [0.0, 1.0, 0.0], [-math.sin(a), 0.0, math.cos(a)]])
    eye = target + turn @ (camera.position - target)
    scene.camera = PerspectiveCamera.look_at(eye, target, yfov=camera.yfov, znear=camera.znear, zfar=camera.zfar)
    return scene

