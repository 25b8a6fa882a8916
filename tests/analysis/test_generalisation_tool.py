"""``tools/generalisation.py`` at smoke size: runs, resumes (skips finished runs), reports."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

TOOL = Path(__file__).resolve().parents[2] / "tools" / "generalisation.py"
ORACLE = TOOL.with_name("population_oracle.py")
SMALL = [
    "--generations",
    "2",
    "--seeds",
    "2",
    "--test-episodes",
    "3",
    "--workers",
    "1",
    *("--set", "team.root_size=8", "--set", "team.n_elite=1", "--set", "team.min_elite_total=0"),
    *("--set", "team.init_team_size=3", "--set", "evaluation.train_episodes=2"),
]


def tool(*args):
    return subprocess.run(
        [sys.executable, str(TOOL), *args], capture_output=True, text=True, check=False
    )


def check(out: Path, scenarios: str, settings: str) -> list[dict]:
    args = ["--out", str(out), "--scenarios", scenarios, "--settings", settings, *SMALL]
    done = tool("run", *args)
    assert done.returncode == 0, done.stderr
    rows = json.loads((out / "generalisation.json").read_text())
    assert (out / "generalisation.md").is_file() and (out / "generalisation.png").is_file()
    again = tool("run", *args)  # resumable: every finished run is skipped
    assert again.returncode == 0 and "starting" not in again.stderr, again.stderr
    assert json.loads((out / "generalisation.json").read_text()) == rows
    return rows


def test_smoke_run_one_task(tmp_path):
    rows = check(tmp_path / "g", "cartpole", "paper,combined")
    assert [(r["scenario"], r["setting"], r["seeds"]) for r in rows] == [
        ("cartpole", "paper", [0, 1]),
        ("cartpole", "combined", [0, 1]),
    ]
    for r in rows:
        assert len(r["all"]["per_run"]) == 2 and r["decisions"] > 0
    header = (tmp_path / "g/cartpole/combined/seed0/metrics.csv").read_text().splitlines()[0]
    assert "validation_decisions" in header and "reevaluated_roots" in header
    cfg = (tmp_path / "g/cartpole/paper/seed1/config.toml").read_text()
    assert "test_episodes = 3" in cfg and "test_interval = 2" in cfg
    # the population oracle replays the run's own test: its champion scores as in the report
    seeds = [str(tmp_path / f"g/cartpole/paper/seed{k}") for k in (0, 1)]
    done = subprocess.run(
        [sys.executable, str(ORACLE), *seeds, "--episodes", "3"],
        capture_output=True,
        text=True,
        check=True,
    )
    lines = [ln.split("|") for ln in done.stdout.splitlines()[2:4]]
    for cells, run in zip(lines, rows[0]["all"]["per_run"], strict=True):
        champion, best, worst = float(cells[4]), float(cells[5]), float(cells[7])
        assert champion == pytest.approx(run[0], abs=0.005)
        assert worst <= champion <= best


@pytest.mark.slow
def test_smoke_run_six_tasks(tmp_path):
    rows = check(tmp_path / "g", "six", "paper,validation,resampling,more-episodes")
    assert all(len(r["all"]["per_run"][0]) == 6 and "single" in r for r in rows)


def test_unknown_names_are_refused():
    done = tool("report", "--out", "x", "--settings", "paper,magic")
    assert done.returncode == 2 and "unknown magic" in done.stderr
