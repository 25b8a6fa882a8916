"""Champions chosen on validation episodes (beyond the paper; off in ``paper`` and ``demo``).

The paper reports the test scores of champions chosen by training score. With
``evaluation.validation_episodes = V > 0``, every generation each subset's champion is
chosen among its best ``evaluation.validation_top_k`` surviving roots by training fitness
(:func:`mtpg.evolve.selection.candidates`) by a score on ``V`` validation episodes per task
(seeds :func:`mtpg.envs.taskset.episode_seeds.validation_seeds`, disjoint from training and test).

The rule for a subset is the paper's multi-task rule, the minimum over the subset's tasks
of a normalised score, with one difference forced by the few candidates: scores are
normalised against the task's fixed reference, ``(score - random) / (best - random)``
(:func:`mtpg.envs.taskset.reference_scores.normalise`, the scale every reported test score uses),
not min-max over the candidates. Min-max over a handful of roots would give every task's worst
candidate 0 and so make most multi-task fitnesses 0; a fixed scale ranks candidates the
same whichever others stand beside them. For a single task the rule orders candidates by
their mean validation score. Ties go to the better root by training fitness.

Selection (elites, parents) never sees validation scores: only the choice of the reported
champion does. A root's validation score is measured once (the validation episodes never
change) and kept with the run state while the root lives.
"""

from __future__ import annotations

import numpy as np

from mtpg.envs.taskset.reference_scores import normalise
from mtpg.envs.taskset.task_table import REGISTERED, TaskTable


def validation_fitness(
    scores: np.ndarray,
    subset: tuple[int, ...],
    task_ids: list[int],
    table: TaskTable = REGISTERED,
) -> np.ndarray:
    """Validation fitness of candidates for one subset.

    Args:
        scores: float64 ``[n_candidates, n_tasks]`` mean validation scores (columns in
            ``task_ids`` order).
        subset: Column indices of the subset's tasks.
        task_ids: Task id of each column.
        table: The task table of the ids (their reference scores).

    Returns:
        float64 ``[n_candidates]``: the minimum over the subset's tasks of the
        reference-normalised score.
    """
    norm = np.stack([normalise(task_ids[j], scores[:, j], table=table) for j in subset], axis=1)
    return norm.min(axis=1)


def choose(
    candidates: list[list[int]],
    validation: dict[int, np.ndarray],
    subsets: list[tuple[int, ...]],
    task_ids: list[int],
    table: TaskTable = REGISTERED,
) -> list[int]:
    """Each subset's champion: its candidate of highest validation fitness.

    Args:
        candidates: Per subset, team ids best first by training fitness.
        validation: Mean validation score per task of every candidate.
        subsets: Task subsets (column indices), in the order of ``candidates``.
        task_ids: Task id of each score column.
        table: The task table of the ids.

    Returns:
        One team id per subset; ties go to the earlier candidate.
    """
    champions = []
    for cands, subset in zip(candidates, subsets, strict=True):
        scores = np.array([validation[r] for r in cands])
        fitness = validation_fitness(scores, subset, task_ids, table)
        champions.append(cands[int(np.argmax(fitness))])  # argmax: first of equals
    return champions
