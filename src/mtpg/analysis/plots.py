"""The figures of paper section 5 from run directories (matplotlib, imported lazily)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from mtpg.analysis.runs import (
    RunData,
    best_run,
    normalise_scores,
    reference_best,
    vs_single_task,
)


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def main_runs(runs: list[RunData]) -> list[RunData]:
    """The runs of the full algorithm (ablation runs have their own figure)."""
    return [r for r in runs if r.label == "TPG"] or runs


def _save(fig, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    _pyplot().close(fig)
    return path


def learning_curves(runs: list[RunData], path: Path) -> Path:
    """Fig. 3: test return per task over generations.

    Solid grey: the multi-task champion of each run; black: the best run; dotted: the
    median over runs of the single-task champion of that task.
    """
    runs = main_runs(runs)
    plt = _pyplot()
    tasks = runs[0].tasks
    best = best_run(runs)
    cols = min(3, len(tasks))
    rows = -(-len(tasks) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.2 * cols, 3.2 * rows), squeeze=False)
    for ax, task in zip(axes.flat, tasks, strict=False):
        for run in runs:
            x, y = run.curve(run.full_set, task)
            is_best = run is best
            ax.plot(
                x,
                y,
                color="black" if is_best else "0.65",
                lw=2 if is_best else 1,
                label=f"multi-task, best run ({run.path.name})" if is_best else None,
            )
        single = [run.curve(task, task) for run in runs]
        n = min(len(x) for x, _ in single)
        if n:
            med = np.median(np.array([y[:n] for _, y in single]), axis=0)
            ax.plot(
                single[0][0][:n],
                med,
                ":",
                color="tab:blue",
                lw=2,
                label="single-task champion (median over runs)",
            )
        if len(runs) > 1:
            ax.plot([], [], color="0.65", label="multi-task, other runs")
        ax.set_title(task)
        ax.set_xlabel("generation")
        ax.set_ylabel("mean test return\n(reward per episode)")
    for ax in list(axes.flat)[len(tasks) :]:
        ax.axis("off")
    handles, labels = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _task_axis(ax, tasks: tuple[str, ...]) -> None:
    ax.set_xticks(range(len(tasks)))
    ax.set_xticklabels(tasks, rotation=25, ha="right")
    ax.set_xlabel("task")
    ax.axhline(0, color="0.5", lw=0.8, ls="--")
    ax.axhline(1, color="0.5", lw=0.8, ls=":")


def normalised_vs_single(runs: list[RunData], path: Path) -> Path:
    """Fig. 4: each run's multi-task champion normalised by its best single-task champions."""
    runs = main_runs(runs)
    plt = _pyplot()
    tasks = runs[0].tasks
    best = best_run(runs)
    fig, ax = plt.subplots(figsize=(7, 4))
    for run in runs:
        norm = vs_single_task(run)
        is_best = run is best
        ax.plot(
            range(len(tasks)),
            [norm[t] for t in tasks],
            marker="o",
            color="black" if is_best else "0.65",
            lw=2 if is_best else 1,
            label=f"{run.path.name}{' (best)' if is_best else ''}",
        )
    _task_axis(ax, tasks)
    ax.set_ylabel("normalised score\n(0 = random, 1 = best single-task)")
    ax.set_title("Multi-task champions against single-task champions")
    ax.legend(fontsize=7)
    return _save(fig, path)


def _bars(ax, tasks, groups: dict[str, dict[str, float]]) -> None:
    width = 0.8 / max(len(groups), 1)
    for k, (name, values) in enumerate(groups.items()):
        xs = np.arange(len(tasks)) + (k - (len(groups) - 1) / 2) * width
        ax.bar(xs, [values[t] for t in tasks], width, label=name)
    _task_axis(ax, tasks)


def normalised_vs_reference(runs: list[RunData], path: Path) -> Path:
    """Fig. 5: best multi-task and single-task champions against the reference best."""
    runs = main_runs(runs)
    plt = _pyplot()
    tasks = runs[0].tasks
    ref = reference_best(tasks)
    multi = normalise_scores(best_run(runs).multitask_scores(), ref)
    single = normalise_scores({t: max(r.best_single(t) for r in runs) for t in tasks}, ref)
    fig, ax = plt.subplots(figsize=(7, 4))
    _bars(ax, tasks, {"multi-task champion (best run)": multi, "best single-task champion": single})
    ax.set_ylabel("normalised score\n(0 = random, 1 = reference best)")
    ax.set_title("Champions against the reference best")
    ax.legend(fontsize=7)
    return _save(fig, path)


def ablations(runs: list[RunData], path: Path) -> Path:
    """Fig. 6: the best multi-task champion of each experiment, side by side."""
    plt = _pyplot()
    tasks = runs[0].tasks
    full = [r for r in runs if r.label == "TPG"] or runs
    single_best = {t: max(r.best_single(t) for r in full) for t in tasks}
    groups = {}
    for label in sorted({r.label for r in runs}, key=lambda s: (s != "TPG", s)):
        members = [r for r in runs if r.label == label]
        groups[label] = normalise_scores(best_run(members).multitask_scores(), single_best)
    fig, ax = plt.subplots(figsize=(7.5, 4))
    _bars(ax, tasks, groups)
    ax.set_ylabel("normalised score\n(0 = random, 1 = best single-task TPG)")
    ax.set_title("Ablations: best multi-task champion of each experiment")
    ax.legend(fontsize=7)
    return _save(fig, path)


def hierarchy(runs: list[RunData], path: Path) -> Path:
    """Fig. 7: teams visited per decision by the champion of every task subset."""
    runs = main_runs(runs)
    plt = _pyplot()
    fig, ax = plt.subplots(figsize=(8, 4))
    for run in runs:
        last = max(r["generation"] for r in run.tests)
        rows = [r for r in run.tests if r["generation"] == last]
        sizes = np.array([len(str(r["subset"]).split("+")) for r in rows])
        jitter = (np.arange(len(rows)) % 7 - 3) * 0.04
        ax.scatter(
            sizes + jitter,
            [r["teams_per_decision"] for r in rows],
            s=18,
            label=f"{run.path.name} (generation {int(last)})",
            alpha=0.8,
        )
    ax.set_xlabel("number of tasks in the subset")
    ax.set_ylabel("teams visited per decision (test)")
    ax.set_title("Hierarchical complexity of each task subset's champion")
    ax.set_xticks(range(1, len(runs[0].tasks) + 1))
    ax.legend(fontsize=7)
    return _save(fig, path)
