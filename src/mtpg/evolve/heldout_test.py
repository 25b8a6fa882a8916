"""The test protocol: roots x tasks x held-out episodes, and the scores it reports.

One function plays a test (:func:`play_test`): every root plays the same ``episodes``
held-out episodes of every task (seeds :func:`mtpg.envs.taskset.episode_seeds.held_out_seeds`,
disjoint from training), deterministically, so testing draws nothing random and a test repeated on
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
from mtpg.envs.taskset.episode_seeds import held_out_seeds
from mtpg.envs.taskset.reference_scores import normalise, reference_of
from mtpg.envs.taskset.task_table import REGISTERED, GivenReference, TaskTable
from mtpg.model.graph import Population

#: ``evaluate(compiled, roots, table) -> (returns, result)``: how the episodes are played
#: (this machine's threads, or a run's evaluation backend). The memory ablation is the
#: compiled graph's (``compiled.no_memory``).
Evaluate = Callable[[CompiledPopulation, list[int], Episodes], tuple]


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

    def evaluate(cp, roots, table):
        return evaluate_roots(cp, roots, table, workers)

    return evaluate


def play_episodes(
    pop: Population | CompiledPopulation,
    roots: Sequence[int],
    task_ids: Sequence[int],
    seeds: np.ndarray,
    no_memory: bool | None = None,
    evaluate: Evaluate | None = None,
    table: TaskTable = REGISTERED,
) -> PlayedEpisodes:
    """Plays every root on the episodes ``seeds`` of every task.

    Args:
        pop: The population (or its compiled form) holding the roots.
        roots: Root team ids.
        task_ids: Task ids of ``table``.
        seeds: int64 episode seeds, the same for every task.
        no_memory: Play with the no-memory ablation semantics: how ``pop`` is compiled
            (:func:`~mtpg.engine.compile.compile_population`). ``None``: a compiled
            ``pop``'s own mode, memory on for a population.
        evaluate: How to play (default: one thread of this machine).
        table: The task table of the ids (the registered tasks by default).

    Returns:
        The measurements, ``[roots, tasks, episodes]``.
    """
    if isinstance(pop, CompiledPopulation):
        cp = pop.with_memory_mode(no_memory)
    else:
        cp = compile_population(pop, no_memory=bool(no_memory))
    roots, task_ids = list(roots), list(task_ids)
    grid = Episodes.grid(task_ids, seeds, table)
    returns, result = (evaluate or local_evaluate())(cp, roots, grid)
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
    no_memory: bool | None = None,
    evaluate: Evaluate | None = None,
    table: TaskTable = REGISTERED,
) -> PlayedEpisodes:
    """The test: :func:`play_episodes` on ``episodes`` held-out episodes of every task.

    The seeds are :func:`mtpg.envs.taskset.episode_seeds.held_out_seeds` ``(episodes, seed)``:
    ``seed`` is their offset, 0 for a run's own test points. ``task_ids`` are ids of ``table``.
    """
    seeds = held_out_seeds(episodes, seed)
    return play_episodes(pop, roots, task_ids, seeds, no_memory, evaluate, table)


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
        random: The random agent's score the normalisation used.
        reference_best: The reference best score it used.
    """

    task: str
    mean: float
    std: float
    episodes: int
    normalised: float
    teams_per_decision: float
    returns: np.ndarray
    random: float = float("nan")
    reference_best: float = float("nan")

    def as_dict(self) -> dict[str, float | int]:
        """JSON-ready summary (without the returns)."""
        return {
            "mean": self.mean,
            "std": self.std,
            "episodes": self.episodes,
            "normalised": self.normalised,
            "teams_per_decision": self.teams_per_decision,
            "random": self.random,
            "reference_best": self.reference_best,
        }


def evaluate_graph(
    pop: Population,
    root: int,
    tasks: list[str],
    episodes: int = 100,
    seed: int = 0,
    workers: int = 1,
    no_memory: bool = False,
    references: Sequence[str | GivenReference] = (),
) -> dict[str, TaskScore]:
    """Tests one root (:func:`play_test`) and scores it per task, raw and normalised.

    Args:
        pop: The population holding the graph.
        root: The root team id.
        tasks: Task names.
        episodes: Episodes per task.
        seed: Offset of the test seeds (see :func:`mtpg.envs.taskset.episode_seeds.held_out_seeds`).
        workers: Threads.
        no_memory: Evaluate with the no-memory ablation semantics.
        references: Reference scores given for variants among ``tasks`` (a run's
            ``evaluation.references`` entries); the others are normalised as
            :func:`mtpg.envs.taskset.reference_scores.reference_of` says.

    Returns:
        Scores by task name, in the order given.
    """
    table = TaskTable.from_names(tasks, references)
    ids = list(table.ids)
    test = play_test(pop, [root], ids, episodes, seed, no_memory, local_evaluate(workers), table)
    returns, steps, teams = test.returns[0], test.steps[0], test.teams[0]
    out = {}
    for k, (name, task) in enumerate(zip(tasks, ids, strict=True)):
        mean = float(returns[k].mean())
        ref = reference_of(task, table)
        out[name] = TaskScore(
            name,
            mean,
            float(returns[k].std()),
            episodes,
            float(normalise(task, mean, table=table)),
            float(teams[k].sum() / steps[k].sum()),
            returns[k],
            ref.random,
            ref.best,
        )
    return out
