"""Checkpoints: exact round trip, atomic writes, and a CheckpointError for every defect."""

import gzip
import hashlib
import json
import os

import numpy as np
import pytest

from mtpg.engine.random_populations import tangled_population
from mtpg.io import (
    CheckpointError,
    checkpoint_path,
    latest_checkpoint,
    list_checkpoints,
    load_checkpoint,
    population_from_dict,
    population_to_dict,
    prune_checkpoints,
    save_checkpoint,
)

SMALL = {"generation": 3, "x": [0.1, 1e-300, -2.5e300, 1 / 3], "name": "run", "ok": True}


def payload():
    pop = tangled_population(np.random.default_rng(0), 8, 20, 6, 4)
    rng = np.random.default_rng(1)
    return {
        "generation": 12,
        "population": population_to_dict(pop),
        "rng": {"state": 2**100 + 7, "inc": 3},
        "scores": rng.normal(size=50).tolist() + [5e-324, 1.7976931348623157e308, -0.0],
        "nested": {"a": [], "b": {}, "c": None, "é": "ü"},
    }


def test_round_trip_is_exact(tmp_path):
    data = payload()
    path = tmp_path / "c.json.gz"
    save_checkpoint(path, data)
    back = load_checkpoint(path)
    assert back == data
    assert [float.hex(x) for x in back["scores"]] == [float.hex(x) for x in data["scores"]]
    assert str(back["scores"][-1]) == "-0.0"
    population_from_dict(back["population"])
    # the file is gzip-compressed canonical JSON with the documented envelope
    doc = json.loads(gzip.decompress(path.read_bytes()))
    assert (doc["format"], doc["version"], sorted(doc)) == (
        "mtpg-checkpoint",
        1,
        ["format", "payload", "sha256", "version"],
    )
    # deterministic bytes
    save_checkpoint(tmp_path / "d.json.gz", data)
    assert (tmp_path / "d.json.gz").read_bytes() == path.read_bytes()


@pytest.mark.parametrize(
    ("bad", "needle"),
    [
        ({"a": np.zeros(3)}, "payload['a'] is a ndarray"),
        ({"a": [1, np.int64(2)]}, "payload['a'][1] is a int64"),
        ({"a": (1, np.float32(2))}, "payload['a'][1] is a float32"),
        ({"a": {1: 2}}, "non-string key 1"),
        ({"a": float("nan")}, "not JSON compliant"),
        ([1, 2], "payload must be a dict"),
    ],
)
def test_save_refuses_non_native_payload(tmp_path, bad, needle):
    with pytest.raises(CheckpointError) as info:
        save_checkpoint(tmp_path / "c.json.gz", bad)
    assert "c.json.gz" in str(info.value) and needle in str(info.value)
    assert list(tmp_path.iterdir()) == []


def test_tuples_load_back_as_lists(tmp_path):
    save_checkpoint(tmp_path / "c.json.gz", {"tasks": ("CartPole", "Acrobot"), "p": (1, (2,))})
    assert load_checkpoint(tmp_path / "c.json.gz") == {
        "tasks": ["CartPole", "Acrobot"],
        "p": [1, [2]],
    }


def write(path, data):
    path.write_bytes(data)
    return path


def envelope(**changes):
    body = json.dumps(SMALL, sort_keys=True, separators=(",", ":"))
    doc = {
        "format": "mtpg-checkpoint",
        "version": 1,
        "sha256": hashlib.sha256(body.encode()).hexdigest(),
        "payload": SMALL,
    }
    doc.update(changes)
    return gzip.compress(json.dumps(doc).encode())


@pytest.mark.parametrize(
    ("content", "needle"),
    [
        (b"", "empty"),
        (b'{"format": "something-else"}', "not gzip-compressed; looks like plain JSON"),
        (b"\x00\x01garbage", "not gzip-compressed"),
        (gzip.compress(b'{"format": "something-else", "version": 1}'), "format 'something-else'"),
        (gzip.compress(b"[1, 2, 3]"), "no mtpg-checkpoint format tag"),
        (gzip.compress(b'{"format": "mtpg-checkpoint", "version": 1'), "invalid JSON"),
        (gzip.compress(b"\xff\xfe{}"), "invalid JSON"),
        (envelope(version=2), "unsupported checkpoint version 2"),
        (envelope(version="1"), "unsupported checkpoint version '1'"),
        (envelope(sha256="0" * 64), "checksum mismatch"),
        (envelope(payload=[1]), "payload must be an object"),
        (envelope(extra=1), "envelope has keys"),
    ],
)
def test_load_rejects_bad_files(tmp_path, content, needle):
    path = write(tmp_path / "gen-000001.json.gz", content)
    with pytest.raises(CheckpointError) as info:
        load_checkpoint(path)
    assert str(info.value).startswith(f"{path}: ")
    assert needle in str(info.value)


def test_load_accepts_hand_built_envelope(tmp_path):
    # key order and whitespace of the envelope do not matter, only the payload digest
    assert load_checkpoint(write(tmp_path / "c.json.gz", envelope())) == SMALL


def test_missing_file(tmp_path):
    with pytest.raises(CheckpointError, match=r"gen-000009\.json\.gz: .*does not exist"):
        load_checkpoint(tmp_path / "gen-000009.json.gz")


def test_directory_instead_of_file(tmp_path):
    with pytest.raises(CheckpointError, match="cannot read"):
        load_checkpoint(tmp_path)


def test_truncated_file(tmp_path):
    path = tmp_path / "c.json.gz"
    save_checkpoint(path, payload())
    data = path.read_bytes()
    for cut in (1, 2, 10, len(data) // 2, len(data) - 9, len(data) - 1):
        write(path, data[:cut])
        with pytest.raises(CheckpointError, match="c.json.gz"):
            load_checkpoint(path)


def test_every_bit_flip_in_gzip_stream_is_caught(tmp_path):
    """Flipping any one bit either raises CheckpointError or loads the same payload.

    (Bits of the gzip header's timestamp and OS fields carry no data.)
    """
    src = tmp_path / "src.json.gz"
    save_checkpoint(src, SMALL)
    data = src.read_bytes()
    path = tmp_path / "flip.json.gz"
    caught = 0
    for i in range(len(data)):
        for bit in range(8):
            flipped = bytearray(data)
            flipped[i] ^= 1 << bit
            write(path, bytes(flipped))
            try:
                assert load_checkpoint(path) == SMALL
            except CheckpointError as exc:
                assert "flip.json.gz" in str(exc)
                caught += 1
    body = range(10, len(data) - 8)  # deflate data and trailer minus the header
    assert caught >= 8 * len(body)


def test_every_bit_flip_in_json_is_caught(tmp_path):
    src = tmp_path / "src.json.gz"
    save_checkpoint(src, SMALL)
    doc = gzip.decompress(src.read_bytes())
    path = tmp_path / "flip.json.gz"
    for i in range(len(doc)):
        for bit in range(8):
            flipped = bytearray(doc)
            flipped[i] ^= 1 << bit
            write(path, gzip.compress(bytes(flipped)))
            try:
                back = load_checkpoint(path)
            except CheckpointError as exc:
                assert "flip.json.gz" in str(exc)
            else:  # only a flip that JSON reads back as the same value may pass
                assert back == SMALL, (i, bit)


def test_atomic_write_leaves_no_temp_files(tmp_path):
    path = checkpoint_path(tmp_path, 5)
    path.parent.mkdir()
    save_checkpoint(path, SMALL)
    save_checkpoint(path, {**SMALL, "generation": 4})
    assert [p.name for p in path.parent.iterdir()] == ["gen-000005.json.gz"]
    umask = os.umask(0)
    os.umask(umask)
    assert path.stat().st_mode & 0o777 == 0o666 & ~umask  # not mkstemp's private 0o600


def test_failed_write_keeps_previous_checkpoint(tmp_path, monkeypatch):
    path = tmp_path / "gen-000001.json.gz"
    save_checkpoint(path, SMALL)
    before = path.read_bytes()

    def broken_replace(src, dst):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", broken_replace)
    with pytest.raises(OSError, match=r"gen-000001\.json\.gz: cannot write.*space"):
        save_checkpoint(path, {"generation": 99})
    monkeypatch.undo()
    assert path.read_bytes() == before
    assert load_checkpoint(path) == SMALL
    assert [p.name for p in tmp_path.iterdir()] == ["gen-000001.json.gz"]


def test_latest_and_prune(tmp_path):
    assert latest_checkpoint(tmp_path) is None
    assert prune_checkpoints(tmp_path) == []
    (tmp_path / "checkpoints").mkdir()
    assert latest_checkpoint(tmp_path) is None
    for gen in (2, 10, 9, 1000000):
        save_checkpoint(checkpoint_path(tmp_path, gen), {"generation": gen})
    ckpt = tmp_path / "checkpoints"
    (ckpt / ".gen-2000000.json.gz.abc123.tmp").write_bytes(b"partial")
    (ckpt / "gen-2000000.json.gz.old").write_bytes(b"x")
    (ckpt / "notes.txt").write_text("x")
    assert [g for g, _ in list_checkpoints(tmp_path)] == [2, 9, 10, 1000000]
    assert latest_checkpoint(tmp_path) == ckpt / "gen-1000000.json.gz"
    assert checkpoint_path(tmp_path, 9).name == "gen-000009.json.gz"
    deleted = prune_checkpoints(tmp_path, keep=2)
    assert sorted(p.name for p in deleted) == [
        ".gen-2000000.json.gz.abc123.tmp",
        "gen-000002.json.gz",
        "gen-000009.json.gz",
    ]
    assert sorted(p.name for p in ckpt.iterdir()) == [
        "gen-000010.json.gz",
        "gen-1000000.json.gz",
        "gen-2000000.json.gz.old",
        "notes.txt",
    ]
    assert load_checkpoint(latest_checkpoint(tmp_path)) == {"generation": 1000000}
    with pytest.raises(ValueError):
        prune_checkpoints(tmp_path, keep=0)
