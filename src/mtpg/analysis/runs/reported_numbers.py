"""The one definition of every number the report, ``mtpg evaluate`` and the HTML page show.

For each run:

- **Final point**: the run's last test point, which is its last generation (the trainer
  always tests there, whatever ``test_interval``).
- **All-task champion**: the root the multi-task selection chose for the set of all active
  tasks at that generation, i.e. the best root by *training* score (the minimum over tasks
  of the min-max normalised training score); its graph is
  ``tests/gen-NNNNNN/<all tasks>.json``.
- **Test score**: its mean return over the run's ``evaluation.test_episodes`` held-out
  episodes per task (seeds from :func:`mtpg.envs.taskset.episode_seeds.held_out_seeds`, offset 0),
  as written to ``tests.csv``; ``mtpg evaluate RUN`` replays the same graph on the same episodes.
- **Normalised (reference)**: ``(test - random) / (reference best - random)``.
- **Single-task denominator**: the run's own single-task champion of the task at the same
  generation, again chosen by training score (never by test score), and its test score on
  that task; ``vs single`` is ``(test - random) / (that score - random)``, undefined (NaN)
  when that champion does no better than random play.
- **Best run** of a group (the black line of Fig. 4, the bars of Figs. 5-7): the run
  whose all-task champion has the highest minimum over tasks of its reference-normalised
  *training* score (ties, e.g. a task no run has learnt, broken by the highest mean), so no
  test result decides which run is shown as best.

Every figure prints these choices (champion, generation, episodes, denominator). Which
graph file is a run's champion, and its training and single-task scores, come from
:mod:`mtpg.analysis.runs.champions`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mtpg.analysis.runs.champions import (
    CHAMPION_RULE,
    champion_path,
    single_task_scores,
    training_scores,
)
from mtpg.analysis.runs.loading import RunData, normalise_scores, reference_best
from mtpg.envs.taskset.episode_seeds import describe_held_out

#: How the best run is chosen, in words.
BEST_RUN_RULE = (
    "Best run = highest minimum (over tasks) reference-normalised training score of its "
    "all-task champion, ties broken by the highest mean"
)
#: The single-task denominator, in words.
SINGLE_RULE = (
    "1 = the run's own single-task champion of the task at the same generation "
    "(selected by training score)"
)


@dataclass(frozen=True)
class RunNumbers:
    """The reported numbers of one run (see the module docstring for each definition).

    Attributes:
        run: The run.
        generation: The final test point.
        root: Root team id of the all-task champion.
        graph_teams: Teams in its graph.
        test: Test score per task of the all-task champion.
        train: Training score per task of the all-task champion.
        single: Test score of each task's single-task champion on its own task.
        normalised: ``test`` normalised against the reference best.
        vs_single: ``test`` normalised against ``single`` (NaN where undefined).
        train_normalised: ``train`` normalised against the reference best.
    """

    run: RunData
    generation: int
    root: int
    graph_teams: int
    test: dict[str, float]
    train: dict[str, float]
    single: dict[str, float]
    normalised: dict[str, float]
    vs_single: dict[str, float]
    train_normalised: dict[str, float]

    @property
    def episodes(self) -> int:
        """Held-out episodes per task behind each test score."""
        return self.run.test_episodes

    @property
    def selection_score(self) -> tuple[float, float]:
        """The best run's key: min, then mean, of the normalised training scores."""
        values = list(self.train_normalised.values())
        return float(min(values)), float(np.mean(values))


def run_numbers(run: RunData) -> RunNumbers:
    """Computes the reported numbers of a run (see the module docstring)."""
    gen = run.final_generation
    row = run.row(run.full_set, gen)
    test = {t: float(row[f"test_{t}"]) for t in run.tasks}
    single = single_task_scores(run, run.tasks)
    path = champion_path(run)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: the champion graph of the final test point is missing")
    train = training_scores(run, path)
    table = run.task_table
    ref = reference_best(table)
    return RunNumbers(
        run=run,
        generation=gen,
        root=int(row["root"]),
        graph_teams=int(row["graph_teams"]),
        test=test,
        train=train,
        single=single,
        normalised=normalise_scores(test, ref, table),
        vs_single=normalise_scores(test, single, table),
        train_normalised=normalise_scores(train, ref, table),
    )


def best_of(numbers: list[RunNumbers]) -> RunNumbers:
    """The best run by training score (:data:`BEST_RUN_RULE`); ties go to the first."""
    return max(numbers, key=lambda n: n.selection_score)


def best_single_task(numbers: list[RunNumbers]) -> dict[str, float]:
    """Per task, the best single-task champion's test score over ``numbers``' runs.

    The shared denominator of the paper's Fig. 7 and of the results page's comparisons:
    every experiment is measured against the same scores, so one run's weak single-task
    champion does not inflate its own ratios.
    """
    tasks = numbers[0].run.tasks
    return {t: max(n.single[t] for n in numbers) for t in tasks}


def describe(numbers: list[RunNumbers]) -> str:
    """One line naming the champion, generation(s) and episodes behind a set of numbers."""
    gens = sorted({n.generation for n in numbers})
    eps = sorted({n.episodes for n in numbers})
    gen_text = f"generation {gens[0]}" if len(gens) == 1 else f"generations {gens}"
    ep_text = (
        describe_held_out(eps[0])
        if len(eps) == 1
        else f"{eps} held-out episodes per task (differs between runs)"
    )
    return f"All-task {CHAMPION_RULE} ({gen_text}); test score = mean return over {ep_text}."
