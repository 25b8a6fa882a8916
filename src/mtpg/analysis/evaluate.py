"""Test scores of a program graph on unseen episodes, raw and normalised."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mtpg.engine.batch import Episodes, evaluate_roots
from mtpg.engine.compile import compile_population
from mtpg.envs.protocol import held_out_seeds
from mtpg.envs.reference import normalise, reference_of
from mtpg.envs.variants import resolve
from mtpg.model.graph import Population


@dataclass(frozen=True)
class TaskScore:
    """Test result of one graph on one task.

    Attributes:
        task: Task name.
        mean: Mean episode return.
        std: Standard deviation of the returns.
        episodes: Number of episodes.
        normalised: ``(mean - random) / (reference best - random)``.
        teams_per_decision: Mean teams visited per decision.
        returns: The episode returns.
    """

    task: str
    mean: float
    std: float
    episodes: int
    normalised: float
    teams_per_decision: float
    returns: np.ndarray

    def as_dict(self) -> dict[str, float | int]:
        """JSON-ready summary (without the returns)."""
        return {
            "mean": self.mean,
            "std": self.std,
            "episodes": self.episodes,
            "normalised": self.normalised,
            "teams_per_decision": self.teams_per_decision,
            "random": reference_of(self.task).random,
            "reference_best": reference_of(self.task).best,
        }


def evaluate_graph(
    pop: Population,
    root: int,
    tasks: list[str],
    episodes: int = 100,
    seed: int = 0,
    workers: int = 1,
    no_memory: bool = False,
) -> dict[str, TaskScore]:
    """Plays ``episodes`` test episodes of every task with one root.

    Args:
        pop: The population holding the graph.
        root: The root team id.
        tasks: Task names.
        episodes: Episodes per task.
        seed: Offset of the test seeds (see :func:`mtpg.envs.protocol.held_out_seeds`).
        workers: Threads.
        no_memory: Evaluate with the no-memory ablation semantics.

    Returns:
        Scores by task name, in the order given.
    """
    ids = [resolve(t) for t in tasks]
    table = Episodes.grid(ids, held_out_seeds(episodes, seed))
    returns, result = evaluate_roots(compile_population(pop), [root], table, workers, no_memory)
    returns = returns.reshape(len(ids), episodes)
    steps = result.steps.reshape(len(ids), episodes)
    teams = result.teams.reshape(len(ids), episodes)
    out = {}
    for k, (name, task) in enumerate(zip(tasks, ids, strict=True)):
        mean = float(returns[k].mean())
        out[name] = TaskScore(
            name,
            mean,
            float(returns[k].std()),
            episodes,
            float(normalise(task, mean)),
            float(teams[k].sum() / steps[k].sum()),
            returns[k],
        )
    return out
