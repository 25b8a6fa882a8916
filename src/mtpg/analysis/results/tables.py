"""Tables of ``results/README.md`` (used by :mod:`mtpg.analysis.results.readme`).

Each function turns the committed files of the runs (``metrics.csv``, ``tests.csv``,
``provenance.csv``, the checkpoint names) into a header and rows of strings; nothing here
is typed in by hand but :data:`PAPER`, the paper's own figures (section 5).
"""

from __future__ import annotations

import csv
import subprocess
from pathlib import Path

import numpy as np

#: What the paper reports (section 5, Figs. 5-8), in its own words.
PAPER = {
    "best_vs_single": 0.9,
    "runs_at_06": "5 of 10",
    "vs_reference": "at least 0.9 in 4 of 6 tasks, about 0.8 and 0.75 in the other two",
    "TPG-NoXover": "at least 0.8 in every task",
    "TPG-NoMemory": "well below 0.5 in every task",
    "TPG-NoHierarchy": "good only in MountainCarContinuous",
}
#: The commit that made the lane engine training's default.
LANE_ENGINE = "34fc1cf53f85672be4d76cb35f245edc1ad9ef62"
#: Within this of the paper's figure counts as level.
LEVEL = 0.05
#: Generations at which the cost is quoted.
COST_AT = (1, 250, 500, 1000)


def markdown_table(head: list[str], rows: list[list[str]]) -> list[str]:
    """A GitHub-flavoured Markdown table, one line per row."""
    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    return out + ["| " + " | ".join(r) + " |" for r in rows]


def checkpoint_generation(run: Path) -> int:
    """Generation of the newest checkpoint of a run directory."""
    names = [p.name for p in (Path(run) / "checkpoints").glob("gen-??????.json.gz")]
    return max((int(n[4:10]) for n in names), default=0)


def provenance(run: Path) -> list[dict[str, str]]:
    """Rows of a run's ``provenance.csv`` (empty when there is none)."""
    path = Path(run) / "provenance.csv"
    return list(csv.DictReader(open(path))) if path.is_file() else []


def metrics(run: Path) -> dict[int, dict[str, str]]:
    """``metrics.csv`` rows by generation, up to the newest checkpoint."""
    last = checkpoint_generation(run)
    rows = csv.DictReader(open(Path(run) / "metrics.csv"))
    return {int(r["generation"]): r for r in rows if int(r["generation"]) <= last}


def status_rows(runs, target: int) -> tuple[list[str], list[list[str]]]:
    """Run, experiment, seed, generations committed, latest test point, mtpg commits."""
    head = ["run", "experiment", "seed", "generations", "latest test point", "mtpg commits"]
    rows = []
    for r in runs:
        gen = checkpoint_generation(r.path)
        commits = sorted({p["mtpg_commit"][:10] for p in provenance(r.path)})
        state = f"{gen} of {target}" + ("" if gen >= target else " (growing)")
        rows.append(
            [
                r.name,
                r.label,
                str(r.config.seed),
                state,
                str(r.final_generation),
                ", ".join(commits),
            ]
        )
    return head, rows


def cost_rows(runs) -> tuple[list[str], list[list[str]]]:
    """Wall-clock and CPU hours per run; s/gen, instructions and teams per decision at COST_AT."""
    head = ["run", "wall h", "CPU h"] + [f"gen {g}: s/gen, instr/dec, teams/dec" for g in COST_AT]
    rows = []
    for r in runs:
        m = metrics(r.path)
        wall = sum(float(x["t_total"]) for x in m.values()) / 3600
        prov = provenance(r.path)
        cpu = sum(float(p["cpu_s"]) for p in prov if p["cpu_s"]) / 3600
        measured = sum(
            int(p["to_generation"]) - int(p["from_generation"]) for p in prov if p["cpu_s"]
        )
        cpu_text = f"{cpu:.2f} ({measured} gens)" if measured < len(m) else f"{cpu:.2f}"
        cells = []
        for g in COST_AT:
            x = m.get(g)
            cells.append(
                "not yet"
                if x is None
                else f"{float(x['t_total']):.1f}, {float(x['instructions_per_decision']):.0f}, "
                f"{float(x['teams_per_decision']):.2f}"
            )
        rows.append([r.name, f"{wall:.2f}", cpu_text, *cells])
    return head, rows


def hierarchy_rows(runs) -> tuple[list[str], list[list[str]]]:
    """Teams per decision of each subset's champion at the final test point, by subset size."""
    by_size: dict[int, list[float]] = {}
    for r in runs:
        for row in r.rows_at(r.final_generation):
            size = len(str(row["subset"]).split("+"))
            by_size.setdefault(size, []).append(float(row["teams_per_decision"]))
    head = ["tasks in subset", "champions", "min", "median", "max"]
    rows = [
        [str(k), str(len(v)), f"{min(v):.2f}", f"{np.median(v):.2f}", f"{max(v):.2f}"]
        for k, v in sorted(by_size.items())
    ]
    return head, rows


def verdict(ours: float, paper: float) -> str:
    """``ahead``, ``level`` or ``behind`` the paper's figure (within :data:`LEVEL`)."""
    if not np.isfinite(ours):
        return "n/a"
    return "ahead" if ours > paper + LEVEL else "level" if ours >= paper - LEVEL else "behind"


def first_reached(run, task: str, best_single: float, level: float) -> str:
    """First test point at which the run's all-task champion reached ``level`` in ``task``."""
    from mtpg.analysis.runs.loading import normalise_scores

    gens, scores = run.curve(run.full_set, task)
    for g, s in zip(gens, scores, strict=True):
        if normalise_scores({task: float(s)}, {task: best_single})[task] >= level:
            return str(int(g))
    return "not yet"


def compare_table(best, best_single: dict[str, float], tasks) -> list[str]:
    """Per task: the best run's all-task champion against the paper's Figs. 5 and 6."""
    from mtpg.analysis.runs.loading import normalise_scores

    vs = normalise_scores(best.test, best_single)
    paper = PAPER["best_vs_single"]
    head = [
        "task",
        "test return",
        "best single-task return",
        "vs best single",
        f"paper (about {paper})",
        f"first reached {paper - LEVEL:.2f}",
        "vs reference",
    ]
    rows = [
        [
            t,
            f"{best.test[t]:.4g}",
            f"{best_single[t]:.4g}",
            f"{vs[t]:.2f}",
            verdict(vs[t], paper),
            first_reached(best.run, t, best_single[t], paper - LEVEL),
            f"{best.normalised[t]:.2f}",
        ]
        for t in tasks
    ]
    n90 = sum(best.normalised[t] >= 0.9 for t in tasks)
    note = (
        f"Against the reference best, the best run's all-task champion is at 0.9 or more in "
        f"{n90} of {len(tasks)} tasks (paper: {PAPER['vs_reference']})."
    )
    return [*markdown_table(head, rows), "", note]


#: A task counts as learnt ("good" in the paper's words) at this much of the best
#: single-task champion; NoXover's claim and NoHierarchy's are read with it.
GOOD = 0.8


def ablation_verdict(experiment: str, vs: dict[str, float]) -> str:
    """Whether an experiment's best run shows what the paper says of it, task by task.

    The paper's words become rules on the scores against the best single-task champion:
    full TPG "about 0.9 in every task" is at least 0.9 - :data:`LEVEL` everywhere;
    NoXover "at least 0.8 in every task"; NoMemory "well below 0.5 in every task" is
    below 0.5 everywhere; NoHierarchy "good only in MountainCarContinuous" is
    :data:`GOOD` or more there and nowhere else.
    """

    def named(tasks: list[str]) -> str:
        return ", ".join(tasks) if tasks else "no task"

    if experiment == "TPG-NoHierarchy":
        good = [t for t, v in vs.items() if v >= GOOD]
        if good == ["MountainCarContinuous"]:
            return "as the paper"
        return f"{GOOD} or more in {named(good)}"
    if experiment == "TPG-NoMemory":
        high = [t for t, v in vs.items() if v >= 0.5]
        return "as the paper" if not high else f"0.5 or more in {named(high)}"
    floor = GOOD if experiment == "TPG-NoXover" else PAPER["best_vs_single"] - LEVEL
    low = [t for t, v in vs.items() if not v >= floor]
    return "as the paper" if not low else f"below {floor:.2f} in {named(low)}"


def ablation_rows(groups, numbers, best_single, tasks) -> tuple[list[str], list[list[str]]]:
    """Each ablation's best run against the best single-task champion, beside the paper."""
    from mtpg.analysis.runs.loading import normalise_scores
    from mtpg.analysis.runs.reported_numbers import best_of

    head = [
        "experiment",
        "run",
        "generation",
        "min vs best single",
        "max vs best single",
        "paper",
        "ours",
    ]
    rows = []
    for g in groups:
        n = best_of([numbers[r.path] for r in g.runs])
        per_task = normalise_scores(n.test, best_single)
        vs = list(per_task.values())
        rows.append(
            [
                g.label,
                n.run.name,
                str(n.generation),
                f"{np.nanmin(vs):.2f}",
                f"{np.nanmax(vs):.2f}",
                PAPER.get(
                    g.experiment, f"about {PAPER['best_vs_single']} in every task (best run)"
                ),
                ablation_verdict(g.experiment, per_task),
            ]
        )
    return head, rows


#: Offset of the block of held-out episodes the champions are re-scored on.
RESCORE_OFFSET = 500_000


def rescore_rows(runs) -> tuple[list[str], list[list[str]], int, int]:
    """Each run's all-task champion: its test return with a 95% interval, and a re-score.

    The interval is ``1.96 * std / sqrt(n)`` over the run's own ``n`` test episodes (the
    scores of ``tests.csv``); the re-score plays ``n`` other held-out episodes
    (:data:`RESCORE_OFFSET`). Two means of independent blocks with that spread differ by
    less than ``sqrt(2)`` half-widths about 95% of the time.

    Returns:
        The table's head and rows, the number of (run, task) cells whose re-score is
        within ``sqrt(2)`` half-widths of the test return, and the number of cells.
    """
    from mtpg.analysis.runs.champions import champion_path
    from mtpg.evolve.heldout_test import evaluate_graph
    from mtpg.io.serialize import load_graph

    tasks = runs[0].tasks
    head = ["run", "generation", *tasks]
    rows, agree = [], 0
    for r in runs:
        pop, root, _ = load_graph(champion_path(r))
        ev = r.config.evaluation
        n = ev.test_episodes
        own = evaluate_graph(pop, root, list(tasks), n, 0, no_memory=ev.no_memory)
        other = evaluate_graph(pop, root, list(tasks), n, RESCORE_OFFSET, no_memory=ev.no_memory)
        half = {t: 1.96 * own[t].std / np.sqrt(n) for t in tasks}
        cells = [f"{own[t].mean:.4g} ± {half[t]:.2g} ({other[t].mean:.4g})" for t in tasks]
        agree += sum(abs(own[t].mean - other[t].mean) <= np.sqrt(2) * half[t] for t in tasks)
        rows.append([r.name, str(r.final_generation), *cells])
    return head, rows, agree, len(rows) * len(tasks)


def resume_check_rows(path: Path) -> tuple[list[str], list[list[str]]]:
    """The rows ``tools/check_resume.py --record`` wrote, one per run."""
    head = ["run", "resumed from", "generations", "rows compared", "result", "by mtpg", "on"]
    rows = [
        [
            r["run"],
            r["resumed_from_commit"][:10],
            f"{r['from_generation']} -> {r['to_generation']}",
            f"{r['metrics_rows']} metrics, {r['test_rows']} tests",
            r["result"],
            r["mtpg_commit"][:10] + ("+dirty" if r["mtpg_commit"].endswith("+dirty") else ""),
            r["checked_utc"][:10],
        ]
        for r in csv.DictReader(path.open())
    ]
    return head, rows


def cpu_seconds_per_generation(paths: list[Path]) -> float:
    """CPU seconds per generation over the sittings of ``provenance.csv`` that recorded it."""
    rows = [p for path in paths for p in provenance(path) if p["cpu_s"]]
    gens = sum(int(p["to_generation"]) - int(p["from_generation"]) for p in rows)
    return sum(float(p["cpu_s"]) for p in rows) / gens if gens else float("nan")


def on_lane_engine(commit: str, repo: Path) -> bool | None:
    """Whether an mtpg commit has the lane engine; None where git cannot tell.

    Args:
        commit: The commit.
        repo: A folder inside the git work tree that knows it.
    """
    try:
        done = subprocess.run(
            ["git", "-C", str(repo), "merge-base", "--is-ancestor", LANE_ENGINE, commit],
            capture_output=True,
            check=False,
        )
    except OSError:
        return None
    return {0: True, 1: False}.get(done.returncode)


def engine_note(groups: dict[str, list[Path]], repo: Path | None = None) -> str:
    """A sentence when the groups grew on different engines (empty when git cannot tell).

    The lane engine takes less CPU time than the engines before it, so a group grown with
    it and one grown without are not compared like for like. ``repo`` is a folder in the
    git work tree (default: the first run's directory).
    """
    if repo is None:
        repo = next((p for paths in groups.values() for p in paths), Path("."))
    kinds = {}
    for label, paths in groups.items():
        commits = {p["mtpg_commit"] for path in paths for p in provenance(path)}
        found = {on_lane_engine(c, repo) for c in commits}
        if None in found or not found:
            return ""
        kinds[label] = "with" if found == {True} else "before" if found == {False} else "mixed"
    if len(set(kinds.values())) == 1:
        return ""
    said = {
        "with": "with the lane engine",
        "before": "with engines before the lane engine",
        "mixed": "partly with the lane engine",
    }
    return (
        "Not like for like: "
        + "; ".join(f"{label} grew {said[k]}" for label, k in kinds.items())
        + f" ({LANE_ENGINE[:7]}, [docs/engine.md](../docs/engine.md#the-lane-engine)), "
        "which takes less CPU time per generation."
    )
