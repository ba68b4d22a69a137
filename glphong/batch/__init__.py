"""Many frames: one render per spec, in worker processes, resumable (``glphong.batch.render_many``).

A batch is a list of small picklable specs (a camera angle, a material parameter, a file name) and a
picklable top-level function ``scene_fn(spec) -> Scene`` that builds each frame's scene in the worker (a
pickled scene would carry and re-upload its meshes).  Frames are written to ``out_dir`` as float32
radiance ``.npy`` files of shape ``(height, width, 3)`` (or 8-bit sRGB PNG files) named by their index,
``frame_NNNNNN.npy``; each is written to a temporary file (``.NAME.partial-*``) and renamed, so a frame file is
whole or absent.  With ``fmt='bop'`` each frame is an image of a BOP scene (`glphong.batch.bop_images`): the
workers write its PNG files, each whole, and the calling process the scenes' JSON files from the entries
the workers return.

The folder of a batch
---------------------
``out_dir`` holds, besides the frames:

``manifest.json``
    The batch: the spec hashes, glphong's version, the image size in pixels and the format, the renderer
    options, and the GL renderer's name.  It is created atomically (a temporary file hard-linked to the
    name, which fails where the name exists) *before* the first frame is rendered, so that of two batches
    started together in one fresh folder exactly one claims it.  The GL renderer, known only after the
    first frame, is added later by an atomic replace; comparisons ignore it.  A rerun of the same batch
    renders only the frames it cannot trust; a different batch is refused (`BatchError`), never mixed.
    A BOP batch adds its settings (depth scale, obj_ids, the hash of the images' ids).
``frames.jsonl``
    The journal: one JSON line ``{"index", "size", "sha256"}`` per completed frame (the size in bytes and
    the SHA-256 of the file as its worker wrote it), appended by the parent as each result comes back.  A
    rerun trusts a frame on disk only where its last record matches the file's size and hash (it reads
    each frame on disk once, to hash it); a frame with no record (its worker died before reporting, or a
    batch written before journals) or a changed one (truncated, corrupted, replaced) is rendered again and
    overwritten atomically.  The journal guards against accidents, not against someone who rewrites frames
    and journal together.  A BOP image's line also lists each of its files (path, size, SHA-256) and holds
    its three JSON entries, its ``sha256`` that of the record itself; it is trusted where every file matches.
``.lock``
    Locked (``fcntl.flock``, exclusive, non-blocking) for the whole batch: a second batch in the same
    folder, the same batch or another, raises `BatchError` while one runs.  The kernel releases the lock
    when the process holding it dies, however it dies.

A folder holding frame files, BOP scene folders (six digits) or a journal but no manifest (a batch that
crashed before manifests were written first, or someone else's files) is refused rather than adopted, and
so is a frame, manifest, journal or lock that is a symbolic link or not a regular file.

Workers
-------
The default executor is a ``concurrent.futures.ProcessPoolExecutor`` started with 'spawn' (a forked child
of a process that made a context would hang: `glphong.gpu.contexts.ForkedProcessError`), one renderer per
worker made on first use and kept, and ``LP_NUM_THREADS`` set in each worker before its first context so
that the workers do not oversubscribe the cores.  Each worker ends when the process that started it dies,
even by ``SIGKILL``: on Linux it asks the kernel for ``SIGKILL`` at its parent's death
(``prctl(PR_SET_PDEATHSIG)``, then checks that its parent is still the one it was started by, for a
parent that died first), and on every system a daemon thread polls ``os.getppid()`` every 0.5 s.
multiprocessing's resource tracker, started with the pool, ends by itself once every holder of its
pipe's write end has closed it; the workers inherit that end, so the tracker ends with the last worker
(on Linux, all of them are gone a fraction of a second after the parent is killed).
(The kernel ties ``PR_SET_PDEATHSIG`` to the thread that started the worker: the pool's workers are
started by the thread that calls `render_many`, which lives until the pool is shut down.)

Any ``concurrent.futures.Executor`` works, a Dask client's included (``client.get_executor()``, for a
real cluster ``Client("tcp://scheduler:8786")`` or dask-jobqueue's), and ``executor="dask"`` starts a
local Dask cluster; the lock, the manifest and the journal are kept by the calling process whatever the
executor.  A worker that dies mid-batch costs no frame: the pool is made again and the frames not yet
reported are rendered again (Dask reschedules the task itself).

Faults
------
A frame whose ``scene_fn``, render or driver raises fails alone (the worker's renderer is made again after a
driver's error) and the others are rendered; a write that fails (a full disk: the error names the file, the free
space and the bytes needed) stops the batch; either way `FramesFailedError` at the end names the frames and keeps
every frame done in the journal, so a rerun renders only the rest.  Ctrl-C journals what came back and terminates
the pool's workers (which ignore SIGINT) at once.  A worker that dies (SIGKILL: the kernel's OOM killer) is warned
about, and the first frame it had in flight is rendered alone on a new pool: if that dies too, the frame fails by
name.  docs/batches.md has the table.

Modules
-------
`glphong.batch.run` (`render_many`), `glphong.batch.folder` (the lock, the manifest, the journal, the
frames on disk, `BatchError`), `glphong.batch.workers` (the pool's initializer, the worker-side
renderer, the local Dask cluster), `glphong.batch.bop_images` (``fmt='bop'``) and `glphong.batch.scenes`
(`turntable_scene`, `orbit_scene`, `tabletop_scene`).
"""
from glphong.batch.folder import BatchError, FramesFailedError
from glphong.batch.run import _spec_hash, render_many  # noqa: F401 - _spec_hash: glphong.batch._spec_hash
from glphong.batch.scenes import orbit_scene, tabletop_scene, turntable_scene
from glphong.batch.workers import _WORKER  # noqa: F401 - the worker's renderers, as glphong.batch._WORKER

__all__ = ["render_many", "turntable_scene", "orbit_scene", "tabletop_scene", "BatchError", "FramesFailedError"]
