"""Score the interface study of ``results/variants`` and write its table and figure.

The study (issue 40, item 3) asks how much of the paper's result the observation
interface of the authors' published code could explain: CartCentering + MountainCar and
the six tasks, each with the paper's interface and with the code's
(``results/plan.toml``: ``[interfaces.authors]``), ``demo`` preset, seeds 1 to 3, 1,000
generations. The six tasks with the paper's interface are the candidates' runs
``results/candidates/runs/demo-seed1..3`` (the same preset and seeds).

For every finished run the all-task champion is played on 100 held-out episodes per task
(``mtpg evaluate RUN --episodes 100 --json``), and on CartCentering's held-out episodes
traced (:func:`mtpg.engine.trace.trace_episode`) to count the episodes that leave the
track (``|x| > 1.5``) and, of those, the share that started left of centre: the
signature of CartCentering played as MountainCar. The figures go to
``results/variants/variants.json``, the table between the markers of
``docs/variants-study.md``, the figure to ``docs/img/variants-study.png``::

    .venv/bin/mtpg report --results results --page variants
"""

from __future__ import annotations

import json
import logging
from pathlib import Path

import numpy as np

from mtpg.analysis.plotting import pyplot, save
from mtpg.analysis.results.candidates import EPISODES, finished
from mtpg.analysis.results.candidates import scores as run_scores
from mtpg.analysis.runs.champions import run_champion
from mtpg.analysis.runs.statistics import aggregate_iqm, per_task_iqm
from mtpg.engine.batch import Episodes
from mtpg.engine.compile import compile_population
from mtpg.engine.trace import trace_episode
from mtpg.envs.taskset.episode_seeds import held_out_seeds
from mtpg.io.runconfig import read_run_config
from mtpg.io.serialize import load_graph

_LOG = logging.getLogger(__name__)
#: The study's folder inside the results folder; its page and figure inside ``docs/``.
FOLDER = "variants"
DOC = "variants-study.md"
FIGURE = "img/variants-study.png"
#: Each group: its label and where its runs are in the results folder (folder, prefix).
GROUPS = {
    "CC+MC, paper": ("variants/runs", "ccmc-paper-seed"),
    "CC+MC, authors' code": ("variants/runs", "ccmc-authors-seed"),
    "six tasks, paper": ("candidates/runs", "demo-seed"),
    "six tasks, authors' code": ("variants/runs", "six-authors-seed"),
}
SEEDS = (1, 2, 3)
BEGIN, END = "<!-- variants table: begin -->", "<!-- variants table: end -->"


def scores(run: Path) -> dict[str, float]:
    """The all-task champion's normalised score per task (base names) on held-out episodes."""
    return {task.split("[")[0]: value for task, value in run_scores(run).items()}


def off_track(run: Path) -> tuple[float, float]:
    """CartCentering's held-out episodes: the share leaving the track (and of those, from x < 0)."""
    pop, root, _ = load_graph(run_champion(run))
    tasks = read_run_config(run).evaluation.task_table()
    name = next(t for t in tasks.names if t.split("[")[0] == "CartCentering")
    task = tasks.id_of(name)
    cp = compile_population(pop, fold_constants=False)
    table = Episodes.grid([task], held_out_seeds(EPISODES).tolist(), tasks)
    left, from_left = 0, 0
    for e in range(EPISODES):
        states = trace_episode(
            cp, root, task, table.starts[e], table.noise[e], params=tasks.params
        ).states
        if abs(states[-1, 0]) > 1.5:
            left += 1
            from_left += int(states[0, 0] < 0)
    return left / EPISODES, (from_left / left if left else float("nan"))


def collect(results: Path) -> dict[str, dict[str, dict]]:
    """Every finished run's scores and CartCentering behaviour, by group."""
    out: dict[str, dict[str, dict]] = {}
    for group, (folder, prefix) in GROUPS.items():
        out[group] = {}
        for s in SEEDS:
            run = results / folder / f"{prefix}{s}"
            if finished(run):
                share, left = off_track(run)
                out[group][run.name] = {"scores": scores(run), "off_track": share, "left": left}
        _LOG.info(f"{group}: {len(out[group])} of {len(SEEDS)} runs finished")
    return out


def table(results: dict[str, dict[str, dict]]) -> str:
    """The markdown section: per run, then per group."""
    lines = []
    for group, runs in results.items():
        if not runs:
            lines += [f"**{group}**: no finished run yet.", ""]
            continue
        tasks = list(next(iter(runs.values()))["scores"])
        lines += [f"**{group}**", ""]
        lines.append("| run | " + " | ".join(tasks) + " | CC off track | of which x0 < 0 |")
        lines.append("|---|" + "---|" * (len(tasks) + 2))
        for name, r in runs.items():
            row = " | ".join(f"{r['scores'][t]:.2f}" for t in tasks)
            lines.append(f"| {name} | {row} | {r['off_track']:.0%} | {r['left']:.0%} |")
        m = np.array([[r["scores"][t] for t in tasks] for r in runs.values()])
        per = " | ".join(e.text() for e in per_task_iqm(m))
        lines.append(f"| IQM [95% CI], {len(m)} runs | {per} | | |")
        lines += ["", f"IQM over runs and tasks: {aggregate_iqm(m).text()}", ""]
    return "\n".join(lines)


#: Each group's colour: the paper's interface blue, the authors' code's orange; CC+MC light.
COLOURS = {
    "CC+MC, paper": "#9ecae1",
    "CC+MC, authors' code": "#fdae6b",
    "six tasks, paper": "#3182bd",
    "six tasks, authors' code": "#e6550d",
}


def figure(results: dict[str, dict[str, dict]], path: Path) -> None:
    """Per task IQM over runs (bars, 95% intervals), and CartCentering's episodes off track."""
    plt = pyplot()
    fig, (ax, off) = plt.subplots(1, 2, figsize=(11, 4), gridspec_kw={"width_ratios": [5, 1.3]})
    order = ["CartPole", "Acrobot", "CartCentering", "Pendulum", "MountainCar"]
    order.append("MountainCarContinuous")
    groups = [g for g in GROUPS if results.get(g)]
    width = 0.8 / max(1, len(groups))
    for k, group in enumerate(groups):
        runs = list(results[group].values())
        tasks = [t for t in order if t in runs[0]["scores"]]
        m = np.array([[r["scores"][t] for t in tasks] for r in runs])
        est = per_task_iqm(m)
        x = np.array([order.index(t) for t in tasks]) + (k - (len(groups) - 1) / 2) * width
        mid = np.array([e.value for e in est])
        err = np.array([[e.value - e.low for e in est], [e.high - e.value for e in est]])
        label = f"{group} ({len(m)} run{'s' if len(m) > 1 else ''})"
        ax.bar(x, mid, width, yerr=np.nan_to_num(err), capsize=2, label=label, color=COLOURS[group])
        shares = [100 * r["off_track"] for r in runs]
        off.bar(k, np.mean(shares), 0.7, color=COLOURS[group])
        off.plot([k] * len(shares), shares, "k.", ms=4)
    ax.set_xticks(range(len(order)), [t.replace("MountainCar", "MC") for t in order])
    ax.axhline(0, color="grey", lw=0.5)
    ax.set_ylabel("normalised score, IQM over runs")
    ax.set_title("All-task champions, 100 held-out episodes per task", fontsize=10)
    ax.legend(fontsize=8, ncol=2)
    off.set_xticks(range(len(groups)), [g.replace(", ", "\n") for g in groups], fontsize=6)
    off.set_ylabel("% of episodes (dots: runs)")
    off.set_ylim(0, 100)
    off.set_title("CartCentering off the track", fontsize=10)
    fig.suptitle("The paper's interface and the authors' code's (demo, 1,000 generations)")
    fig.tight_layout()
    save(fig, path)


def render(page: str, results: dict[str, dict[str, dict]]) -> str:
    """The page's text with the section between the markers written from ``results``."""
    head, _, rest = page.partition(BEGIN)
    _, _, tail = rest.partition(END)
    return f"{head}{BEGIN}\n{table(results)}\n{END}{tail}"


def write(results: Path, out: Path | None = None) -> Path:
    """Scores the finished runs, rewrites the page's table and the figure; the page's path.

    Args:
        results: The results folder (the page is ``docs/`` beside it).
        out: The results folder written to (default: ``results``; the page and the
            figure go to ``docs/`` beside it).

    Raises:
        ValueError: No run has finished.
    """
    scored = collect(results)
    if not any(scored.values()):
        raise ValueError(f"{results}: no finished run of the interface study")
    out = results if out is None else out
    (out / FOLDER).mkdir(parents=True, exist_ok=True)
    (out / FOLDER / "variants.json").write_text(json.dumps(scored, indent=1, sort_keys=True) + "\n")
    page = out.parent / "docs" / DOC
    page.parent.mkdir(parents=True, exist_ok=True)
    page.write_text(render((results.parent / "docs" / DOC).read_text(), scored))
    (out.parent / "docs" / FIGURE).parent.mkdir(parents=True, exist_ok=True)
    figure(scored, out.parent / "docs" / FIGURE)
    return page
