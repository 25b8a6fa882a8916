"""``mtpg probe`` end to end on tiny runs: text, JSON, graph files, resampled runs, errors."""

from __future__ import annotations

import hashlib
import json
import shutil

import pytest

from mtpg.analysis.runs.loading import load_run
from mtpg.cli.main import main
from mtpg.envs.taskset.episode_seeds import resampled_training_seeds
from tinyruns import tiny_args

TASKS = ["CartPole", "CartCentering"]


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    out = tmp_path_factory.mktemp("probe") / "run"
    args = tiny_args(evaluation__test_episodes=4, evaluation__test_interval=2)
    assert main(["train", *args, "--generations", "3", "--out", str(out)]) == 0
    return out


def digest(folder) -> dict[str, str]:
    """Every file under ``folder`` with its content hash and modification time."""
    return {
        str(
            p.relative_to(folder)
        ): f"{hashlib.sha256(p.read_bytes()).hexdigest()} {p.stat().st_mtime_ns}"
        for p in sorted(folder.rglob("*"))
        if p.is_file()
    }


def probe_json(capsys, *args) -> dict:
    capsys.readouterr()
    assert main(["probe", *map(str, args), "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_json_reports_the_three_sets_and_changes_nothing(run, capsys):
    before = digest(run)
    data = probe_json(capsys, run, "--redraws", "6")
    assert digest(run) == before, "the probe wrote into the run directory"
    assert data["generation"] == 3 and data["memory"] is True
    assert data["train"] == {
        "seeds": [0, 1],
        "block": 0,
        "resample_interval": 0,
        "resample_mean": False,
    }
    assert data["fresh_noise"] == {"noise_seed": 0, "redraws": 6}
    assert data["test"] == {"episodes": 4, "offset": 0}
    assert list(data["tasks"]) == TASKS
    final = load_run(run).row("+".join(TASKS), 3)
    for task, row in data["tasks"].items():
        assert row["test"]["mean"] == final[f"test_{task}"]  # bit for bit
        assert len(row["fresh_noise_redraw_means"]) == 6
        for kind in ("raw", "normalised"):
            drop, s = (
                row["drop"][kind],
                {
                    k: row[k]["mean" if kind == "raw" else kind]
                    for k in ("train", "fresh_noise", "test")
                },
            )
            assert drop["noise"] == pytest.approx(s["train"] - s["fresh_noise"])
            assert drop["start_states"] == pytest.approx(s["fresh_noise"] - s["test"])
            assert drop["total"] == pytest.approx(s["train"] - s["test"])
        assert row["single_task_champion"] is not None
    cartpole = data["tasks"]["CartPole"]
    assert not cartpole["observes_noise"] and data["tasks"]["CartCentering"]["observes_noise"]
    assert cartpole["drop"]["raw"]["noise"] == 0.0
    assert cartpole["fresh_noise"]["mean"] == cartpole["train"]["mean"]


def test_noise_seed_moves_only_fresh_noise(run, capsys):
    a = probe_json(capsys, run, "--redraws", "3", "--noise-seed", "11")
    b = probe_json(capsys, run, "--redraws", "3", "--noise-seed", "11")
    c = probe_json(capsys, run, "--redraws", "3", "--noise-seed", "12")
    assert a == b, "the probe is deterministic"
    for task in TASKS:
        assert a["tasks"][task]["train"] == c["tasks"][task]["train"]
        assert a["tasks"][task]["test"] == c["tasks"][task]["test"]
    assert c["fresh_noise"]["noise_seed"] == 12


def test_text_names_every_set_its_seeds_and_the_drops(run, capsys):
    capsys.readouterr()
    assert main(["probe", str(run), "--redraws", "2", "--noise-seed", "7"]) == 0
    out = capsys.readouterr().out
    assert "generation 3" in out and "memory on (as trained)" in out
    assert "(a) train: 2 training episodes per task, seeds 0..1" in out
    assert "redrawn, 2 times (4 episodes per task; noise seed 7)" in out
    assert "(c) test: 4 held-out episodes per task (seeds 1,000,000..1,000,003)" in out
    assert "drop noise = (a) - (b)" in out
    lines = out.splitlines()
    for title in ("normalised:", "mean return:"):
        at = lines.index(title)
        assert lines[at + 1].split()[:2] == ["task", "noise"]
        rows = [line.split() for line in lines[at + 2 : at + 4]]
        assert [r[0] for r in rows] == TASKS
        assert [r[1] for r in rows] == ["no", "yes"]
        assert float(rows[0][5]) == 0.0  # CartPole: drop noise


def test_a_champion_file_of_a_subset_plays_its_own_tasks(run, capsys):
    graph = run / "tests" / "gen-000003" / "CartCentering.json"
    data = probe_json(capsys, graph, "--redraws", "2")
    assert list(data["tasks"]) == ["CartCentering"] and data["graph"] == str(graph)
    single = load_run(run).row("CartCentering", 3)["test_CartCentering"]
    row = data["tasks"]["CartCentering"]
    assert row["single_task_champion"] == single
    assert row["test"]["vs_single"] == pytest.approx(1.0)  # its own test score
    both = probe_json(capsys, graph, "--redraws", "2", "--tasks", "CartPole,CartCentering")
    assert list(both["tasks"]) == TASKS


def test_a_resampled_run_is_probed_on_its_last_training_block(tmp_path, capsys):
    out = tmp_path / "robust"
    args = tiny_args(evaluation__test_episodes=3, evaluation__resample_interval=1)
    assert main(["train", *args, "--generations", "3", "--seed", "4", "--out", str(out)]) == 0
    data = probe_json(capsys, out, "--redraws", "2")
    assert data["train"]["block"] == 2 and data["train"]["resample_interval"] == 1
    assert data["train"]["seeds"] == resampled_training_seeds(4, 2, 2).tolist()
    capsys.readouterr()
    assert main(["probe", str(out), "--redraws", "2"]) == 0
    assert "training block 2 of a run that redraws its training episodes every 1 generations" in (
        capsys.readouterr().out
    )


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--redraws", "0"], "--redraws must be in 1.."),
        (["--episodes", "0"], "--episodes must be in 1.."),
        (["--noise-seed", "-1"], "--noise-seed must be in 0.."),
        (["--tasks", "MountainCar"], "'MountainCar' is not among the run's tasks"),
        (["--tasks", "Pong"], "Pong"),
    ],
)
def test_bad_options_are_one_line_errors(run, capsys, args, message):
    capsys.readouterr()
    assert main(["probe", str(run), *args]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


def test_a_graph_outside_a_run_is_refused(run, tmp_path, capsys):
    lone = tmp_path / "a" / "b" / "c" / "d" / "lone.json"
    lone.parent.mkdir(parents=True)
    shutil.copy(run / "tests" / "gen-000003" / "CartPole.json", lone)
    capsys.readouterr()
    assert main(["probe", str(lone)]) == 2
    assert "not inside a run directory" in capsys.readouterr().err
    assert main(["probe", str(tmp_path / "missing")]) == 2


def test_a_probe_too_large_for_memory_is_refused(run, capsys, monkeypatch):
    import mtpg.limits

    monkeypatch.setattr(mtpg.limits, "available_memory", lambda: 1 << 20)
    capsys.readouterr()
    assert main(["probe", str(run), "--redraws", "1000"]) == 2
    assert "--redraws or --episodes: 4000 episodes need" in capsys.readouterr().err
