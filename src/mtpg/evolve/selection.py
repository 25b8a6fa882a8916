"""Multi-task selection over the power set of tasks (paper section 4.1 step 4)."""

from __future__ import annotations

from itertools import combinations

import numpy as np


def task_subsets(n_tasks: int) -> list[tuple[int, ...]]:
    """Every non-empty subset of ``range(n_tasks)``, smallest first.

    The order decides which subset keeps a root that is among the best of several:
    single tasks claim their elites first, the full set last.
    """
    return [s for k in range(1, n_tasks + 1) for s in combinations(range(n_tasks), k)]


def min_max_over_roots(scores: np.ndarray) -> np.ndarray:
    """Min-max normalises each task's mean scores over the current roots.

    Relative to the population (0: the worst root on the task, 1: the best), unlike
    :func:`mtpg.envs.taskset.reference_scores.normalise`, which scales a score between a
    task's fixed random and best reference scores.

    Args:
        scores: float64 ``[n_roots, n_tasks]`` mean training scores.

    Returns:
        float64 ``[n_roots, n_tasks]`` in [0, 1]; a task where all roots tie gives 1.
    """
    lo = scores.min(axis=0)
    span = scores.max(axis=0) - lo
    out = np.ones_like(scores)
    varied = span > 0
    out[:, varied] = (scores[:, varied] - lo[varied]) / span[varied]
    return out


def rankings(
    root_ids: np.ndarray, scores: np.ndarray, subsets: list[tuple[int, ...]]
) -> list[np.ndarray]:
    """Every subset's ranking of the roots by its fitness, best first.

    A subset's fitness of a root is its minimum normalised score (:func:`min_max_over_roots`) over
    the subset's tasks (paper section 4.1); ties go to the younger root (higher id).

    Args:
        root_ids: int64 ``[n_roots]`` team ids.
        scores: float64 ``[n_roots, n_tasks]`` mean training scores.
        subsets: Task subsets.

    Returns:
        For each subset, int ``[n_roots]`` row indices into ``root_ids``, best first.
    """
    norm = min_max_over_roots(scores)
    out = []
    for subset in subsets:
        fitness = norm[:, list(subset)].min(axis=1)
        out.append(np.lexsort((-root_ids, -fitness)))
    return out


def select(
    root_ids: np.ndarray, scores: np.ndarray, subsets: list[tuple[int, ...]], n_elite: int
) -> tuple[list[list[int]], list[int]]:
    """Chooses the elites of every task subset and its champion.

    Roots are ranked by each subset's fitness (:func:`rankings`). Each subset keeps its
    ``n_elite`` best roots not already kept by an earlier subset.

    Args:
        root_ids: int64 ``[n_roots]`` team ids.
        scores: float64 ``[n_roots, n_tasks]`` mean training scores.
        subsets: Task subsets, in claiming order.
        n_elite: Roots kept per subset.

    Returns:
        The elites of each subset (team ids, best first) and each subset's champion
        (its best root, whether or not an earlier subset kept it).
    """
    kept = np.zeros(len(root_ids), dtype=bool)
    elites, champions = [], []
    for order in rankings(root_ids, scores, subsets):
        champions.append(int(root_ids[order[0]]))
        free = order[~kept[order]][:n_elite]
        kept[free] = True
        elites.append([int(root_ids[i]) for i in free])
    return elites, champions


def candidates(
    root_ids: np.ndarray, orders: list[np.ndarray], kept: set[int], k: int
) -> list[list[int]]:
    """Each subset's best ``k`` surviving roots by training fitness, best first.

    Args:
        root_ids: int64 ``[n_roots]`` team ids.
        orders: The subsets' rankings (:func:`rankings`).
        kept: The roots that survive selection (every subset's elites).
        k: Candidates per subset.

    Returns:
        Team ids per subset; the first is the subset's champion by training fitness.
    """
    out = []
    for order in orders:
        chosen: list[int] = []
        for i in order:
            if int(root_ids[i]) in kept:
                chosen.append(int(root_ids[i]))
                if len(chosen) == k:
                    break
        out.append(chosen)
    return out
