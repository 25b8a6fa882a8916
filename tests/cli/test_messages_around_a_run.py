"""Messages and output met on a finished run: each says what is the case, in one line."""

import re

import numpy as np
import pytest

from mtpg.cli.main import main
from tinyruns import tiny_args

TINY = tiny_args()


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    """A finished two-generation run that was then reported and analysed."""
    path = tmp_path_factory.mktemp("m") / "run"
    assert main(["train", *TINY, "--generations", "2", "--out", str(path)]) == 0
    for sub in ("report", "analysis"):  # what mtpg report and mtpg analyze add
        (path / sub).mkdir()
        (path / sub / "index.html").write_text("<html></html>")
    return path


def test_training_into_a_reported_run_says_it_holds_a_run(run, capsys):
    capsys.readouterr()
    assert main(["train", *TINY, "--out", str(run)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1
    assert "already holds an mtpg run" in err and f"--resume {run}" in err
    assert "not an mtpg run directory" not in err


def test_zero_generations_are_refused_and_write_nothing(tmp_path, capsys):
    out = tmp_path / "zero"
    assert main(["train", *TINY, "--generations", "0", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.endswith("generations must be >= 1, got 0")
    assert not out.exists()


def test_report_on_a_directory_without_a_run_does_not_speak_of_resuming(tmp_path, capsys):
    (tmp_path / "notes.txt").write_text("x")
    assert main(["report", str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"mtpg report: error: {tmp_path}: not an mtpg run directory (no config.toml)"
    assert main(["report", str(tmp_path / "missing")]) == 2
    assert "no such run directory" in capsys.readouterr().err


@pytest.mark.parametrize("command", ["evaluate", "show", "analyze"])
def test_a_missing_path_is_named_as_missing(tmp_path, capsys, command):
    missing = tmp_path / "runs" / "demo"
    assert main([command, str(missing)]) == 2
    err = capsys.readouterr().err.strip()
    assert err == f"mtpg {command}: error: {missing}: no such graph file or run directory"


def _one_team_graph(path):
    from mtpg.engine.random_populations import layered_graphs
    from mtpg.io.serialize import save_graph

    pop, roots = layered_graphs(np.random.default_rng(0), 1, teams=1, programs=3)
    assert len(pop.reachable(roots[0])) == 1
    save_graph(path, pop, roots[0], {})
    return path


def test_evaluate_table_stays_aligned_with_variant_names_and_counts_one_team(tmp_path, capsys):
    graph = _one_team_graph(tmp_path / "g.json")
    tasks = "CartPole[max_steps=500;noise=0.1],MountainCar"
    assert main(["evaluate", str(graph), "--tasks", tasks, "--episodes", "2"]) == 0
    out = capsys.readouterr().out.splitlines()
    assert ", 1 team;" in out[0] and "1 teams" not in out[0]
    header, rows = out[2], out[3:]
    assert len(rows) == 2
    # every column ends where its header ends
    ends = [m.end() for m in re.finditer(r"\S+", header)][1:]
    for row in rows:
        assert [m.end() for m in re.finditer(r"\S+", row)][1:] == ends, (header, row)


def test_a_loaded_replay_iterates_over_its_keys_like_the_npz_file(tmp_path):
    from mtpg.analysis.graph.replay import load_replay, replay_task
    from mtpg.io.serialize import load_graph

    pop, root, _ = load_graph(_one_team_graph(tmp_path / "g.json"))
    path = replay_task(pop, root, "CartPole", episodes=1).save(tmp_path / "r.npz")
    back = load_replay(path)
    with np.load(path) as npz:
        assert list(back) == list(npz.files)
    assert len(back) == len(back.data) and "returns" in back and "nope" not in back
    assert np.array_equal(dict(back)["returns"], back["returns"])
