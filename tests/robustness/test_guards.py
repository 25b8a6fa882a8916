"""A run directory belongs to one run and one process; input is bounded before use."""

import gzip
import json
import os
import shutil
import sys
import time

import pytest

from mtpg.cli.main import main
from mtpg.io.lock import LockedError, lock_dir
from stopruns import ARGS, mtpg, start
from tinyruns import tiny_args


def snapshot(path):
    return {p: p.read_bytes() for p in sorted(path.rglob("*")) if p.is_file()}


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory):
    base = tmp_path_factory.mktemp("runs")
    a, b = base / "a", base / "b"
    assert main(["train", *ARGS, "--generations", "3", "--out", str(a)]) == 0
    assert main(["train", *ARGS, "--generations", "3", "--seed", "5", "--out", str(b)]) == 0
    return a, b


def test_foreign_checkpoint_is_refused_and_nothing_changes(two_runs, tmp_path, capsys):
    a, b = (shutil.copytree(r, tmp_path / r.name) for r in two_runs)
    name = "checkpoints/gen-000003.json.gz"
    (a / name).write_bytes((b / name).read_bytes())  # another seed's checkpoint
    before = snapshot(a)
    assert main(["train", "--resume", str(a), "--generations", "5", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "gen-000003.json.gz: belongs to another run" in err and "seed" in err
    assert len(err.strip().splitlines()) == 1
    assert snapshot(a) == before


def test_renamed_checkpoint_is_refused(two_runs, tmp_path, capsys):
    a = shutil.copytree(two_runs[0], tmp_path / "a")
    (a / "checkpoints" / "gen-000003.json.gz").rename(a / "checkpoints" / "gen-000009.json.gz")
    before = snapshot(a)
    assert main(["train", "--resume", str(a), "--generations", "12", "--quiet"]) == 2
    assert "holds generation 3 but its name says 9" in capsys.readouterr().err
    assert snapshot(a) == before


def test_locked_run_is_refused_and_unchanged(two_runs, tmp_path, capsys):
    run = shutil.copytree(two_runs[0], tmp_path / "a")
    with lock_dir(run):  # as another process would hold it
        before = snapshot(run)
        assert main(["train", "--resume", str(run), "--generations", "5", "--quiet"]) == 1
        assert snapshot(run) == before
    assert "the run directory is in use by" in capsys.readouterr().err


@pytest.mark.slow
def test_second_process_on_a_locked_run_is_refused_at_once(tmp_path):
    run = tmp_path / "run"
    long_run = [*tiny_args(), "--generations", "100000", "--set", "checkpoint_interval=100000"]
    first = start("train", *long_run, "--out", str(run))
    try:
        deadline = time.monotonic() + 120
        while time.monotonic() < deadline and not (run / "metrics.csv").is_file():
            time.sleep(0.05)
        assert first.poll() is None
        for args in (["--resume", str(run)], ["--out", str(run), *tiny_args()]):
            t0 = time.monotonic()
            res = mtpg("train", *args)
            assert res.returncode == 1
            assert f"in use by process {first.pid}" in res.stderr
            assert len(res.stderr.strip().splitlines()) == 1
            assert time.monotonic() - t0 < 60  # refused without waiting for the lock
    finally:
        first.terminate()
        first.communicate(timeout=300)
    assert first.returncode == 143
    assert mtpg("train", "--resume", str(run), "--generations", "2").returncode == 0


def test_experiment_folder_is_locked(tmp_path, capsys):
    folder = tmp_path / "exp"
    folder.mkdir()
    with lock_dir(folder) as held:
        held.claim()
        exp = ["experiment", "--out", str(folder), *tiny_args(quiet=False), "--generations", "1"]
        assert main(exp) == 1
    err = capsys.readouterr().err
    assert "the experiment folder is in use by process" in err
    assert sorted(p.name for p in folder.iterdir()) == [".lock"]


def test_lock_is_exclusive_and_released(tmp_path):
    with lock_dir(tmp_path) as held:
        held.claim()
        with pytest.raises(LockedError, match=f"process {os.getpid()}"):
            lock_dir(tmp_path)
    lock_dir(tmp_path).release()


def test_interrupted_creation_is_recovered(tmp_path, capsys):
    run = tmp_path / "run"
    res = mtpg("train", *ARGS, "--out", str(run), env={"MTPG_TEST_STOP_AT": "create:0:KILL"})
    assert res.returncode == -9
    assert not (run / "config.toml").exists()
    before = snapshot(run)
    assert main(["train", "--resume", str(run)]) == 2
    err = capsys.readouterr().err
    assert "creation was interrupted" in err and "--out" in err
    assert snapshot(run) == before
    assert main(["train", *ARGS, "--generations", "1", "--out", str(run)]) == 0
    assert (run / "checkpoints" / "gen-000001.json.gz").is_file()


def test_decompression_bomb_is_refused_with_bounded_memory(two_runs, tmp_path):
    a = shutil.copytree(two_runs[0], tmp_path / "a")
    bomb = a / "checkpoints" / "gen-000004.json.gz"
    member = gzip.compress(b"\0" * (16 << 20), 9)  # 16 MiB of zeros in ~16 kB
    bomb.write_bytes(member * 96)  # a valid multi-member gzip file inflating to 1.5 GiB
    assert bomb.stat().st_size < 3 * 2**20
    before = snapshot(a)
    probe = (
        "import resource, subprocess, sys;"
        "r = subprocess.run([sys.executable, '-m', 'mtpg', 'train', '--resume', sys.argv[1],"
        " '--quiet'], capture_output=True, text=True);"
        "print(r.returncode, resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss);"
        "print(r.stderr, file=sys.stderr)"
    )
    import subprocess

    res = subprocess.run([sys.executable, "-c", probe, str(a)], capture_output=True, text=True)
    code, peak_kb = map(int, res.stdout.split())
    assert code == 2
    assert "gen-000004.json.gz: checkpoint inflates to more than" in res.stderr
    assert peak_kb < 600 * 1024, f"peak {peak_kb} kB"  # not the 1.5 GB it inflates to
    assert snapshot(a) == before


def test_too_large_configuration_is_refused_before_the_directory_exists(tmp_path, capsys):
    run = tmp_path / "run"
    big = [
        "--set",
        "team.root_size=1000000",
        "--set",
        "team.init_team_size=100000",
        "--set",
        "team.max_team_size=100000",
    ]
    assert main(["train", *tiny_args(), *big, "--out", str(run)]) == 2
    err = capsys.readouterr().err
    assert "needs an estimated" in err and "memory" in err and "available" in err
    assert not run.exists()
    assert main(["train", *tiny_args(), "--set", "team.root_size=10**9", "--out", str(run)]) == 2
    assert not run.exists()


def _graph(two_runs):
    return json.loads((two_runs[0] / "champions" / "CartPole.json").read_text())


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda g: g["layout"].update(n_obs=10**6), "layout.n_obs must be <= 65536"),
        (lambda g: g["layout"].update(n_registers=10**6), "layout.n_registers must be <= 256"),
        (lambda g: g["teams"][0].update(id=2**63), "must fit a 64-bit integer"),
        (lambda g: g.update(root=2**64), "must fit a 64-bit integer"),
        (lambda g: g["programs"][0].update(bank=-1), "bank must be >= 0"),
    ],
)
def test_graph_with_wrong_layout_or_ids_is_refused(two_runs, tmp_path, capsys, change, message):
    g = _graph(two_runs)
    change(g)
    path = tmp_path / "g.json"
    path.write_text(json.dumps(g))
    assert main(["evaluate", str(path), "--episodes", "2"]) == 2
    err = capsys.readouterr().err
    assert message in err and "g.json" in err
    assert len(err.strip().splitlines()) == 1


def test_deep_json_and_huge_graph_files_are_refused(tmp_path, capsys, monkeypatch):
    deep = tmp_path / "deep.json"
    deep.write_text("[" * 100000 + "]" * 100000)
    assert main(["evaluate", str(deep)]) == 2
    assert "nested too deeply" in capsys.readouterr().err
    monkeypatch.setenv("MTPG_MAX_GRAPH_BYTES", "1000")
    big = tmp_path / "big.json"
    big.write_text(" " * 5000 + "{}")
    assert main(["evaluate", str(big)]) == 2
    assert "more than the" in capsys.readouterr().err
    gz = tmp_path / "c.json.gz"
    gz.write_bytes(gzip.compress(b"[" * 100000 + b"]" * 100000))
    from mtpg.io import CheckpointError, load_checkpoint

    with pytest.raises(CheckpointError, match="c.json.gz"):
        load_checkpoint(gz)
