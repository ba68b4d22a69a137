"""Files made whole or not at all: the content written to a temporary file beside the target, renamed over it."""
import os
import secrets
from pathlib import Path

__all__ = ["write_atomically"]


def write_atomically(path, write):
    """Make ``path`` whole or not at all: ``write(temporary)`` fills a new file beside it, then ``os.replace``
    renames that over ``path``; on any error the temporary file is removed and ``path`` is left as it was.

    Parameters
    ----------
    path : path-like
        The file to make (replaced where it exists); its folder must exist.
    write : callable
        ``write(temporary)`` writes the content to the path ``temporary`` (str; an empty file already created, with
        the permissions the umask gives a new file).

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    FileNotFoundError
        The folder does not exist.
    IsADirectoryError
        ``path`` is a folder.
    """
    path = Path(path)
    folder = path.parent
    if not folder.is_dir():
        raise FileNotFoundError(f"{path}: the folder {folder} does not exist")
    if path.is_dir():
        raise IsADirectoryError(f"{path}: is a folder, expected a file name")
    while True:
        temporary = folder / f".{path.name}.partial-{secrets.token_hex(6)}"
        try:
            os.close(os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_CLOEXEC", 0), 0o666))
            break
        except FileExistsError:
            continue
    try:
        write(str(temporary))
        os.replace(temporary, path)
    finally:
        if temporary.exists():
            temporary.unlink()
    return path
