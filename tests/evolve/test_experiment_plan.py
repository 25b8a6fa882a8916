"""Experiment planning and process handling, without training (fast stand-in commands)."""

from __future__ import annotations

import sys

from mtpg.ablations import label_of
from mtpg.evolve import experiment
from mtpg.evolve.experiment import PlannedRun, execute, plan
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
    assert label_of(None) == "TPG"


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
    assert plain[7:] == ["--generations", "7", "--seed", "0", "--out", str(tmp_path / "TPG-seed0")]
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


def stand_in(monkeypatch, exit_codes, seen):
    """Replaces each run's training command by a short process with a chosen exit code."""

    def command(self, train_args, generations, workers):
        seen.append((self.path.name, list(train_args), generations, workers))
        code = exit_codes[self.path.name]
        script = (
            "import sys, time; time.sleep(0.3); print('out'); print('err', file=sys.stderr); "
            f"raise SystemExit({code})"
        )
        return [sys.executable, "-c", script]

    monkeypatch.setattr(experiment.PlannedRun, "command", command)


def test_execute_skips_done_runs_runs_the_rest_and_reports_failures(tmp_path, monkeypatch):
    folder = tmp_path / "deep" / "exp"  # created with its parents
    runs = plan(folder, seeds=3, ablation_seeds=0)
    make_run_dir(runs[0].path, [4])  # already done
    make_run_dir(runs[2].path, [2])  # partial: resumed
    seen: list = []
    stand_in(monkeypatch, {runs[1].path.name: 0, runs[2].path.name: 3}, seen)
    lines: list[str] = []
    failed = execute(runs, ["--tasks", "CartPole"], generations=4, log=lines.append)
    assert failed == [runs[2]]
    # defaults: one process at a time, one worker each
    assert lines == [
        "TPG-seed0: done",
        "TPG-seed1: new -> starting",
        "TPG-seed1: finished",
        "TPG-seed2: partial -> starting",
        "TPG-seed2: failed (3)",
    ]
    assert seen == [
        ("TPG-seed1", ["--tasks", "CartPole"], 4, 1),
        ("TPG-seed2", ["--tasks", "CartPole"], 4, 1),
    ]
    # stdout and stderr of each run go to its log file
    assert (folder / "TPG-seed1.log").read_text() == "out\nerr\n"
    assert not (folder / "TPG-seed0.log").exists()


def test_execute_runs_at_most_parallel_processes(tmp_path, monkeypatch):
    runs = plan(tmp_path / "new" / "exp", seeds=3, ablation_seeds=0)  # folders made as needed
    seen: list = []
    stand_in(monkeypatch, dict.fromkeys((r.path.name for r in runs), 0), seen)
    lines: list[str] = []
    assert execute(runs, [], generations=2, parallel=2, workers=3, log=lines.append) == []
    assert (tmp_path / "new" / "exp" / "TPG-seed2.log").is_file()
    assert lines[:2] == ["TPG-seed0: new -> starting", "TPG-seed1: new -> starting"]
    assert lines.index("TPG-seed2: new -> starting") > 2  # waits for a free slot
    assert {w for *_, w in seen} == {3}
    # more slots than runs
    runs = plan(tmp_path / "exp2", seeds=2, ablation_seeds=0)
    stand_in(monkeypatch, dict.fromkeys((r.path.name for r in runs), 0), seen)
    assert execute(runs, [], generations=2, parallel=3, log=lambda _: None) == []
