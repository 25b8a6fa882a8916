"""The memorisation probe of a run's champion: which graph, which episodes, how to show it.

``mtpg probe TARGET`` and the report's memorisation section play one graph with
:func:`mtpg.evolve.memorisation.probe_graph` on (a) the training episodes it was last
trained on, (b) the same start states with only the U[0, 1] noise input redrawn, (c)
held-out episodes. The target is a run directory (its reported champion,
:func:`mtpg.analysis.runs.champions.run_champion`) or a graph file inside one
(``tests/gen-NNNNNN/*.json``, ``champions/*.json``); the run's ``config.toml`` says which
training episodes the graph saw (:func:`mtpg.evolve.memorisation.champion_training_seeds`)
and whether it runs without memory, and ``tests.csv`` holds the single-task denominators.
Nothing is written into the run directory.
"""

from __future__ import annotations

import html
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mtpg.envs.taskset.episode_seeds import describe_held_out
from mtpg.evolve.memorisation import (
    DEFAULT_REDRAWS,
    SETS,
    TaskProbe,
    champion_training_seeds,
    probe_graph,
    training_block,
)
from mtpg.io.rundir import CONFIG_FILE, champion_filename

#: How far above a graph file its run directory may be (``tests/gen-NNNNNN/x.json``).
RUN_DIR_DEPTH = 3
#: The drops, in words.
DROPS_TEXT = (
    "drop noise = (a) - (b): what the training noise was worth (exactly 0 where the task "
    "does not observe it); drop starts = (b) - (c): what the training start states were "
    "worth; positive = worse on the later set; (b) 95% CI: mean over redraws -+ 1.96 "
    "standard errors"
)


@dataclass(frozen=True)
class Probe:
    """The probe of one graph of a run, with what it was played on.

    Attributes:
        target: The graph file or run directory given.
        graph: The graph file probed.
        run_dir: The run it belongs to.
        generation: The generation the graph was chosen at.
        root: Its root team id.
        teams: Teams in its graph.
        train_seeds: Seeds of (a).
        block: Training block of (a) (0: the run's fixed training episodes, seeds 0..n-1).
        resample_interval: The run's ``evaluation.resample_interval`` (0: off).
        resample_mean: The run's ``evaluation.resample_mean``.
        noise_seed: Seed of the redrawn noise of (b).
        redraws: Redraws of (b).
        test_episodes: Held-out episodes per task of (c).
        test_offset: Offset of their seeds.
        no_memory: Whether the graph was played without memory (as the run trained it).
        tasks: The probe of each task.
    """

    target: Path
    graph: Path
    run_dir: Path
    generation: int
    root: int
    teams: int
    train_seeds: tuple[int, ...]
    block: int
    resample_interval: int
    resample_mean: bool
    noise_seed: int
    redraws: int
    test_episodes: int
    test_offset: int
    no_memory: bool
    tasks: dict[str, TaskProbe]

    def describe_sets(self) -> list[str]:
        """One line per set of episodes: what it is and its seeds."""
        n = len(self.train_seeds)
        if self.resample_interval > 0:
            which = (
                f"training block {self.block} of a run that redraws its training episodes "
                f"every {self.resample_interval} generations: the episodes the graph was last "
                "trained on"
                + (
                    "; its selection score also averaged earlier blocks"
                    if self.resample_mean
                    else ""
                )
            )
        else:
            which = "the run's fixed training episodes, played in every generation"
        seeds = _seeds(self.train_seeds)
        return [
            f"(a) train: {n} training episodes per task, seeds {seeds} ({which})",
            f"(b) fresh noise: the same {n} start states, only the U[0, 1] noise input redrawn, "
            f"{self.redraws} times ({n * self.redraws} episodes per task; noise seed "
            f"{self.noise_seed})",
            f"(c) test: {describe_held_out(self.test_episodes, self.test_offset)}",
        ]


def _seeds(seeds: tuple[int, ...]) -> str:
    if list(seeds) == list(range(seeds[0], seeds[0] + len(seeds))):
        return f"{seeds[0]:,}..{seeds[-1]:,}"
    return ", ".join(f"{s:,}" for s in seeds)


def find_run_dir(graph: Path) -> Path:
    """The run directory a graph file lies in (the nearest folder above with a config).

    Raises:
        FileNotFoundError: When none of the folders above it is a run directory.
    """
    for folder in list(graph.resolve().parents)[:RUN_DIR_DEPTH]:
        if (folder / CONFIG_FILE).is_file():
            return folder
    raise FileNotFoundError(
        f"{graph}: not inside a run directory (no {CONFIG_FILE} up to {RUN_DIR_DEPTH} "
        "folders above it); the probe needs the run's training episodes"
    )


def _subset_of(graph: Path, tasks: tuple[str, ...]) -> tuple[str, ...]:
    """The task subset a champion file is named after (all tasks when none matches)."""
    n = len(tasks)
    for mask in range(1, 1 << n):
        subset = tuple(t for i, t in enumerate(tasks) if mask >> i & 1)
        if champion_filename(subset) == graph.name:
            return subset
    return tasks


def probe_target(
    target: str | Path,
    *,
    tasks: list[str] | None = None,
    noise_seed: int = 0,
    redraws: int = DEFAULT_REDRAWS,
    test_episodes: int | None = None,
    test_offset: int = 0,
    workers: int = 1,
) -> Probe:
    """Probes a run directory's reported champion, or a graph file of a run.

    Args:
        target: A run directory or a graph file inside one.
        tasks: Tasks to play (default: the run's tasks; for a subset's champion file, that
            subset's).
        noise_seed: Seed of the redrawn noise of (b).
        redraws: Redraws of the noise of every training episode.
        test_episodes: Held-out episodes per task (default: the run's ``test_episodes``,
            so (c) equals ``tests.csv``).
        test_offset: Offset of the held-out seeds.
        workers: Threads.

    Raises:
        FileNotFoundError: When the target, its run or its champion is missing.
        ValueError: For a task the run did not train on, or a graph without a generation.
    """
    from mtpg.analysis.runs.champions import run_champion, tested_run
    from mtpg.io.runconfig import read_run_config
    from mtpg.io.serialize import load_graph
    from mtpg.limits import BudgetError, check_evaluation_fits

    target = Path(target)
    if not target.exists():
        raise FileNotFoundError(f"{target}: no such file or directory")
    run_dir = target if target.is_dir() else find_run_dir(target)
    config = read_run_config(run_dir)
    graph = run_champion(run_dir) if target.is_dir() else target
    pop, root, meta = load_graph(graph)
    if not isinstance(meta.get("generation"), int):
        raise ValueError(f"{graph}: no generation in its metadata; cannot tell its episodes")
    generation = int(meta["generation"])
    ev = config.evaluation
    chosen = list(tasks) if tasks else list(_subset_of(graph, tuple(ev.tasks)))
    foreign = [t for t in chosen if t not in ev.tasks]
    if foreign:
        raise ValueError(f"task {foreign[0]!r} is not among the run's tasks {', '.join(ev.tasks)}")
    run = tested_run(run_dir)
    single = {}
    if run is not None:
        for t in chosen:
            try:
                single[t] = float(run.row(t, generation)[f"test_{t}"])
            except ValueError:  # not a test point: no denominator
                pass
    seeds = champion_training_seeds(config, generation)
    episodes = ev.test_episodes if test_episodes is None else test_episodes
    table = ev.task_table()
    longest = max(table.spec(t).max_steps for t in chosen)
    try:
        check_evaluation_fits(len(chosen) * max(len(seeds) * redraws, episodes), longest)
    except BudgetError as exc:
        raise BudgetError(str(exc).replace("--episodes:", "--redraws or --episodes:", 1)) from None
    scores = probe_graph(
        pop,
        root,
        chosen,
        seeds,
        episodes,
        test_offset=test_offset,
        noise_seed=noise_seed,
        redraws=redraws,
        no_memory=ev.no_memory,
        workers=workers,
        single=single,
        table=table,
    )
    return Probe(
        target=target,
        graph=graph,
        run_dir=run_dir,
        generation=generation,
        root=root,
        teams=len(pop.reachable(root)),
        train_seeds=tuple(int(s) for s in seeds),
        block=training_block(config, generation),
        resample_interval=ev.resample_interval,
        resample_mean=ev.resample_mean,
        noise_seed=noise_seed,
        redraws=redraws,
        test_episodes=episodes,
        test_offset=test_offset,
        no_memory=ev.no_memory,
        tasks=scores,
    )


def _clean(value: float) -> float | None:
    return None if math.isnan(value) else value


def probe_json(probe: Probe) -> dict[str, Any]:
    """The probe as one JSON-ready object (undefined ratios are null)."""
    tasks = {}
    for t, p in probe.tasks.items():
        raw, norm, single = p.raw(), p.normalised(), p.vs_single()
        tasks[t] = {
            "observes_noise": p.observes_noise,
            **{
                k: {"mean": raw[k], "normalised": norm[k], "vs_single": _clean(single[k])}
                for k in SETS
            },
            "fresh_noise_redraw_means": list(p.redraw_means),
            "fresh_noise_interval": {
                "raw": list(_interval(list(p.redraw_means))),
                "normalised": list(_interval(_redraw_scores(p, "normalised"))),
            },
            "single_task_champion": _clean(p.single),
            "drop": {
                "raw": p.drops(raw),
                "normalised": p.drops(norm),
                "vs_single": {k: _clean(v) for k, v in p.drops(single).items()},
            },
        }
    return {
        "target": str(probe.target),
        "graph": str(probe.graph),
        "run": str(probe.run_dir),
        "generation": probe.generation,
        "root": probe.root,
        "teams": probe.teams,
        "memory": not probe.no_memory,
        "train": {
            "seeds": list(probe.train_seeds),
            "block": probe.block,
            "resample_interval": probe.resample_interval,
            "resample_mean": probe.resample_mean,
        },
        "fresh_noise": {"noise_seed": probe.noise_seed, "redraws": probe.redraws},
        "test": {"episodes": probe.test_episodes, "offset": probe.test_offset},
        "tasks": tasks,
    }


def probe_text(probe: Probe) -> list[str]:
    """The probe as text lines: a header, then normalised scores and mean returns per task."""
    memory = "memory off (as trained)" if probe.no_memory else "memory on (as trained)"
    lines = [
        f"{probe.target}: graph {probe.graph}, generation {probe.generation}, root team "
        f"{probe.root}, {probe.teams} teams; {memory}",
        *probe.describe_sets(),
        "normalised: 0 = random play, 1 = reference best; noise: whether the task observes "
        "the noise input; " + DROPS_TEXT,
        "",
    ]
    head = (
        f"{'task':<22} {'noise':>5} {'(a) train':>10} {'(b) fresh':>10} {'(c) test':>10} "
        f"{'drop noise':>10} {'drop starts':>11} {'(b) 95% CI':>19} {'(b) redraws min..max':>21}"
    )
    for title, pick in (("normalised", "normalised"), ("mean return", "raw")):
        lines.append(f"{title}:")
        lines.append(head)
        for t, p in probe.tasks.items():
            s = p.normalised() if pick == "normalised" else p.raw()
            d = p.drops(s)
            redraws = _redraw_scores(p, pick)
            lo, hi = _interval(redraws)
            lines.append(
                f"{t:<22} {'yes' if p.observes_noise else 'no':>5} {_num(s['train']):>10} "
                f"{_num(s['fresh_noise']):>10} {_num(s['test']):>10} {_num(d['noise']):>10} "
                f"{_num(d['start_states']):>11} {f'[{_num(lo)}, {_num(hi)}]':>19} "
                f"{f'{_num(min(redraws))}..{_num(max(redraws))}':>21}"
            )
        lines.append("")
    return lines[:-1]


def _num(value: float) -> str:
    """A score as the text tables print it: three decimals, "n/a" for a missing one (NaN)."""
    return "n/a" if math.isnan(value) else f"{value:.3f}"


def _interval(values: list[float]) -> tuple[float, float]:
    """The mean of ``values`` -+ 1.96 standard errors (the mean itself for one value)."""
    mean = sum(values) / len(values)
    if len(values) < 2:
        return mean, mean
    var = sum((v - mean) ** 2 for v in values) / (len(values) - 1)
    half = 1.96 * math.sqrt(var / len(values))
    return mean - half, mean + half


def _redraw_scores(p: TaskProbe, pick: str) -> list[float]:
    """Each redraw's mean of (b), raw or normalised."""
    if pick == "raw":
        return list(p.redraw_means)
    return [p.normalise(v) for v in p.redraw_means]


def probe_html(named: list[tuple[str, str, Probe]]) -> str:
    """The report's memorisation section: one row per (experiment, run, probe)."""
    if not named:
        return ""
    first = named[0][2]
    tasks = list(first.tasks)
    head = "".join(f"<th>{html.escape(t)}</th>" for t in tasks)
    rows = ""
    for group, name, probe in named:
        seeds = _seeds(probe.train_seeds)
        if probe.resample_interval > 0:
            seeds = f"block {probe.block}: {seeds}"
        cells = ""
        for t in tasks:
            s = probe.tasks[t].normalised()
            cells += f"<td>{s['train']:.2f} / {s['fresh_noise']:.2f} / {s['test']:.2f}</td>"
        rows += (
            f"<tr><td>{html.escape(group)}</td><td>{html.escape(name)}</td>"
            f"<td>{probe.generation}</td>"
            f"<td>{html.escape(seeds)}</td>{cells}</tr>"
        )
    return (
        "<h2>Memorisation probe: training episodes, fresh noise, held-out episodes</h2>"
        "<p>Each run's all-task champion, normalised (0 = random play, 1 = reference best), "
        "on (a) / (b) / (c): (a) the training episodes it was last trained on (their seeds "
        "in the third column; a block of redrawn episodes in a run with "
        "<code>evaluation.resample_interval</code>), (b) the same start states with only the "
        f"U[0, 1] noise input redrawn {first.redraws} times (noise seed {first.noise_seed}), "
        "(c) the run's held-out test episodes. (a) minus (b) is what the training noise was "
        "worth (exactly 0 where the task does not observe it: "
        + html.escape(", ".join(t for t in tasks if not first.tasks[t].observes_noise) or "none")
        + "); (b) minus (c) what the training start states were worth. "
        "<code>mtpg probe RUN_DIR</code> prints the same with mean returns, the drops and "
        "the spread over redraws.</p>"
        "<table><tr><th>experiment</th><th>run</th><th>generation</th><th>(a) seeds</th>"
        f"{head}</tr>{rows}</table>"
    )
