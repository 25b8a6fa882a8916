"""Keeps Numba's on-disk kernel cache true to the sources it was compiled from.

Numba's cache (``@njit(cache=True)``) checks only the file that defines a kernel: a
kernel that calls a function of another module keeps the machine code of that function
as it was compiled, after the other module changed. After a ``git pull`` or a branch
switch that edits, say, ``envs/dynamics/dispatch.py`` alone, ``engine/episode_kernels.py``'s cached
episode loop would still observe the old way: results would silently differ from the
sources (this happened once while the variant keys were added).

So the package keeps a fingerprint of all its sources (their bytes, hashed) beside its
cache. :func:`refresh` compares them: if the sources differ from the fingerprint, every
cached kernel of the package is deleted, and Numba compiles afresh. Hashing the ~150
source files takes a few milliseconds. An installed package whose folders cannot be
written is left alone: Numba then caches in a user folder, and an upgrade rewrites
every source file, which Numba does notice.

``import mtpg`` does not call it (importing changes no file). It must run before the
first kernel of a process is called (Numba loads a cached kernel at its first call), so
the programs that run kernels call it first: the command line (``mtpg``, at the start of
every command), the test suite (``tests/conftest.py``) and the scripts of ``tools/`` and
``benchmarks/`` that run kernels in their own process. Python code that edits the sources
of a checkout and then runs kernels in-process calls ``mtpg._kernel_cache.refresh()``.
"""

from __future__ import annotations

import hashlib
import logging
import os
from pathlib import Path

_LOG = logging.getLogger(__name__)

_ROOT = Path(__file__).resolve().parent
_STAMP = _ROOT / "__pycache__" / "kernel-sources.sha256"
#: Numba's cache files: the index and the machine code of each kernel.
_SUFFIXES = (".nbi", ".nbc")


def fingerprint(root: Path = _ROOT) -> str:
    """A hash of every ``.py`` file under ``root``: its path and its bytes."""
    h = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        h.update(path.relative_to(root).as_posix().encode())
        h.update(path.read_bytes())
    return h.hexdigest()


def cached_kernels(root: Path = _ROOT) -> list[Path]:
    """Numba's cache files under ``root``'s ``__pycache__`` folders."""
    return [p for p in root.rglob("__pycache__/*") if p.suffix in _SUFFIXES]


def refresh(root: Path = _ROOT, stamp: Path = _STAMP) -> bool:
    """Deletes the cached kernels if the sources changed since they were stamped.

    Returns:
        True if the cache was cleared (or first stamped), False if it was current or
        cannot be written.
    """
    current = fingerprint(root)
    try:
        if stamp.read_text() == current:
            return False
    except OSError:
        pass
    if not os.access(root, os.W_OK):
        return False
    stale = cached_kernels(root)
    for path in stale:
        try:
            path.unlink()
        except OSError:  # another process cleared it first
            pass
    _LOG.debug("kernel cache: the sources changed; %d cached kernel files removed", len(stale))
    try:
        stamp.parent.mkdir(exist_ok=True)
        tmp = stamp.with_suffix(f".{os.getpid()}")
        tmp.write_text(current)
        tmp.replace(stamp)
    except OSError:
        return True
    return True
