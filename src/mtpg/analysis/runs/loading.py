"""Loading finished runs, grouping them by configuration, and normalising scores.

``normalised = (score - random) / (best - random)``: 0 is random play; ``best`` is either
a single-task champion (Figs. 5 and 7) or the reference best of the task (Fig. 6); see
:mod:`mtpg.analysis.runs.reported_numbers` for which champion every reported number comes from.

Runs are grouped by configuration: two runs belong to one group when their configurations
are equal in everything but the seed and the settings that do not change what a run
computes (``workers``, ``checkpoint_interval`` and where it was evaluated: ``backend``,
``address``, ``dask_workers``). A group is labelled with its experiment
(``TPG`` or an ablation of section 5.2) plus, when needed to tell groups apart, the fields in
which it differs. Groups that differ in more than the ablation switches are a mixture the
figures cannot compare fairly: :func:`group_runs` reports them as warnings.
"""

from __future__ import annotations

import csv
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any

import numpy as np

from mtpg.ablations import ABLATION_FIELDS, experiment_label
from mtpg.config import RunConfig, to_dict
from mtpg.envs.taskset.reference_scores import normalise, reference_of
from mtpg.envs.taskset.task_table import REGISTERED, TaskTable
from mtpg.io.runconfig import read_run_config
from mtpg.io.rundir import TESTS_FILE

#: Settings that do not change what a run computes: ignored when grouping.
NOT_GROUPED = ("seed", "workers", "checkpoint_interval", "backend", "address", "dask_workers")


@dataclass
class RunData:
    """A run directory's test results.

    Attributes:
        path: The run directory.
        config: Its configuration.
        tests: ``tests.csv`` rows with numbers parsed.
        label: Experiment label (:func:`mtpg.ablations.experiment_label`).
    """

    path: Path
    config: RunConfig
    tests: list[dict[str, float | str]] = field(default_factory=list)
    label: str = "TPG"

    @property
    def name(self) -> str:
        """The run directory's name."""
        return self.path.name

    @property
    def tasks(self) -> tuple[str, ...]:
        """Active task names."""
        return self.config.evaluation.tasks

    @cached_property
    def task_table(self) -> TaskTable:
        """The run's task table: its tasks and their given reference scores."""
        return self.config.evaluation.task_table()

    @property
    def full_set(self) -> str:
        """Name of the subset of all active tasks (as in ``tests.csv``)."""
        return "+".join(self.tasks)

    @property
    def test_episodes(self) -> int:
        """Held-out episodes per task at each test point."""
        return self.config.evaluation.test_episodes

    @property
    def final_generation(self) -> int:
        """The last test point (the run's last generation for a finished run)."""
        if not self.tests:
            raise ValueError(f"{self.path}: no test results yet ({TESTS_FILE} is empty)")
        return int(max(r["generation"] for r in self.tests))

    def curve(self, subset: str, task: str) -> tuple[np.ndarray, np.ndarray]:
        """Test score on ``task`` of the champion of ``subset`` at each test point."""
        rows = [r for r in self.tests if r["subset"] == subset]
        return (
            np.array([r["generation"] for r in rows], dtype=float),
            np.array([r[f"test_{task}"] for r in rows], dtype=float),
        )

    def row(self, subset: str, generation: int | None = None) -> dict[str, float | str]:
        """The test row of ``subset`` at ``generation`` (default: the final test point)."""
        gen = self.final_generation if generation is None else generation
        for r in self.tests:
            if r["subset"] == subset and int(r["generation"]) == gen:
                return r
        raise ValueError(f"{self.path}: no test of subset {subset} at generation {gen}")

    def rows_at(self, generation: int) -> list[dict[str, float | str]]:
        """Every subset's test row at ``generation``."""
        return [r for r in self.tests if int(r["generation"]) == generation]


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


def _flat(config: RunConfig) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in to_dict(config).items():
        if isinstance(value, dict):
            out.update({f"{key}.{k}": v for k, v in value.items()})
        else:
            out[key] = value
    return {k: v for k, v in out.items() if k not in NOT_GROUPED}


@dataclass
class RunGroup:
    """Runs of one configuration (all seeds of one experiment).

    Attributes:
        label: Display label (experiment name, plus distinguishing settings if needed).
        runs: The runs, in the order given.
        settings: The group's configuration, flattened (``section.field`` keys).
    """

    label: str
    runs: list[RunData]
    settings: dict[str, Any]

    @property
    def experiment(self) -> str:
        """``TPG`` or the ablation label."""
        return self.runs[0].label


def _value(v: Any) -> str:
    return ",".join(map(str, v)) if isinstance(v, list) else str(v)


def group_runs(runs: list[RunData]) -> tuple[list[RunGroup], list[str]]:
    """Groups runs by configuration and names the mixtures.

    Args:
        runs: Loaded runs.

    Returns:
        ``(groups, warnings)``: groups in order of first appearance, full algorithm first;
        one warning per setting (other than the ablation switches) in which groups differ.
    """
    groups: list[RunGroup] = []
    for run in runs:
        flat = _flat(run.config)
        for g in groups:
            if g.settings == flat:
                g.runs.append(run)
                break
        else:
            groups.append(RunGroup(run.label, [run], flat))
    groups.sort(key=lambda g: g.experiment != "TPG")
    differing = sorted(
        k for k in groups[0].settings if len({repr(g.settings[k]) for g in groups}) > 1
    )
    beyond = [k for k in differing if k not in ABLATION_FIELDS]
    for g in groups:
        same = [h for h in groups if h.experiment == g.experiment]
        if len(same) > 1:
            g.label += " (" + ", ".join(f"{k}={_value(g.settings[k])}" for k in beyond) + ")"
    warnings = [
        f"runs differ in {k}: "
        + "; ".join(f"{g.label}: {_value(g.settings[k])}" for g in groups)
        + " (grouped separately; figures compare groups that are not like for like)"
        for k in beyond
    ]
    return groups, warnings


def normalise_scores(
    scores: dict[str, float], best: dict[str, float], table: TaskTable = REGISTERED
) -> dict[str, float]:
    """``(score - random) / (best - random)`` per task; NaN when ``best`` equals random.

    Args:
        scores: Scores by task name.
        best: The best score of each task to normalise against.
        table: The task table of the names (the run's: its given reference scores); the
            registered tasks by default (a variant's name is refused there).
    """
    out = {}
    for task, score in scores.items():
        try:
            out[task] = float(normalise(task, score, best[task], table))
        except ValueError:  # best equals random play: the ratio is undefined
            out[task] = float("nan")
    return out


def reference_best(table: TaskTable) -> dict[str, float]:
    """The reference best score of each task of a run's table (Fig. 6), by name."""
    return {t: reference_of(t, table).best for t in table.names}
