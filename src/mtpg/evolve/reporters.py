"""The reporters that write a run directory: metrics rows, test results, checkpoints.

Each is a :class:`~mtpg.evolve.trainer.Reporter` that :func:`~mtpg.evolve.trainer.train`
hands every completed generation. The run directory's commit is the checkpoint
(:class:`CheckpointReporter`): champion files, then the checkpoint file, written
atomically; rows and test files of later generations are rolled back on resume (see
:mod:`mtpg.evolve.session`). The loop itself, :class:`Generation` and :class:`Reporter`
live in :mod:`mtpg.evolve.trainer` and are importable from here as before.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from mtpg._faults import point
from mtpg.config import EvaluationConfig
from mtpg.evolve.columns import held_out_columns, metric_columns
from mtpg.evolve.persist import state_to_payload
from mtpg.evolve.trainer import Generation, Reporter, Trainer, generations, train
from mtpg.io.checkpoint import checkpoint_path, prune_checkpoints, save_checkpoint
from mtpg.io.rundir import TESTS_DIR, TESTS_FILE, MetricsWriter, champion_filename, write_champions
from mtpg.io.serialize import save_graph

__all__ = [
    "TESTS_DIR",
    "TESTS_FILE",
    "CallbackReporter",
    "CheckpointReporter",
    "Generation",
    "MetricsReporter",
    "Reporter",
    "TestsReporter",
    "champion_graphs",
    "generations",
    "train",
    "write_test_graphs",
]


class CallbackReporter(Reporter):
    """Calls ``fn(metrics_row, trainer)`` after each generation (e.g. a progress display)."""

    def __init__(self, fn: Callable[[dict[str, float], Trainer], None]) -> None:
        self.fn = fn

    def generation(self, gen: Generation, trainer: Trainer) -> None:
        """Calls the function."""
        self.fn(gen.metrics, trainer)


class MetricsReporter(Reporter):
    """Appends each generation's row to ``metrics.csv``."""

    def __init__(
        self, path: Path, tasks: tuple[str, ...], evaluation: EvaluationConfig | None = None
    ) -> None:
        self.writer = MetricsWriter(path, metric_columns(tasks, evaluation))

    def generation(self, gen: Generation, trainer: Trainer) -> None:
        """Appends the row."""
        self.writer.append(gen.metrics)
        point("metrics", gen.number)

    def close(self) -> None:
        """Closes the file."""
        self.writer.close()


class TestsReporter(Reporter):
    """Writes each test point's rows to ``tests.csv`` and champion graphs to ``tests/``.

    The graphs of the full-set and single-task champions go to
    ``tests/gen-NNNNNN/<subset>.json``.
    """

    __test__ = False  # not a pytest test class

    def __init__(self, run_path: Path, tasks: tuple[str, ...]) -> None:
        self.run_path = run_path
        self.writer = MetricsWriter(run_path / TESTS_FILE, held_out_columns(tasks))

    def generation(self, gen: Generation, trainer: Trainer) -> None:
        """Writes the rows and graphs of a test point."""
        if gen.tests is None:
            return
        for row in gen.tests:
            self.writer.append(row)
        point("test", gen.number)
        write_test_graphs(self.run_path, trainer, gen.tests)

    def close(self) -> None:
        """Closes the file."""
        self.writer.close()


def write_test_graphs(run_path: Path, trainer: Trainer, rows: list[dict[str, Any]]) -> None:
    """Writes the graphs of the tested full-set and single-task champions."""
    state, cfg = trainer.state, trainer.config
    tasks = cfg.evaluation.tasks
    folder = run_path / TESTS_DIR / f"gen-{state.generation:06d}"
    bodies: dict = {}  # a champion of several subsets is rendered once
    for k, row in enumerate(rows):
        names = trainer.subset_names(k)
        if len(names) not in (1, len(tasks)):
            continue
        meta = {
            "generation": state.generation,
            "seed": cfg.seed,
            "test": {t: row[f"test_{t}"] for t in tasks},
            "test_episodes": cfg.evaluation.test_episodes,
            "no_memory": cfg.evaluation.no_memory,
        }
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / champion_filename(names)
        save_graph(path, state.population, int(row["root"]), meta, bodies)


def champion_graphs(trainer: Trainer) -> dict[tuple[str, ...], tuple[Any, int, dict[str, Any]]]:
    """The champion of every task subset with its meta, as ``write_champions`` takes them."""
    state, cfg = trainer.state, trainer.config
    out = {}
    for k, root in enumerate(state.champions):
        names = trainer.subset_names(k)
        scores = state.scores[root]
        meta = {
            "generation": state.generation,
            "seed": cfg.seed,
            "train_scores": {t: float(scores[cfg.evaluation.tasks.index(t)]) for t in names},
            "no_memory": cfg.evaluation.no_memory,
        }
        if root in state.validation:  # chosen on the validation episodes (beyond the paper)
            val = state.validation[root]
            meta["validation_scores"] = {
                t: float(val[cfg.evaluation.tasks.index(t)]) for t in names
            }
        out[names] = (state.population, root, meta)
    return out


class CheckpointReporter(Reporter):
    """Commits the run every ``interval`` generations and at the end.

    A commit writes the champion files, then the checkpoint (atomically: its rename is
    the commit point), then prunes older checkpoints.
    """

    def __init__(self, run_path: Path, interval: int, saved_generation: int) -> None:
        self.run_path = run_path
        self.interval = interval
        self.saved_generation = saved_generation

    def generation(self, gen: Generation, trainer: Trainer) -> None:
        """Commits when the generation is on the interval."""
        if gen.number % self.interval == 0:
            self.commit(trainer)

    def end(self, trainer: Trainer) -> None:
        """Commits the last generation unless already committed."""
        if trainer.state.generation != self.saved_generation:
            self.commit(trainer)

    def commit(self, trainer: Trainer) -> Path:
        """Writes champions and checkpoint of the current (complete) generation."""
        state = trainer.state
        gen = state.generation
        write_champions(self.run_path, champion_graphs(trainer))
        point("commit", gen)
        path = checkpoint_path(self.run_path, gen)
        save_checkpoint(path, state_to_payload(state))  # passes point("checkpoint", gen)
        point("committed", gen)
        prune_checkpoints(self.run_path, keep=2)
        self.saved_generation = gen
        return path
