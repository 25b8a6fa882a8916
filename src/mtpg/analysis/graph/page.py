"""``mtpg analyze``: the section-6 figures of one graph, a JSON summary and an HTML page.

The page is self-contained: its images are embedded.
"""

from __future__ import annotations

import html
import json
from pathlib import Path

import numpy as np

from mtpg.analysis import html as pages
from mtpg.analysis.description.layout import layout_graph, render_svg
from mtpg.analysis.description.listing import graph_dot
from mtpg.analysis.description.numbering import index_graph
from mtpg.analysis.graph import figures
from mtpg.analysis.graph.decomposition import decomposition
from mtpg.analysis.graph.measures import (
    register_access,
    step_series,
    velocity_prediction,
    visit_statistics,
)
from mtpg.analysis.graph.replay import replay_task, replay_tasks
from mtpg.analysis.runs.hierarchical_complexity import (
    hierarchy_statistics,
    mean_by_size,
    run_complexity,
)
from mtpg.envs.specs.compiled_task import is_compiled_name
from mtpg.envs.specs.gym_task import is_gym
from mtpg.envs.taskset.task_table import TaskTable
from mtpg.io.rundir import file_safe
from mtpg.model.graph import Population

#: Why a Gymnasium task gets no velocity panel and no decomposition (one line).
HIDDEN_STATE_NOTE = (
    "no velocity prediction (Figs. 11-12 bottom) or task decomposition (Fig. 10): they "
    "need the task's hidden velocity, and a Gymnasium environment keeps its state to itself"
)
#: The same for a compiled task of a user's module: its state is traced, unnamed.
UNNAMED_STATE_NOTE = (
    "no velocity prediction (Figs. 11-12 bottom) or task decomposition (Fig. 10): they "
    "need to know which state slot is the hidden velocity, and a compiled task of a user's "
    "module does not say (its state is in the replay's hidden_state)"
)


def _no_velocity(task: str) -> str | None:
    """Why ``task`` has no velocity analyses (None: it has them)."""
    if is_gym(task):
        return HIDDEN_STATE_NOTE
    return UNNAMED_STATE_NOTE if is_compiled_name(task) else None


def default_decompose_task(tasks: list[str]) -> str | None:
    """Pendulum when analysed (the paper's Fig. 10a), else the first task with a hidden state.

    None when no task names a hidden velocity (every task is a Gymnasium task or a
    compiled task of a user's module: :func:`not_applicable`).
    """
    if "Pendulum" in tasks:
        return "Pendulum"
    return next((t for t in tasks if _no_velocity(t) is None), None)


def not_applicable(tasks: list[str]) -> dict[str, str]:
    """The analyses skipped for some of ``tasks``, one line per task, by task."""
    return {t: note for t in tasks if (note := _no_velocity(t)) is not None}


def median_episode(returns: np.ndarray) -> int:
    """Index of the episode of median return (the lower middle one for an even count)."""
    return int(np.argsort(returns, kind="stable")[(len(returns) - 1) // 2])


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
    if decompose_task is not None and decompose_task not in tasks:
        raise ValueError(f"--decompose-task {decompose_task!r} is not among the tasks analysed")
    if decompose_task is not None and _no_velocity(decompose_task) is not None:
        raise ValueError(f"--decompose-task {decompose_task}: {_no_velocity(decompose_task)}")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    a = _Analysis(pop, root, tasks, out, episodes, seed, no_memory, label)
    a.graph_figures()
    summary = a.task_figures()
    if decompose_task is not None:
        a.decomposition_figure(decompose_task)
    if run_dir is not None:
        a.run_figure(Path(run_dir))
    a.write_dot()
    summary_path = out / "analysis.json"
    summary_path.write_text(json.dumps(summary, indent=2), encoding="utf-8")
    a.files["summary"] = summary_path
    a.files["index"] = out / "index.html"
    a.files["index"].write_text(a.page(summary), encoding="utf-8")
    return a.files


class _Analysis:
    """The replays of one graph and the files written from them, figure by figure."""

    def __init__(self, pop, root, tasks, out, episodes, seed, no_memory, label) -> None:
        self.pop, self.root, self.tasks, self.out = pop, root, tasks, out
        self.episodes, self.seed, self.no_memory, self.label = episodes, seed, no_memory, label
        self.n_teams = len(index_graph(pop, root).teams)
        self.table = TaskTable.from_names(tasks)  # resolved once, for every replay
        self.replays = replay_tasks(
            pop, root, tasks, episodes, seed, no_memory, memory_episodes=0, table=self.table
        )
        self.visits = visit_statistics(self.replays, self.n_teams)
        self.mem = "memory off" if no_memory else "memory on"
        self.files: dict[str, Path] = {}
        self.sections: list[str] = []

    def _add(self, key: str, path: Path, title: str) -> None:
        self.files[key] = path
        self.sections.append(pages.figure(path, title))

    def graph_figures(self) -> None:
        """Fig. 9: the team graph with visits by task, and memory register access."""
        n, out, label = self.n_teams, self.out, self.label
        title = (
            f"{label}: {n} team{'s' if n > 1 else ''}, visits over {self.episodes} "
            f"test episodes per task ({self.mem})"
        )
        layout = layout_graph(self.pop, self.root)
        path = figures.team_graph(layout, self.visits, out / "team_graph.png", title)
        self._add("team_graph", path, "Team graph with visits by task (Fig. 9 top)")
        access = register_access(self.replays)
        title = (
            f"{label}: share of accesses of the {len(access['labels'])} memory registers used, "
            "by task"
        )
        path = figures.register_access(access, out / "register_access.png", title)
        self._add("registers", path, "Memory register access by task (Fig. 9 bottom)")

    def task_figures(self) -> dict[str, object]:
        """Figs. 11-12 of every task (its episode of median return); the JSON summary."""
        summary: dict[str, object] = {
            "graph": self.label,
            "root_team": int(self.root),
            "memory": self.mem,
            "episodes": self.episodes,
            "seed": self.seed,
            "tasks": {},
        }
        for task in self.tasks:
            summary["tasks"][task] = self._task_figure(task)
        return summary

    def _task_figure(self, task: str) -> dict[str, object]:
        replays, visits = self.replays, self.visits
        typical = median_episode(replays[task]["returns"])
        one = replay_task(
            self.pop, self.root, task, 1, self.seed + typical, self.no_memory, table=self.table
        )
        pred = None if _no_velocity(task) else velocity_prediction(one, 0)
        name = f"timeseries_{file_safe(task)}.png"
        title = (
            f"{task}: the test episode of median return\n(seed {int(one['episode_seeds'][0])}, "
            f"return {one['returns'][0]:.2f}, {one.n_steps} steps)"
        )
        path = figures.time_series(task, step_series(one, 0), pred, self.out / name, title)
        self._add(name, path, f"{task}: run-time dynamics (Figs. 11-12)")
        rates = visits["rate"][:, self.tasks.index(task)]
        if pred is None:
            pred = {"label": None, "r": float("nan"), "variable": None}
        return {
            "mean_return": float(np.mean(replays[task]["returns"])),
            "mean_teams_per_step": float(replays[task].counts("visit").mean()),
            "mean_instructions_per_step": float(replays[task].counts("instr").mean()),
            "best_register": pred["label"],
            "pearson_r": None if pred["r"] != pred["r"] else float(pred["r"]),
            "velocity": pred["variable"],
            "visit_rate": {
                f"team {n}": float(v) for n, v in zip(visits["teams"], rates, strict=True)
            },
            **({"not_applicable": why} if (why := _no_velocity(task)) else {}),
        }

    def decomposition_figure(self, task: str) -> None:
        """Fig. 10: where each team ran in ``task``."""
        dec = decomposition(self.replays[task], self.n_teams)
        ran = [n for n in range(1, self.n_teams + 1) if len(dec["teams"][n - 1]["x"])]
        title = f"{task}: where each team ran over {self.episodes} test episodes"
        path = figures.decomposition(dec, ran, self.out / f"decomposition_{task}.png", title)
        self._add("decomposition", path, f"Task decomposition of {task} (Fig. 10)")

    def run_figure(self, run_dir: Path) -> None:
        """Fig. 8 across the run the graph comes from."""
        stats = hierarchy_statistics(run_dir)
        title = f"{run_dir.name}: hierarchical complexity of task-subset champions"
        path = run_complexity(stats, mean_by_size(stats), self.out / "run_hierarchy.png", title)
        self._add("hierarchy", path, "Hierarchy across the run (Fig. 8)")

    def write_dot(self) -> None:
        """``graph.dot``, and ``graph.svg`` when GraphViz is installed."""
        dot = self.out / "graph.dot"
        dot.write_text(graph_dot(self.pop, self.root, title=self.label), encoding="utf-8")
        self.files["dot"] = dot
        svg = render_svg(dot)
        if svg is not None:
            self.files["svg"] = svg

    def page(self, summary: dict) -> str:
        """The HTML page: the summary table, the visit table and every figure."""
        label = html.escape(self.label)
        rows = "".join(
            f"<tr><td>{html.escape(t)}</td><td>{s['mean_return']:.3f}</td>"
            f"<td>{s['mean_teams_per_step']:.2f}</td>"
            f"<td>{s['mean_instructions_per_step']:.1f}</td>"
            f"<td>{html.escape(str(s['best_register'] or '-'))}</td>"
            f"<td>{'' if s['pearson_r'] is None else format(s['pearson_r'], '.2f')}</td></tr>"
            for t, s in summary["tasks"].items()
        )
        skipped = "".join(
            f"<p>{html.escape(t)}: {html.escape(n)}.</p>"
            for t, n in not_applicable(self.tasks).items()
        )
        body = f"""<h1>Inside {label}</h1>
<p>{self.n_teams} teams; {self.episodes} test episodes per task (seed offset {self.seed}); \
{self.mem}.
Team numbers: team 1 is the root, the others in depth-first order (as in <code>mtpg show</code>).
</p>
<table><tr><th>task</th><th>mean return</th><th>teams/step</th><th>instructions/step</th>
<th>register tracking the velocity</th><th>Pearson r</th></tr>{rows}</table>
{skipped}
{_visit_table(self.visits)}
{"".join(self.sections)}"""
        return pages.page(f"mtpg analyze: {self.label}", body)
