"""Reading untrusted files within bounds: size before and after decompression, nesting.

A checkpoint is gzip-compressed; a small file can inflate to gigabytes (a "decompression
bomb"). :func:`read_gzip_bounded` first counts the inflated size while discarding the
data, chunk by chunk, so refusing a bomb takes constant memory; only a file within the
limit is inflated for real. :func:`read_file_bounded` refuses an uncompressed file larger
than its limit before reading it. Both limits also shrink to a tenth of the memory
available now, because parsing JSON into Python objects takes about ten times the text.

:func:`check_depth` refuses data nested deeper than any mtpg file is, after parsing; the
parsers themselves raise :class:`RecursionError` on absurd nesting, which the loaders
report as such.
"""

from __future__ import annotations

import gzip
import io
import os
from typing import Any

from mtpg.limits import available_memory, gib

#: Largest inflated checkpoint read (bytes); ``MTPG_MAX_CHECKPOINT_BYTES`` overrides it.
MAX_CHECKPOINT_BYTES = 2**30
#: Largest graph file read (bytes); ``MTPG_MAX_GRAPH_BYTES`` overrides it.
MAX_GRAPH_BYTES = 256 * 2**20
#: Deepest nesting of lists and objects in any file mtpg reads.
MAX_DEPTH = 32
#: Parsed JSON takes about this many times the memory of its text.
PARSE_FACTOR = 10
_CHUNK = 1 << 20


class TooLargeError(ValueError):
    """A file is larger than mtpg reads; the message says how large and the limit."""


def limit(default: int, env: str) -> int:
    """``default``, or the byte count in the environment variable ``env``, capped by memory."""
    value = default
    text = os.environ.get(env, "").strip()
    if text.isdigit():
        value = int(text)
    avail = available_memory()
    if avail is not None:
        value = min(value, max(avail // PARSE_FACTOR, 1 << 20))
    return value


def read_file_bounded(path: str | os.PathLike[str], max_bytes: int) -> bytes:
    """Reads a whole file of at most ``max_bytes`` bytes.

    Raises:
        TooLargeError: When the file is larger (checked before reading).
        OSError: When it cannot be read.
    """
    with open(path, "rb") as fh:
        size = os.fstat(fh.fileno()).st_size
        if size > max_bytes:
            raise TooLargeError(f"file is {gib(size)}, more than the {gib(max_bytes)} mtpg reads")
        data = fh.read(max_bytes + 1)
    if len(data) > max_bytes:
        raise TooLargeError(f"file is larger than the {gib(max_bytes)} mtpg reads")
    return data


def read_gzip_bounded(raw: bytes, max_bytes: int) -> bytes:
    """Inflates gzip data whose inflated size is at most ``max_bytes``.

    Raises:
        TooLargeError: When it inflates to more, found with constant memory.
        EOFError: When the stream ends early (truncated).
        OSError, zlib.error: When the stream is corrupt.
    """
    total = 0
    with gzip.GzipFile(fileobj=io.BytesIO(raw)) as fh:
        while chunk := fh.read(_CHUNK):
            total += len(chunk)
            if total > max_bytes:
                raise TooLargeError(
                    f"inflates to more than {gib(max_bytes)} (a {gib(len(raw))} file); "
                    "refusing to read it"
                )
    try:
        return gzip.decompress(raw)
    except MemoryError as exc:  # pragma: no cover - depends on the machine
        raise TooLargeError(f"inflates to {gib(total)}, more than fits in memory") from exc


def check_depth(value: Any, max_depth: int = MAX_DEPTH) -> None:
    """Raises ValueError when lists/objects in ``value`` nest deeper than ``max_depth``."""
    stack = [(value, 1)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, dict):
            children = item.values()
        elif isinstance(item, list):
            children = item
        else:
            continue
        if depth > max_depth:
            raise ValueError(f"data is nested deeper than {max_depth} levels")
        stack.extend((c, depth + 1) for c in children if isinstance(c, dict | list))
