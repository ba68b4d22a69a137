"""Many frames: one render per spec, in worker processes, resumable (``glphong.batch.render_many``).

A batch is a list of small picklable specs (a camera angle, a material parameter, a file name) and a
picklable top-level function ``scene_fn(spec) -> Scene`` that builds each frame's scene in the worker (a
pickled scene would carry and re-upload its meshes).  Frames are written to ``out_dir`` as float32
radiance ``.npy`` files of shape ``(height, width, 3)`` (or 8-bit sRGB PNG files) named by their index,
``frame_NNNNNN.npy``; each is written to a temporary file (``.partial-*``) and renamed, so a frame file is
whole or absent.

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
``frames.jsonl``
    The journal: one JSON line ``{"index", "size", "sha256"}`` per completed frame (the size in bytes and
    the SHA-256 of the file as its worker wrote it), appended by the parent as each result comes back.  A
    rerun trusts a frame on disk only where its last record matches the file's size and hash (it reads
    each frame on disk once, to hash it); a frame with no record (its worker died before reporting, or a
    batch written before journals) or a changed one (truncated, corrupted, replaced) is rendered again and
    overwritten atomically.  The journal guards against accidents, not against someone who rewrites frames
    and journal together.
``.lock``
    Locked (``fcntl.flock``, exclusive, non-blocking) for the whole batch: a second batch in the same
    folder, the same batch or another, raises `BatchError` while one runs.  The kernel releases the lock
    when the process holding it dies, however it dies.

A folder holding frame files or a journal but no manifest (a batch that crashed before manifests were
written first, or someone else's files) is refused rather than adopted, and so is a frame, manifest,
journal or lock that is a symbolic link or not a regular file.

Workers
-------
The default executor is a ``concurrent.futures.ProcessPoolExecutor`` started with 'spawn' (a forked child
of a process that made a context would hang: `glphong.contexts.ForkedProcessError`), one renderer per
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
"""
import ctypes
import errno
import hashlib
import json
import os
import pickle
import stat
import sys
import tempfile
import threading
import time
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

import numpy as np

try:
    import fcntl
except ImportError:  # Windows: no advisory locks, see _lock_folder
    fcntl = None

__all__ = ["render_many", "turntable_scene", "orbit_scene", "BatchError"]

MANIFEST = "manifest.json"
JOURNAL = "frames.jsonl"
LOCK = ".lock"
_PR_SET_PDEATHSIG = 1  # <linux/prctl.h>
_PARENT_POLL_S = 0.5
_JOURNAL_LINE_LIMIT = 4096  # bytes; a longer line is no record of ours
_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_CLOEXEC = getattr(os, "O_CLOEXEC", 0)
_NONBLOCK = getattr(os, "O_NONBLOCK", 0)  # a FIFO put in a file's place does not hang its open

_WORKER = {}


class BatchError(RuntimeError):
    """A batch cannot run as asked: another batch's frames or a running batch in the folder, files the batch
    cannot trust (a symbolic link, frames without a manifest), a spec that cannot be pickled."""


def _spec_hash(spec):
    try:
        data = pickle.dumps(spec, protocol=4)
    except Exception as exc:  # noqa: BLE001 - whatever pickling raises, say which spec
        raise BatchError(f"spec {spec!r} cannot be pickled ({exc}): specs travel to the workers") from None
    return hashlib.sha256(data).hexdigest()[:16]


def _frame_name(index, fmt):
    return f"frame_{index:06d}.{fmt}"


# --- workers ------------------------------------------------------------------------------------------------

def _set_threads(threads):
    """llvmpipe's rasterizer threads per worker, before the worker's first context."""
    if threads:
        os.environ.setdefault("LP_NUM_THREADS", str(threads))


def _init_worker(threads, parent_pid):
    """Pool worker initialiser: `_set_threads`, then `_die_with_parent`.

    Parameters
    ----------
    threads : int
        ``LP_NUM_THREADS`` for this worker (0: leave it).
    parent_pid : int
        The pid of the process that started the pool.
    """
    _set_threads(threads)
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
    import signal

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
    import multiprocessing

    threads = max(1, (os.cpu_count() or 1) // workers)
    return ProcessPoolExecutor(workers, mp_context=multiprocessing.get_context("spawn"),
                               initializer=_init_worker, initargs=(threads, os.getpid()))


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


def _file_digest(fd):
    """``(size, sha256)`` of the open file ``fd`` read from its start: its size in bytes and hex digest."""
    digest = hashlib.sha256()
    size = 0
    os.lseek(fd, 0, os.SEEK_SET)
    while block := os.read(fd, 1 << 20):
        digest.update(block)
        size += len(block)
    return size, digest.hexdigest()


def _write_frame(frame, final, out_dir, fmt):
    """Write ``frame`` to ``final`` through a temporary file renamed when whole; ``(size, sha256)`` of it."""
    handle, temporary = tempfile.mkstemp(dir=out_dir, prefix=".partial-", suffix=f".{fmt}")
    os.close(handle)
    try:
        if fmt == "npy":
            np.save(temporary, np.ascontiguousarray(frame.radiance, dtype=np.float32))
        else:
            frame.save_png(temporary)
        handle = os.open(temporary, os.O_RDONLY | _NOFOLLOW | _CLOEXEC)
        try:
            written = _file_digest(handle)
        finally:
            os.close(handle)
        os.replace(temporary, final)
    finally:
        if os.path.exists(temporary):
            os.remove(temporary)
    return written


def _render_chunk(scene_fn, items, width, height, out_dir, fmt, options):
    """In a worker: render ``items`` (``(index, spec)`` pairs) with the worker's renderer and write each frame
    atomically.

    Returns
    -------
    records : list of tuple
        ``(index, size, sha256)`` of each frame written: its size in bytes and the file's hex SHA-256.
    renderer_name : str
        The worker's GL renderer.
    """
    from .renderer import Renderer

    key = (width, height, tuple(sorted(options.items())))
    renderer = _WORKER.get(key)
    if renderer is None or renderer.context is None:
        renderer = _WORKER[key] = Renderer(width, height, **options)
    records = []
    for index, spec in items:
        frame = renderer.render(scene_fn(spec))
        size, sha256 = _write_frame(frame, Path(out_dir) / _frame_name(index, fmt), out_dir, fmt)
        records.append((index, size, sha256))
    return records, renderer.context.renderer_name


# --- the folder -----------------------------------------------------------------------------------------------

def _regular_or_missing(path, what):
    """``os.lstat(path)``, or None where ``path`` does not exist; `BatchError` where it is a symbolic link or
    not a regular file (``what`` says what it should be)."""
    try:
        info = os.lstat(path)
    except FileNotFoundError:
        return None
    if stat.S_ISLNK(info.st_mode):
        raise BatchError(f"{path} ({what}) is a symbolic link: a batch writes and trusts only its own files; "
                         "remove it or use another out_dir")
    if not stat.S_ISREG(info.st_mode):
        raise BatchError(f"{path} ({what}) is not a regular file; remove it or use another out_dir")
    return info


def _open_regular(path, flags, what, mode=0o666):
    """``os.open`` without following a symbolic link; `BatchError` for a link or a file that is not regular."""
    try:
        fd = os.open(path, flags | _NOFOLLOW | _CLOEXEC | _NONBLOCK, mode)
    except OSError as exc:
        if exc.errno in (errno.ELOOP, errno.EMLINK) or os.path.islink(path):
            _regular_or_missing(path, what)  # raises, naming the link
        if exc.errno in (errno.EISDIR, errno.ENXIO):
            raise BatchError(f"{path} ({what}) is not a regular file; remove it or use another out_dir") from None
        raise
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise BatchError(f"{path} ({what}) is not a regular file; remove it or use another out_dir")
    return fd


def _lock_folder(out):
    """Lock ``out/.lock`` for this batch (exclusive, non-blocking ``flock``) and return its descriptor, to be
    closed at the end; `BatchError` where another batch holds it.  Where ``fcntl`` is missing (Windows) the
    file is opened and nothing is locked."""
    path = out / LOCK
    fd = _open_regular(path, os.O_RDWR | os.O_CREAT, "the batch lock")
    if fcntl is None:
        return fd
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except OSError as exc:
        os.close(fd)
        if exc.errno in (errno.EWOULDBLOCK, errno.EAGAIN, errno.EACCES):
            raise BatchError(f"another batch is running in {out} (it holds {path}): wait for it to finish "
                             "or use another out_dir") from None
        raise
    return fd


def _write_temporary(folder, text):
    """A new file in ``folder`` holding ``text`` (UTF-8); its path."""
    handle, temporary = tempfile.mkstemp(dir=folder, prefix=".partial-", suffix=".json")
    with open(handle, "w", encoding="utf-8") as stream:
        stream.write(text)
    return temporary


def _create_exclusive(path, text):
    """Create ``path`` holding ``text`` atomically, whole or not at all; `FileExistsError` where it exists.

    A temporary file is hard-linked to ``path`` (which fails where ``path`` exists, a symbolic link
    included); where the file system has no hard links, ``O_CREAT | O_EXCL`` does the claiming.
    """
    temporary = _write_temporary(path.parent, text)
    try:
        os.link(temporary, path)
        return
    except FileExistsError:
        raise
    except OSError as exc:
        if exc.errno not in (errno.EPERM, errno.ENOTSUP, errno.EOPNOTSUPP, errno.ENOSYS, errno.EXDEV):
            raise
    finally:
        os.remove(temporary)
    fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL | _NOFOLLOW | _CLOEXEC, 0o666)
    with open(fd, "w", encoding="utf-8") as stream:
        stream.write(text)


def _replace_atomically(path, text):
    """Replace ``path`` by a file holding ``text`` (a temporary file renamed over it)."""
    temporary = _write_temporary(path.parent, text)
    try:
        os.replace(temporary, path)
    finally:
        if os.path.exists(temporary):
            os.remove(temporary)


def _read_manifest(path, limit):
    """The manifest at ``path`` as a dict; `BatchError` for a link, a file over ``limit`` bytes, or one that
    is not a JSON object (none of them is a manifest of this batch)."""
    fd = _open_regular(path, os.O_RDONLY, "the batch manifest")
    with open(fd, "rb") as stream:
        data = stream.read(limit + 1)
    try:
        manifest = json.loads(data) if len(data) <= limit else None
    except ValueError:
        manifest = None
    if not isinstance(manifest, dict):
        raise BatchError(f"{path} is not a glphong batch manifest: remove it or use another out_dir")
    return manifest


def _foreign_file(out):
    """The name of a frame file or journal in ``out`` (the folder has no manifest), or None."""
    with os.scandir(out) as entries:
        return next((e.name for e in entries if e.name.startswith("frame_") or e.name == JOURNAL), None)


def _claim_manifest(out, batch):
    """Create ``out/manifest.json`` for ``batch``, or compare ``batch`` with the one there; the manifest kept
    (with the GL renderer where a run named it).  `BatchError` for another batch, or frames without one."""
    path = out / MANIFEST
    if _regular_or_missing(path, "the batch manifest") is None:
        foreign = _foreign_file(out)
        if foreign is not None:
            raise BatchError(f"{out} holds {foreign} but no {MANIFEST}: files of an unknown batch are not "
                             "adopted; remove them or use another out_dir")
        try:
            _create_exclusive(path, json.dumps(batch, indent=1))
            return dict(batch)
        except FileExistsError:
            pass  # a batch that does not lock (another host, an older glphong) claimed it first: compare
    previous = _read_manifest(path, 65536 + 64 * len(batch["specs"]))
    stored = {k: v for k, v in previous.items() if k != "renderer"}
    if stored != batch:
        differ = sorted(k for k in set(batch) | set(stored) if stored.get(k) != batch.get(k))
        raise BatchError(f"{out} holds another batch (its {', '.join(differ)} differ): glphong never mixes two "
                         "batches in one folder; use another out_dir or remove it")
    return previous


def _parse_record(line, count):
    """``(index, size, sha256)`` from a journal line, or None for a line that is not a record of a frame
    below ``count`` (a line cut short by a crash, say)."""
    try:
        record = json.loads(line)
        index, size, sha256 = record["index"], record["size"], record["sha256"]
    except (ValueError, TypeError, KeyError):
        return None
    if (type(index) is not int or type(size) is not int or not 0 <= index < count or size < 0
            or not isinstance(sha256, str) or len(sha256) != 64):
        return None
    return index, size, sha256


def _read_journal(path, count):
    """The last record of each frame in the journal at ``path``: ``{index: (size, sha256)}``."""
    if _regular_or_missing(path, "the frame journal") is None:
        return {}
    records = {}
    with open(_open_regular(path, os.O_RDONLY, "the frame journal"), "rb") as stream:
        while line := stream.readline(_JOURNAL_LINE_LIMIT):
            if not line.endswith(b"\n"):  # over the limit (skip the rest of it) or cut short at the end
                while line and not line.endswith(b"\n"):
                    line = stream.readline(_JOURNAL_LINE_LIMIT)
                continue
            record = _parse_record(line, count)
            if record is not None:
                records[record[0]] = record[1:]
    return records


def _frame_matches(path, record):
    """Whether the frame file at ``path`` (a regular file) has the ``(size, sha256)`` of its record."""
    fd = _open_regular(path, os.O_RDONLY, "a frame")
    try:
        return os.fstat(fd).st_size == record[0] and _file_digest(fd) == record
    finally:
        os.close(fd)


def _trusted_frames(paths, records):
    """``{index: (size, sha256)}`` of the frames on disk that match their journal record; `BatchError` for a
    frame path that is a symbolic link or not a regular file."""
    trusted = {}
    for index, path in enumerate(paths):
        if _regular_or_missing(path, "a frame") is None:
            continue
        record = records.get(index)
        if record is not None and _frame_matches(path, record):
            trusted[index] = record
    return trusted


def _record_line(index, size, sha256):
    """The journal line of a frame: ``{"index", "size", "sha256"}`` and a newline."""
    return json.dumps({"index": index, "size": size, "sha256": sha256}) + "\n"


class _BatchFolder:
    """``out_dir`` claimed by a running batch: its lock held, its manifest created or compared, its journal
    open for appending, and the frames done so far.

    Parameters
    ----------
    out : pathlib.Path
        The folder (it exists).
    batch : dict
        The manifest of this batch, without the GL renderer.
    paths : list of str
        The frame paths, in spec order.
    """

    def __init__(self, out, batch, paths):
        self.out, self.batch, self.paths = out, batch, paths
        self.lock = self.journal = None
        self.manifest, self.done = None, {}

    def __enter__(self):
        self.lock = _lock_folder(self.out)
        try:
            self.manifest = _claim_manifest(self.out, self.batch)
            _remove_partials(self.out)  # the lock is ours: no writer of this folder is left
            journal = self.out / JOURNAL
            self.done = _trusted_frames(self.paths, _read_journal(journal, len(self.paths)))
            _replace_atomically(journal, "".join(_record_line(i, *r) for i, r in sorted(self.done.items())))
            self.journal = _open_regular(journal, os.O_WRONLY | os.O_APPEND, "the frame journal")
        except BaseException:
            self.__exit__(None, None, None)
            raise
        return self

    def __exit__(self, *exc_info):
        for fd in (self.journal, self.lock):
            if fd is not None:
                os.close(fd)
        self.journal = self.lock = None

    @property
    def missing(self):
        """The indices of the frames not done, ascending."""
        return [i for i in range(len(self.paths)) if i not in self.done]

    def record(self, records):
        """Journal the frames ``records`` (``(index, size, sha256)`` each, as a worker returned them)."""
        for index, size, sha256 in records:
            os.write(self.journal, _record_line(index, size, sha256).encode())
            self.done[index] = (size, sha256)

    def name_renderer(self, renderer_name):
        """Add the GL renderer to the manifest (an atomic replace) where it has none."""
        if renderer_name is not None and "renderer" not in self.manifest:
            self.manifest = self.manifest | {"renderer": renderer_name}
            _replace_atomically(self.out / MANIFEST, json.dumps(self.manifest, indent=1))


def _remove_partials(out):
    """Remove the temporary files of writers that died (``.partial-*``; a frame is renamed when whole)."""
    for leftover in Path(out).glob(".partial-*"):
        try:
            leftover.unlink()
        except OSError:
            pass


# --- the batch ------------------------------------------------------------------------------------------------

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
        Made if missing.  Holds the frames, ``manifest.json``, the journal ``frames.jsonl`` and ``.lock``
        (the module docstring says what each is for).
    executor : concurrent.futures.Executor or 'dask', optional
        Default: a 'spawn' process pool of ``workers`` processes (default: the CPU count) that die with this
        process, shut down at the end; a given executor is used as it is and left running (a Dask client's:
        ``client.get_executor()``).  ``'dask'``: a local Dask cluster of ``workers`` single-threaded
        worker processes (``dask.distributed.LocalCluster``, from the ``[dask]`` extra), closed at the end.
    fmt : {'npy', 'png'}
        float32 radiance ``.npy`` of shape ``(height, width, 3)`` (default) or an 8-bit sRGB PNG at
        exposure 1.
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
        A spec cannot be pickled; another batch is running in ``out_dir``; ``out_dir`` holds another
        batch's manifest, or frame files without a manifest; a frame, the manifest, the journal or the lock
        is a symbolic link or not a regular file.
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
    if isinstance(executor, str):
        _validate.choice("executor", executor, ("dask",))
    batch = {"glphong": __version__, "width": width, "height": height, "format": fmt,
             "options": {k: repr(v) for k, v in sorted(options.items())}, "specs": [_spec_hash(s) for s in specs]}
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = [str(out / _frame_name(i, fmt)) for i in range(len(specs))]
    workers = workers or os.cpu_count() or 1

    def submit(chunk):
        return scene_fn, [(i, specs[i]) for i in chunk], width, height, str(out), fmt, options

    with _BatchFolder(out, batch, paths) as folder:
        if folder.missing:
            _render_missing(folder, submit, executor, workers, frames_per_task, progress_bar(
                len(folder.missing), progress, unit="frame"))
    return paths


def _render_missing(folder, submit, executor, workers, frames_per_task, bar):
    """Render ``folder``'s missing frames on ``executor`` (None: a pool of ``workers`` made here and made
    again where a worker dies; 'dask': a local Dask cluster), journalling each as it comes back."""
    cluster = None
    if isinstance(executor, str):
        cluster, executor = _local_dask(workers)
    own = executor is None
    try:
        while folder.missing:
            if executor is None:
                executor = _spawn_pool(workers)
            broken = _render_round(folder, executor, submit, frames_per_task, bar)
            if broken and own:
                executor.shutdown(wait=True, cancel_futures=True)  # every worker gone: none is writing now
                executor = None
                _remove_partials(folder.out)  # a worker killed with its pool may have left a half-written file
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
        _remove_partials(folder.out)  # the workers are gone: no writer is left


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

