"""`render_many`: a batch of frames rendered on an executor into a folder it claims, resumable.

The folder (lock, manifest, journal) is kept by the calling process (`glphong.batch.folder`); the frames
are rendered by workers (`glphong.batch.workers`): a 'spawn' pool made here by default, made again where
a worker dies, a local Dask cluster, or any ``concurrent.futures.Executor``.
"""
import collections
import contextlib
import hashlib
import os
import pickle
import signal
import warnings
from concurrent.futures import CancelledError
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

from glphong.batch.bop_images import BopImages, bop_settings, manifest_entry
from glphong.batch.folder import BatchError, FramesFailedError, _BatchFolder, _FileFrames, _frame_name, _make_folder
from glphong.batch.workers import _local_dask, _render_chunk, _spawn_pool
from glphong.core import validate as _validate
from glphong.core.timing import progress_bar
from glphong.core.version import __version__
from glphong.gpu.passes import requested_passes

__all__ = ["render_many"]


def _spec_hash(spec):
    try:
        data = pickle.dumps(spec, protocol=4)
    except Exception as exc:  # noqa: BLE001 - whatever pickling raises, say which spec
        raise BatchError(f"spec {spec!r} cannot be pickled ({exc}): specs travel to the workers") from None
    return hashlib.sha256(data).hexdigest()[:16]


def _render_round(folder, executor, submit, frames_per_task, bar, failed, only=None, in_flight=2):
    """Submit the missing frames (but those in ``failed``; ``only`` these, where given) in chunks of
    ``frames_per_task``, at most ``in_flight`` chunks submitted and not yet back, and journal each result in
    submission order, adding the frames that failed to ``failed`` (``{index: failure}``).  Each chunk's future and
    result are dropped once journalled, so the parent holds no per-frame object but the folder's, whatever the
    batch's length, and a Dask worker keeps a task's result only until then.  After a failed write the chunks not
    started are cancelled and no more submitted.  Returns the frames whose chunk the pool broke on (a worker died:
    those in flight, then those not yet submitted), [] where none.  Interrupted (Ctrl-C), the chunks not started
    are cancelled and those already back journalled first."""
    missing = [i for i in folder.missing if i not in failed] if only is None else only
    chunks = (missing[k:k + frames_per_task] for k in range(0, len(missing), frames_per_task))
    pending = collections.deque()  # (chunk, future), oldest first
    lost, unsent, stop = [], [], False
    try:
        while True:
            while not stop and len(pending) < in_flight:
                chunk = next(chunks, None)
                if chunk is None:
                    break
                try:
                    pending.append((chunk, executor.submit(_render_chunk, *submit(chunk))))
                except BrokenProcessPool:  # a worker died: the pool takes no more
                    unsent = [i for c in (chunk, *chunks) for i in c]
                    stop = True
            if not pending:
                break
            chunk, future = pending[0]
            try:
                records, renderer_name, failures = future.result()
            except BrokenProcessPool:
                lost.extend(chunk)  # a worker died: its frames were not reported, and are rendered again
                continue
            except CancelledError:
                continue
            finally:
                if pending and pending[0][1] is future and future.done():
                    pending.popleft()
            del future, chunk
            _journal(folder, records, renderer_name, bar)
            failed.update((f["index"], f) for f in failures)
            write_failed = any(f["stage"] == "write" for f in failures)
            del records, failures
            if write_failed:
                stop = True
                for _, other in pending:
                    other.cancel()
    except BaseException:
        for _, other in pending:
            other.cancel()
        with contextlib.suppress(Exception):  # what came back before the interruption is kept
            for _, future in pending:
                if future.done() and not future.cancelled() and future.exception() is None:
                    _journal(folder, *future.result()[:2], bar)
        raise
    return lost + unsent


def _journal(folder, records, renderer_name, bar):
    folder.record(records)
    folder.name_renderer(renderer_name)
    if bar:
        bar.update(len(records))


def _deaths(processes):
    """What ended the pool's worker ``processes`` that died by a signal (ended, after the pool's shutdown), or ''."""
    codes = [p.exitcode for p in processes if p.exitcode is not None]
    ended = {-c for c in codes if c < 0}
    signals = sorted(ended - {signal.SIGTERM})  # SIGTERM: the pool ends the others when one dies
    exits = sorted({c for c in codes if c > 0})
    if not signals:  # a worker that exited itself (os._exit, a crash's status), or only the pool's SIGTERM
        return f"; a worker exited with status {', '.join(map(str, exits))}" if exits else \
            ("; a worker was ended by SIGTERM" if ended else "")
    names = ", ".join(signal.Signals(n).name if n in signal.Signals._value2member_map_ else str(n) for n in signals)
    oom = " (the kernel's OOM killer sends SIGKILL to a process using too much memory: see `dmesg`)" \
        if signal.SIGKILL in signals else ""
    return f"; a worker was ended by {names}{oom}"


def _stop_pool(executor):
    """Interrupted: end the pool's workers now (a frame half-written is a temporary file, removed after), without
    waiting for the frames they render."""
    for process in list((getattr(executor, "_processes", None) or {}).values()):
        with contextlib.suppress(Exception):
            process.terminate()
    executor.shutdown(wait=True, cancel_futures=True)


def render_many(scene_fn, specs, width, height, out_dir, executor=None, fmt="npy", frames_per_task=1,
                workers=None, progress=True, passes=None, *, bop_ids=None, frames_per_scene=None, obj_ids=None,
                depth_scale=None, count_truncated=None, **options):
    """Render one frame per spec into ``out_dir`` and return the frame paths in spec order.

    Parameters
    ----------
    scene_fn : callable
        A picklable top-level function ``scene_fn(spec) -> glphong.Scene``, called in the workers.
    specs : sequence
        Picklable specs, one frame each.
    width, height : int
    out_dir : str or path-like
        Made if missing.  Holds the frames, ``manifest.json``, the journal ``frames.jsonl`` and ``.lock``
        (the `glphong.batch` docstring says what each is for); with ``fmt='bop'`` it is the BOP split's folder
        (e.g. ``.../train_pbr``), holding a folder per scene.
    executor : concurrent.futures.Executor or 'dask', optional
        Default: a 'spawn' process pool of ``workers`` processes (default: the CPU count) that die with this
        process, shut down at the end; a given executor is used as it is and left running (a Dask client's:
        ``client.get_executor()``).  ``'dask'``: a local Dask cluster of ``workers`` single-threaded
        worker processes (``dask.distributed.LocalCluster``, from the ``[dask]`` extra), closed at the end.
    fmt : {'npy', 'png', 'npz', 'exr', 'bop'}
        float32 radiance ``.npy`` of shape ``(height, width, 3)`` (default) or an 8-bit sRGB PNG at
        exposure 1; or each frame's ``passes`` in one ``.npz`` (`glphong.datasets.save_npz`) or OpenEXR file
        (`glphong.datasets.save_exr`, the extra ``exr``); or ``'bop'``: each frame an image of a BOP scene,
        ``out_dir/{scene_id:06d}/``, the files `glphong.datasets.write_bop` writes, byte for byte
        (`glphong.batch.bop_images`: the workers write the images' files, this process the scenes' JSON files).
    passes : sequence of str, optional
        With ``fmt`` 'npz' or 'exr': the frame passes to render and write (`glphong.Renderer.render`'s names but
        'flow' and 'backward_flow', which need a second scene), default ``('radiance',)``.
    bop_ids : sequence of (int, int), optional
        With ``fmt='bop'``: each spec's ``(scene_id, im_id)`` (0 to 999999), each pair once.
    frames_per_scene : int, optional
        With ``fmt='bop'`` and no ``bop_ids``: frame ``i`` is image ``i % frames_per_scene`` of scene
        ``i // frames_per_scene`` (default 1000, BlenderProc's ``frames_per_chunk``: BOP's ``train_pbr`` layout).
    obj_ids : mapping of int to int, or 'category', optional
        With ``fmt='bop'``: each object's BOP ``obj_id`` by its ``instance_id``, or ``'category'`` (each object's
        ``category`` is its obj_id, BlenderProc's ``category_id``); default the instance_id, as
        `glphong.datasets.write_bop` takes it.
    depth_scale : float, optional
        With ``fmt='bop'``: millimetres per unit of the 16-bit depth PNGs (default 0.1).
    count_truncated : bool, optional
        With ``fmt='bop'``: ``px_count_all`` and ``bbox_obj`` count the silhouette beyond the image (default
        True, the toolkit's way), as in `glphong.datasets.write_bop`.
    frames_per_task : int
        Frames a task renders in a row (fewer round trips for small frames).
    progress : bool
        A tqdm progress bar where tqdm is installed.
    **options
        `glphong.Renderer` options (``backend``, ``samples``, ...).

    Returns
    -------
    list of str
        The frame paths, ``out_dir/frame_NNNNNN.npy``, in spec order (``fmt='bop'``: each image's
        ``out_dir/{scene_id:06d}/rgb/{im_id:06d}.png``).

    Raises
    ------
    BatchError
        A spec cannot be pickled; another batch is running in ``out_dir``; ``out_dir`` holds another
        batch's manifest, or frame files without a manifest; a frame, the manifest, the journal or the lock
        is a symbolic link or not a regular file; with ``fmt='bop'``, a scene folder (six digits) without a
        manifest, or a file in the place of a scene's folder; ``out_dir`` is a file, cannot be made or written;
        the workers died three times in a row without writing a frame (the frames and the signal that ended them
        named: SIGKILL is the kernel's OOM killer's).
    FramesFailedError
        A `BatchError`, at the end: frames whose ``scene_fn`` or render raised (a scene that cannot be written as
        BOP, `glphong.datasets.write_bop` says which; a driver's error, after which the worker's renderer is made
        again) or whose write failed (a full disk: the free space and the bytes needed; the batch stops there).
        It names the first frame, its spec and the error, and holds every failure (``.failures``, with the
        worker's traceback); every other frame was rendered and journalled, and a rerun renders the rest.
    TypeError, ValueError
        A bad argument (which one named): BOP arguments with another ``fmt``, ``bop_ids`` not one pair per spec
        or a pair twice.
    KeyboardInterrupt
        Ctrl-C (SIGINT): the frames back are journalled, the pool's workers (which ignore SIGINT) are ended at once,
        the temporary files of frames half-written removed; a rerun resumes.

    Warns
    -----
    RuntimeWarning
        A worker died (the frames in flight and the signal named); its frames are rendered again.
    """

    specs = list(specs)
    width = _validate.positive_int("width", width, 1, 16384)
    height = _validate.positive_int("height", height, 1, 16384)
    fmt = _validate.choice("fmt", fmt, ("npy", "png", "npz", "exr", "bop"))
    passes = _batch_passes(passes, fmt)
    bop = bop_settings(fmt, len(specs), width, height, options, bop_ids, frames_per_scene, obj_ids, depth_scale,
                       count_truncated)
    frames_per_task = _validate.positive_int("frames_per_task", frames_per_task)
    if not callable(scene_fn):
        raise TypeError(f"scene_fn must be a callable spec -> Scene (got {type(scene_fn).__name__})")
    if isinstance(executor, str):
        _validate.choice("executor", executor, ("dask",))
    batch = {"glphong": __version__, "width": width, "height": height, "format": fmt,
             **({"passes": list(passes)} if passes else {}), **({"bop": manifest_entry(bop)} if bop else {}),
             "options": {k: repr(v) for k, v in sorted(options.items())}, "specs": [_spec_hash(s) for s in specs]}
    out = Path(out_dir)
    _make_folder(out)
    frames = BopImages(out, bop["ids"]) if bop else _FileFrames([str(out / _frame_name(i, fmt))
                                                                 for i in range(len(specs))])
    workers = workers or os.cpu_count() or 1

    def submit(chunk):
        settings = {"ids": {i: bop["ids"][i] for i in chunk}, **{k: v for k, v in bop.items() if k != "ids"}} \
            if bop else None
        return scene_fn, [(i, specs[i]) for i in chunk], width, height, str(out), fmt, options, passes, settings

    with _BatchFolder(out, batch, frames) as folder:
        try:
            if folder.missing:
                _render_missing(folder, submit, executor, workers, frames_per_task, progress_bar(
                    len(folder.missing), progress, unit="frame"))
        except BaseException:
            with contextlib.suppress(Exception):  # the batch's own error is the one to see
                folder.finish()
            raise
        folder.finish()
    return frames.paths


def _batch_passes(passes, fmt):
    """The passes a batch writes (a tuple; empty for 'npy' and 'png', which hold the radiance alone)."""
    if fmt in ("npy", "png"):
        if passes is not None:
            raise ValueError(f"fmt={fmt!r} holds the radiance alone: write frame passes with fmt='npz' or 'exr'")
        return ()
    if fmt == "bop":
        if passes is not None:
            raise ValueError("fmt='bop' writes what BOP holds (rgb, depth, mask, mask_visib and the scene's JSON "
                             "files): write other passes with fmt='npz' or 'exr'")
        return ()
    names = requested_passes(passes)
    motion = [n for n in names if n in ("flow", "backward_flow")]
    if motion:
        raise ValueError(f"render_many renders one scene a frame: {', '.join(motion)} need the next or previous "
                         "scene (render them with Renderer.render(scene, passes=..., next_scene=...))")
    return names


#: pools that may break in a row without a frame written before a batch stops (a killed worker costs a round,
#: a scene function that kills every worker would cost rounds forever)
MAX_STALLED_POOLS = 3


def _render_missing(folder, submit, executor, workers, frames_per_task, bar):
    """Render ``folder``'s missing frames on ``executor`` (None: a pool of ``workers`` made here and made
    again where a worker dies; 'dask': a local Dask cluster), journalling each as it comes back;
    `FramesFailedError` at the end where frames failed.

    Where a worker of the pool made here dies, the first frame it had in flight is rendered alone on a new pool (a
    probe): if that kills its worker too, the frame fails (its worker died rendering it: SIGKILL is what the kernel's
    OOM killer sends) and the batch goes on without it."""
    cluster = None
    if isinstance(executor, str):
        cluster, executor = _local_dask(workers)
    own = executor is None
    stalled = 0  # pools broken in a row without a frame written
    failed = {}  # index -> failure (glphong.batch.workers._failure)
    suspect = None  # the first frame in flight when a worker of our pool died: rendered alone next
    try:
        while [i for i in folder.missing if i not in failed] and not any(f["stage"] == "write" for f in failed.values()):
            if executor is None:
                executor = _spawn_pool(workers)
            before = len(folder.missing)
            lost = _render_round(folder, executor, submit, frames_per_task, bar, failed,
                                 None if suspect is None else [suspect], 2 * _slots(executor, workers))
            processes = list((getattr(executor, "_processes", None) or {}).values())
            stalled = stalled + 1 if lost and len(folder.missing) == before else 0
            if lost and own:
                executor.shutdown(wait=True, cancel_futures=True)  # every worker gone: none is writing now
                executor = None
                folder.remove_partials()  # a worker killed with its pool may have left a half-written file
            if stalled >= MAX_STALLED_POOLS:
                raise BatchError(f"the worker processes died {stalled} times in a row without writing a frame (a "
                                 "scene function that kills its process, a worker out of memory, or workers that "
                                 f"cannot start){_deaths(processes)}: stopped with frame(s) {_listed(lost)} not "
                                 f"written; the {len(folder.done)} frame(s) done are kept and journalled")
            if lost and suspect is not None:  # the probe died: that frame kills its worker
                failed[suspect] = {"index": suspect, "spec": submit([suspect])[1][0][1], "stage": "render",
                                   "error": f"its worker process died rendering it, alone{_deaths(processes)}",
                                   "traceback": ""}
            elif lost:
                warnings.warn(f"a worker died with frame(s) {_listed(lost)} in flight{_deaths(processes)}: they are "
                              "rendered again", RuntimeWarning, stacklevel=3)
            elif [i for i in folder.missing if i not in failed] and not failed and suspect is None:
                missing = folder.missing
                raise BatchError(f"{len(missing)} frame(s) were not written, e.g. {folder.paths[missing[0]]}")
            suspect = lost[0] if lost and own and suspect is None else None
    except BaseException:
        if own and executor is not None:
            _stop_pool(executor)
            executor = None
        raise
    finally:
        if bar:
            bar.close()
        if own and executor is not None:
            executor.shutdown()
        if cluster is not None:
            cluster.close()  # the client, the cluster, then the Dask configuration (all three, whatever raises)
        if own or cluster is not None:
            folder.remove_partials()  # the workers are gone: no writer is left
    if failed:
        raise FramesFailedError(folder.out, [failed[i] for i in sorted(failed)], len(folder.done), len(folder.paths))


def _slots(executor, workers):
    """How many tasks ``executor`` runs at once: its pool's processes or threads, a Dask client's threads, else
    ``workers``."""
    slots = getattr(executor, "_max_workers", None)
    client = getattr(executor, "_client", None)  # distributed's ClientExecutor
    if client is not None:
        with contextlib.suppress(Exception):
            slots = sum(client.nthreads().values())
    return max(1, slots or workers)


def _listed(indices, most=8):
    """``indices`` as a short list: '3, 4, 9' or '3, 4, ... (12 in all)'."""
    shown = ", ".join(map(str, indices[:most]))
    return shown if len(indices) <= most else f"{shown}, ... ({len(indices)} in all)"
