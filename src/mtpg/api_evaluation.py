"""What ``mtpg.evaluate`` returns: a graph's scores on held-out episodes, as ``mtpg evaluate``.

The episodes, seeds and normalisation are those of the command (and of the run's own
test points): :func:`mtpg.evolve.heldout_test.evaluate_graph` plays them. A score that
cannot be given (no reference best for a task, a single-task champion no better than
random play) is NaN in :attr:`Evaluation.scores`, "n/a" in its text and ``null`` in its
JSON.
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from mtpg.evolve.heldout_test import TaskScore
    from mtpg.model import Population

__all__ = ["Evaluation", "fmt", "score_graph"]


def fmt(value: float | None, spec: str = ".3f") -> str:
    """``value`` formatted by ``spec``, or ``"n/a"`` when it is missing (None or NaN)."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return "n/a"
    return format(value, spec)


def _json_value(value: Any) -> Any:
    return None if isinstance(value, float) and math.isnan(value) else value


@dataclass(frozen=True)
class Evaluation(Mapping[str, "TaskScore"]):
    """Test scores of one graph, by task (a read-only mapping of task name to score).

    Attributes:
        source: What was evaluated (a run directory, a graph file, or a run in memory).
        scores: Each task's :class:`mtpg.evolve.heldout_test.TaskScore` (mean, std,
            normalised, teams per decision, the returns, ...).
        single: Per task, the test score of the run's own single-task champion at the
            same test point (runs only): the denominator of ``vs_single``.
        vs_single: Per task, the mean normalised against ``single`` (NaN where that
            champion plays no better than random).
        episodes: Held-out episodes per task.
        seed: Offset of the test seeds.
        no_memory: True when the graph ran without memory.
        memory: The same in words, and whether as evolved ("memory on (as evolved)").
    """

    source: str
    scores: dict[str, TaskScore]
    single: dict[str, float] = field(default_factory=dict)
    vs_single: dict[str, float] = field(default_factory=dict)
    episodes: int = 0
    seed: int = 0
    no_memory: bool = False
    memory: str = "memory on (as evolved)"

    def __getitem__(self, task: str) -> TaskScore:
        return self.scores[task]

    def __iter__(self) -> Iterator[str]:
        return iter(self.scores)

    def __len__(self) -> int:
        return len(self.scores)

    def to_dict(self) -> dict[str, dict[str, Any]]:
        """JSON-ready scores by task, as ``mtpg evaluate --json`` prints them (NaN: None)."""
        out = {}
        for task, score in self.scores.items():
            row: dict[str, Any] = {
                **score.as_dict(),
                "no_memory": self.no_memory,
                "memory": self.memory,
            }
            if task in self.single:
                row["single_task_champion"] = self.single[task]
            if task in self.vs_single:
                row["normalised_single_task"] = self.vs_single[task]
            out[task] = {k: _json_value(v) for k, v in row.items()}
        return out

    def to_json(self) -> str:
        """One strict JSON object (a missing score is ``null``, never ``NaN``)."""
        return json.dumps(self.to_dict(), allow_nan=False)

    def __str__(self) -> str:
        from mtpg.envs.taskset.episode_seeds import describe_held_out

        lines = [f"{self.source}: {describe_held_out(self.episodes, self.seed)}; {self.memory}"]
        width = max(22, *(len(t) for t in self.scores))
        head = f"{'task':<{width}} {'mean':>10} {'std':>9} {'normalised':>10} {'teams/dec':>9}"
        lines.append(head + (f" {'vs single':>9}" if self.vs_single else ""))
        for task, s in self.scores.items():
            line = (
                f"{task:<{width}} {fmt(s.mean):>10} {fmt(s.std):>9} {fmt(s.normalised):>10} "
                f"{fmt(s.teams_per_decision, '.2f'):>9}"
            )
            if self.vs_single:
                line += f" {fmt(self.vs_single.get(task)):>9}"
            lines.append(line)
        return "\n".join(lines)


def score_graph(
    source: str,
    graph: tuple[Population, int, dict[str, Any]],
    tasks: Sequence[str],
    episodes: int | None = None,
    seed: int = 0,
    workers: int = 1,
    memory: bool | None = None,
    references: Sequence[str] = (),
    tests: Sequence[Mapping[str, Any]] | None = None,
) -> Evaluation:
    """Tests one graph on held-out episodes (:func:`mtpg.evaluate` resolves its target).

    Args:
        source: What is evaluated, in words (the first line of the text).
        graph: ``(population, root, meta)``, as :func:`mtpg.io.load_graph` reads a file.
        tasks: Task names.
        episodes: Episodes per task (default 100).
        seed: Offset of the test seeds (episode k of a task uses seed 1,000,000 + seed + k).
        workers: Threads (results do not depend on it).
        memory: None: as evolved (``meta["no_memory"]``); else on/off.
        references: Given reference scores (a run's ``evaluation.references``).
        tests: A run's ``tests.csv`` rows: gives ``vs single`` where the run tested its
            single-task champions at the graph's generation.

    Raises:
        ValueError: Bad episodes, seed or workers, or an unknown task (one line).
        BudgetError: The episodes cannot fit in memory.
    """
    from mtpg._kernel_cache import refresh
    from mtpg.evolve.heldout_test import evaluate_graph

    pop, root, meta = graph
    names = list(tasks)
    if episodes is None:
        from mtpg.envs.taskset.episode_seeds import N_TEST_EPISODES

        episodes = N_TEST_EPISODES
    _check(names, episodes, seed, workers)
    table = _table(names, references, episodes)
    evolved = bool(meta.get("no_memory", False))
    no_memory = evolved if memory is None else not memory
    how = "as evolved" if no_memory == evolved else "overriding the evolved setting"
    words = f"memory {'off' if no_memory else 'on'} ({how})"
    refresh()  # kernels are about to run: the cache must match the sources
    scores = evaluate_graph(pop, root, names, episodes, seed, workers, no_memory, table.given)
    single: dict[str, float] = {}
    vs_single: dict[str, float] = {}
    if tests is not None:
        from mtpg.analysis.runs.loading import normalise_scores

        single = _single_task_scores(tests, names, int(meta.get("generation", -1)))
        means = {t: scores[t].mean for t in single}
        vs_single = normalise_scores(means, single, table) if single else {}
    return Evaluation(source, scores, single, vs_single, episodes, seed, no_memory, words)


def _check(tasks: list[str], episodes: int, seed: int, workers: int) -> None:
    """Refuses what ``mtpg evaluate`` refuses, in one line each."""
    from mtpg.envs.specs.contract import TASK_NAMES
    from mtpg.envs.taskset.variants import known
    from mtpg.limits import LIMITS

    if not 1 <= episodes <= LIMITS["episodes"]:
        raise ValueError(f"episodes must be in 1..{LIMITS['episodes']:,}, got {episodes}")
    if not 0 <= seed <= 2**62:
        raise ValueError(f"seed must be in 0..{2**62}, got {seed}")
    if not 1 <= workers <= LIMITS["workers"]:
        raise ValueError(f"workers must be in 1..{LIMITS['workers']}, got {workers}")
    unknown = [t for t in tasks if not known(t)]
    if unknown or not tasks:
        what = f"unknown task {unknown[0]!r}" if unknown else "no task"
        raise ValueError(f"{what}; choose from {', '.join(TASK_NAMES)}")


def _table(tasks: list[str], given: Sequence[str], episodes: int):
    """The task table, with the run's given reference scores of these tasks.

    Raises:
        BudgetError: The episodes cannot fit in memory (as ``mtpg evaluate`` refuses).
    """
    from mtpg.envs.specs.param_table import MAX_STEPS
    from mtpg.envs.taskset.task_table import TaskTable, parse_given
    from mtpg.limits import check_evaluation_fits

    table = TaskTable.from_names(tasks, [r for r in given if parse_given(r).task in tasks])
    longest = max([int(MAX_STEPS.max()), *(s.max_steps for s in table.specs)])
    check_evaluation_fits(len(tasks) * episodes, longest)
    return table


def _single_task_scores(
    tests: Sequence[Mapping[str, Any]], tasks: list[str], generation: int
) -> dict[str, float]:
    """Each task's single-task champion's test score, where the run tested at ``generation``."""
    out = {}
    for t in tasks:
        rows = [r for r in tests if r["subset"] == t and int(r["generation"]) == generation]
        if rows:
            out[t] = float(rows[-1][f"test_{t}"])
    return out
