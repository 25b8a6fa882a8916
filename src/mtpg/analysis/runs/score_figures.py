"""The score figures of paper section 5 (Figs. 4-7) from run directories (matplotlib, Agg).

Every figure states under its plot which champion it shows (selected on training scores,
at which generation), on how many held-out episodes, and what 0 and 1 mean
(:mod:`mtpg.analysis.runs.reported_numbers`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from mtpg.analysis.plotting import finish, pyplot, title_and_legend_above
from mtpg.analysis.runs.loading import RunGroup, normalise_scores, reference_best
from mtpg.analysis.runs.reported_numbers import (
    BEST_RUN_RULE,
    SINGLE_RULE,
    RunNumbers,
    best_of,
    best_single_task,
    describe,
)
from mtpg.envs.taskset.episode_seeds import describe_held_out

Numbers = dict[Path, RunNumbers]  # run directory -> its numbers


def _task_axis(ax, tasks: tuple[str, ...]) -> None:
    ax.set_xticks(range(len(tasks)))
    ax.set_xticklabels(tasks, rotation=20, ha="right")
    ax.set_xlabel("task")
    ax.axhline(0, color="0.5", lw=0.8, ls="--")
    ax.axhline(1, color="0.5", lw=0.8, ls=":")


def learning_curves(group: RunGroup, numbers: Numbers, path: Path) -> Path:
    """Fig. 4: test return per task over generations, every run of one group.

    Grey: the all-task champion of each run at each test point; black: the best run;
    dotted: the median over runs of the single-task champion of that task (at each test
    point, over the runs that have reached it).
    """
    plt = pyplot()
    runs = group.runs
    tasks = runs[0].tasks
    best = best_of([numbers[r.path] for r in runs]).run
    cols = min(3, len(tasks))
    rows = -(-len(tasks) // cols)
    fig, axes = plt.subplots(rows, cols, figsize=(4.3 * cols, 3.2 * rows + 1.3), squeeze=False)
    for ax, task in zip(axes.flat, tasks, strict=False):
        for run in sorted(runs, key=lambda r: r is best):
            x, y = run.curve(run.full_set, task)
            is_best = run is best
            ax.plot(
                x,
                y,
                color="black" if is_best else "0.65",
                lw=2 if is_best else 1,
                marker="." if len(x) < 30 else None,
                label=(
                    (
                        f"all-task champion, best run ({run.name})"
                        if len(runs) > 1
                        else f"all-task champion ({run.name})"
                    )
                    if is_best
                    else None
                ),
            )
        # The median at each test point over the runs that have reached it, so that a
        # run still growing does not cut the others' curve short.
        at: dict[int, list[float]] = {}
        for run in runs:
            for g, v in zip(*run.curve(task, task), strict=True):
                at.setdefault(int(g), []).append(float(v))
        if at:
            gens = sorted(at)
            med = [float(np.median(at[g])) for g in gens]
            label = "single-task champion" + (" (median over runs)" if len(runs) > 1 else "")
            ax.plot(gens, med, ":", color="tab:blue", lw=2, label=label)
        if len(runs) > 1:
            ax.plot([], [], color="0.65", label="all-task champion, other runs")
        ax.set_title(task)
        ax.set_xlabel("generation")
        ax.set_ylabel("mean test return\n(reward per episode)")
    for ax in list(axes.flat)[len(tasks) :]:
        ax.axis("off")
    handles, labels = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=3, fontsize=8, frameon=False)
    fig.suptitle(f"Learning curves: {group.label}, {len(runs)} run{'s' if len(runs) > 1 else ''}")
    cfg = runs[0].config.evaluation
    caption = (
        f"Test return = mean over {describe_held_out(cfg.test_episodes)}, at every "
        f"{cfg.test_interval} generations and the last. At each test point every champion is "
        f"the best root by training score ({cfg.train_episodes} training episodes per task)."
    )
    if len(runs) > 1:
        caption += f" Black: {BEST_RUN_RULE}, at the final generation."
    return finish(fig, path, caption, legend_rows=1)


def _value_labels(ax, xs, values, fmt="{:.2f}", markers: bool = False) -> None:
    """Each value written above its bar or marker, or below it when negative.

    Beside markers (``markers``) the labels stand further off and on a white ground, so
    that neither hides the other; on bars they sit close and clear, as a ground would hide
    the neighbouring bars.
    """
    for x, v in zip(xs, values, strict=True):
        text = "n/a" if not np.isfinite(v) else fmt.format(v)
        y = 0 if not np.isfinite(v) else v
        ax.annotate(
            text,
            (x, y),
            textcoords="offset points",
            xytext=(0, (7 if markers else 2) * (1 if y >= 0 else -1)),
            ha="center",
            va="bottom" if y >= 0 else "top",
            fontsize=7,
            bbox=(
                {"boxstyle": "square,pad=0.1", "facecolor": "white", "edgecolor": "none"}
                if markers
                else None
            ),
            zorder=5,
        )


def normalised_vs_single(group: RunGroup, numbers: Numbers, path: Path) -> Path:
    """Fig. 5: each run's all-task champion normalised by its own single-task champions."""
    plt = pyplot()
    runs = [numbers[r.path] for r in group.runs]
    tasks = group.runs[0].tasks
    best = best_of(runs)
    fig, ax = plt.subplots(figsize=(7.5, 5))
    undefined = False
    for k, n in enumerate(sorted(runs, key=lambda n: n is best)):
        is_best = n is best
        ys = np.array([n.vs_single[t] for t in tasks])
        # other runs drawn slightly left of the best run, so equal scores stay visible
        shift = 0.0 if is_best else -(k + 1) * min(0.04, 0.3 / len(runs))
        ax.plot(
            np.arange(len(tasks)) + shift,
            ys,
            marker="o",
            color="black" if is_best else "0.65",
            lw=2 if is_best else 1,
            label=f"{n.run.name}{' (best run)' if is_best else ''}",
        )
        bad = ~np.isfinite(ys)
        if bad.any():
            undefined = True
            ax.plot(np.flatnonzero(bad), np.zeros(bad.sum()), "x", color="tab:red", ms=9)
        if is_best:
            _value_labels(ax, range(len(tasks)), ys, markers=True)
    if undefined:
        ax.plot([], [], "x", color="tab:red", label="undefined: single-task champion = random")
    _task_axis(ax, tasks)
    ax.margins(y=0.12)  # room for the value labels above the highest marker
    ax.set_ylabel("normalised test score\n(0 = random, 1 = own single-task champion)")
    ax.set_title(f"All-task champions against single-task champions: {group.label}")
    ax.legend(fontsize=7)
    caption = f"{describe(runs)} Normalised: 0 = random play, {SINGLE_RULE}. {BEST_RUN_RULE}."
    return finish(fig, path, caption)


def _bars(ax, tasks, groups: dict[str, dict[str, float]]) -> None:
    width = 0.8 / max(len(groups), 1)
    for k, (name, values) in enumerate(groups.items()):
        xs = np.arange(len(tasks)) + (k - (len(groups) - 1) / 2) * width
        ys = np.array([values[t] for t in tasks])
        ax.bar(xs, np.where(np.isfinite(ys), ys, 0.0), width, label=name)
        _value_labels(ax, xs, ys)
    _task_axis(ax, tasks)
    ax.margins(y=0.1)  # room for the labels of the highest and lowest bars


def normalised_vs_reference(group: RunGroup, numbers: Numbers, path: Path) -> Path:
    """Fig. 6: the best run's all-task and single-task champions against the reference best."""
    plt = pyplot()
    best = best_of([numbers[r.path] for r in group.runs])
    tasks = best.run.tasks
    single = normalise_scores(best.single, reference_best(best.run.task_table), best.run.task_table)
    fig, ax = plt.subplots(figsize=(7.5, 5))
    _bars(
        ax,
        tasks,
        {
            f"all-task champion ({best.run.name})": best.normalised,
            f"single-task champions ({best.run.name})": single,
        },
    )
    ax.set_ylabel("normalised test score\n(0 = random, 1 = reference best)")
    ax.set_title(f"Champions of the best run against the reference best: {group.label}")
    ax.legend(fontsize=7)
    caption = (
        f"{describe([best])} Single-task champions: the best root on each task alone by "
        f"training score at the same generation, tested on its own task. {BEST_RUN_RULE}. "
        "Reference best: `mtpg envs` (solved thresholds, leaderboard, time-optimal law)."
    )
    return finish(fig, path, caption)


def ablations(groups: list[RunGroup], numbers: Numbers, path: Path) -> Path:
    """Fig. 7: the best run's all-task champion of each experiment, side by side.

    Denominators: per task, the best single-task champion of all runs of the first group
    (the full algorithm when present) by test score, each at its final test point, as in
    the paper's Fig. 7, so every experiment is measured against the same scores and one
    run's weak single-task champion does not inflate the ratios.
    """
    plt = pyplot()
    ref_runs = [numbers[r.path] for r in groups[0].runs]
    tasks = ref_runs[0].run.tasks
    single = best_single_task(ref_runs)
    bars = {}
    shown = []
    for g in groups:
        best = best_of([numbers[r.path] for r in g.runs])
        shown.append(best)
        bars[f"{g.label} ({best.run.name}, {len(g.runs)} run(s))"] = normalise_scores(
            best.test, single, best.run.task_table
        )
    fig, ax = plt.subplots(figsize=(8.5, 5))
    _bars(ax, tasks, bars)
    label = groups[0].label
    ax.set_ylabel(
        f"vs best single: normalised test score\n(0 = random, 1 = best single-task, {label})"
    )
    title_and_legend_above(ax, "Experiments: the best run's all-task champion of each")
    caption = (
        f"{describe(shown)} Normalised (vs best single): 0 = random play, 1 = the best "
        f"single-task champion of the {len(ref_runs)} {label} run(s) by test score (each "
        "run's best root on the task alone by training score, at its final test point; "
        "choosing the best of them by test score biases the ratios downward, "
        "docs/report.md); n/a where it is no better than random. Best run of each "
        f"experiment: {BEST_RUN_RULE.removeprefix('Best run = ')}."
    )
    return finish(fig, path, caption)
