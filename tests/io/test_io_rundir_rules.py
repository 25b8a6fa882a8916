"""Run-directory rules, readable JSON and the metrics writer on hand-made cases."""

from __future__ import annotations

import json
import os

import pytest

from mtpg.io import _readable
from mtpg.io import rundir as rundir_module
from mtpg.io._atomic import is_temp_file
from mtpg.io._readable import dumps_readable
from mtpg.io.lock import LOCK_FILE
from mtpg.io.rundir import (
    MetricsWriter,
    RunDirError,
    check_new_run_dir,
    check_resumable,
    init_run_dir,
)


def test_readable_json_layout_is_exact() -> None:
    value = {
        "a": [1, 2.5, None, True],
        "b": {"atomic": 0},
        "c": [{"x": 1}, []],
        "d": {},
        "e": ["s", "t"],
        "f": {"long": "y" * 80},
    }
    text = dumps_readable(value)
    assert text == (
        "{\n"
        '  "a": [1, 2.5, null, true],\n'
        '  "b": {"atomic": 0},\n'
        '  "c": [\n'
        '    {"x": 1},\n'
        "    []\n"
        "  ],\n"
        '  "d": {},\n'
        '  "e": [\n'
        '    "s",\n'
        '    "t"\n'
        "  ],\n"
        '  "f": {\n'
        f'    "long": "{"y" * 80}"\n'
        "  }\n"
        "}\n"
    )
    assert json.loads(text) == value
    assert dumps_readable([[1, 2], [3]], indent=3) == "[\n   [1, 2],\n   [3]\n]\n"
    assert dumps_readable(7) == "7\n" and dumps_readable(None) == "null\n"


def test_readable_json_inline_width_is_inclusive() -> None:
    width = _readable.INLINE_WIDTH
    key_room = width - len('{"k": ""}')
    exact = {"k": "v" * key_room}
    assert dumps_readable(exact) == json.dumps(exact) + "\n"  # exactly the width: inline
    longer = {"k": "v" * (key_room + 1)}
    assert dumps_readable(longer).startswith("{\n  ")


def test_readable_json_refuses_what_json_cannot_hold() -> None:
    with pytest.raises(TypeError) as err:
        dumps_readable({1: 2})
    assert str(err.value) == "JSON object keys must be strings, got 1"
    with pytest.raises(TypeError) as err:
        dumps_readable({"s": {1, 2}})
    assert str(err.value) == "set is not JSON-serializable: {1, 2}"
    with pytest.raises(ValueError):
        dumps_readable([float("nan")])


def test_temporary_file_names() -> None:
    assert is_temp_file(".metrics.csv.abc.tmp")
    assert not is_temp_file("metrics.tmp") and not is_temp_file(".hidden")


def test_a_new_run_refuses_a_foreign_directory_naming_five_entries(tmp_path) -> None:
    for k in range(7):
        (tmp_path / f"f{k}").write_text("")
    with pytest.raises(RunDirError) as err:
        check_new_run_dir(tmp_path)
    assert str(err.value) == (
        f"{tmp_path}: directory is not empty and is not an mtpg run directory "
        "(contains f0, f1, f2, f3, f4, ...); choose a new or empty directory"
    )
    (tmp_path / "f6").unlink()
    with pytest.raises(RunDirError, match=r"\(contains f0, f1, f2, f3, f4, \.\.\.\); choose"):
        check_new_run_dir(tmp_path)  # six: five shown
    (tmp_path / "f5").unlink()
    with pytest.raises(RunDirError, match=r"\(contains f0, f1, f2, f3, f4\); choose"):
        check_new_run_dir(tmp_path)


def test_leftovers_of_a_run_that_committed_nothing_are_cleared_but_the_lock(tmp_path) -> None:
    run = tmp_path / "run"
    init_run_dir(run, "seed = 1\n")
    (run / "metrics.csv").write_text("generation\n1\n")
    (run / LOCK_FILE).write_text("12 host\n")
    (run / ".config.toml.x.tmp").write_text("")
    assert check_new_run_dir(run) is True
    init_run_dir(run, "seed = 2\n")
    assert sorted(p.name for p in run.iterdir()) == [
        LOCK_FILE,
        "champions",
        "checkpoints",
        "config.toml",
        "format.json",
    ]
    assert (run / "config.toml").read_text() == "seed = 2\n"
    assert (run / LOCK_FILE).read_text() == "12 host\n"


def test_creation_rules_and_their_messages(tmp_path, monkeypatch) -> None:
    with pytest.raises(RunDirError) as err:
        init_run_dir(tmp_path / "new", None)
    assert str(err.value) == f"{tmp_path / 'new'}: a new run needs its configuration"
    afile = tmp_path / "afile"
    afile.write_text("")
    with pytest.raises(RunDirError) as err:
        check_resumable(afile)
    assert str(err.value) == f"{afile}: exists and is not a directory"
    half = tmp_path / "half"
    half.mkdir()
    (half / "checkpoints").mkdir()
    with pytest.raises(RunDirError) as err:
        check_resumable(half)
    assert str(err.value) == (
        f"{half}: holds no mtpg run to resume (its creation was interrupted before "
        f"config.toml was written); start it again with mtpg train --out {half}"
    )
    (half / "notes.txt").write_text("")
    with pytest.raises(RunDirError) as err:
        check_resumable(half)
    assert str(err.value) == f"{half}: holds no mtpg run to resume"
    # the stop points of creation, in order (the robustness tests stop runs there)
    seen = []
    monkeypatch.setattr(rundir_module, "point", lambda phase, gen: seen.append((phase, gen)))
    run = init_run_dir(tmp_path / "run", "seed = 1\n")
    assert seen == [("create", 0), ("created", 0)]
    init_run_dir(run.path, None, resume=True)
    assert seen == [("create", 0), ("created", 0)]  # resuming creates nothing


def test_metrics_header_must_be_non_empty_without_repeats(tmp_path) -> None:
    for header in ((), ("a", "b", "a")):
        with pytest.raises(ValueError) as err:
            MetricsWriter(tmp_path / "m.csv", header)
        assert str(err.value) == f"header must be non-empty without repeats, got {header}"
    writer = MetricsWriter(tmp_path / "m.csv", ("generation", "x"))
    writer.append({"generation": 1, "x": "a,b"})
    writer.close()
    raw = (tmp_path / "m.csv").read_bytes()
    assert raw == b'generation,x\n1,"a,b"\n'  # plain newlines, quoted commas


def test_readable_json_nesting_levels() -> None:
    assert dumps_readable({"a": {"b": 1}}) == '{\n  "a": {"b": 1}\n}\n'
    assert dumps_readable({"a": {"b": [{"x": 1}]}}) == (
        '{\n  "a": {\n    "b": [\n      {"x": 1}\n    ]\n  }\n}\n'
    )
    long = {"k": "y" * 80}
    assert dumps_readable([[long]]) == (
        f'[\n  [\n    {{\n      "k": "{"y" * 80}"\n    }}\n  ]\n]\n'
    )


def test_files_in_checkpoints_that_are_not_checkpoints_do_not_count(tmp_path) -> None:
    run = init_run_dir(tmp_path / "run", "seed = 1\n")
    (run.checkpoints / "notes.txt").write_text("")
    (run.checkpoints / ".gen-000001.json.gz.x.tmp").write_text("")
    assert check_new_run_dir(run.path) is True  # nothing committed: leftovers
    (run.checkpoints / "gen-000001.json.gz").write_text("")
    with pytest.raises(RunDirError, match="already holds an mtpg run"):
        check_new_run_dir(run.path)


def test_atomic_writes_go_through_a_temporary_file_beside_the_target(tmp_path, monkeypatch) -> None:
    from mtpg.io.checkpoint import save_checkpoint

    path = tmp_path / "gen-000001.json.gz"
    seen = []
    real = os.replace

    def replace(src, dst):
        seen.append(sorted(p.name for p in tmp_path.iterdir()))
        real(src, dst)

    monkeypatch.setattr(os, "replace", replace)
    save_checkpoint(path, {"a": 1})
    (names,) = seen
    assert len(names) == 1 and is_temp_file(names[0])
    assert names[0].startswith(".gen-000001.json.gz.")
    assert [p.name for p in tmp_path.iterdir()] == ["gen-000001.json.gz"]
