"""The TPG-robust section of ``results/README.md``: TPG-robust against TPG, seed by seed.

TPG-robust is the ``robust`` preset (the ``paper`` preset with the training episodes
redrawn every 10 generations; ``mtpg experiment --plan results/plan.toml --only robust``),
seeds 1 to 5,
beside the TPG runs in ``results/runs``. :func:`section` writes its part of the page from
the runs' files: both groups compared at one common test point (generation 1,000, with
the TPG-robust runs that have reached it; before any has, the latest test point all
TPG-robust runs have reached, so that the two groups are compared at the same age), seed
by seed and over seeds (interquartile means with 95% bootstrap intervals and the probability of
improvement), the count of runs whose all-task champion reaches 0.6 and 0.9 of the best
single-task champion in all tasks, the memorisation probe of every final champion and
the cost. Once all five runs have reached the target, :func:`answer` writes the page's
three-sentence answer to "does it reproduce the paper?", which the README quotes word for
word (``tests/test_docs_stay_true.py`` checks it).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import cached_property
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


def best_run(runs, norm: dict[str, dict[str, float]]):
    """The group's best run: highest worst-task score, then highest mean (``norm`` by name)."""
    return max(
        runs, key=lambda r: (min(norm[r.name].values()), float(np.mean([*norm[r.name].values()])))
    )


def iqm_rows(estimates: dict[str, tuple[list, object]]) -> list[list[str]]:
    """IQM [95% CI] per task and over all tasks, one row per group (``Comparison.estimates``)."""
    return [
        [f"{label} ({_runs(overall.runs)})", *(e.text(2) for e in per_task), overall.text(2)]
        for label, (per_task, overall) in estimates.items()
    ]


@dataclass(frozen=True)
class Comparison:
    """TPG against TPG-robust at one test point: the figures of the section and the answer.

    Attributes:
        tasks: The task order.
        groups: ``{"TPG": runs, "TPG-robust": the runs compared}``.
        generation: The test point they are compared at.
        growing: TPG-robust runs still short of the target.
        missing: TPG-robust seeds of 1 to 5 not begun.
        norm: Run name -> normalised score per task (against the reference best).
        vs: Run name -> score per task against the best single-task champion.
        matrices: Group -> (runs x tasks) of ``norm``.
    """

    tasks: list[str]
    groups: dict[str, list]
    generation: int
    growing: list[str]
    missing: int
    norm: dict[str, dict[str, float]]
    vs: dict[str, dict[str, float]]
    matrices: dict[str, np.ndarray]

    @property
    def complete(self) -> bool:
        """All five TPG-robust runs have reached the target and are compared there."""
        return not self.growing and self.missing <= 0

    @cached_property
    def estimates(self) -> dict[str, tuple[list, object]]:
        """Group -> (IQM per task, IQM over all tasks), each with its 95% interval."""
        from mtpg.analysis.runs import statistics as stats

        return {
            label: (stats.per_task_iqm(m), stats.aggregate_iqm(m))
            for label, m in self.matrices.items()
        }

    def count(self, label: str, level: float) -> int:
        """Runs of a group whose all-task champion reaches ``level`` of the best single."""
        return reaching([self.vs[r.name] for r in self.groups[label]], level)


def compare(tpg, robust, best_single: dict[str, float], target: int) -> Comparison:
    """Both groups' figures (see :class:`Comparison`).

    Args:
        tpg: The TPG runs (:class:`~mtpg.analysis.runs.loading.RunData`).
        robust: The TPG-robust runs.
        best_single: The best single-task champion's test score per task (the page's
            shared yardstick, from the TPG runs at their final test points).
        target: The generations every run grows to.
    """
    tasks = list(tpg[0].tasks)
    compared, gen = compared_runs(robust, target)
    groups = {"TPG": list(tpg), "TPG-robust": compared}
    norm = {r.name: normalised_at(r, gen) for g in groups.values() for r in g}
    vs = {r.name: normalised_at(r, gen, best_single) for g in groups.values() for r in g}
    matrices = {
        label: np.array([[norm[r.name][t] for t in tasks] for r in runs])
        for label, runs in groups.items()
    }
    growing = [r.name for r in robust if r.final_generation < target]
    return Comparison(tasks, groups, gen, growing, 5 - len(robust), norm, vs, matrices)


def _and(words: list[str]) -> str:
    return words[0] if len(words) == 1 else ", ".join(words[:-1]) + " and " + words[-1]


def _per_task_verdict(c: Comparison) -> str:
    """TPG-robust's IQM per task against TPG's: "better in 5 tasks and level in X"."""
    from mtpg.analysis.results.tables import LEVEL

    ours, theirs = c.estimates["TPG-robust"][0], c.estimates["TPG"][0]
    kinds: dict[str, list[str]] = {"better": [], "level": [], "worse": []}
    for task, a, b in zip(c.tasks, ours, theirs, strict=True):
        diff = a.value - b.value
        kinds["better" if diff >= LEVEL else "worse" if diff <= -LEVEL else "level"].append(task)
    parts = [
        f"{kind} in {_and(names) if len(names) < 3 else f'{len(names)} tasks'}"
        for kind, names in kinds.items()
        if names
    ]
    return _and(parts)


def answer(c: Comparison) -> list[str]:
    """The page's and the README's answer to "does it reproduce the paper?".

    A headline and three sentences from the comparison's figures with the paper's beside
    them: the ``paper`` preset's count, TPG-robust's gain over seeds and its best run
    against the paper's best, and the counts TPG-robust still misses. "Yes" needs the
    paper's rates in both counts (half the runs at 0.6 in all six, one in ten at 0.9);
    a task is better or worse when the IQMs differ by ``results_text.LEVEL`` or more.
    """
    from mtpg.analysis.results.tables import PAPER

    n_tpg, n_rob = (len(c.groups[g]) for g in ("TPG", "TPG-robust"))
    tpg, rob = (c.estimates[g][1] for g in ("TPG", "TPG-robust"))
    r06, r09 = c.count("TPG-robust", 0.6), c.count("TPG-robust", 0.9)
    yes = 2 * r06 >= n_rob and 10 * r09 >= n_rob
    apart = "the intervals apart" if rob.low > tpg.high else "the intervals overlap"
    best = best_run(c.groups["TPG-robust"], c.norm)
    scores = c.norm[best.name]
    high = [t for t in c.tasks if scores[t] >= 0.9]
    low = [t for t in c.tasks if scores[t] < 0.9]
    best_text = f"0.9 or more of the reference best in {len(high)} of {len(c.tasks)} tasks" + (
        f" and {_and([f'{scores[t]:.2f}' for t in low])} in {_and(low)}" if low else ""
    )
    per_task = c.estimates["TPG-robust"][0]
    weak = sorted(zip(per_task, c.tasks, strict=True), key=lambda p: p[0].value)[:2]
    reaches = "reaches" if r06 == 1 else "reach"
    r09_text = "none reaches" if r09 == 0 else f"{r09} {'reaches' if r09 == 1 else 'reach'}"
    return [
        f"**Does it reproduce the paper? {'Yes' if yes else 'Not yet'}.** With the `paper` "
        f"preset, {c.count('TPG', 0.6)} of {n_tpg} TPG runs have an all-task champion at 0.6 "
        "or more of the best single-task champion in all six tasks "
        f"(the paper: {PAPER_COUNTS[0.6]}), because the champions memorise their five fixed "
        "training episodes and mistake CartCentering for MountainCar. Redrawing the "
        "training episodes every 10 generations (TPG-robust, within the paper's rules) "
        f"{'raises' if rob.value > tpg.value else 'lowers'} the IQM over seeds and tasks "
        f"from {tpg.text(2)} to {rob.text(2)} of the "
        f"reference best ({apart}), {_per_task_verdict(c)}, and its best run "
        f"({best.name}) scores {best_text} (the paper's best run: "
        f"{PAPER['vs_reference']}). {'And' if yes else 'Still, only'} {r06} of {n_rob} "
        f"TPG-robust runs {reaches} 0.6 in all six tasks and {r09_text} 0.9 (the paper: "
        f"{PAPER_COUNTS[0.6]} and {PAPER_COUNTS[0.9]}): "
        + _and([f"{t} (IQM {e.value:.2f})" for e, t in weak])
        + " stay behind.",
    ]


def section(c: Comparison, robust, probes: dict, target: int) -> list[str]:
    """The page's TPG-robust section.

    Args:
        c: The comparison (:func:`compare`).
        robust: The TPG-robust runs, all of them.
        probes: Run name -> :class:`~mtpg.analysis.runs.champion_probe.Probe` of its final
            all-task champion (empty: no probe table).
        target: The generations every run grows to.
    """
    from mtpg.analysis.results.memorisation_page import all_task_rows
    from mtpg.analysis.results.tables import (
        cpu_seconds_per_generation,
        engine_note,
        markdown_table,
    )
    from mtpg.analysis.runs import statistics as stats
    from mtpg.analysis.runs.statistics_figures import POI_NOTE, STATS_NOTE

    tasks, groups, gen, norm, matrices = c.tasks, c.groups, c.generation, c.norm, c.matrices
    compared = groups["TPG-robust"]
    lines = [
        "## TPG-robust: the training episodes redrawn every 10 generations",
        "",
        "The champions of the TPG runs memorise their five fixed training episodes, the "
        "noise input included ([docs/memorisation.md](../docs/memorisation.md)). "
        "TPG-robust is the `robust` preset: the `paper` preset with the training episodes "
        "redrawn every 10 generations (`evaluation.resample_interval = 10`), within the "
        "paper's rules. It was chosen at `demo` scale over five seeds "
        "([candidates/README.md](candidates/README.md)) and runs at the paper's scale with "
        "`mtpg experiment --plan results/plan.toml --only robust`, seeds 1 to 5.",
        "",
    ]
    growing = c.growing
    if not c.complete:
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
        *markdown_table(["group", *tasks, "all tasks"], iqm_rows(c.estimates)),
        "",
    ]
    poi = stats.probability_of_improvement(matrices["TPG-robust"], matrices["TPG"])
    lines += [f"P(TPG-robust > TPG) = {poi.text(2)}. {POI_NOTE}", ""]
    count = {(label, lv): c.count(label, lv) for label in groups for lv in PAPER_COUNTS}
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
        label: cpu_seconds_per_generation([r.path for r in runs]) for label, runs in groups.items()
    }
    lines += [
        "Cost: CPU seconds per generation (`provenance.csv`: the user and system time of all "
        "of a sitting's threads over the generations it grew, summed over the group's runs "
        "and divided by their generations, so the thread count does not matter): "
        + ", ".join(f"{label} {sec:.1f} s" for label, sec in cost.items())
        + ". Per run, hours in all: Cost below. "
        + engine_note({label: [r.path for r in runs] for label, runs in groups.items()}),
        "",
    ]
    return lines
