"""Directory locks, the stored run configuration, roll back and checkpoint file names."""

from __future__ import annotations

import os
import socket

import pytest

from mtpg.config import ConfigError, build_config, to_toml
from mtpg.io.checkpoint import checkpoint_generation
from mtpg.io.lock import LOCK_FILE, LockedError, holder, lock_dir
from mtpg.io.runconfig import read_run_config
from mtpg.io.rundir import RunDirError, init_run_dir, roll_back


def test_a_lock_is_exclusive_names_its_holder_and_is_released(tmp_path) -> None:
    lock = lock_dir(tmp_path, "the run directory")
    assert (tmp_path / LOCK_FILE).read_text() == ""  # taking it writes nothing
    assert holder(tmp_path) == ""
    lock.claim()
    me = f"process {os.getpid()} on {socket.gethostname()}"
    assert (tmp_path / LOCK_FILE).read_text() == f"{os.getpid()} {socket.gethostname()}\n"
    assert holder(tmp_path) == me
    with pytest.raises(LockedError) as err:
        lock_dir(tmp_path, "the run directory")
    assert str(err.value) == (
        f"{tmp_path}: the run directory is in use by {me} (a train, --resume or "
        "experiment); wait for it to finish or stop it first"
    )
    lock.release()
    lock.release()  # twice is harmless
    lock.claim()  # after release: does nothing
    with lock_dir(tmp_path) as again:  # free again; the default name
        assert isinstance(again._fd, int)
        with pytest.raises(LockedError, match=r": mtpg is in use by process \d+ on "):
            lock_dir(tmp_path)
    assert again._fd is None


def test_holder_of_an_unreadable_or_odd_lock_file(tmp_path) -> None:
    assert holder(tmp_path / "missing") == ""
    (tmp_path / LOCK_FILE).write_text("x y\n")
    assert holder(tmp_path) == ""  # not a process id
    (tmp_path / LOCK_FILE).write_text("12\n")
    assert holder(tmp_path) == ""  # no host
    (tmp_path / LOCK_FILE).write_text("12 host extra\n")
    assert holder(tmp_path) == "process 12 on host"
    with lock_dir(tmp_path):
        with pytest.raises(LockedError, match=r"is in use by process 12 on host \("):
            lock_dir(tmp_path)


def test_lock_of_a_missing_directory_is_an_os_error(tmp_path) -> None:
    with pytest.raises(FileNotFoundError):
        lock_dir(tmp_path / "missing")


def test_read_run_config_names_the_file_and_the_problem(tmp_path) -> None:
    cfg = build_config("demo", overrides=["seed=7"])
    run = init_run_dir(tmp_path / "run", to_toml(cfg))
    assert read_run_config(run.path) == cfg
    path = run.config
    path.write_bytes(b"seed = 1\n\xff\n")
    with pytest.raises(ConfigError) as err:
        read_run_config(run.path)
    assert str(err.value) == f"{path}: cannot read: not UTF-8 text"
    path.write_text("seed = -1\n")
    with pytest.raises(ConfigError) as err:
        read_run_config(run.path)
    assert str(err.value) == f"{path}: seed must be >= 0, got -1"
    path.write_text("[team\n")
    with pytest.raises(ConfigError, match=rf"^{path}: Expected ']'"):
        read_run_config(run.path)
    path.write_text("v = " + "[" * 5000 + "]" * 5000 + "\n")
    with pytest.raises(ConfigError) as err:
        read_run_config(run.path)
    assert str(err.value) == f"{path}: not valid TOML: nested too deeply"
    path.unlink()  # the directory then says why it holds no run
    with pytest.raises(RunDirError, match="creation was interrupted before config.toml"):
        read_run_config(run.path)
    path.mkdir()
    with pytest.raises(ConfigError) as err:
        read_run_config(run.path)
    assert str(err.value) == f"{path}: cannot read: Is a directory"


def test_read_run_config_of_a_directory_without_a_run_says_so(tmp_path) -> None:
    # reading a run (report, evaluate) is not resuming it: the message says what is missing
    with pytest.raises(RunDirError) as err:
        read_run_config(tmp_path)
    assert str(err.value) == f"{tmp_path}: not an mtpg run directory (no config.toml)"
    with pytest.raises(RunDirError, match="no such run directory"):
        read_run_config(tmp_path / "missing")
    with pytest.raises(RunDirError, match="holds no mtpg run to resume"):
        read_run_config(tmp_path, resuming=True)


def test_roll_back_removes_later_test_folders_and_temporary_files(tmp_path) -> None:
    run = init_run_dir(tmp_path / "run", "seed = 1\n")
    tests = run.path / "tests"
    for name in ("gen-000001", "gen-000002", "gen-000003", "gen-x", "other"):
        (tests / name).mkdir(parents=True)
    temps = [
        run.path / ".metrics.csv.abc.tmp",
        run.checkpoints / ".gen-000002.json.gz.x.tmp",
        run.champions / ".CartPole.json.y.tmp",
        tests / "gen-000001" / ".CartPole.json.z.tmp",
    ]
    for temp in temps:
        temp.write_text("")
    keep = [run.path / "notes.tmp", run.champions / "CartPole.json", tests / "gen-x" / ".a.tmp"]
    for path in keep:
        path.write_text("")
    (run.checkpoints / ".dir.tmp").mkdir()  # a directory, not a temporary file
    removed = roll_back(run.path, 1)
    assert sorted(removed) == sorted([tests / "gen-000002", tests / "gen-000003", *temps])
    assert sorted(p.name for p in tests.iterdir()) == ["gen-000001", "gen-x", "other"]
    assert all(p.exists() for p in keep) and (run.checkpoints / ".dir.tmp").is_dir()
    assert roll_back(run.path, 1) == []
    assert roll_back(tmp_path / "empty", 0) == []  # nothing there: nothing to do


def test_checkpoint_generation_reads_only_checkpoint_names() -> None:
    assert checkpoint_generation("run/checkpoints/gen-000012.json.gz") == 12
    assert checkpoint_generation("gen-1234567.json.gz") == 1234567
    for name in (
        "gen-12.json.gz",
        "gen-000012.json",
        "xgen-000012.json.gz",
        "gen-000012.json.gz.tmp",
    ):
        assert checkpoint_generation(name) is None


def test_lock_file_mode_unnamed_holder_and_undecodable_text(tmp_path) -> None:
    umask = os.umask(0)
    os.umask(umask)
    with lock_dir(tmp_path):  # taken, not claimed: the holder is not known
        assert (tmp_path / LOCK_FILE).stat().st_mode & 0o777 == 0o644 & ~umask
        with pytest.raises(LockedError) as err:
            lock_dir(tmp_path, "the run directory")
    assert str(err.value).startswith(
        f"{tmp_path}: the run directory is in use by another process ("
    )
    (tmp_path / LOCK_FILE).write_bytes(b"\xff\xfe 12 host\n")
    assert holder(tmp_path) == ""  # undecodable bytes are replaced, never an error
    (tmp_path / LOCK_FILE).write_bytes(b"12 h\xffst\n")
    assert holder(tmp_path) == "process 12 on h\ufffdst"
