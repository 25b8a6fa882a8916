"""Score the demo-scale candidates of ``results/candidates`` and write their table.

For every run of the demo group (``mtpg experiment --plan results/plan.toml --only demo``)
that has reached
its last generation, the all-task champion is played on 100 held-out episodes per task
(``mtpg evaluate RUN --episodes 100 --json``: seeds 1,000,000 to 1,000,099, never used by
training or selection). The normalised scores (0 = random play, 1 = the reference best)
go to ``results/candidates/candidates.json``, and the README's section between the
markers below gets the table: per run and task, then per group the interquartile mean
over runs and tasks with its 95% stratified bootstrap interval, per task the IQM over
runs, and the probability that a resampled run beats a plain one on a task, with its
interval (:mod:`mtpg.analysis.runs.statistics`)::

    .venv/bin/mtpg report --results results --page candidates
"""

from __future__ import annotations

import json
import logging
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np

from mtpg.analysis.runs.statistics import aggregate_iqm, per_task_iqm, probability_of_improvement

_LOG = logging.getLogger(__name__)
#: The study's folder inside the results folder.
FOLDER = "candidates"
#: Each group by the prefix of its run folders: the two candidates, and the robust audit's
#: test of them (docs/robust-audit.md: resampling with 6 training episodes instead of 3).
GROUPS = {
    "demo": "demo-seed",
    "demo-resample10": "demo-resample10-seed",
    "demo-resample10-train6": "demo-resample10-train6-seed",
}
#: The comparisons the table states, ``(a, b)``: the probability that a run of ``a``
#: beats one of ``b`` on a task.
PAIRS = (("demo-resample10", "demo"), ("demo-resample10-train6", "demo-resample10"))
EPISODES = 100
BEGIN, END = "<!-- candidates table: begin -->", "<!-- candidates table: end -->"


def finished(run: Path) -> bool:
    """Whether the run has reached the generations of its configuration."""
    if not (run / "config.toml").is_file():
        return False
    target = tomllib.loads((run / "config.toml").read_text())["generations"]
    lines = (run / "metrics.csv").read_text().splitlines()
    return len(lines) > 1 and int(lines[-1].split(",")[0]) >= target


def scores(run: Path) -> dict[str, float]:
    """The all-task champion's normalised score per task on the held-out episodes."""
    out = subprocess.run(
        [sys.executable, "-m", "mtpg", "evaluate", str(run), "--episodes", str(EPISODES)]
        + ["--json"],
        capture_output=True,
        text=True,
        check=True,
    ).stdout
    return {task: row["normalised"] for task, row in json.loads(out).items()}


def table(results: dict[str, dict[str, dict[str, float]]]) -> str:
    """The README section: per run, per group and the pairwise comparison."""
    tasks = list(next(iter(next(iter(results.values())).values())))
    head = "| run | " + " | ".join(tasks) + " | min |\n|---|" + "---|" * (len(tasks) + 1)
    lines = [head]
    matrices = {}
    for group, runs in results.items():
        matrices[group] = np.array([[runs[r][t] for t in tasks] for r in sorted(runs)])
        for r in sorted(runs):
            row = [runs[r][t] for t in tasks]
            lines.append(f"| {r} | " + " | ".join(f"{v:.2f}" for v in row) + f" | {min(row):.2f} |")
    lines += ["", "| group | runs | IQM over runs and tasks [95% CI] | " + " | ".join(tasks) + " |"]
    lines.append("|---|---|---|" + "---|" * len(tasks))
    for group, m in matrices.items():
        per = " | ".join(e.text() for e in per_task_iqm(m))
        lines.append(f"| {group} | {len(m)} | {aggregate_iqm(m).text()} | {per} |")
    for a, b in PAIRS:
        if a in matrices and b in matrices:
            p = probability_of_improvement(matrices[a], matrices[b])
            lines += ["", f"P({a} > {b}) = {p.text()}"]
    return "\n".join(lines)


def render(page: str, results: dict[str, dict[str, dict[str, float]]]) -> str:
    """The README's text with the section between the markers written from ``results``."""
    head, _, rest = page.partition(BEGIN)
    _, _, tail = rest.partition(END)
    body = (
        f"{BEGIN}\nNormalised scores on {EPISODES} held-out episodes per task of each finished "
        "run's all-task champion (written by "
        "`mtpg report --results results --page candidates`):\n\n"
        f"{table(results)}\n{END}"
    )
    return head + body + tail


def write(results: Path, out: Path | None = None) -> Path:
    """Scores the finished runs and rewrites the README's table; returns the README's path.

    Args:
        results: The results folder (its ``candidates/runs`` are scored, its
            ``candidates/README.md`` is the page).
        out: The results folder written to (default: ``results``).

    Raises:
        ValueError: No run has finished.
    """
    folder = results / FOLDER
    scored: dict[str, dict[str, dict[str, float]]] = {}
    for group, prefix in GROUPS.items():
        runs = sorted(p for p in (folder / "runs").glob(f"{prefix}[0-9]*") if p.is_dir())
        done = {r.name: scores(r) for r in runs if finished(r)}
        _LOG.info(f"{group}: {len(done)} of {len(runs)} runs finished")
        if done:  # a group none of whose runs has finished is left out of the table
            scored[group] = done
    if not any(scored.values()):
        raise ValueError(f"{folder / 'runs'}: no finished run")
    where = (results if out is None else out) / FOLDER
    where.mkdir(parents=True, exist_ok=True)
    (where / "candidates.json").write_text(json.dumps(scored, indent=1, sort_keys=True) + "\n")
    readme = where / "README.md"
    readme.write_text(render((folder / "README.md").read_text(), scored))
    return readme
