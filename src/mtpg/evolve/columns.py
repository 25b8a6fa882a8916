"""The columns of ``metrics.csv`` and ``tests.csv``, and the metrics row of a generation.

The headers depend only on the run's task names and the settings beyond the paper that
are on, so readers (the report, the resume check, the analyses) and the trainer that
writes the rows share one definition.
"""

from __future__ import annotations

import numpy as np

from mtpg.config import EvaluationConfig
from mtpg.engine.batch import BatchResult
from mtpg.model.graph import Population

#: Metrics columns that measure time and so differ between otherwise identical runs.
TIMING_COLUMNS = (
    "decisions_per_s",
    "t_variation",
    "t_evaluation",
    "t_selection",
    "t_test",
    "t_total",
)


def held_out_columns(tasks: tuple[str, ...]) -> list[str]:
    """The ``tests.csv`` header for a run on ``tasks``."""
    return ["generation", "subset", "root", "graph_teams", "teams_per_decision"] + [
        f"test_{t}" for t in tasks
    ]


def extra_columns(evaluation: EvaluationConfig | None) -> list[str]:
    """Columns of the settings beyond the paper that are on (none in ``paper``).

    ``validated_roots`` and ``validation_decisions``: roots first measured on the
    validation episodes this generation and the decisions that took (validation on);
    ``reevaluated_roots``: surviving roots evaluated again on redrawn training episodes
    this generation (resampling on; their decisions are in ``decisions``).
    """
    if evaluation is None:
        return []
    cols = []
    if evaluation.validation_episodes > 0:
        cols += ["validated_roots", "validation_decisions"]
    if evaluation.resample_interval > 0:
        cols.append("reevaluated_roots")
    return cols


def metric_columns(tasks: tuple[str, ...], evaluation: EvaluationConfig | None = None) -> list[str]:
    """The ``metrics.csv`` header for a run on ``tasks`` (with ``evaluation``'s extras)."""
    cols = [
        "generation",
        "roots",
        "teams",
        "programs",
        "banks",
        "banks_in_use",
        "programs_per_bank",
        "new_roots",
        "decisions",
        "teams_per_decision",
        "instructions_per_decision",
        "champion_teams",
    ]
    for task in tasks:
        cols += [f"best_{task}", f"median_{task}"]
    return cols + extra_columns(evaluation) + list(TIMING_COLUMNS)


def metrics_row(
    generation: int,
    population: Population,
    scores: dict[int, np.ndarray],
    champion: int,
    names: tuple[str, ...],
    new_roots: list[int],
    result: BatchResult,
    extra: dict[str, float],
    times: tuple[float, float, float, float],
) -> dict[str, float]:
    """The ``metrics.csv`` row of a generation just selected (timing columns included).

    Args:
        generation: The generation.
        population: The population after selection.
        scores: Mean training score per task of every surviving root.
        champion: The champion of the full task set (the last subset).
        names: The run's task names.
        new_roots: Roots first evaluated this generation.
        result: The evaluation's counters (steps, teams, instructions per job).
        extra: The columns of the settings beyond the paper (:func:`extra_columns`).
        times: ``perf_counter`` at the start of variation, evaluation, selection and the end.
    """
    pop = population
    decisions = int(result.steps.sum())
    in_use = pop.banks_in_use()
    table = np.array([scores[r] for r in sorted(scores)])
    row: dict[str, float] = {
        "generation": generation,
        "roots": len(scores),
        "teams": len(pop.teams),
        "programs": len(pop.programs),
        "banks": len(pop.memory_banks),
        "banks_in_use": len(in_use),
        "programs_per_bank": len(pop.programs) / max(len(in_use), 1),
        "new_roots": len(new_roots),
        "decisions": decisions,
        "teams_per_decision": result.teams.sum() / max(decisions, 1),
        "instructions_per_decision": result.instructions.sum() / max(decisions, 1),
        "champion_teams": len(pop.reachable(champion)),
    }
    for k, name in enumerate(names):
        row[f"best_{name}"] = float(table[:, k].max())
        row[f"median_{name}"] = float(np.median(table[:, k]))
    row.update(extra)
    t0, t1, t2, t3 = times
    row.update(
        decisions_per_s=decisions / max(t2 - t1, 1e-9),
        t_variation=t1 - t0,
        t_evaluation=t2 - t1,
        t_selection=t3 - t2,
        t_test=0.0,
        t_total=t3 - t0,
    )
    return row
