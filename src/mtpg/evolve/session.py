"""A training run bound to a run directory: metrics, checkpoints, champions, resume.

A run killed at any moment resumes from its last checkpoint: metrics rows written after
it are dropped and the generations are run again, reproducing them exactly (all but the
timing columns), because the checkpoint holds the whole state including the generator.
"""

from __future__ import annotations

import time
import tomllib
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

from mtpg.config import ConfigError, RunConfig, from_dict, to_dict, to_toml
from mtpg.evolve.persist import state_from_payload, state_to_payload
from mtpg.evolve.trainer import Trainer, metric_columns, test_columns
from mtpg.io.checkpoint import (
    CheckpointError,
    checkpoint_path,
    latest_checkpoint,
    load_checkpoint,
    prune_checkpoints,
    save_checkpoint,
)
from mtpg.io.rundir import (
    MetricsWriter,
    RunDir,
    champion_filename,
    init_run_dir,
    write_champions,
)
from mtpg.io.serialize import FormatError, save_graph

#: Test results of the champions, one row per task subset and test point.
TESTS_FILE = "tests.csv"
#: Graph files of the tested champions (full task set and single tasks) per test point.
TESTS_DIR = "tests"
#: Settings a resumed run may change: they do not alter what the run computes.
RESUMABLE_CHANGES = ("generations", "workers", "checkpoint_interval")

Callback = Callable[[dict[str, float], Trainer], None]


def read_run_config(run_dir: str | Path) -> RunConfig:
    """Reads the resolved configuration stored in a run directory."""
    path = RunDir(Path(run_dir)).config
    try:
        return from_dict(tomllib.loads(path.read_text(encoding="utf-8")))
    except (OSError, tomllib.TOMLDecodeError, ConfigError) as exc:
        raise ConfigError(f"{path}: {exc}") from exc


class Session:
    """Runs a :class:`Trainer` inside a run directory.

    Args:
        run_dir: The run directory.
        config: Configuration of a new run; for a resumed run, None or a configuration
            that differs from the stored one only in :data:`RESUMABLE_CHANGES`.
        resume: Continue the run in ``run_dir`` from its last checkpoint.
    """

    def __init__(
        self, run_dir: str | Path, config: RunConfig | None = None, resume: bool = False
    ) -> None:
        if resume:
            stored = read_run_config(run_dir)
            if config is not None:
                _check_compatible(stored, config)
                stored = replace(stored, **{k: getattr(config, k) for k in RESUMABLE_CHANGES})
            config = stored
        elif config is None:
            raise ConfigError("a new run needs a configuration")
        state = None
        ckpt = latest_checkpoint(run_dir) if resume else None
        if ckpt is not None:  # read before anything is written: a bad file changes nothing
            try:
                state, _ = state_from_payload(load_checkpoint(ckpt))
            except FormatError as exc:
                raise CheckpointError(f"{ckpt}: not a valid run state: {exc}") from exc
            state.config = config
        self.run = init_run_dir(run_dir, to_toml(config), resume=resume)
        self.trainer = Trainer(config, state)
        self.config = config
        self.metrics = MetricsWriter(self.run.metrics, metric_columns(config.evaluation.tasks))
        self.metrics.truncate_after(self.trainer.state.generation)
        self.tests = MetricsWriter(
            self.run.path / TESTS_FILE, test_columns(config.evaluation.tasks)
        )
        self.tests.truncate_after(self.trainer.state.generation)
        self.saved_generation = self.trainer.state.generation

    def run_all(self, on_generation: Callback | None = None) -> None:
        """Runs the remaining generations; checkpoints every interval and on any exit."""
        try:
            while not self.trainer.done:
                row = self.trainer.run_generation()
                if self.trainer.test_due():
                    start = time.perf_counter()
                    self.test()
                    row["t_test"] = time.perf_counter() - start
                    row["t_total"] += row["t_test"]
                self.metrics.append(row)
                if on_generation is not None:
                    on_generation(row, self.trainer)
                if self.trainer.state.generation % self.config.checkpoint_interval == 0:
                    self.checkpoint()
        finally:
            if self.trainer.state.generation != self.saved_generation:
                self.checkpoint()
            self.metrics.close()
            self.tests.close()

    def test(self) -> list[dict[str, float | int | str]]:
        """Tests every subset's champion and keeps the graphs of the full set and each task.

        Rows go to ``tests.csv``; graph files to ``tests/gen-NNNNNN/<subset>.json``.
        """
        state = self.trainer.state
        rows = self.trainer.test_champions()
        for row in rows:
            self.tests.append(row)
        keep = {}
        n = len(self.config.evaluation.tasks)
        for k, row in enumerate(rows):
            names = self.trainer.subset_names(k)
            if len(names) in (1, n):
                meta = {
                    "generation": state.generation,
                    "seed": self.config.seed,
                    "test": {t: row[f"test_{t}"] for t in self.config.evaluation.tasks},
                    "test_episodes": self.config.evaluation.test_episodes,
                    "no_memory": self.config.evaluation.no_memory,
                }
                keep[names] = (state.population, int(row["root"]), meta)
        folder = self.run.path / TESTS_DIR / f"gen-{state.generation:06d}"
        for names, (pop, root, meta) in keep.items():
            folder.mkdir(parents=True, exist_ok=True)
            save_graph(folder / champion_filename(names), pop, root, meta)
        return rows

    def checkpoint(self) -> Path:
        """Writes the champions and an atomic checkpoint of the current generation."""
        state = self.trainer.state
        champions = {}
        for k, root in enumerate(state.champions):
            names = self.trainer.subset_names(k)
            scores = state.scores[root]
            meta = {
                "generation": state.generation,
                "seed": self.config.seed,
                "train_scores": {
                    t: float(scores[self.config.evaluation.tasks.index(t)]) for t in names
                },
                "no_memory": self.config.evaluation.no_memory,
            }
            champions[names] = (state.population, root, meta)
        write_champions(self.run.path, champions)
        path = checkpoint_path(self.run.path, state.generation)
        save_checkpoint(path, state_to_payload(state))
        prune_checkpoints(self.run.path, keep=2)
        self.saved_generation = state.generation
        return path


def _check_compatible(stored: RunConfig, given: RunConfig) -> None:
    a, b = to_dict(stored), to_dict(given)
    for key in RESUMABLE_CHANGES:
        a.pop(key)
        b.pop(key)
    if a != b:
        diff = [k for k in a if a[k] != b[k]]
        raise ConfigError(
            f"cannot resume with a different configuration (differs in {', '.join(diff)}); "
            f"only {', '.join(RESUMABLE_CHANGES)} may change"
        )
