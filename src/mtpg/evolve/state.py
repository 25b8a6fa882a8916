"""The state of a run: everything it needs to continue exactly as if never interrupted.

:class:`~mtpg.evolve.trainer.Trainer` advances it one generation at a time and
:mod:`mtpg.evolve.persist` turns it into a checkpoint and back.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mtpg.config import RunConfig
from mtpg.model.graph import Population


@dataclass
class TrainerState:
    """Everything a run needs to continue exactly as if never interrupted.

    Attributes:
        config: The run configuration.
        generation: Generations completed (0 before initialisation).
        population: Teams, programs and banks.
        scores: Mean training score per active task of every evaluated root.
        elites: Elite root ids of each task subset (``task_subsets`` order).
        champions: Best root id of each task subset.
        rng: The generator of every random draw of the run.
        validation: Mean validation score per active task of every root measured on the
            validation episodes (only with ``evaluation.validation_episodes > 0``).
        returns: Training return of every root per task and episode, ``[n_tasks,
            train_episodes]`` (only with ``team.parent_selection = "lexicase"``).
        blocks: Training blocks each root has played and the sum of its scores on them,
            whose quotient is its score (only with ``evaluation.resample_mean``).
    """

    config: RunConfig
    generation: int
    population: Population
    scores: dict[int, np.ndarray]
    elites: list[list[int]]
    champions: list[int]
    rng: np.random.Generator
    validation: dict[int, np.ndarray] = field(default_factory=dict)
    returns: dict[int, np.ndarray] = field(default_factory=dict)
    blocks: dict[int, tuple[int, np.ndarray]] = field(default_factory=dict)

    @classmethod
    def new(cls, config: RunConfig) -> TrainerState:
        """The state of a run that has not started."""
        rng = np.random.default_rng(np.random.SeedSequence(config.seed))
        return cls(config, 0, Population(), {}, [], [], rng)
