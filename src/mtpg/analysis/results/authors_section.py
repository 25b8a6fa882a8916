"""The TPG-authors section of ``results/README.md``: the three groups side by side.

TPG-authors is the ``paper`` preset (fixed training episodes, as the authors' published
code also has them) on the observation interface of that code: the ``authors`` group of
``results/plan.toml`` (``[interfaces.authors]``: CartCentering's noise in [-1, 1],
Pendulum observed as cos and sin over 300 steps, MountainCar's position in [0, 1] with
noise in [-pi, pi]), seeds 1 to 5, 1,000 generations. Its tasks are variants of the six,
so :func:`section` names them by their base task and normalises them as the interface
study does (``docs/variants-study.md``): 0 = random play measured on the variant itself,
1 = the base task's reference best. Its *vs best single* yardstick is the best
single-task champion of the TPG-authors runs themselves, since the TPG runs' champions
played other tasks (a 300-step Pendulum's returns are not a 200-step one's).

The runs that have reached the target generation are compared there, as for TPG-robust
(:func:`~mtpg.analysis.results.robust_section.compared_runs`); until all five have,
every statement of the section says how many runs it rests on.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mtpg.analysis.results.robust_section import (
    PAPER_COUNTS,
    best_run,
    compared_runs,
    iqm_rows,
    normalised_at,
)

#: The run directories of TPG-authors: ``TPG-authors-seed1`` ...
PREFIX = "TPG-authors-seed"
#: Runs a group has when complete.
SEEDS = 5


def is_authors(path: Path) -> bool:
    """True for a TPG-authors run directory."""
    return path.name.startswith(PREFIX)


def base(task: str) -> str:
    """A variant's base task: ``Pendulum[max_steps=300;...]`` -> ``Pendulum``."""
    return task.split("[")[0]


@dataclass(frozen=True)
class Authors:
    """The TPG-authors figures of the section.

    Attributes:
        runs: Every TPG-authors run (:class:`~mtpg.analysis.runs.loading.RunData`).
        compared: The runs in the comparison.
        generation: The test point they are compared at.
        norm: Run name -> normalised score per base task (against the reference best).
        vs: Run name -> score per base task against the group's best single-task champion.
        matrix: (compared runs x tasks) of ``norm``, tasks in the page's order.
    """

    runs: list
    compared: list
    generation: int
    norm: dict[str, dict[str, float]]
    vs: dict[str, dict[str, float]]
    matrix: np.ndarray

    @property
    def complete(self) -> bool:
        """All five runs have reached the target and are compared there."""
        return len(self.compared) == SEEDS

    def count(self, level: float) -> int:
        """Compared runs whose all-task champion is at ``level`` of the best single in all."""
        return sum(all(v >= level for v in self.vs[r.name].values()) for r in self.compared)

    @property
    def best(self):
        """The best compared run: highest worst-task score, then highest mean."""
        return best_run(self.compared, self.norm)


def _by_base(scores: dict[str, float]) -> dict[str, float]:
    return {base(t): v for t, v in scores.items()}


def gather(runs, tasks: list[str], target: int) -> Authors:
    """The group's figures at its comparison generation.

    Args:
        runs: The TPG-authors runs.
        tasks: The page's task order (base names).
        target: The generations every run grows to.
    """
    compared, gen = compared_runs(runs, target)
    single = {
        t: max(float(r.row(t, gen)[f"test_{t}"]) for r in compared) for t in compared[0].tasks
    }
    norm = {r.name: _by_base(normalised_at(r, gen)) for r in compared}
    vs = {r.name: _by_base(normalised_at(r, gen, single)) for r in compared}
    matrix = np.array([[norm[r.name][t] for t in tasks] for r in compared])
    return Authors(list(runs), compared, gen, norm, vs, matrix)


def answer_sentence(a: Authors) -> str:
    """The answer's sentence on TPG-authors (appended to the page's and README's answer)."""
    from mtpg.analysis.runs import statistics as stats

    n = len(a.compared)
    so_far = "" if a.complete else f", {n} of {SEEDS} runs at generation {a.generation:,} so far"
    r06, r09 = a.count(0.6), a.count(0.9)
    reach = "reaches" if r06 == 1 else "reach"
    return (
        "With the interface of the authors' published code and the paper's fixed training "
        f"episodes (TPG-authors{so_far}), the IQM over seeds and tasks is "
        f"{stats.aggregate_iqm(a.matrix).text(2)} of the reference best; {r06} of {n} runs "
        f"{reach} 0.6 and {r09} {'reaches' if r09 == 1 else 'reach'} 0.9 of the group's own "
        "best single-task champion in all six tasks."
    )


def claim_kinds(rows: list[list[str]]) -> dict[str, list[str]]:
    """The claims sorted: holding with the paper's text, only with its code's, with neither.

    Args:
        rows: :func:`claims`' rows (claim, TPG, TPG-robust, TPG-authors).
    """
    kinds: dict[str, list[str]] = {"text": [], "code": [], "neither": []}
    for claim, tpg, robust, authors in rows:
        text = "holds" in (tpg.split(": ")[1], robust.split(": ")[1])
        code = authors.endswith(": holds")
        kinds["text" if text else "code" if code else "neither"].append(claim.split(" (")[0])
    return kinds


def verdict(rows: list[list[str]]) -> str:
    """Which claims hold with the paper's text, which only with its code's, which with neither.

    Args:
        rows: :func:`claims`' rows (claim, TPG, TPG-robust, TPG-authors).
    """
    kinds = claim_kinds(rows)
    said = {
        "text": "hold with the paper's text (TPG or TPG-robust)",
        "code": "hold only with its code's interface (TPG-authors)",
        "neither": "hold with neither",
    }
    parts = [f"{'; '.join(claims)}: {said[k]}" for k, claims in kinds.items() if claims]
    return ". ".join(p[0].upper() + p[1:] for p in parts) + "."


def claims(c, a: Authors) -> list[list[str]]:
    """The paper's claims, and how many runs of each group meet them."""

    def rate(hit: int, n: int, paper: float) -> str:
        return f"{hit} of {n}: " + ("holds" if n and hit / n >= paper else "does not hold")

    best_rob = best_run(c.groups["TPG-robust"], c.norm)
    best_tpg = best_run(c.groups["TPG"], c.norm)

    def high(scores: dict[str, float]) -> str:
        k = sum(v >= 0.9 for v in scores.values())
        return f"{k} of 6: " + ("holds" if k >= 4 else "does not hold")

    rows = []
    for level, paper in ((0.6, 0.5), (0.9, 0.1)):
        rows.append(
            [
                f"runs at {level} of the best single-task champion in all six "
                f"({PAPER_COUNTS[level]})",
                rate(c.count("TPG", level), len(c.groups["TPG"]), paper),
                rate(c.count("TPG-robust", level), len(c.groups["TPG-robust"]), paper),
                rate(a.count(level), len(a.compared), paper),
            ]
        )
    rows.append(
        [
            "best run at 0.9 or more of the reference best in 4 of 6 tasks",
            high(c.norm[best_tpg.name]),
            high(c.norm[best_rob.name]),
            high(a.norm[a.best.name]),
        ]
    )
    return rows


def _pendulum_note(table) -> str:
    """What the study's normalisation means for a 300-step Pendulum (empty without one)."""
    from mtpg.envs.taskset.reference_scores import reference_of

    pend = next((t for t in table.names if base(t) == "Pendulum" and "[" in t), None)
    if pend is None:
        return ""
    ref = reference_of(pend, table)
    return (
        "For Pendulum's 300 steps that puts 0 at random play over 300 steps "
        f"({ref.random:.1f}) and 1 at the 200-step reference best ({ref.best:.1f}): once the "
        "pendulum is up each step costs almost nothing, so a policy that swings up as fast "
        "scores about as on 200 steps, while the longer random baseline makes any return "
        "read a little higher than it would on the 200-step task. "
    )


def section(c, a: Authors, probes: dict, target: int) -> list[str]:
    """The page's TPG-authors section: the three groups side by side.

    Args:
        c: TPG against TPG-robust (:func:`~mtpg.analysis.results.robust_section.compare`).
        a: The TPG-authors figures (:func:`gather`).
        probes: Run name -> memorisation probe of a TPG-authors run's latest champion.
        target: The generations every run grows to.
    """
    from mtpg.analysis.results.memorisation_page import all_task_rows
    from mtpg.analysis.results.tables import (
        PAPER,
        cpu_seconds_per_generation,
        markdown_table,
        rescore_rows,
    )
    from mtpg.analysis.runs import statistics as stats
    from mtpg.analysis.runs.loading import reference_best
    from mtpg.analysis.runs.statistics_figures import POI_NOTE, STATS_NOTE

    tasks, n = c.tasks, len(a.compared)
    table = a.runs[0].task_table
    lines = [
        "## The three groups: TPG, TPG-robust and TPG-authors",
        "",
        "TPG-authors is the `paper` preset (fixed training episodes, as the authors' "
        "published code also has them) on the observation interface of that code "
        "([docs/variants-study.md](../docs/variants-study.md): CartCentering's noise in "
        "[-1, 1], Pendulum observed as cos and sin over 300 steps, MountainCar's position "
        "in [0, 1] with noise in [-pi, pi]), seeds 1 to 5, grown with "
        "`mtpg experiment --plan results/plan.toml --only authors`. Its scores are "
        "normalised as the interface study normalises them: 0 = random play measured on the "
        "variant itself, 1 = the base task's reference best. "
        + _pendulum_note(table)
        + "Its *vs best single* yardstick is the best single-task champion of "
        "the TPG-authors runs (their tasks are not the TPG runs').",
        "",
    ]
    if not a.complete:
        growing = [r.name for r in a.runs if r.final_generation < target]
        lines += [
            f"**In progress**: {len(a.runs)} of {SEEDS} TPG-authors runs begun, "
            f"{n} at generation {a.generation:,}"
            + (f"; {', '.join(growing)} still growing" if growing else "")
            + ". Every TPG-authors figure below is of those "
            f"{n} runs, and the intervals of so few runs are wide.",
            "",
        ]
    rows = [
        [r.name, str(a.generation), *(f"{a.norm[r.name][t]:.2f}" for t in tasks)]
        + [f"{min(a.norm[r.name].values()):.2f}", f"{np.mean([*a.norm[r.name].values()]):.2f}"]
        for r in a.compared
    ]
    lines += [
        f"TPG-authors' all-task champion at generation {a.generation:,}, normalised against "
        "the reference best:",
        "",
        *markdown_table(["run", "generation", *tasks, "worst task", "mean"], rows),
        "",
    ]
    estimates = dict(c.estimates)
    estimates["TPG-authors"] = (stats.per_task_iqm(a.matrix), stats.aggregate_iqm(a.matrix))
    lines += [
        f"Over seeds, interquartile mean [95% CI] ({STATS_NOTE}):",
        "",
        *markdown_table(["group", *tasks, "all tasks"], iqm_rows(estimates)),
        "",
    ]
    tpg, rob = c.matrices["TPG"], c.matrices["TPG-robust"]
    poi = [
        ("TPG-authors > TPG", stats.probability_of_improvement(a.matrix, tpg)),
        ("TPG-authors > TPG-robust", stats.probability_of_improvement(a.matrix, rob)),
        ("TPG-robust > TPG", stats.probability_of_improvement(rob, tpg)),
    ]
    lines += [
        "; ".join(f"P({label}) = {p.text(2)}" for label, p in poi)
        + f". {POI_NOTE} TPG-authors plays variants of the tasks, so these compare scores on "
        "one scale (random play to the reference best), not returns on the same task.",
        "",
    ]
    best = a.best
    rows = claims(c, a)
    lines += [
        f"Best TPG-authors run: **{best.name}**: "
        + ", ".join(f"{t} {a.norm[best.name][t]:.2f}" for t in tasks)
        + f" of the reference best (the paper's best run: {PAPER['vs_reference']}).",
        "",
        "The paper's claims (section 5), run by run: *holds* where the group meets the "
        "paper's rate (half the runs at 0.6, one in ten at 0.9)"
        + ("" if a.complete else f"; TPG-authors so far on {n} runs")
        + ":",
        "",
        *markdown_table(
            [
                "claim (paper)",
                "TPG: its text",
                "TPG-robust: its text, episodes redrawn",
                "TPG-authors: its code's interface",
            ],
            rows,
        ),
        "",
        verdict(rows) + ("" if a.complete else f" (TPG-authors on {n} of {SEEDS} runs so far.)"),
        "",
    ]
    head, rrows, agree, cells = rescore_rows(a.runs)
    lines += [
        "Every TPG-authors run's latest all-task champion: mean test return ± the half-width "
        "of its 95% interval and, in brackets, re-scored on other held-out episodes (as "
        f"above; close in {agree} of {cells} cells):",
        "",
        *markdown_table([base(h) for h in head], rrows),
        "",
    ]
    if probes:
        head, prows = all_task_rows(probes)
        lines += [
            "The memorisation probe of every TPG-authors run's latest all-task champion "
            "((a) as trained → (b) noise redrawn, (c) held out; as above):",
            "",
            *markdown_table([base(h) for h in head], prows),
            "",
        ]
    cost = cpu_seconds_per_generation([r.path for r in a.runs])
    lines += [
        f"Cost: TPG-authors {cost:.1f} CPU s per generation (as above; its runs grew with "
        "the lane engine, like TPG-robust). Reference best of its tasks: "
        + ", ".join(f"{base(t)} {v:.4g}" for t, v in reference_best(table).items())
        + ".",
        "",
    ]
    return lines
