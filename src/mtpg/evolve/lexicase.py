"""Epsilon-lexicase choice of parent 1 over training episodes (beyond the paper; off).

With ``team.parent_selection = "lexicase"``, parent 1 of a subset's child is drawn from
that subset's elites by semi-dynamic epsilon-lexicase selection over the subset's training
episodes instead of uniformly. Sources: lexicase selection, Helmuth, Spector and Matheson,
"Solving Uncompromising Problems with Lexicase Selection", IEEE Transactions on
Evolutionary Computation 19(5), 2015; its epsilon form for continuous scores, La Cava,
Spector and Danai, "Epsilon-Lexicase Selection for Regression", GECCO 2016, and the
semi-dynamic variant of La Cava, Helmuth, Spector and Moore, "A Probabilistic and
Multi-Objective Analysis of Lexicase Selection and epsilon-Lexicase Selection",
Evolutionary Computation 27(3), 2019.

One draw: the cases (every (task, episode) of the subset) are shuffled; the candidates
start as the whole pool; case by case, only candidates whose return is at least the best
remaining candidate's minus ``epsilon`` of that case are kept, ``epsilon`` being the
median absolute deviation of the case's returns over the pool (computed once per pool);
when one candidate is left or the cases run out, one of those left is drawn uniformly.
Returns are compared within a case only, so no normalisation across tasks is needed.
Every random draw comes from the run's generator; with the option off (the paper) none
of this runs and the generator's stream is the paper's.
"""

from __future__ import annotations

import numpy as np


def case_epsilons(returns: np.ndarray) -> np.ndarray:
    """Median absolute deviation of every case's returns over the pool.

    Args:
        returns: float64 ``[n_pool, n_cases]``.

    Returns:
        float64 ``[n_cases]``.
    """
    median = np.median(returns, axis=0)
    return np.median(np.abs(returns - median), axis=0)


def lexicase_pick(returns: np.ndarray, epsilons: np.ndarray, rng: np.random.Generator) -> int:
    """One semi-dynamic epsilon-lexicase draw.

    Args:
        returns: float64 ``[n_pool, n_cases]`` per-case returns of the pool (higher is
            better).
        epsilons: float64 ``[n_cases]`` (:func:`case_epsilons` of the pool).
        rng: The run's generator.

    Returns:
        The row index of the chosen candidate.
    """
    alive = np.arange(returns.shape[0])
    for case in rng.permutation(returns.shape[1]):
        if len(alive) == 1:
            break
        column = returns[alive, case]
        alive = alive[column >= column.max() - epsilons[case]]
    return int(alive[int(rng.integers(0, len(alive)))])
