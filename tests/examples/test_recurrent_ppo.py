"""The RecurrentPPO example end to end at a smoke-size budget, where the extra is installed."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

pytest.importorskip("sb3_contrib")

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "recurrent_ppo.py"


def load_example():
    spec = importlib.util.spec_from_file_location("recurrent_ppo", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.mark.parametrize("env", ["Pendulum", "MultiTask"])
def test_example_trains_and_evaluates_on_held_out_episodes(env, capsys):
    example = load_example()
    argv = ["--env", env, "--timesteps", "64", "--n-steps", "32", "--episodes", "1"]
    if env == "MultiTask":
        argv += ["--tasks", "CartPole,MountainCar"]
    assert example.main(argv) == 0
    import json

    summary = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert summary["env_steps"] >= 64
    tasks = ["CartPole", "MountainCar"] if env == "MultiTask" else [env]
    assert sorted(summary["test"]) == sorted(tasks)
    assert all(isinstance(v, float) for v in summary["normalised"].values())


def test_example_saves_and_resumes_to_the_full_budget(tmp_path, capsys):
    import json

    example = load_example()
    base = ["--env", "CartPole", "--n-steps", "32", "--episodes", "1", "--save", str(tmp_path)]
    assert example.main([*base, "--timesteps", "64", "--save-every", "32"]) == 0
    first = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert first["env_steps"] == 64 and (tmp_path / "model.zip").is_file()
    assert example.main([*base, "--timesteps", "128", "--resume"]) == 0
    second = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert second["env_steps"] == 128
    sittings = json.loads((tmp_path / "progress.json").read_text())["sittings"]
    assert [(x["from"], x["to"]) for x in sittings] == [(0, 64), (64, 128)]
    assert "CartPole" in second["test"]
