"""Parent pools and elite counts, checked on small hand-set runs.

Paper section 4.1 and ``shared/spec/algorithm.md``: for every task subset, ``n_elite``
children; parent 1 is drawn from that subset's elites, parent 2 uniformly from all roots.
``min_elite_total`` raises the per-subset count to ``ceil(min_elite_total / subsets)``.
"""

from __future__ import annotations

import numpy as np
import pytest

from mtpg.config import build_config
from mtpg.evolve import variation
from mtpg.evolve.selection import select, task_subsets
from mtpg.evolve.trainer import Trainer

TWO_TASKS = 'evaluation.tasks=["CartPole", "MountainCar"]'


def config(n_elite: int, min_elite_total: int = 0, root_size: int = 40, tasks: str = TWO_TASKS):
    return build_config(
        "paper",
        overrides=[
            f"team.root_size={root_size}",
            f"team.n_elite={n_elite}",
            f"team.min_elite_total={min_elite_total}",
            "team.init_team_size=3",
            "evaluation.train_episodes=1",
            tasks,
        ],
    )


@pytest.mark.parametrize(
    ("n_elite", "min_total", "subsets", "want"),
    [
        (2, 0, 3, 2),  # off: n_elite
        (2, 10, 3, 4),  # ceil(10 / 3) = 4 (rounding down would give 3)
        (2, 7, 3, 3),  # ceil(7 / 3) = 3
        (2, 6, 3, 2),  # exactly 2 per subset
        (2, 4, 3, 2),  # below n_elite * subsets: n_elite
        (1, 100, 1, 100),  # one task, one subset
        (4, 100, 63, 4),  # six tasks: ceil(100 / 63) = 2 < 4
        (1, 100, 63, 2),  # six tasks: ceil(100 / 63) = 2
        (1, 127, 63, 3),  # ceil(127 / 63) = 3
    ],
)
def test_elites_per_subset(n_elite: int, min_total: int, subsets: int, want: int) -> None:
    tasks = {1: '["Pendulum"]', 3: '["CartPole", "MountainCar"]'}.get(subsets)
    names = tasks or '["CartPole", "Acrobot", "CartCentering", "Pendulum", "MountainCar",'
    if tasks is None:
        names += ' "MountainCarContinuous"]'
    cfg = config(n_elite, min_total, tasks=f"evaluation.tasks={names}")
    assert cfg.evaluation.n_subsets == subsets
    assert cfg.elites_per_subset == want


def record_parents(monkeypatch) -> list[tuple[int, int]]:
    calls: list[tuple[int, int]] = []
    real = variation.Varier.child

    def spy(self, parent1: int, parent2: int) -> int:
        calls.append((parent1, parent2))
        return real(self, parent1, parent2)

    monkeypatch.setattr(variation.Varier, "child", spy)
    return calls


@pytest.mark.parametrize(("n_elite", "min_total", "per_subset"), [(3, 0, 3), (1, 10, 4)])
def test_children_per_subset_and_parent_pools(monkeypatch, n_elite, min_total, per_subset) -> None:
    trainer = Trainer(config(n_elite, min_total))
    trainer.run_generation()
    st = trainer.state
    elites = [list(e) for e in st.elites]
    roots = set(st.scores)
    assert [len(e) for e in elites] == [per_subset] * 3  # 40 roots suffice for every subset
    calls = record_parents(monkeypatch)
    row = trainer.run_generation()
    assert len(calls) == 3 * per_subset and row["new_roots"] == 3 * per_subset
    for k, subset_elites in enumerate(elites):
        mine = calls[k * per_subset : (k + 1) * per_subset]
        assert all(p1 in subset_elites for p1, _ in mine), (k, mine, subset_elites)
        assert all(p2 in roots for _, p2 in mine)
    # parent 2 comes from all roots, not only the subset's elites
    outside = [
        p2
        for k, e in enumerate(elites)
        for _, p2 in calls[k * per_subset : (k + 1) * per_subset]
        if p2 not in e
    ]
    assert outside


def test_parent_one_covers_the_subset_elites_and_parent_two_all_roots(monkeypatch) -> None:
    trainer = Trainer(config(1, 6))
    trainer.run_generation()
    st = trainer.state
    assert len(st.scores) == 6
    # hand-set pools: every subset gets two elites, parent 2 may be any of six roots
    roots = sorted(st.population.roots())[:6]
    st.scores = {r: st.scores.get(r, np.zeros(2)) for r in roots}
    st.elites = [roots[0:2], roots[2:4], roots[4:6]]
    calls = record_parents(monkeypatch)
    for _ in range(12):
        trainer._vary(trainer.state.generation + 1)
    n = trainer.config.elites_per_subset
    assert len(calls) == 12 * 3 * n
    per_subset = {k: [c for i, c in enumerate(calls) if (i // n) % 3 == k] for k in range(3)}
    for k, mine in per_subset.items():
        assert {p1 for p1, _ in mine} == set(st.elites[k])
    assert {p2 for _, p2 in calls} == set(roots)


def test_select_keeps_n_elite_each_until_the_roots_run_out() -> None:
    ids = np.arange(100, 107)
    rng = np.random.default_rng(0)
    scores = rng.normal(size=(7, 2))
    elites, champions = select(ids, scores, task_subsets(2), n_elite=3)
    assert [len(e) for e in elites] == [3, 3, 1]
    assert len({r for e in elites for r in e}) == 7
    elites, _ = select(ids, scores, task_subsets(2), n_elite=2)
    assert [len(e) for e in elites] == [2, 2, 2]
    # the single-task elites are the best on their task
    order0 = ids[np.argsort(-scores[:, 0])].tolist()
    assert elites[0] == order0[:2]
    assert champions[0] == order0[0]


def test_min_elite_total_in_a_run_keeps_the_rounded_up_count() -> None:
    trainer = Trainer(config(1, 10, root_size=30))
    rows = [trainer.run_generation() for _ in range(3)]
    assert [len(e) for e in trainer.state.elites] == [4, 4, 4]
    assert rows[0]["new_roots"] == 30 and rows[1]["new_roots"] == rows[2]["new_roots"] == 12
    assert rows[-1]["roots"] == 12


def test_min_max_over_roots_shifts_by_the_minimum() -> None:
    from mtpg.evolve.selection import min_max_over_roots

    out = min_max_over_roots(np.array([[2.0, -3.0], [4.0, -1.0], [3.0, -2.0]]))
    assert out.tolist() == [[0.0, 0.0], [1.0, 1.0], [0.5, 0.5]]
