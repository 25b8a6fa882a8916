"""Runs bound to a run directory: test points, checkpoints, callbacks, resume and errors."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from mtpg.config import ConfigError, build_config
from mtpg.engine import evaluator as evaluator_module
from mtpg.envs.taskset.episode_seeds import held_out_seeds
from mtpg.evolve.persist import state_from_payload, state_to_payload
from mtpg.evolve.session import Session, read_run_config
from mtpg.evolve.trainer import Trainer
from mtpg.io.checkpoint import (
    CheckpointError,
    list_checkpoints,
    load_checkpoint,
    save_checkpoint,
)
from mtpg.io.serialize import FormatError, load_graph


def tiny(generations: int = 3, *extra: str):
    return build_config(
        "paper",
        overrides=[
            "team.root_size=10",
            "team.n_elite=2",
            "team.init_team_size=3",
            "evaluation.train_episodes=1",
            "evaluation.test_episodes=2",
            'evaluation.tasks=["CartPole", "MountainCar"]',
            f"generations={generations}",
            *extra,
        ],
    )


@pytest.mark.parametrize(
    ("interval", "due"),
    [(0, []), (1, [1, 2, 3, 4, 5, 6]), (2, [2, 4, 6]), (5, [5, 6]), (4, [4, 6])],
)
def test_test_points(interval: int, due: list[int]) -> None:
    trainer = Trainer(tiny(6, f"evaluation.test_interval={interval}"))
    got = []
    for gen in range(1, 7):
        trainer.state.generation = gen
        if trainer.held_out_due():
            got.append(gen)
    assert got == due


def read_rows(path):
    with open(path) as fh:
        return list(csv.DictReader(fh))


def test_run_all_checkpoints_tests_and_calls_back(tmp_path) -> None:
    run = tmp_path / "run"
    calls = []
    session = Session(run, tiny(5, "evaluation.test_interval=2", "checkpoint_interval=2"))
    assert session.saved_generation == 0
    session.run_all(lambda row, trainer: calls.append((row["generation"], trainer)))
    assert [g for g, _ in calls] == [1, 2, 3, 4, 5]
    assert all(t is session.trainer for _, t in calls)
    # checkpoints at 2 and 4 and at exit (5); the two newest are kept
    assert [g for g, _ in list_checkpoints(run)] == [4, 5]
    assert session.saved_generation == 5
    rows = read_rows(run / "metrics.csv")
    for row in rows:
        tested = int(row["generation"]) in (2, 4, 5)  # and the last generation
        assert (float(row["t_test"]) > 0) == tested
        assert float(row["t_test"]) < 300  # a duration, not a clock reading
        assert float(row["t_total"]) >= float(row["t_test"])
        parts = sum(float(row[k]) for k in ("t_variation", "t_evaluation", "t_selection"))
        assert float(row["t_total"]) == pytest.approx(parts + float(row["t_test"]), abs=1e-3)
    tests = read_rows(run / "tests.csv")
    assert [r["generation"] for r in tests] == ["2"] * 3 + ["4"] * 3 + ["5"] * 3
    for r in tests:
        assert 1.0 <= float(r["teams_per_decision"]) <= int(r["graph_teams"])
    assert [r["subset"] for r in tests[:3]] == ["CartPole", "MountainCar", "CartPole+MountainCar"]
    # graphs of the single-task and full-set champions at every test point
    for gen, rows_at in (("000002", tests[:3]), ("000004", tests[3:])):
        folder = run / "tests" / f"gen-{gen}"
        names = sorted(p.name for p in folder.iterdir())
        assert names == ["CartPole+MountainCar.json", "CartPole.json", "MountainCar.json"]
        _, root, meta = load_graph(folder / "CartPole.json")
        assert root == int(rows_at[0]["root"])
        assert meta["generation"] == int(gen) and meta["seed"] == 0
        assert meta["test_episodes"] == 2
        assert meta["test"] == {
            "CartPole": float(rows_at[0]["test_CartPole"]),
            "MountainCar": float(rows_at[0]["test_MountainCar"]),
        }
    _, _, meta = load_graph(run / "champions" / "CartPole.json")
    assert meta["generation"] == 5 and set(meta["train_scores"]) == {"CartPole"}
    assert meta["seed"] == 0


def test_three_tasks_keep_single_and_full_set_graphs_only(tmp_path) -> None:
    cfg = tiny(
        1, 'evaluation.tasks=["CartPole", "MountainCar", "Pendulum"]', "evaluation.test_interval=1"
    )
    Session(tmp_path / "r", cfg).run_all()
    assert len(read_rows(tmp_path / "r" / "tests.csv")) == 7
    folder = tmp_path / "r" / "tests" / "gen-000001"
    assert sorted(p.name for p in folder.iterdir()) == [
        "CartPole+Pendulum+MountainCar.json",  # canonical task order
        "CartPole.json",
        "MountainCar.json",
        "Pendulum.json",
    ]


def test_resume_continues_from_the_checkpoint(tmp_path) -> None:
    run = tmp_path / "run"
    Session(run, tiny(2)).run_all()
    resumed = Session(run, tiny(4), resume=True)
    assert resumed.trainer.state.generation == 2 and resumed.saved_generation == 2
    assert resumed.config.generations == 4
    resumed.run_all()
    assert [int(r["generation"]) for r in read_rows(run / "metrics.csv")] == [1, 2, 3, 4]
    assert read_run_config(run).generations == 4
    assert Session(run, resume=True).config == resumed.config


def test_session_errors_name_the_problem(tmp_path) -> None:
    with pytest.raises(ConfigError, match="^a new run needs a configuration$"):
        Session(tmp_path / "x")
    run = tmp_path / "run"
    Session(run, tiny(1)).run_all()
    with pytest.raises(ConfigError, match=r"differs in seed\); only generations, workers"):
        Session(run, tiny(2, "seed=1"), resume=True)
    with pytest.raises(ConfigError, match=r"\(differs in seed, team.p_add\); only generations"):
        Session(run, tiny(2, "seed=1", "team.p_add=0.5"), resume=True)
    ckpt = list_checkpoints(run)[-1][1]
    payload = load_checkpoint(ckpt)
    del payload["population"]
    save_checkpoint(ckpt, payload)
    with pytest.raises(CheckpointError, match=rf"^{ckpt}: not a valid run state: run state: "):
        Session(run, resume=True)
    (run / "config.toml").write_text("seed = -1\n")
    with pytest.raises(ConfigError, match=rf"^{run / 'config.toml'}: seed must be >= 0"):
        read_run_config(run)


def test_payload_round_trip_and_errors() -> None:
    trainer = Trainer(tiny(2))
    trainer.run_generation()
    trainer.run_generation()
    payload = json.loads(json.dumps(state_to_payload(trainer.state)))
    state, config = state_from_payload(payload)
    assert config == trainer.config and state.config == trainer.config
    assert state.generation == 2
    assert state.champions == trainer.state.champions
    assert state.elites == trainer.state.elites
    assert set(state.scores) == set(trainer.state.scores)
    for root, row in state.scores.items():
        assert row.dtype == np.float64
        assert np.array_equal(row, trainer.state.scores[root])
    assert state.rng.random() == trainer.state.rng.random()
    with pytest.raises(FormatError, match=r"^run state: KeyError: 'champions'$"):
        state_from_payload({k: v for k, v in payload.items() if k != "champions"})
    bad = dict(payload, scores=[[999, [1.0]], [998, [1.0]], [997, [1.0]], [996, [1.0]]])
    with pytest.raises(
        FormatError, match=r"^run state: scored roots \[999, 998, 997\] are not in the population$"
    ):
        state_from_payload(bad)


def test_test_seeds_are_held_out() -> None:
    seeds = held_out_seeds(3)
    assert seeds.tolist() == [1_000_000, 1_000_001, 1_000_002] and seeds.dtype == np.int64
    assert held_out_seeds(2, offset=5).tolist() == [1_000_005, 1_000_006]
    with pytest.raises(ValueError, match="^test seed offset must be >= 0, got -1$"):
        held_out_seeds(2, offset=-1)


@pytest.mark.parametrize("no_memory", [False, True])
def test_champion_tests_honour_the_memory_ablation(monkeypatch, no_memory: bool) -> None:
    trainer = Trainer(tiny(1, f"evaluation.no_memory={str(no_memory).lower()}"))
    trainer.run_generation()
    seen = []
    real = evaluator_module.evaluate_roots

    def spy(*args, **kwargs):
        seen.append(args[0].no_memory)  # the compiled graph carries the ablation
        return real(*args, **kwargs)

    monkeypatch.setattr(evaluator_module, "evaluate_roots", spy)
    trainer.held_out_scores()
    assert seen == [no_memory]


def test_resume_drops_test_rows_after_the_checkpoint(tmp_path) -> None:
    run = tmp_path / "run"
    Session(run, tiny(3, "evaluation.test_interval=1", "checkpoint_interval=2")).run_all()
    assert [g for g, _ in list_checkpoints(run)] == [2, 3]
    list_checkpoints(run)[-1][1].unlink()  # as if killed after generation 3's rows
    assert {r["generation"] for r in read_rows(run / "tests.csv")} == {"1", "2", "3"}
    session = Session(run, resume=True)
    assert session.trainer.state.generation == 2
    session.tests.close()
    session.metrics.close()
    assert {r["generation"] for r in read_rows(run / "tests.csv")} == {"1", "2"}
    assert [r["generation"] for r in read_rows(run / "metrics.csv")] == ["1", "2"]
