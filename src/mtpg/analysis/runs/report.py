"""``mtpg report``: section 5's figures and statistics across seeds, PNGs plus one HTML page.

Every number comes from :mod:`mtpg.analysis.runs.reported_numbers` (the same definitions
``mtpg evaluate`` uses) or, for the memorisation probe of every run's all-task champion,
:mod:`mtpg.analysis.runs.champion_probe` (as ``mtpg probe``); runs are grouped by configuration
(:func:`mtpg.analysis.runs.loading.group_runs`) and a mixture of configurations beyond the
ablation switches raises :class:`MixedRunsWarning`.
"""

from __future__ import annotations

import html
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np

from mtpg.analysis import html as pages
from mtpg.analysis.runs import score_figures, statistics_figures
from mtpg.analysis.runs.champion_probe import probe_html, probe_target
from mtpg.analysis.runs.hierarchical_complexity import subset_complexity
from mtpg.analysis.runs.loading import RunData, RunGroup, group_runs, load_run, reference_best
from mtpg.analysis.runs.reported_numbers import (
    BEST_RUN_RULE,
    SINGLE_RULE,
    RunNumbers,
    best_of,
    describe,
    run_numbers,
)
from mtpg.analysis.runs.training_curves import training_curves


class MixedRunsWarning(UserWarning):
    """The runs of a report differ in more than seeds and ablation switches."""


def _fmt(v: float) -> str:
    return "n/a" if not np.isfinite(v) else f"{v:.3f}"


def _table(title: str, note: str, tasks, rows: list[tuple[str, str, dict[str, float]]]) -> str:
    head = "".join(f"<th>{html.escape(t)}</th>" for t in tasks)
    body = "".join(
        f"<tr><td>{html.escape(group)}</td><td>{html.escape(name)}</td>"
        + "".join(f"<td>{_fmt(values[t])}</td>" for t in tasks)
        + "</tr>"
        for group, name, values in rows
    )
    return (
        f"<h2>{html.escape(title)}</h2><p>{html.escape(note)}</p>"
        f"<table><tr><th>experiment</th><th>run</th>{head}</tr>{body}</table>"
    )


def _stats_table(groups: list[RunGroup], estimates, tasks) -> str:
    head = "".join(f"<th>{html.escape(t)}</th>" for t in (*tasks, "all tasks"))
    body = ""
    for g in groups:
        per_task, overall = estimates[g.label]
        cells = "".join(f"<td>{html.escape(e.text(3))}</td>" for e in (*per_task, overall))
        body += f"<tr><td>{html.escape(g.label)}</td><td>{len(g.runs)}</td>{cells}</tr>"
    return (
        "<h2>Across seeds: IQM [95% CI] of the normalised test score</h2>"
        f"<p>{html.escape(statistics_figures.STATS_NOTE)} Normalised: 0 = random play, "
        "1 = reference best.</p>"
        f"<table><tr><th>experiment</th><th>runs</th>{head}</tr>{body}</table>"
    )


def _runs_list(groups: list[RunGroup], numbers: dict[Path, RunNumbers]) -> str:
    items = []
    for g in groups:
        best = best_of([numbers[r.path] for r in g.runs])
        for r in g.runs:
            n = numbers[r.path]
            mark = " <b>(best run of the experiment)</b>" if n is best else ""
            items.append(
                f"<li>{html.escape(str(r.path))}: {html.escape(g.label)}, seed {r.config.seed}, "
                f"final generation {n.generation}, {n.episodes} test episodes per task, "
                f"all-task champion root {n.root} ({n.graph_teams} team"
                f"{'s' if n.graph_teams != 1 else ''}), normalised training score: minimum "
                f"{n.selection_score[0]:.3f}, mean {n.selection_score[1]:.3f}{mark}</li>"
            )
    return "<ul>" + "".join(items) + "</ul>"


Numbers = dict[Path, RunNumbers]
#: A figure of the report: file name, title, and how to draw it into a path.
Figure = tuple[str, str, Callable[[Path], Path]]


def build_report(run_dirs: list[str | Path], out: str | Path | None = None) -> Path:
    """Writes the PNG figures and ``index.html`` for one or more runs.

    Args:
        run_dirs: Run directories on the same tasks. Runs are grouped by configuration;
            ablation runs form their own groups and get the experiments figure.
        out: Output directory (default: ``report/`` inside the first run).

    Returns:
        The path of ``index.html``.

    Raises:
        ValueError: If the runs are on different tasks or have no test results.
    """
    runs = _load_runs(run_dirs)
    groups, mixed = group_runs(runs)
    for text in mixed:
        warnings.warn(text, MixedRunsWarning, stacklevel=2)
    numbers = {r.path: run_numbers(r) for r in runs}
    raw = sorted({t for n in numbers.values() for t, v in n.normalised.items() if v != v})
    if raw:  # a Gymnasium task without a reference best: its scores are raw
        raise ValueError(
            f"{', '.join(raw)}: no reference best, so the report's normalised figures cannot "
            'be drawn; give one, evaluation.references = ["TASK: best=NUMBER, source=TEXT"] '
            "(mtpg evaluate prints the raw scores)"
        )
    estimates = {g.label: statistics_figures.group_estimates(g, numbers) for g in groups}
    pairs = statistics_figures.improvements(groups, numbers)
    out = Path(out) if out is not None else runs[0].path / "report"
    out.mkdir(parents=True, exist_ok=True)
    sections = [
        pages.figure(draw(out / name), title)
        for name, title, draw in _figures(groups, numbers, estimates, pairs)
    ]
    ordered = [(g.label, numbers[r.path]) for g in groups for r in g.runs]
    warn_html = "".join(f'<p class="warn">Warning: {html.escape(w)}</p>' for w in mixed)
    body = (
        f"<h1>mtpg report</h1>{warn_html}\n"
        f"<p>{html.escape(describe([n for _, n in ordered]))} {html.escape(BEST_RUN_RULE)}.</p>\n"
        f"{_runs_list(groups, numbers)}\n"
        f"{''.join(_tables(groups, ordered, estimates, runs[0]))}\n"
        f"{probe_html([(g.label, r.name, probe_target(r.path)) for g in groups for r in g.runs])}\n"
        f"{_improvement_table(pairs)}\n"
        f"{''.join(sections)}"
    )
    index = out / "index.html"
    page = pages.page("mtpg report", body, ".warn{color:#a00;font-weight:bold}")
    index.write_text(page, encoding="utf-8")
    return index


def _load_runs(run_dirs: list[str | Path]) -> list[RunData]:
    """The runs, refusing runs on different tasks."""
    runs: list[RunData] = [load_run(p) for p in run_dirs]
    tasks = runs[0].tasks
    for run in runs:
        if run.tasks != tasks:
            raise ValueError(f"{run.path}: tasks {run.tasks} differ from {tasks}")
    return runs


def _improvement_table(pairs) -> str:
    """P(X > Y) with its interval for every pair, or nothing with a single group."""
    if not pairs:
        return ""
    body = "".join(
        f"<tr><td>P({html.escape(x)} &gt; {html.escape(y)})</td>"
        f"<td>{html.escape(e.text(3))}</td></tr>"
        for (x, y), e in pairs.items()
    )
    note = html.escape(statistics_figures.POI_NOTE)
    return (
        f"<h2>Probability of improvement [95% CI]</h2><p>{note}</p>"
        f"<table><tr><th>pair</th><th>estimate [95% CI]</th></tr>{body}</table>"
    )


def _figures(groups: list[RunGroup], numbers: Numbers, estimates, pairs) -> list[Figure]:
    """The report's figures in page order: Figs. 4-6, 7 (several experiments), 8, statistics."""
    main = groups[0]
    figures: list[Figure] = [
        (
            "learning_curves.png",
            "Learning curves (Fig. 4)",
            lambda p: score_figures.learning_curves(main, numbers, p),
        ),
        (
            "normalised_vs_single.png",
            "Against single-task champions (Fig. 5)",
            lambda p: score_figures.normalised_vs_single(main, numbers, p),
        ),
        (
            "normalised_vs_reference.png",
            "Against the reference best (Fig. 6)",
            lambda p: score_figures.normalised_vs_reference(main, numbers, p),
        ),
    ]
    if len(groups) > 1:
        figures.append(
            (
                "ablations.png",
                "Experiments and ablations (Fig. 7)",
                lambda p: score_figures.ablations(groups, numbers, p),
            )
        )
    return figures + [
        (
            "hierarchy.png",
            "Teams per decision by task subset (Fig. 8)",
            lambda p: subset_complexity(main, numbers, p),
        ),
        (
            "aggregate.png",
            "Across seeds: interquartile mean with 95% CIs",
            lambda p: statistics_figures.aggregate(groups, numbers, estimates, p),
        ),
        (
            "performance_profile.png",
            "Across seeds: performance profile",
            lambda p: statistics_figures.profile(groups, numbers, p),
        ),
        *(
            [
                (
                    "probability_of_improvement.png",
                    "Between experiments: probability of improvement",
                    lambda p: statistics_figures.improvement(groups, numbers, pairs, p),
                )
            ]
            if pairs
            else []
        ),
        (
            "training_curves.png",
            "Training scores and population sizes over generations (metrics.csv)",
            lambda p: training_curves(groups, p),
        ),
    ]


def _tables(groups, ordered: list[tuple[str, RunNumbers]], estimates, first: RunData) -> list[str]:
    """The statistics table, then the test, normalised and denominator tables of every run.

    The tasks and reference scores are those of the first run (``first``).
    """
    tasks = first.tasks
    ref = reference_best(first.task_table)
    return [
        _stats_table(groups, estimates, tasks),
        _table(
            "Test return of each run's all-task champion",
            describe([n for _, n in ordered]),
            tasks,
            [(g, n.run.name, n.test) for g, n in ordered],
        ),
        _table(
            "Normalised against the reference best",
            "0 = random play, 1 = reference best ("
            + ", ".join(f"{t} {v:g}" for t, v in ref.items())
            + ").",
            tasks,
            [(g, n.run.name, n.normalised) for g, n in ordered],
        ),
        _table(
            "Normalised against the run's own single-task champions",
            f"0 = random play, {SINGLE_RULE}; n/a where that champion does no better than "
            "random play.",
            tasks,
            [(g, n.run.name, n.vs_single) for g, n in ordered],
        ),
        _table(
            "Test return of each run's single-task champions (the denominators above)",
            "Each task's single-task champion (best root on that task alone by training "
            "score, same generation), tested on its own task.",
            tasks,
            [(g, n.run.name, n.single) for g, n in ordered],
        ),
    ]
