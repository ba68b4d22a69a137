"""The folder of a batch: its lock, its manifest claimed atomically, its frames journal, the frames on disk.

`_BatchFolder` claims ``out_dir`` for a running batch; the `glphong.batch` docstring says what
``manifest.json``, ``frames.jsonl`` and ``.lock`` are for.  Every file of the folder is opened without
following a symbolic link, and a link or a file that is not regular is refused (`BatchError`).
"""
import errno
import hashlib
import json
import os
import stat
import tempfile
from pathlib import Path

from glphong.core.atomic_files import write_atomically

try:
    import fcntl
except ImportError:  # Windows: no advisory locks, see _lock_folder
    fcntl = None

__all__ = ["BatchError", "FramesFailedError"]

MANIFEST = "manifest.json"
JOURNAL = "frames.jsonl"
LOCK = ".lock"
_JOURNAL_LINE_LIMIT = 1 << 20  # bytes; a longer line is no record of ours (a BOP image's record: a few kB)
_NOFOLLOW = getattr(os, "O_NOFOLLOW", 0)
_CLOEXEC = getattr(os, "O_CLOEXEC", 0)
_NONBLOCK = getattr(os, "O_NONBLOCK", 0)  # a FIFO put in a file's place does not hang its open


class BatchError(RuntimeError):
    """A batch cannot run as asked: another batch's frames or a running batch in the folder, files the batch
    cannot trust (a symbolic link, frames without a manifest), a spec that cannot be pickled."""


class FramesFailedError(BatchError):
    """Frames of a batch failed (their scene function raised, the renderer or the driver raised, or writing failed);
    every other frame was rendered (but after a failed write, which stops the batch), and the frames done are in
    the folder and its journal: running the same batch again renders only the frames missing.

    Attributes
    ----------
    failures : list of dict
        One per failed frame, in frame order: ``{"index", "spec", "stage", "error", "traceback"}``; ``stage`` is
        'scene_fn', 'render' or 'write'; ``error`` the exception's type and message; ``traceback`` the worker's.
    done : int
        Frames done in the folder (journalled), of ``total``.
    total : int
    """

    def __init__(self, out, failures, done, total):
        self.failures, self.done, self.total = failures, done, total
        first = failures[0]
        stage = {"scene_fn": "in scene_fn", "render": "rendering it", "write": "writing it"}[first["stage"]]
        stopped = "; the batch stopped (a failed write fails the frames after it too)" \
            if any(f["stage"] == "write" for f in failures) else ""
        spec = repr(first["spec"])
        spec = spec if len(spec) <= 160 else f"{spec[:60]}...{spec[-97:]}"  # a path's end names the file
        super().__init__(f"{len(failures)} of {total} frame(s) failed; the first, frame {first['index']} (spec "
                         f"{spec}), {stage}: {first['error']}{stopped}.  The {done} frame(s) done are "
                         f"kept and journalled in {out}: run the same batch again to render only the "
                         f"{total - done} missing (the worker's traceback: .failures[0]['traceback'])")


def _write_error(exc, path, needed, what=None):
    """An `OSError` of the same kind as ``exc``, raised while writing ``path`` (the temporary file is gone), naming the
    file (or ``what``), and for a full disk or quota the free space there and the ``needed`` bytes (a str)."""
    message = f"writing {what or path} failed: {exc.strerror or exc}"
    if exc.errno in (errno.ENOSPC, errno.EDQUOT):
        try:
            info = os.statvfs(os.path.dirname(path))
            free = f"{info.f_bavail * info.f_frsize / 2**20:.1f} MiB free"
        except (OSError, AttributeError):
            free = "free space unknown"
        message += f" ({free} on its file system; the file needs {needed}): free space and run the batch again"
    return OSError(exc.errno, message)


def _make_folder(out):
    """Make the folder ``out`` (a `pathlib.Path`) where missing; `BatchError` naming it where it is a file, cannot be
    made, or cannot be written (the user's rights, a read-only file system)."""
    if out.exists() and not out.is_dir():
        raise BatchError(f"out_dir {out} is a file, not a folder: a batch writes its frames into a folder; give another "
                         "out_dir (or remove the file)")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise BatchError(f"out_dir {out} cannot be made: {exc.strerror or exc} ({exc.filename or out})") from exc
    if not os.access(out, os.W_OK | os.X_OK):
        raise BatchError(f"out_dir {out} cannot be written by this user (its mode is "
                         f"{stat.filemode(os.stat(out).st_mode)}): give a folder this process may write")


def _frame_name(index, fmt):
    return f"frame_{index:06d}.{fmt}"


def _file_digest(fd):
    """``(size, sha256)`` of the open file ``fd`` read from its start: its size in bytes and hex digest."""
    digest = hashlib.sha256()
    size = 0
    os.lseek(fd, 0, os.SEEK_SET)
    while block := os.read(fd, 1 << 20):
        digest.update(block)
        size += len(block)
    return size, digest.hexdigest()


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
    """Replace ``path`` by a file holding ``text`` (UTF-8), whole or not at all
    (`glphong.core.atomic_files.write_atomically`)."""
    write_atomically(path, lambda temporary: Path(temporary).write_text(text, encoding="utf-8"))


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
    """The name of a frame file, a BOP scene folder (six digits) or a journal in ``out`` (the folder has no
    manifest), or None."""
    with os.scandir(out) as entries:
        return next((e.name for e in entries if e.name.startswith("frame_") or e.name == JOURNAL
                     or (len(e.name) == 6 and e.name.isdigit() and e.name.isascii())), None)


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
    previous = _read_manifest(path, 65536 + 64 * len(batch["specs"]) + 2 * len(json.dumps(batch.get("bop", {}))))
    stored = {k: v for k, v in previous.items() if k != "renderer"}
    if stored != batch:
        differ = sorted(k for k in set(batch) | set(stored) if stored.get(k) != batch.get(k))
        raise BatchError(f"{out} holds another batch (its {', '.join(differ)} differ): glphong never mixes two "
                         "batches in one folder; use another out_dir or remove it")
    return previous


def _parse_record(line, count, parse):
    """``(index, value)`` from a journal line, or None for a line that is not a record of a frame below ``count``
    (a line cut short by a crash, say); ``parse(index, record)`` checks the record's value (`_FileFrames.parse`)."""
    try:
        record = json.loads(line)
        index = record["index"]
    except (ValueError, TypeError, KeyError):
        return None
    if type(index) is not int or not 0 <= index < count:
        return None
    value = parse(index, record)
    return None if value is None else (index, value)


def _read_journal(path, count, parse):
    """The last record of each frame in the journal at ``path``: ``{index: value}``."""
    if _regular_or_missing(path, "the frame journal") is None:
        return {}
    records = {}
    with open(_open_regular(path, os.O_RDONLY, "the frame journal"), "rb") as stream:
        while line := stream.readline(_JOURNAL_LINE_LIMIT):
            if not line.endswith(b"\n"):  # over the limit (skip the rest of it) or cut short at the end
                while line and not line.endswith(b"\n"):
                    line = stream.readline(_JOURNAL_LINE_LIMIT)
                continue
            record = _parse_record(line, count, parse)
            if record is not None:
                records[record[0]] = record[1]
    return records


def _file_record(size, sha256):
    """The journal value of a file, ``{"size", "sha256"}``; None where either is not what a record holds."""
    if type(size) is not int or size < 0 or not isinstance(sha256, str) or len(sha256) != 64:
        return None
    return {"size": size, "sha256": sha256}


def _file_matches(path, size, sha256, what):
    """Whether the file at ``path`` exists with ``size`` bytes and the hex SHA-256 ``sha256``; `BatchError` for a
    symbolic link or a file that is not regular (``what`` names it)."""
    if _regular_or_missing(path, what) is None:
        return False
    fd = _open_regular(path, os.O_RDONLY, what)
    try:
        return os.fstat(fd).st_size == size and _file_digest(fd) == (size, sha256)
    finally:
        os.close(fd)


class _FileFrames:
    """The frames of a batch that writes one file a frame (fmt 'npy', 'png', 'npz', 'exr'): a frame's journal
    value is ``{"size", "sha256"}`` of its file as its worker wrote it.

    `_BatchFolder` asks a batch's frames to ``parse`` a journal record's value, whether a frame on disk is
    ``trusted``, to ``remove_partials``, what it keeps in memory of a journalled value (``kept``), and, as frames
    come back and at the end, ``recorded`` and ``finish``
    (nothing to do here; `glphong.batch.bop_images.BopImages` writes its scenes' JSON files then).

    Parameters
    ----------
    paths : list of str
        The frame paths, in spec order.
    """

    def __init__(self, paths):
        self.paths = paths

    def parse(self, index, record):
        """The value of journal ``record`` (a dict) of frame ``index``, or None where it is not one of ours."""
        return _file_record(record.get("size"), record.get("sha256"))

    def trusted(self, index, value):
        """Whether frame ``index`` on disk matches its journal ``value`` (None: no record); `BatchError` for a
        frame that is a symbolic link or not a regular file, recorded or not."""
        path = self.paths[index]
        if value is None:
            _regular_or_missing(path, "a frame")
            return False
        return _file_matches(path, value["size"], value["sha256"], "a frame")

    def remove_partials(self):
        """Remove what writers that died left beyond ``.partial-*`` in the folder (nothing for these frames)."""

    def kept(self, value):
        """What the batch keeps in memory of a frame journalled with ``value``: nothing (None), the journal holds it."""
        return None

    def recorded(self, done, indices):
        """Frames ``indices`` were journalled; ``done`` the values of every frame done (nothing to do here)."""

    def finish(self, done):
        """The batch ends (finished or not) with the frames ``done`` (nothing to do here)."""


def _record_line(index, value):
    """The journal line of a frame: ``{"index", ...its value}`` and a newline."""
    return json.dumps({"index": index, **value}) + "\n"


class _BatchFolder:
    """``out_dir`` claimed by a running batch: its lock held, its manifest created or compared, its journal
    open for appending, and the frames done so far.

    Parameters
    ----------
    out : pathlib.Path
        The folder (it exists).
    batch : dict
        The manifest of this batch, without the GL renderer.
    frames : _FileFrames or glphong.batch.bop_images.BopImages
        The batch's frames: their paths (``frames.paths``, in spec order), how a journal record is read and a
        frame on disk trusted.
    """

    def __init__(self, out, batch, frames):
        self.out, self.batch, self.frames, self.paths = out, batch, frames, frames.paths
        self.lock = self.journal = None
        self.manifest, self.done = None, {}

    def __enter__(self):
        self.lock = _lock_folder(self.out)
        try:
            self.manifest = _claim_manifest(self.out, self.batch)
            self.remove_partials()  # the lock is ours: no writer of this folder is left
            journal = self.out / JOURNAL
            records = _read_journal(journal, len(self.paths), self.frames.parse)
            self.done = {i: records[i] for i in range(len(self.paths)) if self.frames.trusted(i, records.get(i))}
            _replace_atomically(journal, "".join(_record_line(i, v) for i, v in sorted(self.done.items())))
            self.done = {i: self.frames.kept(v) for i, v in self.done.items()}
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
        """Journal the frames ``records`` (``(index, value)`` each, as a worker returned them)."""
        for index, value in records:
            os.write(self.journal, _record_line(index, value).encode())
            self.done[index] = self.frames.kept(value)
        self.frames.recorded(self.done, [index for index, _ in records])

    def remove_partials(self):
        """Remove the temporary files of writers that died (`_remove_partials`, and the frames' own)."""
        _remove_partials(self.out)
        self.frames.remove_partials()

    def finish(self):
        """Tell the frames the batch ends, with the frames done (a BOP batch writes its scenes' JSON files)."""
        self.frames.finish(self.done)

    def name_renderer(self, renderer_name):
        """Add the GL renderer to the manifest (an atomic replace) where it has none."""
        if renderer_name is not None and "renderer" not in self.manifest:
            self.manifest = self.manifest | {"renderer": renderer_name}
            _replace_atomically(self.out / MANIFEST, json.dumps(self.manifest, indent=1))


def _remove_partials(out):
    """Remove the temporary files of writers that died (``.partial-*``, and ``.NAME.partial-*`` of
    `glphong.core.atomic_files.write_atomically`, which ``fmt`` 'npz' and 'exr' write through; a frame is renamed
    when whole)."""
    for leftover in [*Path(out).glob(".partial-*"), *Path(out).glob(".*.partial-*")]:
        try:
            leftover.unlink()
        except OSError:
            pass
