"""The pytpg arm of ``mtpg bench tasks`` and the own-task study's two sides.

The fast tests need no pytpg: without it the benchmark says so in one line and keeps its
three arms. The slow ones train on tiny budgets (pytpg's side only where it is installed).
"""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

from mtpg.bench import pytpg_arm, tasks

STUDY = Path(__file__).resolve().parents[2] / "examples" / "own_task" / "study.py"


def _fake_train(task: str, preset: str, generations: int, seed: int, folder: Path) -> dict:
    return {"decisions": 1000.0, "seconds": 1.0, "best": 10.0, "roots": 4, "folder": folder}


def test_bench_tasks_says_in_one_line_that_pytpg_is_absent(monkeypatch):
    monkeypatch.setattr(tasks, "_train", _fake_train)
    monkeypatch.setattr(pytpg_arm, "available", lambda: False)
    lines: list[str] = []
    r = tasks.benchmark(repeats=1, log=lines.append)
    assert lines[-1] == pytpg_arm.absent_line()
    assert "\n" not in lines[-1] and "pip install pytpg" in lines[-1]
    assert r["pytpg_absent"] == lines[-1]
    assert set(r["arms"]) == {label for label, _ in tasks.ARMS}


def test_bench_tasks_without_the_pytpg_arm_prints_nothing_of_it(monkeypatch):
    monkeypatch.setattr(tasks, "_train", _fake_train)
    lines: list[str] = []
    r = tasks.benchmark(repeats=1, log=lines.append, pytpg=False)
    assert r["pytpg_absent"] is None and "pytpg" not in r["arms"]
    assert not any("pytpg" in line for line in lines)


def test_the_arm_reports_decisions_per_second_from_its_own_counts():
    run = pytpg_arm.PytpgRun(steps=500, seconds=0.25)
    assert run.decisions_per_s == 2000.0
    assert pytpg_arm.PytpgRun().decisions_per_s != pytpg_arm.PytpgRun().decisions_per_s  # NaN


def _study(monkeypatch):
    monkeypatch.syspath_prepend(str(STUDY.parent))
    spec = importlib.util.spec_from_file_location("own_task_study", STUDY)
    module = importlib.util.module_from_spec(spec)
    monkeypatch.setitem(sys.modules, "own_task_study", module)
    spec.loader.exec_module(module)
    return module


@pytest.mark.slow
def test_study_mtpg_side_counts_steps_and_scores_held_out_episodes(tmp_path, monkeypatch):
    study = _study(monkeypatch)
    monkeypatch.setenv("PYTHONPATH", f"{Path(tasks.__file__).parents[2]}:{STUDY.parent}")
    monkeypatch.setitem(
        study.ARMS, "tiny", ("cue", "gym:own_envs:CueMemory-v0[delay=1]", 2, 4, 2, [])
    )
    rec = study.mtpg_arm("tiny", 1, tmp_path / "run")
    assert rec["steps"] == rec["curve"][-1][0] > 0
    assert -1.0 <= rec["test_mean"] <= 1.0 and rec["decisions_per_s"] > 0


@pytest.mark.slow
def test_pytpg_trains_to_the_budget_and_replays_its_test_episodes(monkeypatch):
    pytest.importorskip("pytpg")
    study = _study(monkeypatch)
    make = study.pytpg_env("gym:Pendulum-v1")  # continuous: played through 5 torques
    assert make().action_space.n == study.PYTPG_TORQUES
    run = pytpg_arm.train(make, 1000, 1, 4, seed=3)
    steps = [s for s, _ in run.curve]
    assert steps == sorted(steps) and run.steps == steps[-1] >= 1000
    assert run.steps - steps[-2] == 4 * 200  # one generation: 4 graphs, one 200-step episode
    again = pytpg_arm.train(make, 1000, 1, 4, seed=3)
    assert again.curve == run.curve
    seeds = [1_000_000, 1_000_001]
    assert pytpg_arm.score(make, run.champion, seeds) == pytpg_arm.score(
        make, again.champion, seeds
    )
