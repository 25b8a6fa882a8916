"""The robust audit's test at ``demo`` scale: 6 training episodes against 3, with resampling.

docs/robust-audit.md recommends more training episodes for the noisiest tasks and tests
it at ``demo`` scale: ``demo`` with ``evaluation.resample_interval = 10`` and
``evaluation.train_episodes = 6`` (the ``episodes6`` group of ``results/plan.toml``, runs
``results/candidates/runs/demo-resample10-train6-seedN``) against the committed
``demo-resample10`` runs (TPG-robust at ``demo`` scale, 3 training episodes). Both arms
are scored by the candidates page (:mod:`~mtpg.analysis.results.candidates`: the all-task
champion of each finished run on 100 held-out episodes per task, stored in
``results/candidates/candidates.json``); this module reads those stored scores, so it
replays nothing, and writes the comparison between the page's second pair of markers.

The rule the page states in advance: the change is worth a per-task option and the
paper's scale only if the six-task IQM of the new arm beats the old one's with the 95%
intervals apart.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from mtpg.analysis.runs.statistics import aggregate_iqm, per_task_iqm, probability_of_improvement

#: The arm the recommendation is measured against, then the recommendation.
ARMS = ("demo-resample10", "demo-resample10-train6")
#: The two tasks TPG-robust lags in, shown on their own.
LAGGING = ("CartCentering", "Pendulum")
#: Seeds per arm.
SEEDS = 5
BEGIN, END = "<!-- audit trial: begin -->", "<!-- audit trial: end -->"
COMMAND = ".venv/bin/mtpg report --results results --page candidates --page robust-audit"


def _decisions_per_generation(run: Path) -> float:
    """Mean decisions per generation over the run's ``metrics.csv`` (engine-independent)."""
    with (run / "metrics.csv").open(newline="") as f:
        values = [float(row["decisions"]) for row in csv.DictReader(f)]
    return float(np.mean(values)) if values else float("nan")


def trial_block(scored: dict[str, dict[str, dict[str, float]]], runs: Path) -> list[str]:
    """The block: the two arms side by side, the probability of improvement, the verdict.

    Args:
        scored: ``{group: {run name: {task: normalised score}}}`` as the candidates page
            stores it (``candidates.json``).
        runs: The folder of the runs (``results/candidates/runs``), for their costs.
    """
    head = [
        f"Written by `{COMMAND}` from the stored scores of the candidates page "
        "(`results/candidates/candidates.json`: each finished run's all-task champion on "
        "100 held-out episodes per task, normalised: 0 = random play, 1 = the reference best).",
        "",
    ]
    old, new = ARMS
    if new not in scored or old not in scored:
        missing = new if new not in scored else old
        return head + [f"No run of `{missing}` has finished yet (0 of {SEEDS})."]
    tasks = list(next(iter(scored[old].values())))
    cols = [f"{t} IQM" for t in LAGGING]
    lines = head + [
        "| arm | training episodes | runs finished | IQM over runs and tasks [95% CI] | "
        + " | ".join(cols)
        + " | decisions per generation |",
        "|---|---|---|---|" + "---|" * len(cols) + "---|",
    ]
    matrices = {}
    for arm, episodes in zip(ARMS, (3, 6), strict=True):
        names = sorted(scored[arm])
        m = np.array([[scored[arm][r][t] for t in tasks] for r in names])
        matrices[arm] = m
        per = per_task_iqm(m)
        lag = " | ".join(per[tasks.index(t)].text() for t in LAGGING)
        cost = np.mean([_decisions_per_generation(runs / r) for r in names])
        lines.append(
            f"| {arm} | {episodes} | {len(names)} of {SEEDS} | {aggregate_iqm(m).text()} | "
            f"{lag} | {cost:,.0f} |"
        )
    a, b = aggregate_iqm(matrices[new]), aggregate_iqm(matrices[old])
    p = probability_of_improvement(matrices[new], matrices[old])
    lines += ["", f"P({new} > {old}) = {p.text()}", ""]
    if a.low > b.high:
        verdict = "beats it with the intervals apart: worth a per-task option and the paper's scale"
    elif a.high < b.low:
        verdict = "is worse, with the intervals apart"
    else:
        verdict = (
            "does not beat it with the intervals apart (they overlap): by the rule stated "
            "above, not carried to the paper's scale"
        )
    done = min(len(scored[arm]) for arm in ARMS)
    provisional = "" if done >= SEEDS else f" Provisional: {done} of {SEEDS} runs per arm."
    lines.append(
        f"**Verdict:** `{new}` (IQM {a.value:.2f}) against `{old}` ({b.value:.2f}) {verdict}."
        + provisional
    )
    return lines


def write_trial(results: Path, page: Path) -> None:
    """Rewrites the block between :data:`BEGIN` and :data:`END` of ``page``, if it has them.

    Args:
        results: The results folder (its ``candidates/candidates.json`` and runs are read).
        page: The audit page written to.
    """
    text = page.read_text(encoding="utf-8")
    if BEGIN not in text or END not in text:
        return
    stored = results / "candidates" / "candidates.json"
    scored = json.loads(stored.read_text()) if stored.is_file() else {}
    block = trial_block(scored, results / "candidates" / "runs")
    head, rest = text.split(BEGIN, 1)
    tail = rest.split(END, 1)[1]
    page.write_text(head + BEGIN + "\n" + "\n".join(block) + "\n" + END + tail, encoding="utf-8")
