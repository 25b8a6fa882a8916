"""A variant end to end: train, resume exactly, evaluate, export, report; bad strings refused."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import pytest

from mtpg.cli.main import main
from mtpg.evolve.columns import TIMING_COLUMNS
from tinyruns import tiny_args

TASKS = "CartPole[max_steps=500],Pendulum[observe=theta;max_steps=60;noise=0.1]"
CANONICAL = ["CartPole[max_steps=500]", "Pendulum[max_steps=60;noise=0.1;observe=theta]"]
TINY = tiny_args(TASKS, root_size=16, n_elite=2, evaluation__test_interval=2)


def rows(run: Path, name: str = "metrics.csv") -> list[dict]:
    with open(run / name) as fh:
        return [{k: v for k, v in r.items() if k not in TIMING_COLUMNS} for r in csv.DictReader(fh)]


def test_variant_trains_resumes_evaluates_exports_and_reports(tmp_path, capsys):
    straight, split = tmp_path / "straight", tmp_path / "split"
    assert main(["train", *TINY, "--generations", "4", "--out", str(straight)]) == 0
    assert main(["train", *TINY, "--generations", "2", "--out", str(split)]) == 0
    assert main(["train", "--resume", str(split), "--generations", "4", "--quiet"]) == 0
    assert rows(split) == rows(straight)
    assert rows(split, "tests.csv") == rows(straight, "tests.csv")
    config = (straight / "config.toml").read_text()
    assert all(f'"{name}"' in config for name in CANONICAL)
    champions = sorted(p.name for p in (straight / "champions").glob("*.json"))
    assert champions == sorted(
        [f"{CANONICAL[0]}.json", f"{CANONICAL[1]}.json", "+".join(CANONICAL) + ".json"]
    )
    steps = [float(r["best_CartPole[max_steps=500]"]) for r in rows(straight)]
    assert max(steps) <= 500
    capsys.readouterr()
    assert main(["evaluate", str(straight), "--episodes", "3", "--json"]) == 0
    result = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert sorted(result) == sorted(CANONICAL)
    assert all(row["episodes"] == 3 for row in result.values())
    graph = straight / "champions" / f"{CANONICAL[0]}.json"
    assert (
        main(["evaluate", str(graph), "--episodes", "2", "--tasks", "CartPole[max_steps=9]"]) == 0
    )
    assert "CartPole[max_steps=9]" in capsys.readouterr().out
    assert main(["export", str(straight), "--lang", "python", "--out", str(tmp_path / "g.py")]) == 0
    assert main(["report", str(straight), "--out", str(tmp_path / "report")]) == 0
    assert any((tmp_path / "report").iterdir())


@pytest.mark.parametrize(
    ("tasks", "message"),
    [
        ("CartPole[max_step=500]", "unknown key 'max_step'; allowed: max_steps, force"),
        ("Pendulum[observe=phi]", "observe: unknown state variable 'phi'; allowed: theta"),
    ],
)
def test_bad_variant_is_refused_in_one_line_with_exit_2(tmp_path, capsys, tasks, message):
    assert main(["train", *tiny_args(tasks), "--out", str(tmp_path / "run")]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and len(err.splitlines()) == 1 and "Traceback" not in err
    assert not (tmp_path / "run").exists()


def test_task_tables_in_toml_name_variants(tmp_path):
    from mtpg.config import ConfigError, build_config

    toml = tmp_path / "tasks.toml"
    toml.write_text(
        '[[task]]\nbase = "CartPole"\nmax_steps = 500\n\n'
        '[[task]]\nbase = "Pendulum"\nobserve = ["theta"]\n\n[[task]]\nbase = "Acrobot"\n'
    )
    config = build_config("demo", toml)
    assert config.evaluation.tasks == (
        "CartPole[max_steps=500]",
        "Pendulum[observe=theta]",
        "Acrobot",
    )
    toml.write_text('[[task]]\nbase = "Pendulum"\nobserve = ["x"]\n')
    with pytest.raises(ConfigError, match=r"task\[0\]: task 'Pendulum\[observe=x\]': observe"):
        build_config("demo", toml)
