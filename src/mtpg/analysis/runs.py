"""Loading finished runs and computing the normalised scores of paper section 5.

``normalised = (score - random) / (best - random)``: 0 is random play; ``best`` is either
the best single-task champion of the same run (Figs. 4 and 6) or the reference best of the
task (Fig. 5).
"""

from __future__ import annotations

import csv
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from mtpg.config import RunConfig
from mtpg.envs.core import TASK_NAMES
from mtpg.envs.reference import REFERENCE, normalise
from mtpg.evolve.session import TESTS_FILE, read_run_config


def experiment_label(config: RunConfig) -> str:
    """Names the ablation a configuration stands for (section 5.2), or ``"TPG"``."""
    if config.evaluation.no_memory:
        return "TPG-NoMemory"
    if config.team.p_atomic == 1.0:
        return "TPG-NoHierarchy"
    if config.team.p_crossover == 0.0:
        return "TPG-NoXover"
    return "TPG"


@dataclass
class RunData:
    """A run directory's test results.

    Attributes:
        path: The run directory.
        config: Its configuration.
        tests: ``tests.csv`` rows with numbers parsed.
        label: Experiment label (see :func:`experiment_label`).
    """

    path: Path
    config: RunConfig
    tests: list[dict[str, float | str]] = field(default_factory=list)
    label: str = "TPG"

    @property
    def tasks(self) -> tuple[str, ...]:
        """Active task names."""
        return self.config.evaluation.tasks

    @property
    def full_set(self) -> str:
        """Name of the subset of all active tasks."""
        return "+".join(self.tasks)

    def curve(self, subset: str, task: str) -> tuple[np.ndarray, np.ndarray]:
        """Test score on ``task`` of the champion of ``subset`` at each test point."""
        rows = [r for r in self.tests if r["subset"] == subset]
        return (
            np.array([r["generation"] for r in rows], dtype=float),
            np.array([r[f"test_{task}"] for r in rows], dtype=float),
        )

    def final(self, subset: str) -> dict[str, float | str]:
        """The last test row of ``subset``."""
        rows = [r for r in self.tests if r["subset"] == subset]
        if not rows:
            raise ValueError(f"{self.path}: no test results yet (tests.csv is empty)")
        return rows[-1]

    def best_single(self, task: str) -> float:
        """Best test score of the run's single-task champion of ``task`` over all test points."""
        return float(self.curve(task, task)[1].max())

    def multitask_scores(self) -> dict[str, float]:
        """Final test score per task of the champion of all tasks."""
        row = self.final(self.full_set)
        return {t: float(row[f"test_{t}"]) for t in self.tasks}


def load_run(path: str | Path) -> RunData:
    """Reads a run directory's configuration and test results."""
    path = Path(path)
    config = read_run_config(path)
    tests_file = path / TESTS_FILE
    if not tests_file.is_file():
        raise FileNotFoundError(f"{tests_file}: no test results (was test_interval 0?)")
    with open(tests_file, encoding="utf-8") as fh:
        rows: list[dict[str, float | str]] = []
        for raw in csv.DictReader(fh):
            rows.append({k: (v if k == "subset" else float(v)) for k, v in raw.items()})
    return RunData(path, config, rows, experiment_label(config))


def normalise_scores(scores: dict[str, float], best: dict[str, float]) -> dict[str, float]:
    """``(score - random) / (best - random)`` per task, with the stored random means."""
    out = {}
    for task, score in scores.items():
        try:
            out[task] = float(normalise(TASK_NAMES.index(task), score, best[task]))
        except ValueError:  # best equals random play: the ratio is undefined
            out[task] = float("nan")
    return out


def reference_best(tasks: tuple[str, ...]) -> dict[str, float]:
    """The reference best score of each task (Fig. 5)."""
    return {t: REFERENCE[TASK_NAMES.index(t)].best for t in tasks}


def vs_single_task(run: RunData) -> dict[str, float]:
    """The run's multi-task champion normalised by its best single-task champions (Fig. 4)."""
    return normalise_scores(run.multitask_scores(), {t: run.best_single(t) for t in run.tasks})


def best_run(runs: list[RunData]) -> RunData:
    """The run whose multi-task champion has the highest minimum normalised score."""
    return max(runs, key=lambda r: np.nanmin(list(vs_single_task(r).values()) + [np.inf]))
