"""`render_many`: a batch of frames rendered on an executor into a folder it claims, resumable.

The folder (lock, manifest, journal) is kept by the calling process (`glphong.batch.folder`); the frames
are rendered by workers (`glphong.batch.workers`): a 'spawn' pool made here by default, made again where
a worker dies, a local Dask cluster, or any ``concurrent.futures.Executor``.
"""
import contextlib
import hashlib
import os
import pickle
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

from glphong.batch.bop_images import BopImages, bop_settings, manifest_entry
from glphong.batch.folder import BatchError, _BatchFolder, _FileFrames, _frame_name
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


def _render_round(folder, executor, submit, frames_per_task, bar):
    """Submit the missing frames in chunks of ``frames_per_task`` and journal each result as it comes back;
    True where the pool broke (a worker died) before every chunk came back."""
    missing = folder.missing
    chunks = [missing[k:k + frames_per_task] for k in range(0, len(missing), frames_per_task)]
    futures = [executor.submit(_render_chunk, *submit(chunk)) for chunk in chunks]
    broken = False
    for future in futures:
        try:
            records, renderer_name = future.result()
        except BrokenProcessPool:
            broken = True  # a worker died: its frames were not reported, and are rendered again
            continue
        folder.record(records)
        folder.name_renderer(renderer_name)
        if bar:
            bar.update(len(records))
    return broken


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
        manifest, or a file in the place of a scene's folder.
    TypeError, ValueError
        A bad argument (which one named): BOP arguments with another ``fmt``, ``bop_ids`` not one pair per spec
        or a pair twice; and from the workers, a scene that cannot be written as BOP (`glphong.datasets.write_bop`
        says which).
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
    out.mkdir(parents=True, exist_ok=True)
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
    again where a worker dies; 'dask': a local Dask cluster), journalling each as it comes back."""
    cluster = None
    if isinstance(executor, str):
        cluster, executor = _local_dask(workers)
    own = executor is None
    stalled = 0  # pools broken in a row without a frame written
    try:
        while folder.missing:
            if executor is None:
                executor = _spawn_pool(workers)
            before = len(folder.missing)
            broken = _render_round(folder, executor, submit, frames_per_task, bar)
            stalled = stalled + 1 if broken and len(folder.missing) == before else 0
            if stalled >= MAX_STALLED_POOLS:
                raise BatchError(f"the worker processes died {stalled} times in a row without writing a frame (a "
                                 "scene function that kills its process, or workers that cannot start): stopped")
            if broken and own:
                executor.shutdown(wait=True, cancel_futures=True)  # every worker gone: none is writing now
                executor = None
                folder.remove_partials()  # a worker killed with its pool may have left a half-written file
            elif folder.missing and not broken:
                missing = folder.missing
                raise BatchError(f"{len(missing)} frame(s) were not written, e.g. {folder.paths[missing[0]]}")
    finally:
        if bar:
            bar.close()
        if own and executor is not None:
            executor.shutdown()
        if cluster is not None:
            for closing in cluster:
                closing.close()
    if own or cluster is not None:
        folder.remove_partials()  # the workers are gone: no writer is left
