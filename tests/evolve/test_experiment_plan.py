"""Experiment planning and process handling, without training (fast stand-in commands)."""

from __future__ import annotations

import sys

from mtpg.evolve import experiment
from mtpg.evolve.experiment import LABELS, PlannedRun, execute, plan
from mtpg.io.checkpoint import checkpoint_path


def test_plan_lists_seeds_then_each_ablation(tmp_path) -> None:
    runs = plan(tmp_path, seeds=2, ablation_seeds=1)
    assert [r.path.name for r in runs] == [
        "TPG-seed0",
        "TPG-seed1",
        "TPG-NoXover-seed0",
        "TPG-NoMemory-seed0",
        "TPG-NoHierarchy-seed0",
    ]
    assert [r.seed for r in runs] == [0, 1, 0, 0, 0]
    assert [r.ablation for r in runs] == [None, None, "no-crossover", "no-memory", "no-hierarchy"]
    assert all(r.path.parent == tmp_path for r in runs)
    assert len(plan(tmp_path, 3, 2)) == 3 + 3 * 2
    assert LABELS[None] == "TPG"


def make_run_dir(path, generations: list[int]) -> None:
    (path / "checkpoints").mkdir(parents=True)
    (path / "config.toml").write_text("")
    for g in generations:
        checkpoint_path(path, g).write_bytes(b"")


def test_state_and_command_of_new_partial_and_done_runs(tmp_path) -> None:
    run = PlannedRun(tmp_path / "TPG-NoMemory-seed3", 3, "no-memory")
    assert run.state(5) == "new"
    cmd = run.command(["--tasks", "CartPole"], 5, 2)
    assert cmd[:8] == [
        sys.executable,
        "-m",
        "mtpg",
        "train",
        "--quiet",
        "--workers",
        "2",
        "--tasks",
    ]
    assert cmd[8:] == [
        "CartPole",
        "--no-memory",
        "--generations",
        "5",
        "--seed",
        "3",
        "--out",
        str(run.path),
    ]
    plain = PlannedRun(tmp_path / "TPG-seed0", 0, None).command([], 7, 1)
    assert "--no-memory" not in plain and plain[-6:-4] == ["--generations", "7"]
    make_run_dir(run.path, [2, 4])
    assert run.state(5) == "partial"
    assert run.state(4) == "done" and run.state(3) == "done"
    assert run.command(["--tasks", "CartPole"], 9, 1)[7:] == [
        "--resume",
        str(run.path),
        "--generations",
        "9",
    ]
    empty = PlannedRun(tmp_path / "e", 0, None)
    make_run_dir(empty.path, [])
    assert empty.state(1) == "partial"


def test_execute_skips_done_runs_runs_the_rest_and_reports_failures(tmp_path, monkeypatch):
    runs = plan(tmp_path / "exp", seeds=3, ablation_seeds=0)
    make_run_dir(runs[0].path, [4])  # already done
    exit_codes = {runs[1].path.name: 0, runs[2].path.name: 3}

    def command(self, train_args, generations, workers):
        code = exit_codes[self.path.name]
        return [sys.executable, "-c", f"print('{self.path.name}'); raise SystemExit({code})"]

    monkeypatch.setattr(experiment.PlannedRun, "command", command)
    lines: list[str] = []
    failed = execute(runs, [], generations=4, parallel=2, log=lines.append)
    assert failed == [runs[2]]
    assert "TPG-seed0: done" in lines
    assert "TPG-seed1: new -> starting" in lines and "TPG-seed1: finished" in lines
    assert "TPG-seed2: failed (3)" in lines
    assert (tmp_path / "exp" / "TPG-seed1.log").read_text() == "TPG-seed1\n"
    assert not (tmp_path / "exp" / "TPG-seed0.log").exists()
