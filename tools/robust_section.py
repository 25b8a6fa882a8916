"""The TPG-robust section of ``results/README.md``: TPG-robust against TPG, seed by seed.

TPG-robust is the ``robust`` preset (the ``paper`` preset with the training episodes
redrawn every 10 generations; ``tools/grow_results.py --plan robust``), seeds 1 to 5,
beside the TPG runs in ``results/runs``. :func:`section` writes its part of the page from
the runs' files: both groups compared at one common test point (generation 1,000, with
the TPG-robust runs that have reached it; before any has, the latest test point all
TPG-robust runs have reached, so that the two groups are compared at the same age), seed
by seed and over seeds (interquartile means with 95% bootstrap intervals and the probability of
improvement), the count of runs whose all-task champion reaches 0.6 and 0.9 of the best
single-task champion in all tasks, the memorisation probe of every final champion and
the cost.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

#: The run directories of TPG-robust: ``TPG-robust-seed1`` ...
PREFIX = "TPG-robust-seed"
#: The paper's counts of its 10 runs (section 5): at least 0.6 and about 0.9 of the best
#: single-task agent in all six tasks.
PAPER_COUNTS = {0.6: "5 of 10", 0.9: "1 of 10"}


def is_robust(path: Path) -> bool:
    """True for a TPG-robust run directory."""
    return path.name.startswith(PREFIX)


def seed_of(name: str) -> int:
    """The seed a run directory's name ends with (``TPG-robust-seed3`` -> 3)."""
    found = re.search(r"seed(\d+)$", name)
    if found is None:
        raise ValueError(f"{name}: a run name ends with seedN")
    return int(found.group(1))


def common_generation(robust, target: int) -> int:
    """The test point both groups are compared at: the latest all robust runs have reached."""
    return min(target, *(r.final_generation for r in robust))


def compared_runs(robust, target: int) -> tuple[list, int]:
    """The TPG-robust runs in the comparison and its generation.

    The runs that have reached ``target`` are compared there; a run still growing would
    pull the comparison back to its own age, so it waits until it arrives. Before any run
    has arrived, every run is compared at the latest test point all have reached.
    """
    done = [r for r in robust if r.final_generation >= target]
    if done:
        return done, target
    return list(robust), common_generation(robust, target)


def scores_at(run, generation: int) -> dict[str, float]:
    """The all-task champion's test score per task at ``generation`` (``tests.csv``)."""
    row = run.row(run.full_set, generation)
    return {t: float(row[f"test_{t}"]) for t in run.tasks}


def normalised_at(run, generation: int, best: dict[str, float] | None = None):
    """Those scores normalised: against the reference best, or ``best`` when given."""
    from mtpg.analysis.runs.loading import normalise_scores, reference_best

    table = run.task_table
    return normalise_scores(scores_at(run, generation), best or reference_best(table), table)


def seed_rows(pairs: list[tuple[str, int, dict[str, float]]], tasks) -> list[list[str]]:
    """One row per run, TPG and TPG-robust of each seed together.

    Args:
        pairs: ``(run name, generation, normalised score per task)``.
        tasks: The task order of the columns.
    """
    rows = []
    for name, gen, norm in sorted(pairs, key=lambda p: (seed_of(p[0]), is_robust(Path(p[0])))):
        values = [norm[t] for t in tasks]
        rows.append(
            [
                name,
                str(gen),
                *(f"{v:.2f}" for v in values),
                f"{min(values):.2f}",
                f"{float(np.mean(values)):.2f}",
            ]
        )
    return rows


def reaching(vs_best_single: list[dict[str, float]], level: float) -> int:
    """Runs whose all-task champion is at ``level`` or more in every task."""
    return sum(all(v >= level for v in vs.values()) for vs in vs_best_single)


def _runs(n: int) -> str:
    return f"{n} run" if n == 1 else f"{n} runs"


def iqm_rows(matrices: dict[str, np.ndarray]) -> list[list[str]]:
    """IQM [95% CI] per task and over all tasks, one row per group of (runs x tasks)."""
    from mtpg.analysis.runs import statistics as stats

    rows = []
    for label, m in matrices.items():
        per_task, overall = stats.per_task_iqm(m), stats.aggregate_iqm(m)
        rows.append(
            [f"{label} ({_runs(m.shape[0])})", *(e.text(2) for e in per_task), overall.text(2)]
        )
    return rows


def seconds_per_generation(paths: list[Path], generation: int) -> float:
    """Mean ``t_total`` (``metrics.csv``) of generations 1 to ``generation`` over the runs.

    Compared over the same generations, since a generation costs more as graphs grow.
    """
    from results_text import metrics

    times = [
        float(row["t_total"])
        for path in paths
        for gen, row in metrics(path).items()
        if gen <= generation
    ]
    return float(np.mean(times)) if times else float("nan")


def section(tpg, robust, best_single: dict[str, float], probes: dict, target: int) -> list[str]:
    """The page's TPG-robust section.

    Args:
        tpg: The TPG runs (:class:`~mtpg.analysis.runs.loading.RunData`).
        robust: The TPG-robust runs.
        best_single: The best single-task champion's test score per task (the page's
            shared yardstick, from the TPG runs at their final test points).
        probes: Run name -> :class:`~mtpg.analysis.runs.memorisation.Probe` of its final
            all-task champion (empty: no probe table).
        target: The generations every run grows to.
    """
    from memorisation_doc import all_task_rows
    from results_text import markdown_table

    from mtpg.analysis.runs import statistics as stats
    from mtpg.analysis.runs.statistics_figures import POI_NOTE, STATS_NOTE

    tasks = tpg[0].tasks
    compared, gen = compared_runs(robust, target)
    groups = {"TPG": tpg, "TPG-robust": compared}
    norm = {r.name: normalised_at(r, gen) for g in groups.values() for r in g}
    vs = {r.name: normalised_at(r, gen, best_single) for g in groups.values() for r in g}
    matrices = {
        label: np.array([[norm[r.name][t] for t in tasks] for r in runs])
        for label, runs in groups.items()
    }
    lines = [
        "## TPG-robust: the training episodes redrawn every 10 generations",
        "",
        "The champions of the TPG runs memorise their five fixed training episodes, the "
        "noise input included ([docs/memorisation.md](../docs/memorisation.md)). "
        "TPG-robust is the `robust` preset: the `paper` preset with the training episodes "
        "redrawn every 10 generations (`evaluation.resample_interval = 10`), within the "
        "paper's rules. It was chosen at `demo` scale over five seeds "
        "([candidates/README.md](candidates/README.md)) and runs at the paper's scale with "
        "`tools/grow_results.py --plan robust`, seeds 1 to 5.",
        "",
    ]
    growing = [r.name for r in robust if r.final_generation < target]
    missing = 5 - len(robust)
    if growing or missing > 0:
        if gen == target:
            where = (
                f"Both groups are compared at generation {gen:,} with the "
                f"{_runs(len(compared))} of TPG-robust that have reached it; the runs still "
                "growing are not in the comparison (their latest champions are in the probe "
                "table below)."
            )
        else:
            where = (
                f"Both groups are compared at generation {gen:,}, the latest test point "
                "every TPG-robust run has reached, from `tests.csv`: the TPG runs' champions "
                "of that generation, not their final ones."
            )
        lines += [
            f"**In progress**: {len(robust)} of 5 TPG-robust runs begun"
            + (f", {', '.join(growing)} still growing" if growing else "")
            + f". {where}",
            "",
        ]
    lines += [
        f"All-task champion at generation {gen:,}, normalised against the reference best "
        "(0 = random play, 1 = reference best), seed by seed:",
        "",
        *markdown_table(
            ["run", "generation", *tasks, "worst task", "mean"],
            seed_rows([(name, gen, n) for name, n in norm.items()], tasks),
        ),
        "",
        f"Over seeds, interquartile mean [95% CI] ({STATS_NOTE}):",
        "",
        *markdown_table(["group", *tasks, "all tasks"], iqm_rows(matrices)),
        "",
    ]
    poi = stats.probability_of_improvement(matrices["TPG-robust"], matrices["TPG"])
    lines += [f"P(TPG-robust > TPG) = {poi.text(2)}. {POI_NOTE}", ""]
    count = {
        (label, level): reaching([vs[r.name] for r in runs], level)
        for label, runs in groups.items()
        for level in PAPER_COUNTS
    }
    lines += [
        f"Runs whose all-task champion at generation {gen:,} reaches 0.6 and 0.9 of the best "
        "single-task champion (of the TPG runs at their final test points, the yardstick of "
        "the sections above) in all six tasks:",
        "",
        *markdown_table(
            ["group", "0.6 in all six", "0.9 in all six"],
            [
                [label, *(f"{count[label, lv]} of {len(runs)}" for lv in PAPER_COUNTS)]
                for label, runs in groups.items()
            ]
            + [["paper (10 runs)", *PAPER_COUNTS.values()]],
        ),
        "",
    ]
    if probes:
        head, rows = all_task_rows(probes)
        lines += [
            "The memorisation probe (`mtpg probe RUN`) of every run's latest all-task "
            "champion, normalised against the reference best: (a) on its own training "
            "episodes as trained → (b) the same start states with the noise input redrawn "
            "(mean of 20 redraws) and, in brackets, (c) on the run's held-out episodes. A "
            "memorising champion drops from (a) to (b):",
            "",
            *markdown_table(head, rows),
            "",
        ]
    cost = {
        label: seconds_per_generation([r.path for r in runs], gen) for label, runs in groups.items()
    }
    lines += [
        f"Cost: seconds per generation over generations 1 to {gen:,} (`metrics.csv`'s "
        "`t_total`, test points included; one thread per run, two runs at a time on a "
        "2-core machine shared with other work, except where a run's `provenance.csv` "
        "names more threads): "
        + ", ".join(f"{label} {sec:.1f} s" for label, sec in cost.items())
        + ". Per run, hours in all: Cost below.",
        "",
    ]
    return lines
