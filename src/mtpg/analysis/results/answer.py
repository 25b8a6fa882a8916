"""The answer to "does it reproduce the paper?" once the three groups are complete.

Until every TPG-authors run has reached the target generation, the page and the README
answer with :func:`mtpg.analysis.results.robust_section.answer` and the TPG-authors
sentence appended (:func:`~mtpg.analysis.results.authors_section.answer_sentence`). With
all three groups complete the answer is a headline and three sentences, one per kind of
claim: what the paper's text gives (TPG and TPG-robust), what its code's interface adds
(TPG-authors), and what neither gives. The headline follows the claims' verdict
(:func:`~mtpg.analysis.results.authors_section.claims`): "Yes" when every claim holds with
the paper's text, "Only with its code's interface" when the rest hold with TPG-authors,
"In part" when some claim holds with neither, "No" when none holds.
"""

from __future__ import annotations

GROUPS = ("TPG", "TPG-robust", "TPG-authors")


def headline(kinds: dict[str, list[str]]) -> str:
    """The headline's verdict from the claims sorted into text / code / neither."""
    if not kinds["code"] and not kinds["neither"]:
        return "Yes"
    if not kinds["neither"]:
        return "Only with its code's interface"
    return "In part" if kinds["text"] or kinds["code"] else "No"


def weakest(estimates: dict[str, tuple[list, object]], tasks: list[str]) -> list[str]:
    """The tasks among the two lowest per-task IQMs of every group, in the page's order."""
    common = set(tasks)
    for per_task, _ in estimates.values():
        low = sorted(zip(per_task, tasks, strict=True), key=lambda p: p[0].value)[:2]
        common &= {t for _, t in low}
    return [t for t in tasks if t in common]


def three_groups(c, a) -> list[str]:
    """The headline and three sentences (one paragraph) from the groups' figures.

    Args:
        c: TPG against TPG-robust (:class:`~mtpg.analysis.results.robust_section.Comparison`).
        a: The complete TPG-authors group (:class:`~mtpg.analysis.results.authors_section.Authors`).
    """
    from mtpg.analysis.results.authors_section import claim_kinds, claims
    from mtpg.analysis.results.robust_section import PAPER_COUNTS, _and, best_run
    from mtpg.analysis.runs import statistics as stats

    n = {g: len(c.groups[g]) for g in GROUPS[:2]} | {"TPG-authors": len(a.compared)}
    r06 = {"TPG": c.count("TPG", 0.6), "TPG-robust": c.count("TPG-robust", 0.6)}
    r06["TPG-authors"] = a.count(0.6)
    r09 = c.count("TPG", 0.9) + c.count("TPG-robust", 0.9) + a.count(0.9)
    tpg, rob = (c.estimates[g][1] for g in GROUPS[:2])
    apart = "the intervals apart" if rob.low > tpg.high else "the intervals overlap"
    best = c.norm[best_run(c.groups["TPG-robust"], c.norm).name]
    high = sum(v >= 0.9 for v in best.values())
    authors = stats.aggregate_iqm(a.matrix)
    poi = stats.probability_of_improvement(a.matrix, c.matrices["TPG-robust"])
    estimates = {**c.estimates, "TPG-authors": (stats.per_task_iqm(a.matrix), authors)}
    weak = weakest(estimates, list(c.tasks))
    weak_text = (
        f", and {_and(weak)} {'is' if len(weak) == 1 else 'are'} among the two weakest tasks "
        "of every group"
        if weak
        else ""
    )
    reach = {g: "reaches" if r06[g] == 1 else "reach" for g in GROUPS}
    total = sum(n.values())
    return [
        f"**Does it reproduce the paper? {headline(claim_kinds(claims(c, a)))}.** With the "
        f"paper's text, {r06['TPG']} of {n['TPG']} TPG runs and {r06['TPG-robust']} of "
        f"{n['TPG-robust']} TPG-robust runs (the training episodes redrawn every 10 "
        "generations) have an all-task champion at 0.6 or more of the best single-task "
        f"champion in all six tasks (the paper: {PAPER_COUNTS[0.6]}), though TPG-robust "
        f"raises the IQM over seeds and tasks from {tpg.text(2)} to {rob.text(2)} of the "
        f"reference best ({apart}) and its best run scores 0.9 or more of the reference best "
        f"in {high} of {len(best)} tasks (the paper's best run: 4 of 6). With the interface "
        "of the authors' published code and the paper's fixed training episodes "
        f"(TPG-authors), {r06['TPG-authors']} of {n['TPG-authors']} runs "
        f"{reach['TPG-authors']} 0.6 in all six tasks and the IQM is {authors.text(2)}, "
        f"P(TPG-authors > TPG-robust) = {poi.text(2)}. {r09} of the {total} runs "
        f"{'reaches' if r09 == 1 else 'reach'} 0.9 of their group's best single-task "
        f"champion in all six tasks (the paper: {PAPER_COUNTS[0.9]}){weak_text}.",
    ]
