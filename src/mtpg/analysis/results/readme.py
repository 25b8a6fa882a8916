"""Regenerate ``results/README.md`` and its figures from the committed runs.

One command, from the repository root with the project's environment::

    .venv/bin/mtpg report --results results --page results

It reads ``results/runs/*`` (grown by ``mtpg experiment --plan results/plan.toml``),
draws the section-5 figures with ``mtpg report`` into ``results/figures/``, the
section-6 figures of the best run's all-task champion with ``mtpg analyze`` into
``results/analysis/``, and writes the README: status and cost of every run, the tables
behind the figures, and the comparison with the paper task by task. Every number in the
text is computed here from the runs' files, by the same library functions the report
uses (:mod:`mtpg.analysis.runs.reported_numbers`, :mod:`mtpg.analysis.runs.statistics`).
"""

from __future__ import annotations

import dataclasses
import subprocess
import sys
import warnings
from pathlib import Path

from mtpg.analysis.results.answer import three_groups
from mtpg.analysis.results.authors_section import answer_sentence, gather, is_authors
from mtpg.analysis.results.authors_section import section as authors_section
from mtpg.analysis.results.robust_section import answer, compare, is_robust
from mtpg.analysis.results.robust_section import section as robust_section
from mtpg.analysis.results.tables import (
    GOOD,
    LEVEL,
    PAPER,
    ablation_rows,
    compare_table,
    cost_rows,
    hierarchy_rows,
    markdown_table,
    rescore_rows,
    resume_check_rows,
    status_rows,
)
from mtpg.growing.tidy import KEEP_TESTS_EVERY

TARGET = 1000
GROWING = [
    "## Growing the runs",
    "",
    "Each run directory holds `config.toml`, `metrics.csv`, `tests.csv`, its newest "
    "checkpoint, the champion files of all 63 task subsets packed in `champions.tar.xz` "
    "(`tar xf champions.tar.xz`; a resume writes `champions/` anew), the test-point "
    "graphs of the latest test point in `tests/gen-NNNNNN/` and those of every "
    f"{KEEP_TESTS_EVERY}th generation packed in `tests/archive.tar.xz` (`tests.csv` has "
    "the scores of every test point), and `provenance.csv`: which mtpg commit ran which "
    "generations, when, for how long, on "
    "which processor. To continue them, from a clone of the repository:",
    "",
    "```sh",
    "python3 -m venv .venv && .venv/bin/pip install -e .",
    ".venv/bin/mtpg experiment --plan results/plan.toml --budget 150 --only paper  # minutes",
    ".venv/bin/mtpg report --results results --page results  # this page and its figures",
    "git push",
    "```",
    "",
    "`mtpg experiment --plan` continues the unfinished runs of the plan's groups in "
    "order, two at a time with one "
    "thread each, stops them with SIGTERM at a generation boundary every `--slice` minutes "
    "and when the budget is spent (or when it is itself stopped), keeps the newest "
    "checkpoint and commits `results/runs`. It refuses to run an mtpg whose `src/` has "
    "uncommitted changes or whose commit is not in the repository's history, so the "
    "commit it records reproduces the generations. A single run can also be continued by "
    "hand: `mtpg train --resume results/runs/TPG-seed3 --workers 2`.",
    "",
    "Resuming with a later commit is exact because `tests/evolve/test_paper_pin.py` pins the "
    "`paper` preset: a fresh three-generation run and a stored checkpoint resumed to "
    "generation 6 must repeat stored metrics, tests and run-state digests. A change that "
    "fails it alters the `paper` preset: it must say so, and the runs here restart from "
    "generation 0 with the new commit recorded.",
    "",
]


def _runs(results: Path) -> list[Path]:
    return sorted(
        (p for p in (results / "runs").iterdir() if (p / "tests.csv").is_file()),
        key=lambda p: (not p.name.startswith("TPG-seed"), p.name),
    )


def _fig(name: str, caption: str) -> str:
    return f"![{caption}](figures/{name})\n\n*{caption}*\n"


def _robust_figure(comparison, tpg, numbers, path: Path) -> Path:
    """Both groups' IQM per task and over all tasks (the section's table, drawn)."""
    from mtpg.analysis.runs.loading import RunGroup
    from mtpg.analysis.runs.reported_numbers import run_numbers
    from mtpg.analysis.runs.statistics_figures import aggregate

    robust = comparison.groups["TPG-robust"]
    groups = [tpg, RunGroup("TPG-robust", robust, {})]
    drawn = {**numbers, **{r.path: run_numbers(r) for r in robust}}
    return aggregate(groups, drawn, comparison.estimates, path)


def _three_figure(comparison, tpg, numbers, three, path: Path) -> Path:
    """The three groups' IQM per task and over all tasks (the authors section's table)."""
    from mtpg.analysis.runs import statistics as stats
    from mtpg.analysis.runs.loading import RunGroup
    from mtpg.analysis.runs.reported_numbers import run_numbers
    from mtpg.analysis.runs.statistics_figures import aggregate

    robust = comparison.groups["TPG-robust"]
    groups = [tpg, RunGroup("TPG-robust", robust, {}), RunGroup("TPG-authors", three.compared, {})]
    drawn = {**numbers, **{r.path: run_numbers(r) for r in [*robust, *three.compared]}}
    estimates = dict(comparison.estimates)
    estimates["TPG-authors"] = (stats.per_task_iqm(three.matrix), stats.aggregate_iqm(three.matrix))
    return aggregate(groups, drawn, estimates, path)


def build(results: Path, analyze: bool = True, probe: bool = True, out: Path | None = None) -> Path:
    """Writes the figures and ``README.md`` of ``results``; returns the README's path.

    ``out`` is the folder they are written to (default: ``results`` itself; the page's
    links are relative to it, so a copy elsewhere compares byte for byte).

    The TPG-robust runs (``TPG-robust-seedN``) are listed with the others (status,
    re-scores, cost) and compared with TPG in a section of their own
    (:mod:`~mtpg.analysis.results.robust_section`); the paper's experiment (figures,
    summaries, ablations) is of the other runs. ``probe`` adds the memorisation probe of
    every TPG and TPG-robust final champion to that section.
    """
    from mtpg.analysis.runs.champions import CHAMPION_RULE
    from mtpg.analysis.runs.loading import group_runs, load_run
    from mtpg.analysis.runs.report import build_report
    from mtpg.analysis.runs.reported_numbers import (
        BEST_RUN_RULE,
        best_of,
        best_single_task,
        run_numbers,
    )
    from mtpg.analysis.runs.statistics_figures import STATS_NOTE, group_estimates

    every = [load_run(p) for p in _runs(results)]
    robust = [dataclasses.replace(r, label="TPG-robust") for r in every if is_robust(r.path)]
    authors = [dataclasses.replace(r, label="TPG-authors") for r in every if is_authors(r.path)]
    runs = [r for r in every if not is_robust(r.path) and not is_authors(r.path)]
    every = runs + robust + authors  # the paper's experiment, then TPG-robust, TPG-authors
    paths = [r.path for r in runs]
    groups, _ = group_runs(runs)
    numbers = {r.path: run_numbers(r) for r in runs}
    tasks = runs[0].tasks
    # While some runs grow, the figures and summaries (best run, IQM, best single-task
    # champion, counts) are of the runs at the target generation, so that a run just
    # begun does not stand beside finished ones in one statistic; every run is listed.
    tpg = groups[0]
    at_target = {r.path for r in runs if r.final_generation >= TARGET}
    finished = [r for r in tpg.runs if r.path in at_target]
    partial = bool(finished) and len(finished) < len(tpg.runs)
    if partial:
        tpg = dataclasses.replace(tpg, runs=finished)
    drawn = [p for p in paths if p in at_target] if partial else paths
    out = results if out is None else out
    figures = out / "figures"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        build_report(drawn, figures)
    (figures / "index.html").unlink(missing_ok=True)  # the PNGs are committed instead
    best = best_of([numbers[r.path] for r in tpg.runs])
    per_task, overall = group_estimates(tpg, numbers)
    best_single = best_single_task([numbers[r.path] for r in tpg.runs])

    lines = [
        "# The paper's experiment, reproduced",
        "",
        "Five runs of the `paper` preset (seeds 1 to 5) and one run of each ablation of "
        "section 5.2 (seed 1), each grown to 1,000 generations over several sittings with "
        "`mtpg experiment --plan results/plan.toml` and committed with its last "
        "checkpoint, so that "
        "`mtpg train --resume results/runs/RUN` continues any of them exactly. This page "
        "and its figures are written by `.venv/bin/mtpg report --results results --page "
        "results` from "
        "the committed files alone."
        + (
            " Beside them, five runs of TPG-robust (the `robust` preset), compared with "
            "TPG in their own section below."
            if robust
            else ""
        )
        + (
            " TPG-authors (the `paper` preset on the interface of the authors' published "
            "code) joins both in the section after it."
            if authors
            else ""
        ),
        "",
    ]
    comparison = compare(tpg.runs, robust, best_single, TARGET) if robust else None
    three = gather(authors, list(tasks), TARGET) if authors and comparison else None
    if comparison is not None and comparison.complete:
        said = answer(comparison)
        if three is not None and three.complete:
            said = three_groups(comparison, three)
        elif three is not None:
            said[-1] += " " + answer_sentence(three)
        lines += [*said, ""]
    lines += ["## Status", ""]
    done = len(at_target) == len(runs)
    if done and any(r.final_generation < TARGET for r in robust):
        lines += [
            "**TPG-robust in progress**: the paper's experiment below is complete; the "
            "TPG-robust runs are still growing, and their section compares both groups at "
            "the TPG-robust runs' latest common test point.",
            "",
        ]
    if not done:
        lines += [
            "**In progress**: not every run has reached generation 1,000, so every figure "
            "and number below is of the runs' latest test point (named in each table), "
            "not of the paper's 1,000 generations.",
            "",
        ]
    lines += markdown_table(*status_rows(every, TARGET)) + [""]
    if partial:
        lines += [
            f"Figures and summaries (best run, interquartile means, best single-task "
            f"champions, counts) are of the {len(tpg.runs)} TPG runs at generation {TARGET:,} "
            f"({', '.join(r.path.name for r in tpg.runs)}); the runs still growing are "
            "listed at their latest test point beside them.",
            "",
        ]
    lines += [
        "## Section 5: test scores",
        "",
        f"Champions: {CHAMPION_RULE}. {BEST_RUN_RULE}. Test score: mean return over "
        f"{runs[0].test_episodes} held-out episodes per task. "
        "Normalised: 0 = random play, 1 = the reference best (`mtpg envs`) or, for "
        "*vs best single*, the best single-task champion of all TPG runs at their final "
        "test points, chosen by test score as the paper's Fig. 7 chooses it: the one "
        "choice made on test scores, which biases the ratios downward "
        "([docs/report.md](../docs/report.md#the-numbers-of-one-run)). "
        "`normalised_vs_single.png` (Fig. 5) uses *vs single*: each run's own "
        "single-task champion.",
        "",
        f"Best TPG run: **{best.run.name}** (generation {best.generation}, all-task "
        f"champion of {best.graph_teams} teams).",
        "",
    ]
    lines += compare_table(best, best_single, tasks)
    lines += [
        "",
        "Every run's all-task champion, normalised against the reference best, and the "
        f"interquartile mean across the {len(tpg.runs)} TPG seeds with its 95% confidence "
        f"interval ({STATS_NOTE})",
        "",
    ]
    head = ["run", "generation", *tasks]
    rows = [
        [n.run.name, str(n.generation), *(f"{n.normalised[t]:.2f}" for t in tasks)]
        for n in (numbers[r.path] for g in groups for r in g.runs)
    ]
    at = f" at generation {TARGET:,}" if partial else ""
    rows.append([f"IQM over TPG seeds{at}", "", *(e.text(2) for e in per_task)])
    lines += markdown_table(head, rows)
    lines += ["", f"IQM over TPG seeds{at} and all tasks: {overall.text(2)}.", ""]
    head, rows, agree, cells = rescore_rows(runs + robust)  # TPG-authors: its own tasks
    lines += [
        "Every run's all-task champion: mean test return ± the half-width of its 95% "
        f"confidence interval (1.96 std / sqrt(n), n = {runs[0].test_episodes} test "
        "episodes, the scores of `tests.csv`), and in brackets the same graph re-scored on "
        f"{runs[0].test_episodes} other held-out episodes (seed offset "
        "500,000: `mtpg evaluate results/runs/RUN --seed 500000`). Two means over "
        "independent blocks of episodes differ by less than 1.41 times the half-width "
        f"about 95% of the time; here the re-score is that close in {agree} of {cells} "
        "cells.",
        "",
        *markdown_table(head, rows),
        "",
    ]
    vs_single_rows = [
        [n.run.name, *(f"{x:.2f}" for x in _vs(n.test, best_single, tasks))]
        for n in (numbers[r.path] for g in groups for r in g.runs)
    ]
    at_06 = sum(
        all(v >= 0.6 for v in _vs(numbers[r.path].test, best_single, tasks)) for r in tpg.runs
    )
    lines += [
        "Every run's all-task champion, *vs best single*:",
        "",
        *markdown_table(["run", *tasks], vs_single_rows),
        "",
        f"TPG runs whose all-task champion reaches 0.6 of the best single-task champion in "
        f"all six tasks: **{at_06} of {len(tpg.runs)}** (paper: {PAPER['runs_at_06']}).",
        "",
    ]
    lines += [
        "The best run of each experiment, *vs best single* (Fig. 7). *Ours* reads the "
        "paper's words as rules on these scores: full TPG "
        f"{PAPER['best_vs_single'] - LEVEL:.2f} or more in every task, TPG-NoXover {GOOD} "
        "or more in every task, TPG-NoMemory below 0.5 in every task, TPG-NoHierarchy "
        f"{GOOD} or more in MountainCarContinuous and in no other task:",
        "",
        *markdown_table(*ablation_rows([tpg, *groups[1:]], numbers, best_single, tasks)),
        "",
    ]
    for name, caption in (
        ("learning_curves.png", "Fig. 4: learning curves (test return at every test point)"),
        ("normalised_vs_single.png", "Fig. 5: against single-task champions"),
        ("normalised_vs_reference.png", "Fig. 6: against the reference best"),
        ("ablations.png", "Fig. 7: the ablations beside full TPG"),
        ("hierarchy.png", "Fig. 8: teams per decision by task subset"),
        ("aggregate.png", "Across seeds: IQM with 95% bootstrap confidence intervals"),
        ("performance_profile.png", "Across seeds: performance profile"),
        ("probability_of_improvement.png", "Across seeds: probability of improvement"),
        ("training_curves.png", "Training scores and population sizes, every generation"),
    ):
        if (figures / name).is_file():
            lines.append(_fig(name, caption))
    lines += ["## Fig. 8: teams per decision by subset size", ""]
    lines += markdown_table(*hierarchy_rows(tpg.runs)) + [""]
    analysis = out / "analysis"
    if analyze:
        subprocess.run(
            [sys.executable, "-m", "mtpg", "analyze", str(best.run.path), "--out", str(analysis)],
            check=True,
            capture_output=True,
        )
        (analysis / "index.html").unlink(missing_ok=True)
    pngs = sorted(analysis.glob("*.png")) if analysis.is_dir() else []
    if pngs:
        lines += [
            "## Section 6: inside the best champion (Figs. 9-12)",
            "",
            f"`mtpg analyze {best.run.path.relative_to(results.parent)}`: the all-task "
            f"champion of {best.run.name} at generation {best.generation}, replayed on 100 "
            "test episodes per task.",
            "",
        ]
        lines += [f"![{p.stem}](analysis/{p.name})\n" for p in pngs]
    if robust:
        probes = {}
        if probe:
            from mtpg.analysis.runs.champion_probe import probe_target

            probes = {r.name: probe_target(r.path) for r in [*tpg.runs, *robust]}
        lines += robust_section(comparison, robust, probes, TARGET)
        if comparison.complete:
            _robust_figure(comparison, tpg, numbers, figures / "robust_vs_tpg.png")
            lines.append(_fig("robust_vs_tpg.png", "TPG-robust beside TPG: IQM with 95% CIs"))
    if three is not None:
        probes = {}
        if probe:
            from mtpg.analysis.runs.champion_probe import probe_target

            probes = {r.name: probe_target(r.path) for r in authors}
        lines += authors_section(comparison, three, probes, TARGET)
        _three_figure(comparison, tpg, numbers, three, figures / "three_groups.png")
        caption = "TPG, TPG-robust and TPG-authors: IQM with 95% CIs (TPG-authors on its variants)"
        lines.append(_fig("three_groups.png", caption))
    lines += ["## Cost", ""]
    lines += [
        "Wall-clock hours: the sum of `metrics.csv`'s `t_total` (every generation, test "
        "points included). CPU hours: from `provenance.csv` (the process's user and system "
        "time per sitting; sittings recorded without it are left out and the generations "
        "covered are named). Each run ran with `--workers 1` (one thread; `provenance.csv` "
        "names the sittings that ran on more), two runs at a time on a 2-core machine, "
        "while other work shared it, so these are upper bounds of what a quiet machine "
        "needs (the processor is in each run's `provenance.csv`).",
        "",
    ]
    lines += markdown_table(*cost_rows(every)) + [""]
    lines += GROWING
    checked = results / "resume_check.csv"
    if checked.is_file():
        lines += [
            "Checked on the runs themselves by `.venv/bin/python tools/check_resume.py "
            "--record`: each run as an earlier commit holds it (its checkpoint then), "
            "written into an empty folder as a fresh clone would hold it, resumed with the "
            "mtpg named up to its next test point, and the rows it writes compared with "
            "those committed since (`metrics.csv` without its timing columns, `tests.csv` "
            "value for value):",
            "",
            *markdown_table(*resume_check_rows(checked)),
            "",
        ]
    if caught:
        lines += [f"Report warning: {w.message}" for w in caught] + [""]
    readme = out / "README.md"
    readme.write_text("\n".join(lines).rstrip() + "\n")
    return readme


def _vs(test: dict[str, float], best: dict[str, float], tasks) -> list[float]:
    from mtpg.analysis.runs.loading import normalise_scores

    v = normalise_scores(test, best)
    return [v[t] for t in tasks]
