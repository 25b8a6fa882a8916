"""The test protocol: roots x tasks x held-out episodes, and the scores it reports.

One function plays a test (:func:`play_test`): every root plays the same ``episodes``
held-out episodes of every task (seeds :func:`mtpg.envs.protocol.held_out_seeds`, disjoint
from training), deterministically, so testing draws nothing random and a test repeated on
the same graph gives the same numbers. The trainer tests its champions with it at every
test point (``tests.csv``); ``mtpg evaluate``, ``mtpg report`` and the analyses test a
graph with it through :func:`evaluate_graph`. :func:`play_episodes` is the same grid on
other seeds (the training episodes a champion was selected on).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from mtpg.engine.batch import Episodes, evaluate_roots
from mtpg.engine.compile import CompiledPopulation, compile_population
from mtpg.envs.protocol import held_out_seeds
from mtpg.envs.reference import normalise, reference_of
from mtpg.envs.variants import resolve
from mtpg.model.graph import Population

#: ``evaluate(compiled, roots, table, no_memory) -> (returns, result)``: how the episodes
#: are played (this machine's threads, or a run's evaluation backend).
Evaluate = Callable[[CompiledPopulation, list[int], Episodes, bool], tuple]


@dataclass(frozen=True)
class PlayedEpisodes:
    """What a test measured: one entry per root, task and episode.

    Attributes:
        roots: Root team ids, in the order played.
        task_ids: Task ids, in the order played.
        returns: float64 ``[roots, tasks, episodes]`` episode returns.
        steps: int64 ``[roots, tasks, episodes]`` decisions made.
        teams: int64 ``[roots, tasks, episodes]`` teams visited over those decisions.
    """

    roots: list[int]
    task_ids: list[int]
    returns: np.ndarray
    steps: np.ndarray
    teams: np.ndarray

    def mean_returns(self) -> np.ndarray:
        """float64 ``[roots, tasks]`` mean return over the episodes."""
        return self.returns.mean(axis=2)

    def teams_per_decision(self) -> np.ndarray:
        """float64 ``[roots]`` teams visited per decision over every task's episodes."""
        n = len(self.roots)
        return self.teams.reshape(n, -1).sum(axis=1) / self.steps.reshape(n, -1).sum(axis=1)


def local_evaluate(workers: int = 1) -> Evaluate:
    """Plays episodes on this machine's ``workers`` threads."""

    def evaluate(cp, roots, table, no_memory):
        return evaluate_roots(cp, roots, table, workers, no_memory)

    return evaluate


def play_episodes(
    pop: Population | CompiledPopulation,
    roots: Sequence[int],
    task_ids: Sequence[int],
    seeds: np.ndarray,
    no_memory: bool = False,
    evaluate: Evaluate | None = None,
) -> PlayedEpisodes:
    """Plays every root on the episodes ``seeds`` of every task.

    Args:
        pop: The population (or its compiled form) holding the roots.
        roots: Root team ids.
        task_ids: Task ids.
        seeds: int64 episode seeds, the same for every task.
        no_memory: Play with the no-memory ablation semantics.
        evaluate: How to play (default: one thread of this machine).

    Returns:
        The measurements, ``[roots, tasks, episodes]``.
    """
    cp = pop if isinstance(pop, CompiledPopulation) else compile_population(pop)
    roots, task_ids = list(roots), list(task_ids)
    table = Episodes.grid(task_ids, seeds)
    returns, result = (evaluate or local_evaluate())(cp, roots, table, no_memory)
    shape = (len(roots), len(task_ids), len(seeds))
    return PlayedEpisodes(
        roots,
        task_ids,
        np.asarray(returns).reshape(shape),
        np.asarray(result.steps).reshape(shape),
        np.asarray(result.teams).reshape(shape),
    )


def play_test(
    pop: Population | CompiledPopulation,
    roots: Sequence[int],
    task_ids: Sequence[int],
    episodes: int,
    seed: int = 0,
    no_memory: bool = False,
    evaluate: Evaluate | None = None,
) -> PlayedEpisodes:
    """The test: :func:`play_episodes` on ``episodes`` held-out episodes of every task.

    The seeds are :func:`mtpg.envs.protocol.held_out_seeds` ``(episodes, seed)``: ``seed``
    is their offset, 0 for a run's own test points.
    """
    seeds = held_out_seeds(episodes, seed)
    return play_episodes(pop, roots, task_ids, seeds, no_memory, evaluate)


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
    """Tests one root (:func:`play_test`) and scores it per task, raw and normalised.

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
    test = play_test(pop, [root], ids, episodes, seed, no_memory, local_evaluate(workers))
    returns, steps, teams = test.returns[0], test.steps[0], test.teams[0]
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
