"""A graph evolved without memory is evaluated without memory unless the user says otherwise."""

import csv
import json

import pytest

from mtpg.cli.main import main
from mtpg.io.rundir import champion_filename
from mtpg.io.serialize import load_graph
from tinyruns import tiny_args

TASKS = ("Pendulum", "CartCentering")  # both read a_c = m[0]: memory changes their scores
EPISODES = 4


def tiny_run(tmp_path_factory, *flags, seed=2):
    out = tmp_path_factory.mktemp("run") / "run"
    args = tiny_args(
        ",".join(TASKS),
        root_size=30,
        team__init_team_size=10,
        seed=seed,
        evaluation__test_interval=5,
        evaluation__test_episodes=EPISODES,
    )
    assert main(["train", *args, *flags, "--generations", "5", "--out", str(out)]) == 0
    return out


@pytest.fixture(scope="module")
def no_memory_run(tmp_path_factory):
    # Many tiny champions never read memory, so forcing it on would change nothing: take
    # the first seed whose champion does (the search is deterministic).
    for seed in range(2, 30):
        run = tiny_run(tmp_path_factory, "--no-memory", seed=seed)
        if _reads_memory(run):
            return run
    raise AssertionError("no seed in 2..29 evolves a tiny champion that reads memory")


def _reads_memory(run):
    from mtpg.evolve.heldout_test import evaluate_graph

    pop, root, _ = load_graph(run / "tests" / "gen-000005" / champion_filename(TASKS))
    off = evaluate_graph(pop, root, list(TASKS), EPISODES, 0, 1, True)
    on = evaluate_graph(pop, root, list(TASKS), EPISODES, 0, 1, False)
    return any(off[t].mean != on[t].mean for t in TASKS)


def evaluate_json(capsys, target, *extra):
    capsys.readouterr()
    code = main(
        ["evaluate", str(target), "--tasks", ",".join(TASKS), "--episodes", str(EPISODES)]
        + ["--json", *extra]
    )
    assert code == 0
    return json.loads(capsys.readouterr().out.strip().splitlines()[-1])


def test_champion_files_record_the_ablation(no_memory_run, tmp_path_factory):
    name = champion_filename(TASKS)
    for path in (no_memory_run / "champions" / name, no_memory_run / "tests/gen-000005" / name):
        assert load_graph(path)[2]["no_memory"] is True
    with_memory = tiny_run(tmp_path_factory)
    assert load_graph(with_memory / "champions" / name)[2]["no_memory"] is False


def test_evaluate_scores_a_no_memory_champion_as_tests_csv_did(no_memory_run, capsys):
    with open(no_memory_run / "tests.csv") as fh:
        row = next(r for r in csv.DictReader(fh) if r["subset"] == "+".join(TASKS))
    graph = no_memory_run / "tests" / "gen-000005" / champion_filename(TASKS)
    assert load_graph(graph)[1] == int(row["root"])
    as_evolved = evaluate_json(capsys, graph)
    for task in TASKS:
        assert as_evolved[task]["mean"] == float(row[f"test_{task}"])
        assert as_evolved[task]["no_memory"] is True
        assert as_evolved[task]["memory"] == "memory off (as evolved)"
    assert evaluate_json(capsys, graph, "--memory", "off") == as_evolved
    forced = evaluate_json(capsys, graph, "--memory", "on")
    assert forced[TASKS[0]]["memory"] == "memory on (overriding the evolved setting)"
    assert any(forced[t]["mean"] != as_evolved[t]["mean"] for t in TASKS)


def test_evaluate_prints_the_memory_setting(no_memory_run, capsys):
    capsys.readouterr()
    assert main(["evaluate", str(no_memory_run), "--episodes", "2"]) == 0
    assert "memory off (as evolved)" in capsys.readouterr().out
    assert main(["evaluate", str(no_memory_run), "--episodes", "2", "--memory", "on"]) == 0
    assert "memory on (overriding the evolved setting)" in capsys.readouterr().out
