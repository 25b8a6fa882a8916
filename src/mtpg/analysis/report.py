"""``mtpg report``: the figures of section 5 as PNG files plus one self-contained HTML page."""

from __future__ import annotations

import base64
import html
from pathlib import Path

from mtpg.analysis import plots
from mtpg.analysis.runs import (
    RunData,
    best_run,
    load_run,
    normalise_scores,
    reference_best,
    vs_single_task,
)

FIGURES = (
    ("learning_curves.png", "Learning curves (Fig. 3)", plots.learning_curves),
    (
        "normalised_vs_single.png",
        "Against single-task champions (Fig. 4)",
        plots.normalised_vs_single,
    ),
    (
        "normalised_vs_reference.png",
        "Against the reference best (Fig. 5)",
        plots.normalised_vs_reference,
    ),
    ("hierarchy.png", "Teams per decision by task subset (Fig. 7)", plots.hierarchy),
)


def _table(title: str, tasks: tuple[str, ...], rows: dict[str, dict[str, float]]) -> str:
    head = "".join(f"<th>{html.escape(t)}</th>" for t in tasks)
    body = "".join(
        f"<tr><td>{html.escape(name)}</td>"
        + "".join(f"<td>{values[t]:.3f}</td>" for t in tasks)
        + "</tr>"
        for name, values in rows.items()
    )
    return f"<h2>{html.escape(title)}</h2><table><tr><th></th>{head}</tr>{body}</table>"


def build_report(run_dirs: list[str | Path], out: str | Path | None = None) -> Path:
    """Writes the PNG figures and ``index.html`` for one or more runs.

    Args:
        run_dirs: Run directories on the same tasks (ablation runs are recognised from
            their configuration and get their own figure).
        out: Output directory (default: ``report/`` inside the first run).

    Returns:
        The path of ``index.html``.
    """
    runs: list[RunData] = [load_run(p) for p in run_dirs]
    tasks = runs[0].tasks
    for run in runs:
        if run.tasks != tasks:
            raise ValueError(f"{run.path}: tasks {run.tasks} differ from {tasks}")
        run.final(run.full_set)  # raises a clear error for a run without tests
    out = Path(out) if out is not None else runs[0].path / "report"
    out.mkdir(parents=True, exist_ok=True)
    figures = list(FIGURES)
    if len({r.label for r in runs}) > 1:
        figures.insert(3, ("ablations.png", "Ablations (Fig. 6)", plots.ablations))
    sections = []
    for name, title, draw in figures:
        png = draw(runs, out / name)
        data = base64.b64encode(png.read_bytes()).decode("ascii")
        sections.append(
            f'<h2>{html.escape(title)}</h2><img alt="{html.escape(title)}" '
            f'src="data:image/png;base64,{data}">'
        )
    best = best_run(runs)
    tables = [
        _table(
            "Final test return of each run's all-task champion",
            tasks,
            {r.path.name: r.multitask_scores() for r in runs},
        ),
        _table(
            "Normalised against the run's best single-task champions",
            tasks,
            {r.path.name: vs_single_task(r) for r in runs},
        ),
        _table(
            "Normalised against the reference best",
            tasks,
            {
                f"{best.path.name} (best run)": normalise_scores(
                    best.multitask_scores(), reference_best(tasks)
                )
            },
        ),
    ]
    runs_list = "".join(
        f"<li>{html.escape(str(r.path))}: {html.escape(r.label)}, seed "
        f"{r.config.seed}, {int(r.tests[-1]['generation'])} generations, "
        f"{r.config.evaluation.test_episodes} test episodes per task</li>"
        for r in runs
    )
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>mtpg report</title>
<style>body{{font-family:sans-serif;max-width:1100px;margin:2em auto}}img{{max-width:100%}}
table{{border-collapse:collapse}}td,th{{border:1px solid #ccc;padding:3px 8px;text-align:right}}
</style></head><body>
<h1>mtpg report</h1><ul>{runs_list}</ul>
{"".join(tables)}
{"".join(sections)}
</body></html>
"""
    index = out / "index.html"
    index.write_text(page, encoding="utf-8")
    return index
