import numpy as np

from mtpg.evolve.selection import min_max_over_roots, select, task_subsets


def test_subsets_power_set_order():
    subs = task_subsets(3)
    assert len(subs) == 7 and subs[:3] == [(0,), (1,), (2,)] and subs[-1] == (0, 1, 2)
    assert len(task_subsets(6)) == 63


def test_min_max_over_roots_and_ties():
    scores = np.array([[0.0, 5.0], [10.0, 5.0], [5.0, 5.0]])
    norm = min_max_over_roots(scores)
    assert norm[:, 0].tolist() == [0.0, 1.0, 0.5]
    assert norm[:, 1].tolist() == [1.0, 1.0, 1.0]  # all tie: everyone 1


def test_select_min_normalised_fitness_and_disjoint_elites():
    ids = np.array([10, 11, 12, 13])
    scores = np.array(
        [
            [1.0, 0.0],  # best task 0 only
            [0.0, 1.0],  # best task 1 only
            [0.6, 0.6],  # best generalist
            [0.5, 0.5],
        ]
    )
    elites, champions = select(ids, scores, task_subsets(2), n_elite=1)
    assert elites == [[10], [11], [12]]
    assert champions == [10, 11, 12]
    elites, champions = select(ids, scores, task_subsets(2), n_elite=2)
    # task 0 keeps 10 and 12; task 1 keeps 11 and (12 taken) 13; the pair gets the rest
    assert elites == [[10, 12], [11, 13], []]
    assert champions[2] == 12


def test_ties_go_to_the_younger_root():
    ids = np.array([3, 7, 5])
    scores = np.array([[1.0], [1.0], [0.0]])
    elites, champions = select(ids, scores, task_subsets(1), n_elite=1)
    assert champions == [7] and elites == [[7]]
