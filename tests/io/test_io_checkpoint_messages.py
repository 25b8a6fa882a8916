"""Checkpoint files: the exact message and cause of every refusal, deterministic bytes."""

from __future__ import annotations

import errno
import gzip
import json

import pytest

from mtpg.io import CheckpointError, load_checkpoint, save_checkpoint
from mtpg.io import checkpoint as checkpoint_module
from mtpg.io.checkpoint import COMPRESS_LEVEL

SMALL = {"generation": 3, "x": [0.1, 1 / 3], "name": "run", "ok": True}


def envelope(**changes) -> bytes:
    doc = {
        "format": "mtpg-checkpoint",
        "version": 1,
        "sha256": checkpoint_module.payload_digest(SMALL),
        "payload": SMALL,
    }
    doc.update(changes)
    return gzip.compress(json.dumps(doc).encode())


ENVELOPE = "['format', 'payload', 'sha256', 'version']"


@pytest.mark.parametrize(
    ("content", "message", "cause"),
    [
        (b"", "checkpoint file is empty", None),
        (
            b'{"format": "x"}',
            "not an mtpg checkpoint (not gzip-compressed; looks like plain JSON)",
            None,
        ),
        (b"\x00\x01garbage", "not an mtpg checkpoint (not gzip-compressed; looks like data)", None),
        (
            gzip.compress(b'{"format": "x", "version": 1}'),
            "not an mtpg checkpoint (format 'x')",
            None,
        ),
        (gzip.compress(b"[1]"), "not an mtpg checkpoint (no mtpg-checkpoint format tag)", None),
        (envelope(version=2), "unsupported checkpoint version 2 (this mtpg reads 1)", None),
        (envelope(version=True), "unsupported checkpoint version True (this mtpg reads 1)", None),
        (envelope(sha256="0" * 64), "checkpoint is corrupt (SHA-256 checksum mismatch)", None),
        (envelope(payload=[1]), "checkpoint payload must be an object, got list", None),
        (
            envelope(extra=1),
            f"checkpoint envelope has keys ['extra', 'format', 'payload', 'sha256', 'version'], "
            f"expected {ENVELOPE}",
            None,
        ),
        (
            gzip.compress(b"x" * 100)[:-8],
            "checkpoint is truncated (compressed stream ends early)",
            EOFError,
        ),
        (
            b"\x1f\x8bxxxxxxxxxxxxxxxxxxxx",
            "checkpoint is corrupt (compression error: Unknown compression method)",
            OSError,
        ),
        (
            gzip.compress(b"{"),
            "checkpoint is corrupt (invalid JSON: Expecting property name enclosed in double "
            "quotes: line 1 column 2 (char 1))",
            ValueError,
        ),
    ],
)
def test_every_refusal_names_the_file_the_problem_and_keeps_the_cause(
    tmp_path, content, message, cause
) -> None:
    path = tmp_path / "gen-000001.json.gz"
    path.write_bytes(content)
    with pytest.raises(CheckpointError) as err:
        load_checkpoint(path)
    assert str(err.value) == f"{path}: {message}"
    if cause is None:
        assert err.value.__cause__ is None
    else:
        assert isinstance(err.value.__cause__, cause)


def test_missing_unreadable_and_too_large_files(tmp_path, monkeypatch) -> None:
    missing = tmp_path / "gen-000009.json.gz"
    with pytest.raises(CheckpointError) as err:
        load_checkpoint(missing)
    assert str(err.value) == f"{missing}: checkpoint file does not exist"
    assert isinstance(err.value.__cause__, FileNotFoundError)
    with pytest.raises(CheckpointError) as err:
        load_checkpoint(tmp_path)
    assert str(err.value) == f"{tmp_path}: cannot read checkpoint: Is a directory"
    assert isinstance(err.value.__cause__, IsADirectoryError)
    path = tmp_path / "gen-000001.json.gz"
    path.write_bytes(envelope())
    assert load_checkpoint(path) == SMALL
    monkeypatch.setenv("MTPG_MAX_CHECKPOINT_BYTES", "10")
    with pytest.raises(CheckpointError) as err:
        load_checkpoint(path)
    assert str(err.value).startswith(f"{path}: checkpoint file is ")
    assert "more than the" in str(err.value)


def test_saved_bytes_are_deterministic_and_use_the_stated_compression(tmp_path) -> None:
    a, b = tmp_path / "a.json.gz", tmp_path / "b.json.gz"
    save_checkpoint(a, SMALL)
    save_checkpoint(b, SMALL)
    raw = a.read_bytes()
    assert raw == b.read_bytes()  # no time stamp in the gzip header
    assert raw == gzip.compress(gzip.decompress(raw), compresslevel=COMPRESS_LEVEL, mtime=0)


def test_save_refuses_a_non_dict_and_passes_its_fault_point_before_the_rename(
    tmp_path, monkeypatch
) -> None:
    path = tmp_path / "gen-000002.json.gz"
    with pytest.raises(CheckpointError) as err:
        save_checkpoint(path, [1])
    assert str(err.value) == f"{path}: payload must be a dict, got list"
    seen = []
    monkeypatch.setattr(checkpoint_module, "point", lambda *at: seen.append((*at, path.exists())))
    save_checkpoint(path, SMALL)
    assert seen == [("checkpoint", 2, False)] and load_checkpoint(path) == SMALL
    save_checkpoint(tmp_path / "other.json.gz", SMALL)  # not a generation's name: no point
    assert len(seen) == 1


def test_a_failed_write_keeps_its_error_number(tmp_path, monkeypatch) -> None:
    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(checkpoint_module, "atomic_write_bytes", full)
    path = tmp_path / "gen-000001.json.gz"
    with pytest.raises(OSError) as err:
        save_checkpoint(path, SMALL)
    assert err.value.errno == errno.ENOSPC
    assert err.value.strerror == f"{path}: cannot write checkpoint: No space left on device"
