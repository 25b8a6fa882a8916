"""Figures of the statistics across seeds: IQM with 95% CIs, and performance profiles.

Scores are the reference-normalised test scores of each run's final all-task champion
(:mod:`mtpg.analysis.runs.reported_numbers`); reference normalisation is defined for every
task and run, unlike normalisation by a single-task champion that may equal random play.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from mtpg.analysis.plotting import finish, pyplot, title_and_legend_above
from mtpg.analysis.runs import statistics as stats
from mtpg.analysis.runs.loading import RunGroup
from mtpg.analysis.runs.reported_numbers import RunNumbers, describe

STATS_NOTE = (
    "IQM = interquartile mean (mean of the middle 50% of scores); bars: 95% stratified "
    "bootstrap confidence intervals (runs resampled within each task; "
    f"{stats.N_RESAMPLES:,} resamples, percentile method, SciPy); none for a single run."
)


def score_matrix(group: RunGroup, numbers: dict[Path, RunNumbers]) -> np.ndarray:
    """(runs x tasks) reference-normalised test scores of the group's all-task champions."""
    tasks = group.runs[0].tasks
    return np.array([[numbers[r.path].normalised[t] for t in tasks] for r in group.runs])


def group_estimates(
    group: RunGroup, numbers: dict[Path, RunNumbers]
) -> tuple[list[stats.Estimate], stats.Estimate]:
    """Per-task IQM and the IQM over all tasks of a group, with their intervals."""
    scores = score_matrix(group, numbers)
    return stats.per_task_iqm(scores), stats.aggregate_iqm(scores)


def aggregate(
    groups: list[RunGroup],
    numbers: dict[Path, RunNumbers],
    estimates: dict[str, tuple[list[stats.Estimate], stats.Estimate]],
    path: Path,
) -> Path:
    """IQM per task and over all tasks of every group, with 95% stratified bootstrap CIs."""
    plt = pyplot()
    tasks = groups[0].runs[0].tasks
    cols = [*tasks, "all tasks"]
    fig, ax = plt.subplots(figsize=(max(7.5, 1.3 * len(cols) + 3), 5))
    width = 0.8 / len(groups)
    for k, g in enumerate(groups):
        per_task, overall = estimates[g.label]
        est = [*per_task, overall]
        xs = np.arange(len(cols)) + (k - (len(groups) - 1) / 2) * width
        vals = np.array([e.value for e in est])
        lo = np.array([e.low for e in est])
        hi = np.array([e.high for e in est])
        has = np.isfinite(lo)
        ax.bar(xs, vals, width, label=f"{g.label} ({len(g.runs)} run(s))", alpha=0.85)
        if has.any():
            ax.errorbar(
                xs[has],
                vals[has],
                yerr=[vals[has] - lo[has], hi[has] - vals[has]],
                fmt="none",
                ecolor="black",
                capsize=3,
                lw=1,
            )
        # each value above its interval's top (below its bottom when negative), so that
        # the error bar does not cross the number
        tops = np.where(has, np.where(vals >= 0, np.fmax(hi, vals), np.fmin(lo, vals)), vals)
        for x, v, top in zip(xs, vals, tops, strict=True):
            ax.annotate(
                f"{v:.2f}",
                (x, top),
                textcoords="offset points",
                xytext=(0, 3 if v >= 0 else -9),
                ha="center",
                fontsize=7,
            )
    ax.set_xticks(range(len(cols)))
    ax.set_xticklabels(cols, rotation=20, ha="right")
    ax.axvline(len(tasks) - 0.5, color="0.6", lw=0.8)
    ax.axhline(0, color="0.5", lw=0.8, ls="--")
    ax.axhline(1, color="0.5", lw=0.8, ls=":")
    ax.set_xlabel("task")
    ax.set_ylabel("IQM of normalised test score\n(0 = random, 1 = reference best)")
    title_and_legend_above(ax, "Across seeds: interquartile mean with 95% confidence intervals")
    shown = [numbers[r.path] for g in groups for r in g.runs]
    return finish(fig, path, f"{describe(shown)} {STATS_NOTE}")


def profile(groups: list[RunGroup], numbers: dict[Path, RunNumbers], path: Path) -> Path:
    """Performance profile: fraction of (run, task) scores above each threshold, per group."""
    plt = pyplot()
    mats = {g.label: score_matrix(g, numbers) for g in groups}
    top = max(1.2, max(float(m.max()) for m in mats.values()) + 0.05)
    bottom = min(0.0, min(float(m.min()) for m in mats.values()) - 0.05)
    taus = np.linspace(bottom, top, 61)
    fig, ax = plt.subplots(figsize=(7.5, 5))
    for k, g in enumerate(groups):
        frac, lo, hi = stats.performance_profile(mats[g.label], taus)
        (line,) = ax.plot(
            taus,
            frac,
            lw=2,
            ls=("-", "--", "-.", ":")[k % 4],
            drawstyle="steps-post",
            label=f"{g.label} ({len(g.runs)} run(s))",
        )
        if np.isfinite(lo).any():
            ax.fill_between(taus, lo, hi, color=line.get_color(), alpha=0.2, lw=0, step="post")
    ax.axvline(0, color="0.5", lw=0.8, ls="--")
    ax.axvline(1, color="0.5", lw=0.8, ls=":")
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlabel("normalised test score threshold tau (0 = random, 1 = reference best)")
    ax.set_ylabel("fraction of (run, task) scores > tau")
    ax.set_title("Performance profile of the all-task champions")
    ax.legend(fontsize=7)
    shown = [numbers[r.path] for g in groups for r in g.runs]
    caption = (
        f"{describe(shown)} Shaded: 95% stratified bootstrap bands "
        f"({stats.N_RESAMPLES_PROFILE:,} resamples per threshold; none for a single run)."
    )
    return finish(fig, path, caption)


def improvements(
    groups: list[RunGroup], numbers: dict[Path, RunNumbers]
) -> dict[tuple[str, str], stats.Estimate]:
    """P(first group > X) for every other group X (P(X > first) is one minus it)."""
    first = groups[0]
    base = score_matrix(first, numbers)
    return {
        (first.label, g.label): stats.probability_of_improvement(base, score_matrix(g, numbers))
        for g in groups[1:]
    }


POI_NOTE = (
    "Probability of improvement P(X > Y): the chance that a run of X has a higher "
    "normalised test score than a run of Y on a task (ties count one half), averaged over "
    "tasks; 0.5 = neither is better. Bars: 95% stratified bootstrap intervals (the runs of "
    f"both groups resampled within each task; {stats.N_RESAMPLES:,} resamples, percentile "
    "method; a group of one run is resampled as itself); none when both have one run. "
    "P(Y > X) = 1 - P(X > Y)."
)


def improvement(
    groups: list[RunGroup],
    numbers: dict[Path, RunNumbers],
    estimates: dict[tuple[str, str], stats.Estimate],
    path: Path,
) -> Path:
    """P(X > Y) with its interval for the pairs of :func:`improvements`, one row each."""
    plt = pyplot()
    pairs = list(estimates)
    fig, ax = plt.subplots(figsize=(7.5, 1.2 + 0.45 * len(pairs) + 1.5))
    ys = np.arange(len(pairs))[::-1]
    for y, pair in zip(ys, pairs, strict=True):
        e = estimates[pair]
        if np.isfinite(e.low):
            ax.plot([e.low, e.high], [y, y], color="tab:blue", lw=6, alpha=0.45)
        ax.plot([e.value], [y], "|", color="black", ms=14, mew=2)
        ax.annotate(
            e.text(2),
            (e.value, y),
            textcoords="offset points",
            xytext=(0, 9),
            ha="center",
            fontsize=7,
        )
    ax.set_yticks(ys)
    ax.set_yticklabels([f"P({x} > {y})" for x, y in pairs], fontsize=8)
    ax.axvline(0.5, color="0.5", lw=0.8, ls="--")
    ax.set_xlim(0, 1)
    ax.set_ylim(-0.7, len(pairs) - 0.3)
    ax.set_xlabel("probability of improvement (0.5 = neither better)")
    ax.set_ylabel("pair of experiments")
    ax.set_title("Pairwise comparison of experiments")
    ax.plot([], [], color="tab:blue", lw=6, alpha=0.45, label="95% CI")
    ax.plot([], [], "|", color="black", ms=10, mew=2, label="estimate")
    ax.legend(fontsize=7, loc="lower right")
    shown = [numbers[r.path] for g in groups for r in g.runs]
    return finish(fig, path, f"{describe(shown)} {POI_NOTE}")
