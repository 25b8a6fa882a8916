"""The run directory's schema version: written, read, and refused in one line when unknown.

The frozen fixture is the paper-pin run directory (``tests/data/paper-pin/run-gen3``),
written before ``format.json`` existed, like the committed runs of ``results/``.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from mtpg.cli.main import main
from mtpg.io.runconfig import read_run_config
from mtpg.io.rundir import check_new_run_dir, init_run_dir
from mtpg.io.runschema import (
    READABLE_VERSIONS,
    RUN_FORMAT,
    RUN_SCHEMA_VERSION,
    SCHEMA_FILE,
    UNVERSIONED,
    RunSchemaError,
    check_schema,
    read_schema,
)

FROZEN = Path(__file__).resolve().parents[1] / "data" / "paper-pin" / "run-gen3"


def _old_run(tmp_path: Path) -> Path:
    """A copy of the frozen run directory, as a run written before ``format.json``."""
    run = tmp_path / "old"
    shutil.copytree(FROZEN, run)
    (run / SCHEMA_FILE).unlink(missing_ok=True)  # should the pin be regenerated one day
    return run


def _snapshot(root: Path) -> dict[str, bytes]:
    return {str(p.relative_to(root)): p.read_bytes() for p in root.rglob("*") if p.is_file()}


def _write_version(run: Path, version: object) -> None:
    (run / SCHEMA_FILE).write_text(json.dumps({"format": RUN_FORMAT, "version": version}))


def test_a_new_run_records_the_current_version(tmp_path: Path) -> None:
    run = init_run_dir(tmp_path / "run", "seed = 1\n")
    doc = json.loads((run.path / SCHEMA_FILE).read_text())
    assert doc == {"format": RUN_FORMAT, "version": RUN_SCHEMA_VERSION}
    assert read_schema(run.path) == RUN_SCHEMA_VERSION == check_schema(run.path)


def test_leftover_schema_file_of_an_interrupted_creation_is_cleared(tmp_path: Path) -> None:
    run = tmp_path / "run"
    run.mkdir()
    (run / SCHEMA_FILE).write_text("{}")  # creation stopped before config.toml
    assert check_new_run_dir(run) is True  # a run's own name, not a foreign file
    init_run_dir(run, "seed = 1\n")
    assert read_schema(run) == RUN_SCHEMA_VERSION


def test_the_frozen_unversioned_run_is_read_as_version_1_and_stamped_on_resume(
    tmp_path: Path,
) -> None:
    run = _old_run(tmp_path)
    before = _snapshot(run)
    assert UNVERSIONED == 1 and UNVERSIONED in READABLE_VERSIONS
    assert read_schema(run) == 1
    config = read_run_config(run)  # readers take it as it is, writing nothing
    assert config.seed == 1 and _snapshot(run) == before
    init_run_dir(run, None, resume=True)
    after = _snapshot(run)
    assert json.loads(after.pop(SCHEMA_FILE)) == {"format": RUN_FORMAT, "version": 1}
    assert after == before  # nothing else of the run changed


@pytest.mark.parametrize(
    ("version", "why"),
    [
        (RUN_SCHEMA_VERSION + 1, "written by a newer mtpg; upgrade mtpg to read it"),
        (0, "an older layout this mtpg no longer reads"),
    ],
)
def test_an_unknown_version_is_refused_in_one_line_naming_both(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], version: int, why: str
) -> None:
    run = _old_run(tmp_path)
    _write_version(run, version)
    before = _snapshot(run)
    assert main(["train", "--resume", str(run), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert f"run-directory schema version {version} ({SCHEMA_FILE})" in err
    assert f"this mtpg reads version {RUN_SCHEMA_VERSION}: {why}" in err
    assert err.startswith(f"mtpg train: error: {run}: ")
    assert _snapshot(run) == before  # refused before anything was written
    with pytest.raises(RunSchemaError, match=f"schema version {version} "):
        read_run_config(run)  # every reader of a run, not only resume
    with pytest.raises(RunSchemaError, match=f"schema version {version} "):
        init_run_dir(run, None, resume=True)
    assert _snapshot(run) == before


def test_a_newer_run_is_refused_by_commands_that_read_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    run = _old_run(tmp_path)
    _write_version(run, 7)
    assert main(["show", str(run)]) == 2
    err = capsys.readouterr().err
    assert "schema version 7" in err and err.count("\n") == 1


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("not json", "not a run-directory schema file"),
        ('{"format": "mtpg-graph", "version": 1}', "no format 'mtpg-run'"),
        ('{"format": "mtpg-run", "version": true}', "must be an integer, got True"),
        ('{"format": "mtpg-run", "version": "1"}', "must be an integer, got '1'"),
        ('{"format": "mtpg-run"}', "must be an integer, got None"),
        ("[" * 4000, "not a run-directory schema file"),  # nested too deeply to parse
        (" " * 5000, "larger than 4096 bytes"),
    ],
)
def test_a_damaged_schema_file_is_named(tmp_path: Path, text: str, message: str) -> None:
    run = _old_run(tmp_path)
    (run / SCHEMA_FILE).write_text(text)
    with pytest.raises(RunSchemaError, match=message) as caught:
        check_schema(run)
    assert str(run / SCHEMA_FILE) in str(caught.value)
    assert "\n" not in str(caught.value)
