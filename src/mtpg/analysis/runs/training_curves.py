"""Training curves from ``metrics.csv``: training scores and population sizes per generation.

What a run learns on its *training* episodes, and how large its populations are, as the
trainer records them every generation: per task the best and the median training score
over the roots kept by the generation's selection (each root's mean over
``evaluation.train_episodes`` episodes), the numbers of roots, teams and programs, and
the memory banks (all, and those some program points to). These are not test scores: a
root's training score is measured on the few episodes it was selected on
(docs/report.md).
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from mtpg.analysis.plotting import finish, pyplot
from mtpg.analysis.runs.loading import RunData, RunGroup
from mtpg.io.rundir import METRICS_FILE


def read_metrics(run: RunData) -> dict[str, np.ndarray]:
    """The numeric columns of a run's ``metrics.csv``, one array per column.

    Raises:
        FileNotFoundError: When the run has no ``metrics.csv``.
        ValueError: When it has no rows.
    """
    path = Path(run.path) / METRICS_FILE
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such file (the run has no generation yet)")
    with open(path, encoding="utf-8", newline="") as fh:
        rows = list(csv.DictReader(fh))
    if not rows:
        raise ValueError(f"{path}: no generations recorded")
    return {key: np.array([float(r[key]) for r in rows]) for key in rows[0]}


def training_curves(groups: list[RunGroup], path: Path) -> Path:
    """Best and median training score per task, and population sizes, over generations.

    One panel per task (solid: best root, dotted: median root; one colour per group, one
    line per run), then one panel of roots and teams and one of programs and memory banks.
    """
    plt = pyplot()
    tasks = groups[0].runs[0].tasks
    panels = len(tasks) + 2
    cols = min(3, panels)
    rows = -(-panels // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.3 * cols, 3.0 * rows + 1.6), squeeze=False)
    flat = list(axes.flat)
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    episodes = set()
    for k, group in enumerate(groups):
        colour = colours[k % len(colours)]
        for run in group.runs:
            episodes.add(run.config.evaluation.train_episodes)
            m = read_metrics(run)
            gen = m["generation"]
            for ax, task in zip(flat, tasks, strict=False):
                ax.plot(gen, m[f"best_{task}"], color=colour, lw=1.2)
                ax.plot(gen, m[f"median_{task}"], color=colour, lw=1.0, ls=":")
            for key, style in (("roots", "--"), ("teams", "-")):
                flat[len(tasks)].plot(gen, m[key], color=colour, lw=1.0, ls=style)
            for key, style in (("programs", "-"), ("banks", "--"), ("banks_in_use", ":")):
                flat[len(tasks) + 1].plot(gen, m[key], color=colour, lw=1.0, ls=style)
    for ax, task in zip(flat, tasks, strict=False):
        ax.set_title(task, fontsize=10)
        ax.set_ylabel("training score\n(mean return)")
    flat[len(tasks)].set_title("population: roots and teams", fontsize=10)
    flat[len(tasks)].set_ylabel("count")
    flat[len(tasks) + 1].set_title("programs and memory banks", fontsize=10)
    flat[len(tasks) + 1].set_ylabel("count")
    flat[len(tasks) + 1].set_yscale("log")
    for ax in flat[:panels]:
        ax.set_xlabel("generation")
    for ax in flat[panels:]:
        ax.set_visible(False)
    _legend(fig, groups, colours)
    caption = (
        "Training scores from each run's metrics.csv: per task the best and the median over "
        "the roots kept by the generation's selection of each root's mean return on "
        f"{' or '.join(str(e) for e in sorted(episodes))} training episodes (the episodes "
        "selection sees, not held-out test episodes; the best root may differ per task). "
        "Population: roots, teams, programs, memory banks and banks some program points to, "
        "after each generation."
    )
    return finish(fig, path, caption, legend_rows=2)


def _legend(fig, groups: list[RunGroup], colours: list[str]) -> None:
    from matplotlib.lines import Line2D

    handles = [
        Line2D(
            [], [], color=colours[k % len(colours)], lw=2, label=f"{g.label} ({len(g.runs)} run(s))"
        )
        for k, g in enumerate(groups)
    ]
    handles += [
        Line2D([], [], color="0.3", lw=1.2, label="best root / teams / programs"),
        Line2D([], [], color="0.3", lw=1.0, ls=":", label="median root / banks in use"),
        Line2D([], [], color="0.3", lw=1.0, ls="--", label="roots / banks"),
    ]
    fig.legend(handles=handles, loc="lower center", ncol=min(len(handles), 4), fontsize=7)
