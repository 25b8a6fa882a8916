"""The public API at the top level of ``mtpg``: its names, and runs equal to the commands'."""

import json
import math
import subprocess
import sys

import numpy as np
import pytest

import mtpg
from mtpg.cli.main import main
from mtpg.config import ConfigError, RunConfig, build_config
from mtpg.evolve.columns import TIMING_COLUMNS
from mtpg.evolve.heldout_test import TaskScore
from mtpg.io.rundir import RunDirError

TASKS = ["CartPole", "MountainCar"]
PUBLIC = {"Config", "ConfigError", "Evaluation", "Policy", "Run", "evaluate", "load", "preset"}


def tiny(generations: int = 3) -> RunConfig:
    """Two tasks, small populations, few generations: seconds to train."""
    settings = ("team.root_size=30", "evaluation.test_episodes=5")
    return mtpg.preset("demo", *settings, tasks=TASKS, generations=generations)


def test_all_lists_the_public_api_and_every_name_resolves():
    assert PUBLIC | {"train", "resume", "Champion"} <= set(mtpg.__all__)
    for name in mtpg.__all__:
        assert getattr(mtpg, name) is not None, name
    assert mtpg.Config is RunConfig and mtpg.ConfigError is ConfigError
    assert set(mtpg.__all__) <= set(dir(mtpg))
    with pytest.raises(AttributeError, match="no attribute 'no_such_name'"):
        _ = mtpg.no_such_name


def test_import_mtpg_loads_no_public_module_until_a_name_is_used():
    code = (
        "import json, sys, mtpg; first = set(sys.modules); mtpg.preset; "
        "print(json.dumps([sorted(first), sorted(set(sys.modules) - first)]))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    first, later = json.loads(done.stdout)
    assert not {"mtpg.api", "mtpg.policy", "mtpg.config", "numba"} & set(first)
    assert "mtpg.api_config" in later and "mtpg.api" not in later


def test_preset_is_build_config_with_the_options_of_mtpg_train():
    config = mtpg.preset(
        "demo",
        "team.root_size=30",
        tasks=["CartPole", "CartPole[max_steps=500]"],
        generations=7,
        seed=3,
        workers=1,
    )
    overrides = [
        "team.root_size=30",
        'evaluation.tasks=["CartPole", "CartPole[max_steps=500]"]',
        "generations=7",
        "seed=3",
        "workers=1",
    ]
    assert config == build_config("demo", None, overrides)
    assert mtpg.preset() == build_config("demo")


@pytest.mark.parametrize(
    ("args", "kwargs", "message"),
    [
        (("nope",), {}, "unknown preset 'nope'"),
        (("demo",), {"tasks": "CartPole"}, "give a list of task names"),
        (("demo", "team.n_elite=0"), {}, "team.n_elite"),
    ],
)
def test_preset_refuses_bad_settings_in_one_line(args, kwargs, message):
    with pytest.raises(ConfigError, match=message) as info:
        mtpg.preset(*args, **kwargs)
    assert "\n" not in str(info.value)


def _computed(rows):
    """Metrics rows without the columns that measure time."""
    return [{k: v for k, v in r.items() if k not in TIMING_COLUMNS} for r in rows]


def test_a_run_in_memory_is_the_run_in_a_directory(tmp_path):
    memory = mtpg.train(tiny())
    disk = mtpg.train(tiny(), out=tmp_path / "run")
    assert memory.path is None and disk.path == tmp_path / "run"
    assert memory.finished and disk.finished and memory.generation == disk.generation == 3
    columns = set(disk.metrics[0])
    assert _computed([{k: r[k] for k in columns} for r in memory.metrics]) == _computed(
        disk.metrics
    )
    assert [{k: r[k] for k in disk.tests[0]} for r in memory.tests] == disk.tests
    assert memory.champion.root == disk.champion.root
    assert memory.champion.teams == disk.champion.teams
    assert memory.test_scores() == disk.test_scores() != {}
    assert mtpg.evaluate(memory).scores.keys() == mtpg.evaluate(disk).scores.keys()
    assert mtpg.evaluate(memory).to_dict() == mtpg.evaluate(disk).to_dict()
    assert mtpg.load(disk.path).metrics == disk.metrics
    assert str(disk).startswith(f"{disk.path}: generation 3 of 3 (finished); tasks: CartPole")


def test_evaluate_gives_what_mtpg_evaluate_prints(tmp_path, capsys):
    run = mtpg.train(tiny(2), out=tmp_path / "run")
    capsys.readouterr()
    assert main(["evaluate", str(run.path), "--json"]) == 0
    assert mtpg.evaluate(run.path).to_dict() == json.loads(capsys.readouterr().out)
    graph = run.champion.path
    assert main(["evaluate", str(graph), "--json", "--episodes", "7", "--memory", "off"]) == 0
    by_file = mtpg.evaluate(graph, episodes=7, memory=False)
    assert by_file.to_dict() == json.loads(capsys.readouterr().out)
    assert by_file.no_memory and by_file.memory == "memory off (overriding the evolved setting)"
    assert main(["evaluate", str(run.path)]) == 0
    table = capsys.readouterr().out.splitlines()[2:]  # the command's header lines differ
    assert str(mtpg.evaluate(run)).splitlines()[1:] == table


def test_a_missing_score_is_na_in_text_and_null_in_json():
    score = TaskScore("gym:X-v0", 3.0, 0.5, 4, math.nan, 1.0, np.ones(4))
    found = mtpg.Evaluation("graph.json", {"gym:X-v0": score}, episodes=4)
    assert found["gym:X-v0"] is score and list(found) == ["gym:X-v0"] and len(found) == 1
    row = str(found).splitlines()[-1].split()
    assert row[:5] == ["gym:X-v0", "3.000", "0.500", "n/a", "1.00"]
    assert json.loads(found.to_json())["gym:X-v0"]["normalised"] is None
    assert "NaN" not in found.to_json() and "nan" not in str(found)


def test_the_policy_of_a_run_needs_a_task_where_there_are_several():
    run = mtpg.Run(tiny())
    with pytest.raises(FileNotFoundError, match="no champion yet"):
        _ = run.champion
    with pytest.raises(ValueError, match="name the task"):
        run.policy()


def test_bad_targets_are_refused_in_one_line(tmp_path):
    with pytest.raises(RunDirError, match="not an mtpg run directory"):
        mtpg.load(tmp_path)
    with pytest.raises(FileNotFoundError, match="no such run directory or graph file"):
        mtpg.evaluate(tmp_path / "nowhere")
    with pytest.raises(ValueError, match="trained without a run directory"):
        mtpg.Run(tiny()).report()


def test_load_reads_the_committed_generations_only(tmp_path):
    run = mtpg.train(tiny(), out=tmp_path / "run")
    metrics = run.path / "metrics.csv"
    lines = metrics.read_text().splitlines()
    metrics.write_text("\n".join([*lines, "4" + lines[-1][1:]]) + "\n")  # killed after gen 4
    again = mtpg.load(run.path)
    assert again.generation == 3 and again.metrics == run.metrics
