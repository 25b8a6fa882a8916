"""An exclusive advisory lock on a run directory: one writing process at a time.

``mtpg train`` (new or ``--resume``) and ``mtpg experiment`` hold ``DIR/.lock`` for as
long as they write into ``DIR``. The lock is the operating system's, taken through
:func:`filelock.lock_descriptor` (``flock`` on Linux and macOS, ``LockFileEx`` on
Windows; the primitive of ``filelock.FileLock``) on a descriptor this module opens and
keeps, so that taking the lock writes nothing and the holder can leave a note in the
file. The operating system releases the lock when the process ends, however it ends
(SIGKILL included), so a stale lock cannot outlive its holder. The file holds the
holder's process id and host name, which a refused process names (on Windows the
locked first byte cannot be read by another process, which then names "another
process"). Readers (``evaluate``, ``report``) take no lock.
"""

from __future__ import annotations

import contextlib
import os
import socket
from pathlib import Path

from filelock import lock_descriptor, unlock_descriptor

#: Name of the lock file inside a locked directory.
LOCK_FILE = ".lock"

#: Flags of the lock file's descriptor: not inherited by child processes where the
#: platform has the flag, binary where it has that one (Windows).
_OPEN_FLAGS = os.O_RDWR | os.O_CREAT | getattr(os, "O_CLOEXEC", 0) | getattr(os, "O_BINARY", 0)


class LockedError(RuntimeError):
    """The directory is locked by another process; the message names the holder."""


class DirLock:
    """An acquired lock on a directory (see :func:`lock_dir`)."""

    def __init__(self, path: Path, fd: int) -> None:
        self.path = path
        self._fd: int | None = fd

    def claim(self) -> None:
        """Writes this process's id and host into the lock file, for refused processes.

        Separate from taking the lock so that a process which takes it, finds a problem
        and gives up leaves the directory byte for byte as it was.
        """
        if self._fd is None:
            return
        try:
            os.ftruncate(self._fd, 0)
            os.lseek(self._fd, 0, os.SEEK_SET)
            os.write(self._fd, f"{os.getpid()} {socket.gethostname()}\n".encode())
        except OSError:
            pass  # the lock holds without the note

    def release(self) -> None:
        """Releases the lock (the file stays, for the next holder)."""
        if self._fd is not None:
            with contextlib.suppress(OSError):
                unlock_descriptor(self._fd)
            os.close(self._fd)
            self._fd = None

    def __enter__(self) -> DirLock:
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()


def holder(directory: str | os.PathLike[str]) -> str:
    """What the lock file of ``directory`` says about its holder (may be empty)."""
    try:
        text = (Path(directory) / LOCK_FILE).read_text(encoding="utf-8", errors="replace")
    except OSError:
        return ""
    parts = text.split()
    if len(parts) >= 2 and parts[0].isdigit():
        return f"process {parts[0]} on {parts[1]}"
    return ""


def lock_dir(directory: str | os.PathLike[str], what: str = "mtpg") -> DirLock:
    """Takes the exclusive lock of an existing directory, without waiting.

    Args:
        directory: The directory; it must exist.
        what: The kind of directory, for the message.

    Returns:
        The held lock (call :meth:`DirLock.claim` to record the holder); release it, or
        let the process end, to let others in.

    Raises:
        LockedError: When another process holds it, naming that process.
        OSError: When the lock file cannot be created or opened, or the file system
            cannot lock it.
    """
    path = Path(directory) / LOCK_FILE
    fd = os.open(path, _OPEN_FLAGS, 0o644)
    try:
        taken = lock_descriptor(fd, blocking=False)
    except BaseException:
        os.close(fd)
        raise
    if not taken:
        os.close(fd)
        who = holder(directory) or "another process"
        raise LockedError(
            f"{directory}: {what} is in use by {who} (a train, --resume or experiment); "
            "wait for it to finish or stop it first"
        )
    return DirLock(path, fd)
