"""The figures of paper section 6 (Figs. 9-12), drawn from :mod:`mtpg.analysis.graph.measures`.

Each function draws one PNG from arrays it is given and computes nothing of its own.
Task colours come from :mod:`mtpg.analysis.palette`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from mtpg.analysis.description.layout import GraphDrawing, GraphLayout
from mtpg.analysis.palette import (
    ACTION_COLOURS,
    CONTINUOUS_CMAP,
    PASSED_COLOUR,
    task_colour,
)
from mtpg.analysis.plotting import pyplot, save

#: Smallest |Pearson r| at which the velocity panel calls a register a velocity prediction;
#: below it the panel says that no register tracks the velocity (sec. 6.3 reads r as such).
TRACKS_R = 0.3


def _task_legend(fig_or_ax, tasks, **kw) -> None:
    from matplotlib.patches import Patch

    handles = [Patch(facecolor=task_colour(t), label=t) for t in tasks]
    fig_or_ax.legend(handles=handles, **kw)


def team_graph(layout: GraphLayout, visits: dict, path: Path, title: str) -> Path:
    """Fig. 9 top: the team graph, each team a pie of its visit rate in each task."""
    plt = pyplot()
    tasks = [str(t) for t in visits["tasks"]]
    width = max(7.0, min(16.0, 1.6 * (np.ptp(layout.pos[:, 0]) + 2)))
    height = max(3.5, min(14.0, 1.4 * (np.ptp(layout.pos[:, 1]) + 2))) + 1.2
    fig, ax = plt.subplots(figsize=(width, height))
    GraphDrawing(ax, layout, visits["pie"], [task_colour(t) for t in tasks])
    ax.set_title(title, fontsize=11)
    _task_legend(fig, tasks, loc="lower center", ncol=min(3, len(tasks)), fontsize=8)
    fig.text(
        0.01,
        0.99,
        "pie slice: share of the task's steps in which the team ran (normalised over tasks)\n"
        "root = team 1 (top); rows are depths; arrows: program pointers; "
        "dashed: never visited",
        va="top",
        fontsize=7,
        color="0.3",
    )
    fig.tight_layout(rect=(0, 0.1, 1, 0.93))
    return save(fig, path)


def register_access(access: dict, path: Path, title: str) -> Path:
    """Fig. 9 bottom: stacked bars of each memory register's accesses by task."""
    plt = pyplot()
    tasks = [str(t) for t in access["tasks"]]
    n = len(access["labels"])
    fig, ax = plt.subplots(figsize=(min(18.0, max(7.0, 0.16 * n + 2)), 4.2))
    bottom = np.zeros(n)
    for k, task in enumerate(tasks):
        ax.bar(
            np.arange(n),
            access["share"][:, k],
            bottom=bottom,
            width=0.85,
            color=task_colour(task),
            label=task,
        )
        bottom += access["share"][:, k]
    ax.set_xlim(-0.8, n - 0.2)
    ax.set_ylim(0, 1)
    step = max(1, n // 60)
    ax.set_xticks(np.arange(0, n, step))
    ax.set_xticklabels(access["labels"][::step], rotation=90, fontsize=6)
    ax.set_xlabel("memory register (bank b, register m), from most specialised to most shared")
    ax.set_ylabel("share of accesses\n(read or write, per step)")
    ax.set_title(title, fontsize=11)
    fig.legend(*ax.get_legend_handles_labels(), fontsize=7, ncol=len(tasks), loc="lower center")
    fig.tight_layout(rect=(0, 0.07, 1, 1))
    return save(fig, path)


def time_series(task: str, series: dict, prediction: dict | None, path: Path, title: str) -> Path:
    """Figs. 11-12: complexity, memory window and velocity prediction of one episode.

    ``prediction`` None (a task whose hidden state mtpg does not see, a Gymnasium task):
    the three panels without the velocity.
    """
    plt = pyplot()
    colour = task_colour(task)
    rows = 3 if prediction is None else 4
    fig, axes = plt.subplots(rows, 1, figsize=(7.5, 2.05 * rows), sharex=True)
    steps = series["step"]
    axes[0].step(steps, series["teams"], where="mid", color=colour, lw=1.2)
    axes[0].set_ylabel("teams visited")
    axes[0].set_ylim(0, max(2, series["teams"].max(initial=1)) + 0.5)
    axes[1].step(steps, series["instructions"], where="mid", color=colour, lw=1.2)
    axes[1].set_ylabel("instructions\nexecuted")
    window = len(steps) // 40
    if window >= 10:  # long episodes: the per-step curve becomes a band; add its running mean
        kernel = np.ones(window) / window
        for ax, key in ((axes[0], "teams"), (axes[1], "instructions")):
            mean = np.convolve(series[key], kernel, mode="valid")
            ax.plot(
                steps[window - 1 :],
                mean,
                color="black",
                lw=1.0,
                label=f"running mean over {window} steps",
            )
            ax.legend(fontsize=7, loc="lower left")
    has = ~np.isnan(series["oldest"])
    if has.any():
        axes[2].vlines(
            steps[has], series["newest"][has], series["oldest"][has], color=colour, lw=1.0
        )
        axes[2].plot(steps[has], series["oldest"][has], ".", ms=2, color="0.2", label="oldest")
        axes[2].plot(steps[has], series["newest"][has], ".", ms=2, color="0.6", label="newest")
        axes[2].legend(fontsize=7, loc="upper left")
    else:
        axes[2].text(
            0.5, 0.5, "no written memory value read", ha="center", transform=axes[2].transAxes
        )
    axes[2].set_ylabel("memory window\n(age of values read,\nsteps)")
    if prediction is not None:
        _velocity_panel(axes[3], steps, prediction, colour)
    axes[-1].set_xlabel("time step")
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    return save(fig, path)


def _velocity_panel(ax, steps: np.ndarray, prediction: dict, colour: str) -> None:
    """The bottom panel of :func:`time_series`: the velocity and the closest register."""
    ax.plot(steps, prediction["velocity"], color="black", lw=1.2, label=prediction["variable"])
    if prediction["label"]:
        r = prediction["r"]
        neg = " (negated)" if r < 0 else ""
        ax.plot(
            steps,
            prediction["register"],
            color=colour,
            lw=1.2,
            label=f"register {prediction['label']}{neg}, Pearson r = {r:.2f}",
        )
    ax.set_ylim(-1.15, 1.45)
    r = prediction["r"]
    tracks = prediction["label"] and abs(r) >= TRACKS_R
    ax.set_ylabel(
        ("velocity prediction" if tracks else "hidden velocity and\nclosest register")
        + "\n(scaled to [-1, 1])"
    )
    if not tracks:  # a weak correlation is no prediction: say so on the panel
        ax.text(
            0.99,
            0.97,
            f"no register tracks the velocity (|r| < {TRACKS_R})",
            ha="right",
            va="top",
            fontsize=7,
            color="0.3",
            transform=ax.transAxes,
        )
    ax.legend(fontsize=7, loc="upper left", ncol=2)


def decomposition(dec: dict, numbers: list[int], path: Path, title: str) -> Path:
    """Fig. 10: one panel per team, points where it ran, coloured by action when final."""
    plt = pyplot()
    from matplotlib.lines import Line2D

    teams = [dec["teams"][k - 1] for k in numbers]
    cols = min(4, max(1, len(teams)))
    rows = -(-len(teams) // cols)
    fig, axes = plt.subplots(
        rows,
        cols,
        figsize=(3.3 * cols + (2.2 if dec["continuous"] else 0.6), 2.9 * rows + 1.3),
        squeeze=False,
        sharex=True,
        sharey=True,
    )
    all_actions = np.concatenate([t["action"][t["final"]] for t in teams] + [np.zeros(0)])
    top = float(np.abs(all_actions).max()) if len(all_actions) else 1.0
    lo, hi = -(top or 1.0), top or 1.0  # symmetric: no force sits mid-scale
    mappable = None
    for ax, number, team in zip(axes.flat, numbers, teams, strict=False):
        passed = ~team["final"]
        ax.scatter(team["x"][passed], team["y"][passed], s=3, c=PASSED_COLOUR, lw=0)
        fin = team["final"]
        if dec["continuous"]:
            mappable = ax.scatter(
                team["x"][fin],
                team["y"][fin],
                s=4,
                c=team["action"][fin],
                cmap=CONTINUOUS_CMAP,
                vmin=lo,
                vmax=hi,
                lw=0,
            )
        else:
            acts = team["action"][fin].astype(int)
            ax.scatter(
                team["x"][fin],
                team["y"][fin],
                s=4,
                c=[ACTION_COLOURS[a % 3] for a in acts],
                lw=0,
            )
        ax.set_title(f"team {number} ({len(team['x'])} visits, {int(fin.sum())} final)", fontsize=8)
    for ax in list(axes.flat)[len(teams) :]:
        ax.axis("off")
    for ax in axes[-1]:
        ax.set_xlabel(dec["x_label"], fontsize=8)
    for ax in axes[:, 0]:
        ax.set_ylabel(dec["y_label"], fontsize=8)
    fig.suptitle(title, fontsize=11)
    passed_handle = Line2D([], [], ls="", marker="o", color=PASSED_COLOUR, label="passed on")
    if dec["continuous"] and mappable is not None:
        handles = [passed_handle]
    else:
        handles = [
            Line2D([], [], ls="", marker="o", color=c, label=f"final team, a_d = {a}")
            for a, c in enumerate(ACTION_COLOURS)
        ] + [passed_handle]
    fig.legend(handles=handles, loc="lower center", ncol=4, fontsize=8)
    bottom = 0.45 / (2.9 * rows + 1.3)
    coloured = dec["continuous"] and mappable is not None
    fig.tight_layout(rect=(0, bottom, 0.86 if coloured else 1.0, 0.95))
    if dec["continuous"] and mappable is not None:
        cax = fig.add_axes((0.89, 0.2, 0.02, 0.6))
        fig.colorbar(mappable, cax=cax, label="a_c of the step (coloured: final team)")
    return save(fig, path)
