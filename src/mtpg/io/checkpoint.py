"""Versioned, checksummed, atomically written checkpoint files of whole runs.

A checkpoint is gzip-compressed canonical JSON (sorted keys, no spaces)::

    {"format": "mtpg-checkpoint", "payload": {...}, "sha256": "<hex>", "version": 1}

where ``sha256`` is the digest of the canonical JSON of the payload. Python's ``json``
writes floats with ``repr``, so they round-trip exactly. The gzip CRC and the digest
together catch truncation and bit flips; the format tag catches foreign files. Every
problem on load raises :class:`CheckpointError` naming the file.

Checkpoints of a run live in ``RUN_DIR/checkpoints/gen-NNNNNN.json.gz``.
"""

from __future__ import annotations

import gzip
import hashlib
import json
import os
import re
import zlib
from pathlib import Path
from typing import Any

from mtpg._faults import point
from mtpg.io._atomic import atomic_write_bytes, is_temp_file
from mtpg.io._bounded import (
    MAX_CHECKPOINT_BYTES,
    TooLargeError,
    limit,
    read_file_bounded,
    read_gzip_bounded,
)

#: Format tag and version of a checkpoint file.
CHECKPOINT_FORMAT = "mtpg-checkpoint"
CHECKPOINT_VERSION = 1
#: gzip level: 1 is ~7x faster than 6 on populations and only ~25% larger.
COMPRESS_LEVEL = 1
#: Subdirectory of a run directory holding its checkpoints.
CHECKPOINT_DIR = "checkpoints"

_NAME = re.compile(r"^gen-(\d{6,})\.json\.gz$")
_ENVELOPE_KEYS = {"format", "payload", "sha256", "version"}


class CheckpointError(ValueError):
    """A checkpoint cannot be written or read; the message names the file and problem."""


def _check_native(value: Any, where: str) -> None:
    """Raises TypeError naming the first value JSON would not give back unchanged."""
    stack = [(value, where)]
    while stack:
        item, at = stack.pop()
        if isinstance(item, dict):
            for key, sub in item.items():
                if not isinstance(key, str):
                    raise TypeError(f"{at} has a non-string key {key!r}")
                stack.append((sub, f"{at}[{key!r}]"))
        elif isinstance(item, list | tuple):
            if item and all(type(x) is int for x in item):
                continue  # fast path: a list of plain ints
            stack.extend((sub, f"{at}[{i}]") for i, sub in enumerate(item))
        elif not (item is None or isinstance(item, str | int | float)):
            raise TypeError(
                f"{at} is a {type(item).__name__}, not JSON-native (convert it to a "
                "list, dict, str, int, float, bool or None)"
            )


def canonical_json(payload: Any) -> bytes:
    """The canonical JSON bytes of a payload (sorted keys, no spaces, no NaN).

    Args:
        payload: JSON-native data: dicts with string keys, lists, strings, ints, finite
            floats, bools and None. Tuples are written as lists (and load back as
            lists); numpy values and non-string keys are refused because they would not
            load back as the values saved.

    Returns:
        UTF-8 bytes.

    Raises:
        TypeError: Naming the first value that is not JSON-native.
        ValueError: For NaN or infinity.
    """
    _check_native(payload, "payload")
    text = json.dumps(payload, sort_keys=True, separators=(",", ":"), allow_nan=False)
    return text.encode("utf-8")


def payload_digest(payload: Any) -> str:
    """Hex SHA-256 of :func:`canonical_json` of ``payload``."""
    return hashlib.sha256(canonical_json(payload)).hexdigest()


def save_checkpoint(path: str | os.PathLike[str], payload: dict[str, Any]) -> None:
    """Writes a checkpoint atomically (temp file, fsync, rename, directory fsync).

    Once the data is in the temporary file, just before it is renamed into place, the
    fault-injection point ``checkpoint`` of the generation the file's name states is
    passed (:mod:`mtpg._faults`; none for a file not named ``gen-NNNNNN.json.gz``).

    Args:
        path: Destination file; its directory must exist.
        payload: JSON-native run state.

    Raises:
        CheckpointError: When the payload is not JSON-native.
        OSError: When the file cannot be written (disk full, permission), naming it; a
            previous file at ``path`` is then left intact.
    """
    if not isinstance(payload, dict):
        raise CheckpointError(f"{path}: payload must be a dict, got {type(payload).__name__}")
    try:
        body = canonical_json(payload)
    except (TypeError, ValueError) as exc:
        raise CheckpointError(f"{path}: cannot write checkpoint: {exc}") from exc
    digest = hashlib.sha256(body).hexdigest()
    # The envelope in sorted-key canonical form, with the payload bytes spliced in.
    doc = b"".join(
        (
            b'{"format":',
            json.dumps(CHECKPOINT_FORMAT).encode(),
            b',"payload":',
            body,
            b',"sha256":',
            json.dumps(digest).encode(),
            b',"version":',
            str(CHECKPOINT_VERSION).encode(),
            b"}",
        )
    )
    data = gzip.compress(doc, compresslevel=COMPRESS_LEVEL, mtime=0)
    gen = checkpoint_generation(path)
    before_replace = None if gen is None else lambda: point("checkpoint", gen)
    try:
        atomic_write_bytes(path, data, before_replace)
    except OSError as exc:
        raise OSError(exc.errno, f"{path}: cannot write checkpoint: {exc.strerror}") from exc


def load_checkpoint(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Reads and verifies a checkpoint.

    Args:
        path: The file.

    Returns:
        The payload, equal to the one saved.

    Raises:
        CheckpointError: Naming the file and the problem: missing or unreadable, empty,
            truncated or corrupt compression, invalid JSON, a foreign file, an
            unsupported version or a checksum mismatch.
    """

    def fail(problem: str, cause: BaseException | None = None) -> CheckpointError:
        err = CheckpointError(f"{path}: {problem}")
        err.__cause__ = cause
        return err

    max_bytes = limit(MAX_CHECKPOINT_BYTES, "MTPG_MAX_CHECKPOINT_BYTES")
    try:
        raw = read_file_bounded(path, max_bytes)
    except FileNotFoundError as exc:
        raise fail("checkpoint file does not exist", exc) from exc
    except TooLargeError as exc:
        raise fail(f"checkpoint {exc}", exc) from exc
    except OSError as exc:
        raise fail(f"cannot read checkpoint: {exc.strerror or exc}", exc) from exc
    if not raw:
        raise fail("checkpoint file is empty")
    if raw[:2] != b"\x1f\x8b":
        kind = "plain JSON" if raw.lstrip()[:1] in (b"{", b"[") else "data"
        raise fail(f"not an mtpg checkpoint (not gzip-compressed; looks like {kind})")
    try:
        doc_bytes = read_gzip_bounded(raw, max_bytes)
    except TooLargeError as exc:
        raise fail(
            f"checkpoint {exc} (set MTPG_MAX_CHECKPOINT_BYTES to read larger ones)", exc
        ) from exc
    except EOFError as exc:
        raise fail("checkpoint is truncated (compressed stream ends early)", exc) from exc
    except (OSError, zlib.error, ValueError) as exc:
        raise fail(f"checkpoint is corrupt (compression error: {exc})", exc) from exc
    try:
        doc = json.loads(doc_bytes.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
        raise fail(f"checkpoint is corrupt (invalid JSON: {exc})", exc) from exc
    if not isinstance(doc, dict) or doc.get("format") != CHECKPOINT_FORMAT:
        tag = doc.get("format") if isinstance(doc, dict) else None
        what = f"format {tag!r}" if isinstance(tag, str) else "no mtpg-checkpoint format tag"
        raise fail(f"not an mtpg checkpoint ({what})")
    version = doc.get("version")
    if version != CHECKPOINT_VERSION or isinstance(version, bool):
        raise fail(
            f"unsupported checkpoint version {version!r} (this mtpg reads {CHECKPOINT_VERSION})"
        )
    if set(doc) != _ENVELOPE_KEYS:
        raise fail(f"checkpoint envelope has keys {sorted(doc)}, expected {sorted(_ENVELOPE_KEYS)}")
    payload, digest = doc["payload"], doc["sha256"]
    if not isinstance(payload, dict):
        raise fail(f"checkpoint payload must be an object, got {type(payload).__name__}")
    try:
        actual = payload_digest(payload)
    except (TypeError, ValueError, RecursionError) as exc:  # e.g. a float read as infinity
        raise fail(f"checkpoint is corrupt (payload: {exc})", exc) from exc
    if actual != digest:
        raise fail("checkpoint is corrupt (SHA-256 checksum mismatch)")
    return payload


def checkpoint_generation(path: str | os.PathLike[str]) -> int | None:
    """The generation a checkpoint's file name states, or None for another name."""
    match = _NAME.match(Path(path).name)
    return int(match.group(1)) if match else None


def checkpoint_path(run_dir: str | os.PathLike[str], generation: int) -> Path:
    """The checkpoint file of a generation: ``RUN_DIR/checkpoints/gen-NNNNNN.json.gz``."""
    if generation < 0:
        raise ValueError(f"generation must be >= 0, got {generation}")
    return Path(run_dir) / CHECKPOINT_DIR / f"gen-{generation:06d}.json.gz"


def list_checkpoints(run_dir: str | os.PathLike[str]) -> list[tuple[int, Path]]:
    """The checkpoints of a run as ``(generation, path)``, oldest first.

    Temporary files of interrupted writes and unrelated files are skipped.
    """
    directory = Path(run_dir) / CHECKPOINT_DIR
    if not directory.is_dir():
        return []
    found = []
    for entry in directory.iterdir():
        match = _NAME.match(entry.name)
        if match and entry.is_file():
            found.append((int(match.group(1)), entry))
    return sorted(found)


def latest_checkpoint(run_dir: str | os.PathLike[str]) -> Path | None:
    """The checkpoint of the highest generation, or None when there is none."""
    found = list_checkpoints(run_dir)
    return found[-1][1] if found else None


def prune_checkpoints(run_dir: str | os.PathLike[str], keep: int = 2) -> list[Path]:
    """Deletes all but the ``keep`` newest checkpoints, and leftover temporary files.

    Call it only while no checkpoint of this run is being written.

    Args:
        run_dir: The run directory.
        keep: Number of newest checkpoints to keep (>= 1).

    Returns:
        The files deleted.
    """
    if keep < 1:
        raise ValueError(f"keep must be >= 1, got {keep}")
    doomed = [path for _, path in list_checkpoints(run_dir)[:-keep]]
    directory = Path(run_dir) / CHECKPOINT_DIR
    if directory.is_dir():
        doomed += [e for e in directory.iterdir() if is_temp_file(e.name) and e.is_file()]
    for path in doomed:
        path.unlink(missing_ok=True)
    return doomed
