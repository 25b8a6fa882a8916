"""``replay`` plays the returns ``evaluate`` and training report, bit for bit.

Training and ``mtpg evaluate`` play the lane engine (:func:`mtpg.engine.lanes.run_lanes_queue`,
through :func:`mtpg.engine.batch.evaluate_roots`); ``mtpg replay`` and ``trace`` play the
scalar loop with a recorder (:mod:`mtpg.engine.trace`). One tiny run is trained with
memory and one with the no-memory ablation; for each champion and a few other teams of
its graph as roots, on the same held-out episodes, every path must give the same bits:
the lane engine as the trainer calls it, the scalar kernel, ``mtpg evaluate``'s path
(:func:`~mtpg.evolve.heldout_test.evaluate_graph`), the replay's traced episodes
(:func:`~mtpg.analysis.graph.replay.replay_task`), the two commands themselves, and the
means the training wrote to ``tests.csv``.
"""

import csv
import json

import numpy as np
import pytest

from mtpg.analysis.graph.replay import load_replay, replay_task
from mtpg.cli.main import main
from mtpg.engine.batch import Episodes, evaluate_roots
from mtpg.engine.compile import compile_population
from mtpg.envs.taskset.episode_seeds import held_out_seeds
from mtpg.envs.taskset.task_table import TaskTable
from mtpg.evolve.heldout_test import evaluate_graph, local_evaluate, play_test
from mtpg.io.rundir import champion_filename
from mtpg.io.serialize import load_graph
from tinyruns import tiny_args

TASKS = ("CartPole", "Pendulum")  # Pendulum reads a_c = m[0]: memory changes its returns
EPISODES = 3
GENERATIONS = 2
OTHER_ROOTS = 2  # teams of a champion's graph played as roots besides the champion


def bits(values) -> list[int]:
    return np.ascontiguousarray(values, dtype=np.float64).view(np.int64).tolist()


@pytest.fixture(scope="module", params=[False, True], ids=["memory", "no-memory"])
def run(request, tmp_path_factory):
    out = tmp_path_factory.mktemp("run") / "run"
    args = tiny_args(
        ",".join(TASKS),
        root_size=16,
        seed=3,
        evaluation__test_interval=GENERATIONS,
        evaluation__test_episodes=EPISODES,
    )
    flags = ["--preset", "demo", "--workers", "1"] + (["--no-memory"] if request.param else [])
    assert main(["train", *args, *flags, "--generations", str(GENERATIONS), "--out", str(out)]) == 0
    return out, request.param


def _graph(run_dir, row):
    name = champion_filename(tuple(row["subset"].split("+")))
    return run_dir / "tests" / f"gen-{GENERATIONS:06d}" / name


def _test_rows(run_dir):
    with open(run_dir / "tests.csv") as fh:
        return [r for r in csv.DictReader(fh) if int(r["generation"]) == GENERATIONS]


def test_every_path_plays_the_same_returns(run):
    run_dir, no_memory = run
    table = TaskTable.from_names(list(TASKS))
    ids = list(table.ids)
    rows = _test_rows(run_dir)
    assert rows
    for row in rows:
        pop, champion, meta = load_graph(_graph(run_dir, row))
        assert champion == int(row["root"]) and meta["no_memory"] is no_memory
        others = sorted(t for t in pop.teams if t != champion)[:OTHER_ROOTS]
        roots = [champion, *others]
        # the lane engine as training and evaluate call it, and the scalar kernel
        lanes = play_test(pop, roots, ids, EPISODES, 0, no_memory, local_evaluate(1), table)
        cp = compile_population(pop, no_memory=no_memory)
        grid = Episodes.grid(ids, held_out_seeds(EPISODES, 0), table)
        scalar = evaluate_roots(cp, roots, grid, lanes=0)[0].reshape(lanes.returns.shape)
        assert bits(scalar) == bits(lanes.returns)
        for i, root in enumerate(roots):
            scores = evaluate_graph(pop, root, list(TASKS), EPISODES, 0, 1, no_memory)
            for k, task in enumerate(TASKS):
                replay = replay_task(pop, root, task, EPISODES, 0, no_memory)
                assert bits(replay["returns"]) == bits(scores[task].returns), (root, task)
                assert bits(replay["returns"]) == bits(lanes.returns[i, k]), (root, task)
                if root == champion:  # what the training wrote at its test point
                    assert scores[task].mean == float(row[f"test_{task}"])
                    assert float(np.mean(replay["returns"])) == float(row[f"test_{task}"])


def test_the_commands_agree_on_the_champion(run, tmp_path, capsys):
    run_dir, no_memory = run
    row = next(r for r in _test_rows(run_dir) if r["subset"] == "+".join(TASKS))
    graph = _graph(run_dir, row)
    capsys.readouterr()
    args = ["evaluate", str(graph), "--tasks", ",".join(TASKS), "--episodes", str(EPISODES)]
    assert main([*args, "--json"]) == 0
    evaluated = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    for task in TASKS:
        npz = tmp_path / f"{task}.npz"
        args = ["replay", str(graph), "--task", task, "--episodes", str(EPISODES)]
        assert main([*args, "--out", str(npz)]) == 0
        replay = load_replay(npz)
        assert bool(replay["no_memory"]) is no_memory
        assert evaluated[task]["mean"] == float(np.mean(replay["returns"]))
        assert evaluated[task]["mean"] == float(row[f"test_{task}"])
