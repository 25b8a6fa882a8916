"""Regenerate the measured section of ``docs/memorisation.md`` from the committed runs.

One command, from the repository root with the project's environment::

    .venv/bin/mtpg report --results results --page memorisation

It runs the memorisation probe (``mtpg probe``, :mod:`mtpg.analysis.runs.champion_probe`)
with its defaults on the all-task champion of every run in ``results/runs/`` and on the
single-task champions of the ``TPG`` seeds, and writes the tables between the markers
``<!-- probe:begin -->`` and ``<!-- probe:end -->`` of the page. It reads the runs and
writes nothing into them.
"""

from __future__ import annotations

import re
import statistics
from pathlib import Path

import numpy as np

from mtpg.analysis.runs.champion_probe import Probe, probe_target, probe_text
from mtpg.analysis.runs.champions import champion_path, tested_run
from mtpg.evolve.memorisation import DEFAULT_REDRAWS

#: The page, in ``docs/`` beside the results folder.
PAGE = "memorisation.md"
BEGIN, END = "<!-- probe:begin -->", "<!-- probe:end -->"
#: The figures issue 40 quotes: (run, task) -> (training, fresh noise), normalised.
ISSUE = {
    ("TPG-seed1", "CartCentering"): (0.87, 0.45),
    ("TPG-seed3", "CartCentering"): (0.83, 0.63),
    ("TPG-seed4", "CartCentering"): (0.72, 0.56),
    ("TPG-seed1", "Pendulum"): (0.71, 0.43),
    ("TPG-seed3", "Pendulum"): (0.74, 0.53),
    ("TPG-seed5", "Pendulum"): (0.58, 0.42),
}
#: Redraws behind the comparison with the issue: enough for the spread of single redraws.
ISSUE_REDRAWS = 200
#: The run whose probe is shown as printed.
EXAMPLE = "TPG-seed1"
#: The runs the page probes: the paper's experiment (the ``paper`` group of
#: ``results/plan.toml``: TPG and its ablations). TPG-robust and TPG-authors are probed on
#: the results page, beside their groups (TPG-authors plays other task variants).
PAPER_RUN = re.compile(r"TPG-(No[A-Za-z]+-)?seed\d+")
#: Single-task champions probed besides the all-task ones.
SINGLE_TASKS = ("CartCentering", "Pendulum")


def table(head: list[str], rows: list[list[str]]) -> list[str]:
    """A markdown table."""
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    return lines + ["| " + " | ".join(r) + " |" for r in rows]


def fresh_interval(probe: Probe, task: str) -> tuple[float, float, float, float]:
    """(b) normalised: its mean's 95% interval and the central 95% of single redraws.

    The interval is the mean over redraws -+ 1.96 standard errors; the central 95% runs
    from the 2.5th to the 97.5th percentile of the means of single redraws.
    """
    values = [probe.tasks[task].normalise(v) for v in probe.tasks[task].redraw_means]
    mean = statistics.fmean(values)
    half = 1.96 * statistics.stdev(values) / len(values) ** 0.5
    low, high = np.percentile(values, [2.5, 97.5])
    return mean - half, mean + half, float(low), float(high)


def all_task_rows(probes: dict[str, Probe]) -> tuple[list[str], list[list[str]]]:
    """One row per run: (a) -> (b) (c) per task, normalised."""
    tasks = list(next(iter(probes.values())).tasks)
    rows = []
    for name, p in probes.items():
        cells = []
        for t in tasks:
            s = p.tasks[t].normalised()
            cells.append(f"{s['train']:.2f} → {s['fresh_noise']:.2f} ({s['test']:.2f})")
        rows.append([name, str(p.generation), *cells])
    return ["run", "generation", *tasks], rows


def issue_summary(rows: list[list[str]]) -> str:
    """One sentence: how many of the issue's figures the probe reproduces, and how."""
    n = len(rows)
    same, in_ci, in_spread = (sum(r[k] == "yes" for r in rows) for k in (7, 8, 9))
    worst = max(abs(float(r[6])) for r in rows)
    return (
        f"(a) equals the issue's training figure to two decimals in {same} of {n} cells; "
        f"the issue's fresh-noise figure lies within the central 95% of single redraws in "
        f"{in_spread} of {n} and within the 95% interval of the {ISSUE_REDRAWS}-redraw mean "
        f"in {in_ci} of {n}, at most {worst:.3f} from that mean."
    )


def issue_rows(results: Path) -> list[list[str]]:
    """The issue's figures beside the probe's with :data:`ISSUE_REDRAWS` redraws."""
    rows = []
    for (run, task), (a, b) in ISSUE.items():
        probe = probe_target(results / "runs" / run, tasks=[task], redraws=ISSUE_REDRAWS)
        s = probe.tasks[task].normalised()
        lo, hi, low, high = fresh_interval(probe, task)
        rows.append(
            [
                run,
                task,
                f"{a:.2f} → {b:.2f}",
                f"{s['train']:.3f}",
                f"{s['fresh_noise']:.3f} [{lo:.3f}, {hi:.3f}]",
                f"{low:.3f}..{high:.3f}",
                f"{b - s['fresh_noise']:+.3f}",
                "yes" if round(s["train"], 2) == a else "no",
                "yes" if lo <= b <= hi else "no",
                "yes" if low <= b <= high else "no",
            ]
        )
    return rows


def single_rows(runs: list[Path]) -> list[list[str]]:
    """Each TPG seed's single-task champions of :data:`SINGLE_TASKS` on their own task."""
    rows = []
    for task in SINGLE_TASKS:
        for run in runs:
            graph = champion_path(tested_run(run), (task,))
            p = probe_target(graph)
            s = p.tasks[task].normalised()
            lo, hi, low, high = fresh_interval(p, task)
            rows.append(
                [
                    run.name,
                    task,
                    f"{s['train']:.3f}",
                    f"{s['fresh_noise']:.3f} [{lo:.3f}, {hi:.3f}]",
                    f"{low:.3f}..{high:.3f}",
                    f"{s['test']:.3f}",
                ]
            )
    return rows


def summary(probes: dict[str, Probe]) -> list[str]:
    """Median drops over the TPG seeds per task (normalised), one sentence each."""
    tpg = [p for name, p in probes.items() if name.startswith("TPG-seed")]
    out = []
    for t in tpg[0].tasks:
        noise = [p.tasks[t].drops(p.tasks[t].normalised())["noise"] for p in tpg]
        starts = [p.tasks[t].drops(p.tasks[t].normalised())["start_states"] for p in tpg]
        out.append(
            f"- {t}: median drop over the {len(tpg)} TPG seeds {statistics.median(noise):.2f} "
            f"from (a) to (b) (range {min(noise):.2f} to {max(noise):.2f}), "
            f"{statistics.median(starts):.2f} from (b) to (c)."
        )
    return out


def block(results: Path) -> list[str]:
    """The generated section."""
    runs = sorted(
        p
        for p in (results / "runs").iterdir()
        if (p / "config.toml").is_file() and PAPER_RUN.fullmatch(p.name)
    )
    probes = {run.name: probe_target(run) for run in runs}
    first = next(iter(probes.values()))
    head, rows = all_task_rows(probes)
    issue_head = [
        "run",
        "task",
        "issue 40: (a) → (b)",
        "(a) measured",
        "(b) measured [95% CI]",
        "(b) single redraws, central 95%",
        "issue's (b) - measured (b)",
        "(a) equal",
        "issue's (b) in CI",
        "issue's (b) in single redraws' 95%",
    ]
    tpg = [r for r in runs if r.name.startswith("TPG-seed")]
    root = f"{results.resolve().parent}/"
    example = [line.replace(root, "") for line in probe_text(probes[EXAMPLE])]
    return [
        "Generated by `.venv/bin/mtpg report --results results --page memorisation` (each "
        "probe is "
        f"`mtpg probe RUN_DIR` with its defaults: {len(first.train_seeds)} training "
        f"episodes, {DEFAULT_REDRAWS} noise redraws each, noise seed {first.noise_seed}, "
        f"{first.test_episodes} held-out episodes per task).",
        "",
        "**Every run's all-task champion**, normalised (0 = random play, 1 = reference "
        "best): (a) training → (b) fresh noise, and in brackets (c) test.",
        "",
        *table(head, rows),
        "",
        "Median drops of the all-task champions, normalised:",
        "",
        *summary(probes),
        "",
        f"What `mtpg probe results/runs/{EXAMPLE}` prints:",
        "",
        "```text",
        *example,
        "```",
        "",
        "**The figures of issue 40 beside the probe's**, with "
        f"{ISSUE_REDRAWS} redraws (`mtpg probe RUN_DIR --tasks TASK --redraws "
        f"{ISSUE_REDRAWS}`). (b) measured: the mean over the redraws with its 95% interval "
        "(1.96 standard errors); single redraws: the 2.5th to 97.5th percentile of the "
        f"mean of one redraw of the {len(first.train_seeds)} training start states, the "
        "spread of a figure measured with one redraw.",
        "",
        *table(issue_head, issued := issue_rows(results)),
        "",
        issue_summary(issued),
        "",
        "**Single-task champions** of the TPG seeds at generation "
        f"{first.generation} (`mtpg probe results/runs/RUN/tests/gen-NNNNNN/TASK.json`), "
        "normalised, on their own task:",
        "",
        *table(
            [
                "run",
                "task",
                "(a) train",
                "(b) fresh noise [95% CI]",
                "(b) single redraws, central 95%",
                "(c) test",
            ],
            single_rows(tpg),
        ),
    ]


def write(results: Path, out: Path | None = None) -> Path:
    """Rewrites the generated section of ``docs/memorisation.md``; returns the page's path.

    Args:
        results: The results folder (the page is ``docs/`` beside it).
        out: The results folder written to (default: ``results``; the page goes to
            ``docs/`` beside it).

    Raises:
        ValueError: The page has no section between the markers.
    """
    source = results.parent / "docs" / PAGE
    text = source.read_text(encoding="utf-8")
    if BEGIN not in text or END not in text:
        raise ValueError(f"{source}: no {BEGIN} ... {END} section to rewrite")
    before, rest = text.split(BEGIN, 1)
    after = rest.split(END, 1)[1]
    lines = block(results)
    page = (results if out is None else out).parent / "docs" / PAGE
    page.parent.mkdir(parents=True, exist_ok=True)
    page.write_text(before + BEGIN + "\n" + "\n".join(lines) + "\n" + END + after, "utf-8")
    return page
