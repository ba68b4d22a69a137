"""The workers of a batch: the 'spawn' pool, the worker-side `_render_chunk`, a local Dask cluster.

The pool's initializer (`_init_worker`) makes each worker die with its parent, by ``PR_SET_PDEATHSIG`` on
Linux and a watchdog thread everywhere; `_render_chunk` renders frames in a worker with the renderer it
keeps and writes each atomically; `_local_dask` starts the local Dask cluster of ``executor='dask'``.

Functions the pool runs (`_init_worker`, `_render_chunk`) are top-level functions of this module: a
'spawn' worker unpickles them by their module path.
"""
import contextlib
import ctypes
import multiprocessing
import os
import signal
import sys
import threading
import time
import traceback
from concurrent.futures import ProcessPoolExecutor, ThreadPoolExecutor
from functools import partial
from pathlib import Path

import numpy as np
from glphong.batch.bop_images import bop_job
from glphong.batch.folder import _CLOEXEC, _NOFOLLOW, _file_digest, _frame_name, _write_error
from glphong.core.atomic_files import write_atomically
from glphong.core.imaging import png_bytes
from glphong.datasets import save_exr, save_npz
from glphong.gpu.renderer import Renderer

_PR_SET_PDEATHSIG = 1  # <linux/prctl.h>
_PARENT_POLL_S = 0.5

_WORKER = {}
#: the writer thread of this process, by pid (a forked child makes its own)
_WRITER = {}


def _set_threads(threads):
    """llvmpipe's rasterizer threads per worker, before the worker's first context."""
    if threads:
        os.environ.setdefault("LP_NUM_THREADS", str(threads))


def _init_worker(threads, parent_pid):
    """Pool worker initialiser: `_set_threads`, SIGINT ignored (Ctrl-C reaches the terminal's whole process group:
    the parent ends its workers itself, `glphong.batch.run._stop_pool`), then `_die_with_parent`.

    Parameters
    ----------
    threads : int
        ``LP_NUM_THREADS`` for this worker (0: leave it).
    parent_pid : int
        The pid of the process that started the pool.
    """
    _set_threads(threads)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    _die_with_parent(parent_pid)


def _die_with_parent(parent_pid):
    """End this process when ``parent_pid``, its parent, dies: ``PR_SET_PDEATHSIG`` on Linux, a check for a
    parent that died before that, and a daemon thread polling ``os.getppid()`` everywhere."""
    if sys.platform.startswith("linux"):
        _request_death_signal()
    if os.getppid() != parent_pid:
        os._exit(1)  # the parent died before the death signal was asked for: nobody will collect our work
    threading.Thread(target=_watch_parent, args=(parent_pid,), name="glphong-parent-watch", daemon=True).start()


def _request_death_signal():
    """Ask the Linux kernel to ``SIGKILL`` this process when its parent dies; False where it cannot."""
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        return libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0
    except (OSError, AttributeError):
        return False


def _watch_parent(parent_pid, interval=_PARENT_POLL_S):
    """Poll every ``interval`` seconds; exit the process at once when the parent is no longer ``parent_pid``
    (an orphan is adopted by init or a subreaper)."""
    while os.getppid() == parent_pid:
        time.sleep(interval)
    os._exit(1)


def _spawn_pool(workers):
    """A 'spawn' `ProcessPoolExecutor` of ``workers`` processes that die with this one."""
    threads = max(1, (os.cpu_count() or 1) // workers)
    return ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"),
                               initializer=_init_worker, initargs=(threads, os.getpid()))


#: Dask settings of the local cluster of ``executor='dask'``: off or empty, what only a dashboard (this cluster has
#: none) or someone debugging Dask would read, and what grew with a batch: the workers' statistical profiler (a stack
#: sample every 10 ms, up to ``low-level-log-length`` one-second profiles: about 1.1 MiB a worker per 10^3 frames),
#: the logs "for developers" (each connection's last ``low-level-log-length`` (1000) message batches: in the
#: scheduler, which runs in this process, every task's arguments, a chunk's specs, sent to a worker, and each graph
#: the client sent; the scheduler's transitions and events), and the system monitor's history (``log-length``
#: (7200) samples, 0.5 s apart).  docs/long_runs.md has the figures.
_DASK_SETTINGS = {"distributed.worker.profile.enabled": False,
                  "distributed.admin.low-level-log-length": 0,
                  "distributed.admin.system-monitor.log-length": 1}


def _local_dask(workers):
    """``(cluster, executor)``: a local Dask cluster of ``workers`` single-threaded processes, without a dashboard,
    and without what only a dashboard or someone debugging Dask would read (`_DASK_SETTINGS`): the workers'
    statistical profiler, and the logs that kept in this process the arguments of the tasks sent to each worker, its
    last 1000 message batches (about 35 kB a task of 84 small specs: 0.47 MiB per 10^3 frames).  ``cluster`` is a
    `contextlib.ExitStack`: its ``close()`` closes the client, then the cluster, then gives this process its Dask
    configuration back.  The settings stay in it until then: the scheduler reads them again for a worker that
    connects anew (one restarted, or one that lost its connection under load), and the nannies pass them to their
    workers."""
    try:
        import dask
        from distributed import Client, LocalCluster
    except ImportError:
        raise ImportError("executor='dask' needs dask.distributed: pip install 'glphong[dask]'") from None
    threads = max(1, (os.cpu_count() or 1) // workers)
    with contextlib.ExitStack() as starting:
        starting.enter_context(dask.config.set(_DASK_SETTINGS))
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None,
                               env={"LP_NUM_THREADS": str(threads)})
        starting.callback(cluster.close)
        client = Client(cluster)
        starting.callback(client.close)
        running = starting.pop_all()  # started: closed by the caller, in reverse order
    return running, client.get_executor(pure=False)  # a task writes files: never one result for two


def _write_frame(frame, final, fmt):
    """Write ``frame`` to ``final`` through a temporary file renamed when whole; ``(size, sha256)`` of it.  An
    `OSError` names ``final`` (and, for a full disk, the free space and the bytes the frame needs)."""
    try:
        return _write_frame_file(frame, final, fmt)
    except OSError as exc:
        radiance = 128 + frame.radiance.size * 4  # a float32 .npy: its header and data
        needed = f"{radiance} bytes" if fmt == "npy" else f"up to {radiance} bytes ({fmt}, compressed)"
        raise _write_error(exc, final, needed) from exc


def _write_frame_file(frame, final, fmt):
    """Write ``frame`` to ``final`` whole or not at all (`glphong.core.atomic_files.write_atomically`); the
    ``(size, sha256)`` of what was written, read back from the temporary file before it is renamed."""
    written = []

    def write(temporary):
        if fmt == "npy":
            with open(temporary, "wb") as stream:
                np.save(stream, np.ascontiguousarray(frame.radiance, dtype=np.float32))
        elif fmt == "png":
            with open(temporary, "wb") as stream:
                stream.write(png_bytes(frame.radiance))
        else:  # every pass of the frame
            (save_npz if fmt == "npz" else save_exr)(temporary, frame)
        handle = os.open(temporary, os.O_RDONLY | _NOFOLLOW | _CLOEXEC)
        try:
            written.append(_file_digest(handle))
        finally:
            os.close(handle)

    write_atomically(final, write)
    return written[0]


def _render_chunk(scene_fn, items, width, height, out_dir, fmt, options, passes=(), bop=None):
    """In a worker: render ``items`` (``(index, spec)`` pairs) with the worker's renderer and write each frame
    atomically, its files encoded and written on the writer thread while the next frame renders.

    Parameters
    ----------
    scene_fn, items, width, height, out_dir, fmt, options, passes
        As `glphong.batch.render_many` gave them (``out_dir`` a str).
    bop : dict, optional
        With ``fmt='bop'``: ``{"ids": {index: (scene_id, im_id)}, "obj_ids", "depth_scale", "count_truncated"}``
        (`glphong.batch.bop_images.bop_job`).

    Returns
    -------
    records : list of tuple
        ``(index, value)`` of each frame written: its journal value (``{"size", "sha256"}`` of the file; a BOP
        image's files and JSON entries, `glphong.batch.bop_images.BopImages`).
    renderer_name : str
        The worker's GL renderer.
    failures : list of dict
        The frames that failed (`_failure`): their scene function or render raised (the others go on; after an
        error that is not a TypeError or ValueError the renderer is made again), or their write did (the rest of
        the chunk is not rendered).  KeyboardInterrupt and SystemExit are raised, not reported.
    """

    renderer = _renderer(width, height, options)
    records, failures, pending = [], [], None
    try:
        for index, spec in items:
            stage = "scene_fn"
            try:
                scene = scene_fn(spec)
                stage = "render"
                if fmt == "bop":  # the GPU's part here, the files' on the writer thread
                    job = bop_job(renderer, scene, index, out_dir, bop,
                                  partial(_renderer, 3 * width, 3 * height, options))
                else:
                    job = partial(_write_record, index, renderer.render(scene, passes=passes or None), out_dir, fmt)
            except Exception as exc:  # noqa: BLE001 - the frame fails, the batch says which and goes on
                failures.append(_failure(index, spec, stage, exc))
                if stage == "render" and not isinstance(exc, (TypeError, ValueError)):
                    renderer = _renew_renderer(width, height, options)  # a driver's error: the next frame starts afresh
                continue
            if pending is not None and not _finish_write(pending, records, failures):
                pending = None
                break  # a write failed (a full disk fails the next one too): stop, the parent says so
            pending = (index, spec, _writer().submit(job))
    finally:
        if pending is not None:  # a frame being written is finished (or its error raised) before this returns
            _finish_write(pending, records, failures)
    return records, renderer.context.renderer_name, failures


def _finish_write(pending, records, failures):
    """Wait for the write of ``pending`` (``(index, spec, future)``): its record appended to ``records``, or its
    `OSError` to ``failures``; False where it failed."""
    index, spec, future = pending
    try:
        records.append(future.result())
        return True
    except OSError as exc:
        failures.append(_failure(index, spec, "write", exc))
        return False


def _failure(index, spec, stage, exc):
    """What the parent reports of a frame that failed (plain data: an exception may not unpickle in the parent)."""
    return {"index": index, "spec": spec, "stage": stage, "error": f"{type(exc).__name__}: {exc}",
            "traceback": "".join(traceback.format_exception(exc))}


def _renew_renderer(width, height, options):
    """Release the worker's renderer of that size and options (a driver reported an error with it) and make another."""
    old = _WORKER.pop(_renderer_key(width, height, options), None)
    if old is not None:
        try:
            old.release()
        except Exception:  # noqa: BLE001 - a context in a bad state: dropped either way
            pass
    return _renderer(width, height, options)


def _renderer(width, height, options):
    """The worker's renderer of that size and those options, made on first use and kept (`_WORKER`)."""
    key = _renderer_key(width, height, options)
    renderer = _WORKER.get(key)
    if renderer is None or renderer.context is None:
        renderer = _WORKER[key] = Renderer(width, height, **options)
    return renderer


def _renderer_key(width, height, options):
    return width, height, tuple(sorted(options.items()))


def _write_record(index, frame, out_dir, fmt):
    size, sha256 = _write_frame(frame, Path(out_dir) / _frame_name(index, fmt), fmt)
    return index, {"size": size, "sha256": sha256}


def _writer():
    """The worker's one writer thread: a frame is encoded and written while the next renders (the encode's numpy
    passes and zlib release the GIL), one frame in flight at most."""
    pool = _WRITER.get(os.getpid())
    if pool is None:
        _WRITER.clear()
        pool = _WRITER[os.getpid()] = ThreadPoolExecutor(1, thread_name_prefix="glphong-writer")
    return pool
