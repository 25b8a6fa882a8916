"""Epsilon-lexicase choice of parent 1 (beyond the paper; ``team.parent_selection``)."""

from __future__ import annotations

import numpy as np
import pytest

from mtpg.config import ConfigError, build_config
from mtpg.evolve import trainer as trainer_module
from mtpg.evolve.lexicase import case_epsilons, lexicase_pick
from mtpg.evolve.persist import identity_fields, state_from_payload, state_to_payload
from mtpg.evolve.trainer import Trainer

TINY = [
    "team.root_size=12",
    "team.n_elite=2",
    "team.init_team_size=3",
    "evaluation.train_episodes=2",
    'evaluation.tasks=["CartPole", "CartCentering"]',
]
LEXICASE = 'team.parent_selection="lexicase"'


def test_the_option_is_validated_off_in_the_presets_and_out_of_the_identity_when_off():
    with pytest.raises(ConfigError, match=r"team\.parent_selection must be one of uniform"):
        build_config("paper", overrides=['team.parent_selection="tournament"'])
    for preset in ("paper", "demo"):
        assert build_config(preset).team.parent_selection == "uniform"
    assert "parent_selection" not in identity_fields(build_config("paper"))["team"]
    on = build_config("paper", overrides=[LEXICASE])
    assert identity_fields(on)["team"]["parent_selection"] == "lexicase"


def test_case_epsilons_are_the_median_absolute_deviation_per_case():
    returns = np.array([[10.0, 0.0], [0.0, 10.0], [5.0, 4.0]])
    # case 0: median 5, deviations 5 5 0 -> 5; case 1: median 4, deviations 4 6 0 -> 4
    assert case_epsilons(returns).tolist() == [5.0, 4.0]


def test_without_epsilon_the_first_case_decides_and_generalists_lose():
    returns = np.array([[10.0, 0.0], [0.0, 10.0], [5.0, 5.0]])
    rng = np.random.default_rng(0)
    picks = [lexicase_pick(returns, np.zeros(2), rng) for _ in range(200)]
    assert set(picks) == {0, 1}  # each specialist wins when its case comes first


def test_epsilon_keeps_near_best_candidates():
    returns = np.array([[10.0, 0.0], [0.0, 10.0], [5.0, 5.0]])
    rng = np.random.default_rng(0)
    # epsilon 5: case 0 first keeps {0, 2}, then case 1 keeps both; case 1 first: {1, 2}
    picks = [lexicase_pick(returns, np.array([5.0, 5.0]), rng) for _ in range(300)]
    assert set(picks) == {0, 1, 2}
    assert picks.count(2) > picks.count(0) and picks.count(2) > picks.count(1)


def test_a_dominated_candidate_is_never_chosen():
    returns = np.array([[3.0, 3.0, 3.0], [1.0, 2.0, 3.0], [3.0, 3.0, 2.0]])
    rng = np.random.default_rng(1)
    picks = {lexicase_pick(returns, np.zeros(3), rng) for _ in range(100)}
    assert 1 not in picks and 0 in picks


def test_in_a_run_parent_one_is_drawn_by_lexicase_from_the_subset_elites(monkeypatch):
    tr = Trainer(build_config("paper", overrides=[*TINY, LEXICASE]))
    tr.run_generation()
    st = tr.state
    assert set(st.returns) == set(st.scores)
    for root, table in st.returns.items():
        assert table.shape == (2, 2) and np.allclose(table.mean(axis=1), st.scores[root])
    picks = []
    real = trainer_module.lexicase_pick

    def spy(returns, eps, rng):
        i = real(returns, eps, rng)
        picks.append(returns[i].tolist())
        return i

    monkeypatch.setattr(trainer_module, "lexicase_pick", spy)
    elites = [list(e) for e in st.elites]
    tables = {r: st.returns[r].copy() for e in elites for r in e}
    tr.run_generation()
    n = tr.config.elites_per_subset
    assert len(picks) == n * len(elites)
    for k, subset in enumerate(tr.subsets):
        pool = [tables[r][list(subset)].ravel().tolist() for r in elites[k]]
        assert all(got in pool for got in picks[k * n : (k + 1) * n])
    tr.close()


def test_a_lexicase_run_continued_from_its_payload_equals_the_uninterrupted_one():
    config = build_config("paper", overrides=[*TINY, LEXICASE, "evaluation.resample_interval=2"])
    whole = Trainer(config)
    for _ in range(5):
        whole.run_generation()
    first = Trainer(config)
    for _ in range(3):
        first.run_generation()
    payload = state_to_payload(first.state)
    assert "returns" in payload and "validation" not in payload
    second = Trainer(config, state_from_payload(payload)[0])
    for _ in range(2):
        second.run_generation()
    a, b = whole.state, second.state
    assert a.elites == b.elites and a.champions == b.champions
    assert a.rng.bit_generator.state == b.rng.bit_generator.state
    assert {r: t.tolist() for r, t in a.returns.items()} == {
        r: t.tolist() for r, t in b.returns.items()
    }
    for tr in (whole, first, second):
        tr.close()


def test_paper_runs_store_no_returns():
    tr = Trainer(build_config("paper", overrides=TINY))
    tr.run_generation()
    assert tr.state.returns == {} and "returns" not in state_to_payload(tr.state)
    tr.close()
