"""The paper's selection and champion rules pinned against hand-worked tables.

Paper section 4.1 step 4: per task, each root's mean score is min-max normalised over the
current roots; a subset's fitness is the MINIMUM normalised score over its tasks; each
subset keeps its ``n_elite`` best roots not kept by an earlier subset (single tasks first);
its champion is its best root. The tables below were worked by hand; each is built so that
a plausible wrong rule (the mean or the maximum instead of the minimum, raw scores instead
of normalised ones, normalising without the shift by the minimum) picks other roots.
"""

from __future__ import annotations

import numpy as np
import pytest

from mtpg.evolve.selection import candidates, min_max_over_roots, rankings, select, task_subsets

#: Normalised scores worked by hand: every column has its minimum 0 and maximum 1.
NORM = np.array(
    [
        [1.0, 0.0, 0.5],  # root 1
        [0.0, 1.0, 0.0],  # root 2
        [0.7, 0.7, 0.2],  # root 3
        [0.5, 0.95, 1.0],  # root 4
        [0.6, 0.6, 0.6],  # root 5
    ]
)
IDS = np.array([1, 2, 3, 4, 5], dtype=np.int64)
#: Raw scores with a different offset and scale per task, so normalising matters:
#: task 0 = 10 n, task 1 = 50 n - 200, task 2 = 2 n + 1.
RAW = np.stack([10 * NORM[:, 0], 50 * NORM[:, 1] - 200, 2 * NORM[:, 2] + 1], axis=1)

#: Subsets in claiming order and, by hand, each root's fitness (min over the subset) and
#: the champion (best fitness; ties to the younger root).
#:   subset    r1   r2   r3   r4   r5   champion
#:   (0)       1.0  0.0  0.7  0.5  0.6  1
#:   (1)       0.0  1.0  0.7  0.95 0.6  2
#:   (2)       0.5  0.0  0.2  1.0  0.6  4
#:   (0,1)     0.0  0.0  0.7  0.5  0.6  3   (mean: 4; raw minimum: 2)
#:   (0,2)     0.5  0.0  0.2  0.5  0.6  5
#:   (1,2)     0.0  0.0  0.2  0.95 0.6  4   (already kept by (2): still its champion)
#:   (0,1,2)   0.0  0.0  0.2  0.5  0.6  5   (mean: 4; maximum: 1..4)
CHAMPIONS = [1, 2, 4, 3, 5, 4, 5]
#: Elites with n_elite = 1: each subset's best root not kept by an earlier subset.
ELITES_1 = [[1], [2], [4], [3], [5], [], []]
#: Elites with n_elite = 2: (2) finds 4 taken, keeps 5; later subsets find all taken.
ELITES_2 = [[1, 3], [2, 4], [5], [], [], [], []]


def test_the_normalised_table_is_the_raw_one_min_max_normalised() -> None:
    assert np.allclose(min_max_over_roots(RAW), NORM)


def test_task_subsets_claim_single_tasks_first() -> None:
    assert task_subsets(3) == [(0,), (1,), (2,), (0, 1), (0, 2), (1, 2), (0, 1, 2)]


@pytest.mark.parametrize(("n_elite", "elites"), [(1, ELITES_1), (2, ELITES_2)])
def test_elites_and_champions_follow_the_hand_worked_table(n_elite, elites) -> None:
    got_elites, got_champions = select(IDS, RAW, task_subsets(3), n_elite)
    assert got_champions == CHAMPIONS
    assert got_elites == elites


def test_rankings_are_by_minimum_normalised_score() -> None:
    orders = rankings(IDS, RAW, task_subsets(3))
    ranked = [[int(IDS[i]) for i in order] for order in orders]
    assert ranked[3] == [3, 5, 4, 2, 1]  # (0,1): 0.7, 0.6, 0.5, then the tie 0/0 younger first
    assert ranked[6] == [5, 4, 3, 2, 1]


def test_the_multi_task_champion_is_not_the_best_on_average() -> None:
    # the mean would choose root 4 for (0,1) (0.725) and for (0,1,2); the rule is the minimum
    assert NORM[:, [0, 1]].mean(axis=1).argmax() + 1 == 4
    assert NORM.mean(axis=1).argmax() + 1 == 4
    _, champions = select(IDS, RAW, task_subsets(3), 1)
    assert champions[3] == 3 and champions[6] == 5


def test_population_normalisation_is_over_all_current_roots() -> None:
    # adding a root that sets a new minimum on task 1 changes every other root's normalised
    # score there; here it makes root 1 (best on task 0) the (0,1) champion.
    ids = np.append(IDS, 6)
    raw = np.vstack([RAW, [0.0, -1000.0, 1.0]])
    _, champions = select(ids, raw, task_subsets(3), 1)
    norm = min_max_over_roots(raw)
    assert norm[0, 1] == pytest.approx(800 / 850)  # root 1: (-200 + 1000) / (-150 + 1000)
    # (0,1): root 1 min(1.0, 0.94) = 0.94; root 3 min(0.7, 0.98) = 0.7; root 6 0
    assert champions[3] == 1


def test_a_task_where_every_root_ties_does_not_decide() -> None:
    raw = np.column_stack([RAW[:, 0], np.full(5, 7.0)])
    _, champions = select(IDS, raw, task_subsets(2), 1)
    assert champions == [1, 5, 1]  # the tied task gives everyone 1: (0,1) follows task 0


def test_candidates_are_the_best_surviving_roots_in_ranking_order() -> None:
    orders = rankings(IDS, RAW, task_subsets(3))
    kept = {1, 2, 3, 4}
    got = candidates(IDS, orders, kept, 3)
    assert got[3] == [3, 4, 2]  # (0,1) ranks 3, 5, 4, 2, 1; 5 did not survive
    assert got[0] == [1, 3, 4]
    assert candidates(IDS, orders, set(IDS.tolist()), 1) == [[c] for c in CHAMPIONS]
