"""Atomic file replacement: a reader sees the old file or the new one, never a mix."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Callable
from pathlib import Path

#: Suffix of the temporary files :func:`atomic_write_bytes` creates (and cleans up).
TEMP_SUFFIX = ".tmp"


def _read_umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


#: The process umask, read once at import (reading it means briefly changing it).
_UMASK = _read_umask()


def fsync_dir(directory: Path) -> None:
    """Flushes a directory entry to disk (a no-op where directories cannot be opened)."""
    try:
        fd = os.open(directory, os.O_RDONLY)
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def atomic_write_bytes(
    path: str | os.PathLike[str], data: bytes, before_replace: Callable[[], None] | None = None
) -> None:
    """Writes ``data`` to ``path`` atomically.

    The bytes go to a temporary file in the same directory (``.NAME.XXXX.tmp``), which is
    flushed, fsynced and renamed over ``path``; the directory is then fsynced. On any
    failure the temporary file is removed and ``path`` is left as it was. The file gets
    the mode of the file it replaces, else the usual ``0o666`` less the umask.

    Args:
        path: Destination file; its directory must exist.
        data: The complete new contents.
        before_replace: Called after the data is flushed to the temporary file and before
            the rename (the checkpoint's fault-injection point: a stop there leaves only the
            temporary file).

    Raises:
        OSError: When writing or renaming fails.
    """
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=TEMP_SUFFIX)
    try:
        mode = path.stat().st_mode & 0o7777
    except OSError:
        mode = 0o666 & ~_UMASK
    try:
        with os.fdopen(fd, "wb") as fh:
            os.fchmod(fh.fileno(), mode)
            fh.write(data)
            fh.flush()
            os.fsync(fh.fileno())
        if before_replace is not None:
            before_replace()
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
    fsync_dir(path.parent)


def is_temp_file(name: str) -> bool:
    """True for the name of a temporary file left by :func:`atomic_write_bytes`."""
    return name.startswith(".") and name.endswith(TEMP_SUFFIX)
