"""Which champion of a run is reported: the one choice ``mtpg report`` and ``evaluate`` share.

The trainer chooses the champion of every task subset at each generation (by training
score, :func:`mtpg.evolve.selection.select`; or among the best few by validation score,
:mod:`mtpg.evolve.validation`) and writes the tested ones into ``tests/gen-NNNNNN/``. The
functions here never choose again: they say which of those files a run stands for and
read the scores that go with it.

- A run's champion (:func:`run_champion`): the all-task champion at the run's final test
  point (:func:`champion_path`); for a run without test results yet, the latest all-task
  champion in ``champions/``.
- Its single-task denominators (:func:`single_task_scores`): each task's own single-task
  champion at the same test point, tested on its task (read from ``tests.csv``).
"""

from __future__ import annotations

from pathlib import Path

from mtpg.analysis.runs.loading import RunData, load_run
from mtpg.io.runconfig import read_run_config
from mtpg.io.rundir import TESTS_DIR, TESTS_FILE, RunDir, champion_filename

#: How the champions are chosen, in words (printed on figures and pages).
CHAMPION_RULE = "champion = best root by training score at the final generation"


def champion_path(run: RunData, subset: tuple[str, ...] | None = None) -> Path:
    """Graph file of a subset's champion (default: all tasks) at the run's final test point."""
    names = run.tasks if subset is None else subset
    folder = run.path / TESTS_DIR / f"gen-{run.final_generation:06d}"
    return folder / champion_filename(tuple(names))


def tested_run(run_dir: str | Path) -> RunData | None:
    """The run's test results, or None when it has none yet (no or an empty ``tests.csv``)."""
    run_dir = Path(run_dir)
    if not (run_dir / TESTS_FILE).is_file():
        return None
    run = load_run(run_dir)
    return run if run.tests else None


def run_champion(run_dir: str | Path) -> Path:
    """The graph file a run directory's reported champion is in (see the module docstring).

    Raises:
        FileNotFoundError: When the run has no champion yet.
    """
    run_dir = Path(run_dir)
    run = tested_run(run_dir)
    if run is not None:
        path = champion_path(run)
    else:
        tasks = tuple(read_run_config(run_dir).evaluation.tasks)
        path = RunDir(run_dir).champions / champion_filename(tasks)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: the run has no champion yet")
    return path


def single_task_scores(run: RunData, tasks: tuple[str, ...] | list[str]) -> dict[str, float]:
    """Test score of each task's single-task champion on its task, at the final test point.

    The denominators of ``vs single``: chosen by training score, never by test score.
    Tasks the run did not train on are left out.
    """
    gen = run.final_generation
    return {t: float(run.row(t, gen)[f"test_{t}"]) for t in tasks if t in run.tasks}


def training_scores(run: RunData, path: Path) -> dict[str, float]:
    """Mean training return per task of a graph file, replayed on the run's training episodes.

    The episodes are those the graph was last scored on at its generation
    (:func:`mtpg.evolve.memorisation.champion_training_seeds`: the run's fixed training
    episodes, or the block of a run that redraws them). Deterministic, so equal to the
    score selection used (with ``evaluation.resample_mean``, to its last block's part);
    recomputed rather than read so that it does not depend on what a graph file's metadata
    holds.
    """
    from mtpg.evolve.heldout_test import play_episodes
    from mtpg.evolve.memorisation import champion_training_seeds
    from mtpg.io.serialize import load_graph

    pop, root, meta = load_graph(path)
    ev = run.config.evaluation
    generation = int(meta.get("generation", run.final_generation))
    seeds = champion_training_seeds(run.config, generation)
    table = run.task_table
    played = play_episodes(pop, [root], list(table.ids), seeds, ev.no_memory, table=table)
    means = played.returns[0].mean(axis=1)
    return {t: float(m) for t, m in zip(run.tasks, means, strict=True)}
