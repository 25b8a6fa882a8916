"""End-to-end runs of ``mtpg train`` on tiny budgets."""

import csv
import gzip
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from mtpg.cli.main import main
from mtpg.evolve.columns import TIMING_COLUMNS
from tinyruns import tiny_args

TINY = tiny_args("CartPole,MountainCar", root_size=20, n_elite=3)


def metrics(run_dir, name="metrics.csv"):
    with open(Path(run_dir) / name) as fh:
        return [{k: v for k, v in r.items() if k not in TIMING_COLUMNS} for r in csv.DictReader(fh)]


def snapshot(path):
    return {p: p.read_bytes() for p in sorted(Path(path).rglob("*")) if p.is_file()}


def test_train_writes_run_directory(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["train", *TINY, "--generations", "3", "--out", str(out)]) == 0
    assert (out / "config.toml").is_file()
    assert len(metrics(out)) == 3
    assert (out / "checkpoints" / "gen-000003.json.gz").is_file()
    names = sorted(p.name for p in (out / "champions").glob("*.json"))
    assert names == ["CartPole+MountainCar.json", "CartPole.json", "MountainCar.json"]
    # a champion file loads and runs
    from mtpg.engine.batch import Episodes, evaluate_roots
    from mtpg.engine.compile import compile_population
    from mtpg.io.serialize import load_graph

    pop, root, meta = load_graph(out / "champions" / "CartPole.json")
    returns, _ = evaluate_roots(compile_population(pop), [root], Episodes.grid([0], [0, 1]))
    assert returns.mean() == pytest.approx(meta["train_scores"]["CartPole"])


@pytest.mark.parametrize(
    ("override", "message"),
    [
        ("team.foo=1", "unknown field 'team.foo'"),
        ('team.n_elite="many"', "team.n_elite must be int"),
        ("team.root_size=-5", "team.root_size must be >= 1"),
        ("program.p_swap=1.5", "program.p_swap must be in [0, 1]"),
    ],
)
def test_bad_config_is_refused_and_writes_nothing(tmp_path, capsys, override, message):
    out = tmp_path / "run"
    assert main(["train", *TINY, "--set", override, "--out", str(out)]) == 2
    assert message in capsys.readouterr().err
    assert not out.exists()


def test_bad_config_file_names_file_and_field(tmp_path, capsys):
    cfg = tmp_path / "bad.toml"
    cfg.write_text("[team]\nn_elite = 2.5\n")
    assert main(["train", *TINY, "--config", str(cfg), "--out", str(tmp_path / "r")]) == 2
    err = capsys.readouterr().err
    assert "bad.toml" in err and "team.n_elite must be int" in err


def test_existing_run_is_not_overwritten(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["train", *TINY, "--generations", "1", "--out", str(out)]) == 0
    before = snapshot(out)
    assert main(["train", *TINY, "--generations", "1", "--out", str(out)]) == 2
    assert "already holds an mtpg run" in capsys.readouterr().err
    assert snapshot(out) == before


@pytest.mark.parametrize("damage", ["truncate", "bitflip", "foreign", "version"])
def test_corrupt_checkpoint_is_refused_on_resume(tmp_path, capsys, damage):
    out = tmp_path / "run"
    assert main(["train", *TINY, "--generations", "2", "--out", str(out)]) == 0
    ckpt = out / "checkpoints" / "gen-000002.json.gz"
    data = ckpt.read_bytes()
    if damage == "truncate":
        ckpt.write_bytes(data[: len(data) // 2])
    elif damage == "bitflip":
        raw = bytearray(gzip.decompress(data))
        raw[len(raw) // 2] ^= 0x04
        ckpt.write_bytes(gzip.compress(bytes(raw)))
    elif damage == "foreign":
        ckpt.write_bytes(gzip.compress(b'{"hello": "world"}'))
    else:
        raw = gzip.decompress(data).replace(b'"version":1', b'"version":99')
        ckpt.write_bytes(gzip.compress(raw))
    before = snapshot(out)
    assert main(["train", "--resume", str(out), "--generations", "4", "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "gen-000002.json.gz" in err
    assert snapshot(out) == before


def test_sigkill_mid_run_then_resume_reproduces_the_uninterrupted_run(tmp_path):
    gens = "30"
    ref = tmp_path / "ref"
    assert main(["train", *TINY, "--generations", gens, "--out", str(ref)]) == 0
    run = tmp_path / "killed"
    cmd = [
        sys.executable,
        "-m",
        "mtpg",
        "train",
        *TINY,
        "--generations",
        gens,
        "--set",
        "checkpoint_interval=2",
        "--out",
        str(run),
    ]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 120
    while time.time() < deadline and proc.poll() is None:
        if list((run / "checkpoints").glob("gen-00000[4-9].json.gz")):
            break
        time.sleep(0.02)
    killed = proc.poll() is None
    if killed:
        os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    assert killed, "the run finished before it could be killed"
    done_before = len(metrics(run))
    assert done_before < int(gens)
    env = dict(os.environ)
    res = subprocess.run(
        [sys.executable, "-m", "mtpg", "train", "--resume", str(run), "--quiet"],
        env=env,
        capture_output=True,
        text=True,
    )
    assert res.returncode == 0, res.stderr
    assert metrics(run) == metrics(ref)
    assert metrics(run, "tests.csv") == metrics(ref, "tests.csv")
    for f in (ref / "champions").glob("*.json"):
        assert (run / "champions" / f.name).read_bytes() == f.read_bytes()


def test_test_points_follow_the_interval(tmp_path):
    out = tmp_path / "run"
    args = ["--set", "evaluation.test_interval=2", "--set", "evaluation.test_episodes=4"]
    assert main(["train", *TINY, *args, "--generations", "5", "--out", str(out)]) == 0
    rows = metrics(out, "tests.csv")
    assert sorted({int(r["generation"]) for r in rows}) == [2, 4, 5]  # and the last generation
    assert {r["subset"] for r in rows} == {"CartPole", "MountainCar", "CartPole+MountainCar"}
    for gen in ("gen-000002", "gen-000004"):
        names = sorted(p.name for p in (out / "tests" / gen).glob("*.json"))
        assert names == ["CartPole+MountainCar.json", "CartPole.json", "MountainCar.json"]
    # the stored test score is the champion's mean over the held-out episodes
    from mtpg.evolve.heldout_test import evaluate_graph
    from mtpg.io.serialize import load_graph

    pop, root, meta = load_graph(out / "tests" / "gen-000004" / "CartPole.json")
    score = evaluate_graph(pop, root, ["CartPole"], episodes=4)["CartPole"].mean
    assert score == meta["test"]["CartPole"]
    row = next(r for r in rows if r["generation"] == "4" and r["subset"] == "CartPole")
    assert float(row["test_CartPole"]) == score


def test_a_lost_backend_commits_the_generation_and_resume_finishes_the_run(
    tmp_path, capsys, monkeypatch
):
    """A backend lost during generation 2 stops ``mtpg train`` right after it, committed."""
    import mtpg.evolve.session as session_module
    from standins import losing_backend

    reference = tmp_path / "reference"
    assert main(["train", *TINY, "--generations", "4", "--out", str(reference)]) == 0
    # lost while generation 2 was evaluated
    lost = losing_backend(2, "lost the dask cluster at tcp://127.0.0.1:1 (gone)")
    monkeypatch.setattr(session_module, "make_evaluator", lambda cfg, wait=None: lost(1))
    out = tmp_path / "run"
    capsys.readouterr()
    assert main(["train", *TINY, "--generations", "4", "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert "lost the evaluation backend (lost the dask cluster at tcp://127.0.0.1:1" in err
    assert f"after generation 2 (committed); resume with: mtpg train --resume {out}" in err
    assert "Traceback" not in err
    assert (out / "checkpoints" / "gen-000002.json.gz").is_file()
    assert len(metrics(out)) == 2
    monkeypatch.undo()
    assert main(["train", "--resume", str(out), "--quiet"]) == 0
    assert metrics(out) == metrics(reference)
    champions = {p.name: p.read_bytes() for p in (out / "champions").iterdir()}
    assert champions == {p.name: p.read_bytes() for p in (reference / "champions").iterdir()}
