import numpy as np
import pytest

from inside_graphs import cycle, single_team, writer_every_k
from mtpg.analysis.graph.decomposition import decomposition
from mtpg.analysis.graph.measures import (
    best_register,
    register_access,
    scale_pm1,
    step_series,
    velocity_prediction,
    visit_statistics,
)
from mtpg.analysis.graph.replay import Replay, load_replay, replay_observations, replay_task


def hand_trace(task, visits_per_step, banks=None):
    """A replay built by hand: one episode, the given team numbers visited per step."""
    n = len(visits_per_step)
    flat = np.array([t for step in visits_per_step for t in step], dtype=np.int64)
    off = np.concatenate([[0], np.cumsum([len(s) for s in visits_per_step])])
    banks = banks or [[] for _ in range(n)]
    cells = [c for step in banks for c in step]
    mem_off = np.concatenate([[0], np.cumsum([len(s) for s in banks])])
    return Replay(
        {
            "task": np.array(task),
            "step": np.arange(n),
            "visit_team": flat,
            "visit_offsets": off,
            "n_memory": np.array(8),
            "bank_ids": np.arange(2),
            "mem_bank": np.array([b for b, _ in cells], dtype=np.int64),
            "mem_register": np.array([r for _, r in cells], dtype=np.int64),
            "mem_offsets": mem_off,
        }
    )


def test_visit_shares_sum_to_one_per_task_and_pies_per_team():
    replays = {
        "CartPole": hand_trace("CartPole", [[1, 2], [1, 2, 3], [1]]),
        "Pendulum": hand_trace("Pendulum", [[1], [1, 3]]),
    }
    v = visit_statistics(replays, 3)
    assert np.allclose(v["share"].sum(axis=0), 1.0)
    assert np.allclose(v["pie"].sum(axis=1), 1.0)
    assert v["rate"][0].tolist() == [1.0, 1.0]  # the root runs at every step
    assert np.allclose(v["rate"][:, 0], [1, 2 / 3, 1 / 3])
    assert np.allclose(v["rate"][:, 1], [1, 0, 1 / 2])
    assert np.allclose(v["final"][:, 0], [1 / 3, 1 / 3, 1 / 3])
    assert np.allclose(v["pie"][1], [1, 0])  # team 2 only ever ran in CartPole


def test_register_shares_are_per_step_and_sum_to_one():
    replays = {
        "CartPole": hand_trace("CartPole", [[1]] * 4, [[(1, 0), (2, 3)]] * 4),
        "Pendulum": hand_trace("Pendulum", [[1]] * 2, [[(1, 0)]] * 2),
    }
    a = register_access(replays)
    assert np.allclose(a["share"].sum(axis=1), 1.0)
    got = {lab: row.tolist() for lab, row in zip(a["labels"], a["share"], strict=True)}
    assert got == {"b2.m3": [1.0, 0.0], "b1.m0": [0.5, 0.5]}  # per step: equal rates
    assert a["labels"][-1] == "b1.m0"  # evenly shared registers come last


@pytest.mark.parametrize("k", [2, 3])
def test_memory_ages_are_exact_when_a_register_is_written_every_k_steps(k):
    pop, root = writer_every_k()
    n = 4 * k + 1
    obs = np.zeros((n, 2))
    obs[:, 0] = np.where(np.arange(n) % k == 0, 1.0, -1.0)
    rep = replay_observations(pop, root, obs)
    assert np.array_equal(rep["observation"], obs)  # the trace records what each decision saw
    teams = rep.per_step("visit", "visit_team")
    assert [len(t) for t in teams] == [2 if t % k == 0 else 1 for t in range(n)]
    reads = ~rep["mem_is_write"]
    step_of = np.repeat(np.arange(n), rep.counts("mem"))
    read_steps = step_of[reads]
    assert read_steps.tolist() == list(range(n))  # the root reads m[1] once per step
    ages = rep["mem_age"][reads]
    expected = [t + 1 if t == 0 else t - k * ((t - 1) // k) for t in range(n)]
    assert ages.tolist() == expected
    assert rep["mem_from_reset"][reads].tolist() == [True] + [False] * (n - 1)
    writes = step_of[rep["mem_is_write"]]
    assert writes.tolist() == list(range(0, n, k))
    series = step_series(rep, 0)
    assert np.isnan(series["oldest"][0])  # the reset value does not widen the window
    assert series["oldest"][1:].tolist() == expected[1:]
    # the memory snapshot holds m[1] = |s[0]| = 1 once written
    assert rep["memory"][:, 1].tolist() == [1.0] * n


def test_best_register_is_found_when_one_register_is_the_velocity():
    rng = np.random.default_rng(0)
    velocity = np.sin(np.linspace(0, 6, 80))
    memory = rng.normal(size=(80, 12))
    memory[:, 5] = 0.0  # constant columns are ignored
    memory[:, 7] = 3.0 * velocity + 2.0
    assert best_register(velocity, memory) == (7, pytest.approx(1.0))
    memory[:, 7] = -velocity
    col, r = best_register(velocity, memory)
    assert col == 7 and r == pytest.approx(-1.0)
    col, r = best_register(velocity, np.zeros((80, 3)))
    assert col == -1 and np.isnan(r)
    scaled = scale_pm1(memory[:, 7])
    assert scaled.min() == -1.0 and scaled.max() == 1.0


def test_velocity_prediction_on_a_replay_scales_both_series():
    pop, root = single_team(action=1)
    rep = replay_task(pop, root, "CartCentering", episodes=1)
    pred = velocity_prediction(rep, 0)
    assert pred["velocity"].max() == pytest.approx(1.0)
    assert pred["velocity"].min() == pytest.approx(-1.0)
    assert pred["label"].startswith("b1.m")


def test_a_cycle_forming_pointer_never_visits_a_team_twice():
    pop, root = cycle()
    rep = replay_task(pop, root, "CartPole", episodes=2)
    for path in rep.per_step("visit", "visit_team"):
        assert path.tolist() == [1, 2]
    assert set(rep["a_d"].tolist()) == {1}


def test_replayed_returns_equal_evaluate(tmp_path):
    from mtpg.engine.random_populations import layered_graphs
    from mtpg.evolve.heldout_test import evaluate_graph

    pop, roots = layered_graphs(np.random.default_rng(3), 2, teams=3, programs=4, instructions=5)
    for root in roots:
        for task in ("CartPole", "Pendulum"):
            scores = evaluate_graph(pop, root, [task], episodes=3, seed=2)
            rep = replay_task(pop, root, task, episodes=3, seed=2)
            assert rep["returns"].tolist() == scores[task].returns.tolist()
            steps = rep.counts("visit").sum() / rep.n_steps
            assert steps == pytest.approx(scores[task].teams_per_decision)
    path = rep.save(tmp_path / "r.npz")
    back = load_replay(path)
    assert set(back.data) == set(rep.data)
    assert np.array_equal(back["mem_age"], rep["mem_age"])
    assert back.task == "Pendulum"


def test_decomposition_points_match_visits_and_final_teams():
    pop, root = cycle()
    rep = replay_task(pop, root, "CartPole", episodes=1)
    dec = decomposition(rep, 2)
    n = rep.n_steps
    assert len(dec["teams"][0]["x"]) == n and not dec["teams"][0]["final"].any()
    assert len(dec["teams"][1]["x"]) == n and dec["teams"][1]["final"].all()
    assert not dec["continuous"]
    assert np.array_equal(dec["teams"][1]["y"], rep["hidden_state"][:, 3])
