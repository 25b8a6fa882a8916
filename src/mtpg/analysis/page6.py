"""``mtpg analyze``: the section-6 figures of one graph, a JSON summary and an HTML page.

The page is self-contained: its images are embedded.
"""

from __future__ import annotations

import base64
import html
import json
from pathlib import Path

import numpy as np

from mtpg.analysis import figures6
from mtpg.analysis.decompose import decomposition
from mtpg.analysis.graphinfo import graph_dot, index_graph
from mtpg.analysis.graphlayout import layout_graph, render_svg
from mtpg.analysis.hierarchy import hierarchy_statistics, mean_by_size
from mtpg.analysis.inside import (
    register_access,
    step_series,
    velocity_prediction,
    visit_statistics,
)
from mtpg.analysis.replay import replay_task, replay_tasks
from mtpg.model.graph import Population


def default_decompose_task(tasks: list[str]) -> str:
    """Pendulum when analysed (the paper's Fig. 10a), else the first task."""
    return "Pendulum" if "Pendulum" in tasks else tasks[0]


def median_episode(returns: np.ndarray) -> int:
    """Index of the episode of median return (the lower middle one for an even count)."""
    return int(np.argsort(returns, kind="stable")[(len(returns) - 1) // 2])


def _img(path: Path, title: str) -> str:
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    return (
        f'<h2>{html.escape(title)}</h2><img alt="{html.escape(title)}" '
        f'src="data:image/png;base64,{data}">'
    )


def _visit_table(visits: dict) -> str:
    tasks = [str(t) for t in visits["tasks"]]
    head = "".join(f"<th>{html.escape(t)}</th>" for t in tasks)
    rows = "".join(
        f"<tr><td>team {n}</td>"
        + "".join(f"<td>{100 * v:.1f}%</td>" for v in visits["rate"][n - 1])
        + "</tr>"
        for n in visits["teams"]
    )
    return (
        "<h2>Share of each task's steps in which a team ran</h2>"
        f"<table><tr><th></th>{head}</tr>{rows}</table>"
    )


def build_analysis(
    pop: Population,
    root: int,
    tasks: list[str],
    out: str | Path,
    episodes: int = 100,
    seed: int = 0,
    no_memory: bool = False,
    decompose_task: str | None = None,
    run_dir: str | Path | None = None,
    label: str = "graph",
) -> dict[str, Path]:
    """Replays every task and writes the figures and the page into ``out``.

    Besides the PNG figures: ``graph.dot`` (and ``graph.svg`` when GraphViz is installed),
    ``analysis.json`` (the numbers of the page) and ``index.html``.

    Args:
        pop: The population holding the graph.
        root: Root team id.
        tasks: Task names to replay.
        out: Output directory (created).
        episodes: Test episodes per task (visit shares, register shares, decomposition);
            the time series replay the episode of median return again, recording memory.
        seed: Test seed offset (the episodes ``mtpg evaluate`` uses with this offset).
        no_memory: Replay with memory off.
        decompose_task: Task of the decomposition figure (default
            :func:`default_decompose_task`).
        run_dir: A run directory: adds its hierarchy statistics (Fig. 8).
        label: Name of the graph in titles.

    Returns:
        Written files by name (``index`` is the HTML page).
    """
    decompose_task = decompose_task or default_decompose_task(tasks)
    if decompose_task not in tasks:
        raise ValueError(f"--decompose-task {decompose_task!r} is not among the tasks analysed")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    index = index_graph(pop, root)
    n_teams = len(index.teams)
    layout = layout_graph(pop, root)
    replays = replay_tasks(pop, root, tasks, episodes, seed, no_memory, memory_episodes=0)
    visits = visit_statistics(replays, n_teams)
    access = register_access(replays)
    mem = "memory off" if no_memory else "memory on"
    files: dict[str, Path] = {}
    sections = []
    files["team_graph"] = figures6.team_graph(
        layout,
        visits,
        out / "team_graph.png",
        f"{label}: {n_teams} team{'s' if n_teams > 1 else ''}, visits over {episodes} "
        f"test episodes per task ({mem})",
    )
    sections.append(_img(files["team_graph"], "Team graph with visits by task (Fig. 9 top)"))
    files["registers"] = figures6.register_access(
        access,
        out / "register_access.png",
        f"{label}: share of accesses of the {len(access['labels'])} memory registers used, by task",
    )
    sections.append(_img(files["registers"], "Memory register access by task (Fig. 9 bottom)"))
    summary: dict[str, object] = {
        "graph": label,
        "root_team": int(root),
        "memory": mem,
        "episodes": episodes,
        "seed": seed,
        "tasks": {},
    }
    for task in tasks:
        typical = median_episode(replays[task]["returns"])
        one = replay_task(pop, root, task, 1, seed + typical, no_memory)
        series = step_series(one, 0)
        pred = velocity_prediction(one, 0)
        name = f"timeseries_{task}.png"
        files[name] = figures6.time_series(
            task,
            series,
            pred,
            out / name,
            f"{task}: the test episode of median return\n(seed {int(one['episode_seeds'][0])}, "
            f"return {one['returns'][0]:.2f}, {one.n_steps} steps)",
        )
        sections.append(_img(files[name], f"{task}: run-time dynamics (Figs. 11-12)"))
        summary["tasks"][task] = {
            "mean_return": float(np.mean(replays[task]["returns"])),
            "mean_teams_per_step": float(replays[task].counts("visit").mean()),
            "mean_instructions_per_step": float(replays[task].counts("instr").mean()),
            "best_register": pred["label"],
            "pearson_r": None if pred["r"] != pred["r"] else float(pred["r"]),
            "velocity": pred["variable"],
            "visit_rate": {
                f"team {n}": float(v)
                for n, v in zip(visits["teams"], visits["rate"][:, tasks.index(task)], strict=True)
            },
        }
    dec = decomposition(replays[decompose_task], n_teams)
    ran = [n for n in range(1, n_teams + 1) if len(dec["teams"][n - 1]["x"])]
    files["decomposition"] = figures6.decomposition(
        dec,
        ran,
        out / f"decomposition_{decompose_task}.png",
        f"{decompose_task}: where each team ran over {episodes} test episodes",
    )
    sections.append(
        _img(files["decomposition"], f"Task decomposition of {decompose_task} (Fig. 10)")
    )
    if run_dir is not None:
        stats = hierarchy_statistics(run_dir)
        files["hierarchy"] = figures6.run_hierarchy(
            stats,
            mean_by_size(stats),
            out / "run_hierarchy.png",
            f"{Path(run_dir).name}: hierarchical complexity of task-subset champions",
        )
        sections.append(_img(files["hierarchy"], "Hierarchy across the run (Fig. 8)"))
    dot = out / "graph.dot"
    dot.write_text(graph_dot(pop, root, title=label), encoding="utf-8")
    files["dot"] = dot
    svg = render_svg(dot)
    if svg is not None:
        files["svg"] = svg
    summary_path = out / "analysis.json"
    summary_path.write_text(json.dumps(summary, indent=2), encoding="utf-8")
    files["summary"] = summary_path
    rows = "".join(
        f"<tr><td>{html.escape(t)}</td><td>{s['mean_return']:.3f}</td>"
        f"<td>{s['mean_teams_per_step']:.2f}</td><td>{s['mean_instructions_per_step']:.1f}</td>"
        f"<td>{html.escape(str(s['best_register']))}</td>"
        f"<td>{'' if s['pearson_r'] is None else format(s['pearson_r'], '.2f')}</td></tr>"
        for t, s in summary["tasks"].items()
    )
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>mtpg analyze: {html.escape(label)}</title>
<style>body{{font-family:sans-serif;max-width:1100px;margin:2em auto}}img{{max-width:100%}}
table{{border-collapse:collapse}}td,th{{border:1px solid #ccc;padding:3px 8px;text-align:right}}
</style></head><body>
<h1>Inside {html.escape(label)}</h1>
<p>{n_teams} teams; {episodes} test episodes per task (seed offset {seed}); {mem}.
Team numbers: team 1 is the root, the others in depth-first order (as in <code>mtpg show</code>).
</p>
<table><tr><th>task</th><th>mean return</th><th>teams/step</th><th>instructions/step</th>
<th>register tracking the velocity</th><th>Pearson r</th></tr>{rows}</table>
{_visit_table(visits)}
{"".join(sections)}
</body></html>
"""
    files["index"] = out / "index.html"
    files["index"].write_text(page, encoding="utf-8")
    return files
