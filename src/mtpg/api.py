"""The public API: train, resume, load and evaluate runs (what ``import mtpg`` offers).

A thin layer over the modules the commands use (:mod:`mtpg.evolve.session`,
:mod:`mtpg.evolve.trainer`, :mod:`mtpg.evolve.heldout_test`), so a run trained here is the
run ``mtpg train`` makes with the same settings: it resumes with ``mtpg train --resume``
and reports with ``mtpg report``. A score a run cannot give is NaN in the numbers, "n/a"
in text and ``null`` in JSON. Examples: docs/api.md.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from mtpg.api_config import preset
from mtpg.api_evaluation import Evaluation, fmt, score_graph
from mtpg.io.csvrows import read_rows

if TYPE_CHECKING:
    from mtpg.config import RunConfig
    from mtpg.evolve.trainer import Reporter, Trainer
    from mtpg.model import Population
    from mtpg.policy import Policy

__all__ = ["Champion", "Evaluation", "Run", "evaluate", "load", "preset", "resume", "train"]

PathLike = str | os.PathLike[str]
#: Called after each generation with its metrics row and the trainer.
OnGeneration = Callable[[dict[str, float], "Trainer"], None]


@dataclass(frozen=True)
class Champion:
    """A run's all-task champion: the root the run answers with, and its graph.

    Attributes:
        population: The population holding its graph.
        root: Its root team id.
        meta: The graph file's metadata (generation, training scores, ``no_memory``, ...).
        path: The graph file it was read from; None for a run trained without a directory.
    """

    population: Population
    root: int
    meta: dict[str, Any]
    path: Path | None = None

    @property
    def generation(self) -> int:
        """The generation it was chosen at."""
        return int(self.meta.get("generation", 0))

    @property
    def teams(self) -> int:
        """Teams in its graph."""
        return len(self.population.reachable(self.root))


@dataclass
class Run:
    """A training run: settings, one metrics row per generation, test results, champion.

    Made by :func:`train`, :func:`resume` or :func:`load`; nothing here trains.

    Attributes:
        config: The run's configuration.
        path: Its run directory; None for a run trained in memory (``train(config)``).
        metrics: One dict per generation: the columns of ``metrics.csv``.
        tests: One dict per task subset and test point: the columns of ``tests.csv``.
    """

    config: RunConfig
    path: Path | None = None
    metrics: list[dict[str, Any]] = field(default_factory=list)
    tests: list[dict[str, Any]] = field(default_factory=list)
    _champion: Champion | None = field(default=None, repr=False)

    @property
    def tasks(self) -> tuple[str, ...]:
        """The run's task names."""
        return tuple(self.config.evaluation.tasks)

    @property
    def generation(self) -> int:
        """Generations completed (for a run directory: committed, as a resume keeps them)."""
        return int(self.metrics[-1]["generation"]) if self.metrics else 0

    @property
    def finished(self) -> bool:
        """True once every configured generation has run."""
        return self.generation >= self.config.generations

    @property
    def champion(self) -> Champion:
        """The all-task champion, the one ``mtpg evaluate RUN_DIR`` scores.

        For a run directory: the champion at its last test point. For a run trained in
        memory: the champion of its last generation.

        Raises:
            FileNotFoundError: The run has no champion yet (no generation completed).
        """
        if self._champion is None:
            if self.path is None:
                raise FileNotFoundError("the run has no champion yet")
            from mtpg.analysis.runs.champions import run_champion
            from mtpg.io.serialize import load_graph

            graph = run_champion(self.path)
            pop, root, meta = load_graph(graph)
            meta.setdefault("no_memory", self.config.evaluation.no_memory)
            self._champion = Champion(pop, root, meta, graph)
        return self._champion

    def test_scores(self, subset: Iterable[str] | None = None) -> dict[str, float]:
        """Mean test return per task of a subset's champion at the last test point.

        Args:
            subset: Task names (default: all the run's tasks: the all-task champion).

        Returns:
            Scores by task; empty when the run has no test point yet.
        """
        names = "+".join(self.tasks if subset is None else subset)
        rows = [r for r in self.tests if r["subset"] == names]
        if not rows:
            return {}
        last = max(rows, key=lambda r: int(r["generation"]))
        return {t: float(last[f"test_{t}"]) for t in self.tasks}

    def policy(self, task: str | None = None, memory: bool | None = None) -> Policy:
        """The all-task champion as an :class:`mtpg.Policy` acting in ``task``.

        Args:
            task: The task to act in; may be left out where the run has one task.
            memory: None: as evolved (a TPG-NoMemory champion acts without memory).
        """
        from mtpg.policy import Policy

        if task is None:
            if len(self.tasks) != 1:
                raise ValueError(f"name the task to act in (task=...), one of {self.tasks}")
            task = self.tasks[0]
        champ = self.champion
        evolved = bool(champ.meta.get("no_memory", False))
        no_memory = evolved if memory is None else not memory
        return Policy(champ.population, champ.root, task, no_memory=no_memory)

    def evaluate(self, tasks: Sequence[str] | None = None, **options: Any) -> Evaluation:
        """:func:`mtpg.evaluate` of this run (same options)."""
        return evaluate(self, tasks, **options)

    def report(self, out: PathLike | None = None) -> Path:
        """Writes the report of ``mtpg report RUN_DIR``; returns its ``index.html``."""
        from mtpg.analysis.runs.report import build_report

        return build_report([self._directory("report")], out)

    def analyze(self, out: PathLike | None = None, episodes: int = 100) -> Path:
        """Writes the champion's section-6 figures (``mtpg analyze``); returns ``index.html``.

        Args:
            out: Output folder (default: ``analysis/`` in the run directory).
            episodes: Test episodes per task replayed.
        """
        from mtpg._kernel_cache import refresh
        from mtpg.analysis.graph.page import build_analysis

        refresh()
        champ = self.champion
        where = out if out is not None else Path(self._directory("analyze")) / "analysis"
        files = build_analysis(
            champ.population,
            champ.root,
            list(self.tasks),
            where,
            episodes,
            no_memory=bool(champ.meta.get("no_memory", False)),
            run_dir=self.path,
            label=self.path.name if self.path is not None else "graph",
        )
        return files["index"]

    def _directory(self, what: str) -> Path:
        if self.path is None:
            raise ValueError(f"{what}: the run was trained without a run directory (out=None)")
        return self.path

    def __str__(self) -> str:
        where = str(self.path) if self.path is not None else "run in memory"
        state = "finished" if self.finished else "not finished"
        text = (
            f"{where}: generation {self.generation} of {self.config.generations} ({state}); "
            f"tasks: {', '.join(self.tasks)}"
        )
        scores = self.test_scores()
        if scores:
            shown = ", ".join(f"{t} {fmt(v, '.4g')}" for t, v in scores.items())
            text += f"; all-task champion's test score: {shown}"
        return text


def train(
    config: RunConfig,
    out: PathLike | None = None,
    *,
    on_generation: OnGeneration | None = None,
    should_stop: Callable[[], bool] | None = None,
    reporters: Sequence[Reporter] = (),
) -> Run:
    """Trains a run: into a new run directory (as ``mtpg train --out``), or in memory.

    With ``out`` the run is exactly the one ``mtpg train`` makes: checkpoints, champions,
    ``metrics.csv`` and ``tests.csv`` are written as it goes, and a run stopped by
    ``should_stop`` continues with :func:`resume`. Without ``out`` nothing is written and
    the returned run holds the metrics, test results and final champion. No signal
    handling is installed: stop a run by ``should_stop``.

    Args:
        config: The configuration (:func:`preset`).
        out: A new run directory; None trains in memory.
        on_generation: Called with each generation's metrics row and the trainer.
        should_stop: Asked before each generation; True ends the run there (committed).
        reporters: More observers of each generation (:class:`mtpg.evolve.trainer.Reporter`).

    Returns:
        The run, as far as it went.

    Raises:
        ConfigError, RunDirError, BudgetError, LockedError: Bad input; nothing written.
    """
    from mtpg._kernel_cache import refresh

    refresh()  # kernels are about to run: the cache must match the sources
    if out is not None:
        from mtpg.evolve.session import Session

        Session(out, config).run_all(on_generation, should_stop, reporters)
        return load(out)
    return _train_in_memory(config, on_generation, should_stop, reporters)


def resume(
    run_dir: PathLike,
    config: RunConfig | None = None,
    *,
    on_generation: OnGeneration | None = None,
    should_stop: Callable[[], bool] | None = None,
    reporters: Sequence[Reporter] = (),
) -> Run:
    """Continues a run directory from its last checkpoint (``mtpg train --resume``).

    The finished run equals one that was never stopped (all but the timing columns).

    Args:
        run_dir: The run directory.
        config: None, or the stored configuration with only resumable changes
            (:data:`mtpg.evolve.session.RESUMABLE_CHANGES`, e.g. more ``generations``).
        on_generation: As for :func:`train`.
        should_stop: As for :func:`train`.
        reporters: As for :func:`train`.

    Returns:
        The run, as far as it went.
    """
    from mtpg._kernel_cache import refresh
    from mtpg.evolve.session import Session

    refresh()
    Session(run_dir, config, resume=True).run_all(on_generation, should_stop, reporters)
    return load(run_dir)


def _train_in_memory(
    config: RunConfig,
    on_generation: OnGeneration | None,
    should_stop: Callable[[], bool] | None,
    reporters: Sequence[Reporter],
) -> Run:
    """Runs a :class:`Trainer` without a directory, keeping its rows and last champion."""
    from mtpg.evolve.reporters import CallbackReporter, champion_graphs
    from mtpg.evolve.trainer import Reporter, Trainer
    from mtpg.evolve.trainer import train as run_generations
    from mtpg.limits import check_training_fits

    check_training_fits(config)
    run = Run(config)

    class Keep(Reporter):
        def generation(self, gen: Any, trainer: Trainer) -> None:
            run.metrics.append(dict(gen.metrics))
            run.tests.extend(dict(r) for r in gen.tests or ())

    observers: list[Reporter] = [Keep(), *reporters]
    if on_generation is not None:
        observers.append(CallbackReporter(on_generation))
    trainer = Trainer(config)
    try:
        run_generations(trainer, observers, should_stop)
        if trainer.state.generation > 0:
            everything = tuple(config.evaluation.tasks)
            for names, (pop, root, meta) in champion_graphs(trainer).items():
                if len(names) == len(everything):
                    run._champion = Champion(pop, root, {"tasks": list(names), **meta})
    finally:
        trainer.close()
    return run


def evaluate(
    target: Run | PathLike,
    tasks: Sequence[str] | None = None,
    *,
    episodes: int | None = None,
    seed: int = 0,
    workers: int = 1,
    memory: bool | None = None,
) -> Evaluation:
    """Tests a run's all-task champion, or a graph file, on held-out episodes.

    The episodes, seeds and numbers are those of ``mtpg evaluate GRAPH_OR_RUN``.

    Args:
        target: A :class:`Run`, a run directory or a graph ``.json`` file.
        tasks: Task names (default: the run's or the graph file's tasks).
        episodes: Episodes per task (default: a run's ``evaluation.test_episodes``, so
            the numbers equal its test results; 100 for a graph file).
        seed: Offset of the test seeds (episode k of a task uses seed 1,000,000 + seed + k).
        workers: Threads (results do not depend on it).
        memory: None: as evolved (a TPG-NoMemory graph runs without memory); else on/off.

    Returns:
        The scores by task, with ``vs single`` for a run.

    Raises:
        ValueError: Bad episodes, seed or workers, or an unknown task (one line).
        FileNotFoundError: No such run directory or graph file, or no champion yet.
    """
    if not isinstance(target, Run):
        path = Path(target)
        if not path.exists():
            raise FileNotFoundError(f"{path}: no such run directory or graph file")
        if not path.is_dir():
            from mtpg.envs.specs.registry import PAPER_TASKS
            from mtpg.io.serialize import load_graph

            pop, root, meta = load_graph(path)
            names = tasks if tasks is not None else meta.get("tasks", PAPER_TASKS)
            return score_graph(str(path), (pop, root, meta), names, episodes, seed, workers, memory)
        target = load(path)
    champ = target.champion
    return score_graph(
        str(target.path) if target.path is not None else "run in memory",
        (champ.population, champ.root, champ.meta),
        tasks if tasks is not None else target.tasks,
        episodes if episodes is not None else target.config.evaluation.test_episodes,
        seed,
        workers,
        memory,
        target.config.evaluation.references,
        target.tests,
    )


def load(run_dir: PathLike) -> Run:
    """Reads a run directory: configuration, metrics and test results (writes nothing).

    Only committed generations are read (those up to the last checkpoint: what a resume
    keeps), so a run killed between two checkpoints reads as it will resume.

    Raises:
        RunDirError: The directory holds no run (the message says why).
        RunSchemaError: A run of a schema version this mtpg does not read.
        ConfigError: Its ``config.toml`` cannot be read.
    """
    from mtpg.io.checkpoint import checkpoint_generation, latest_checkpoint
    from mtpg.io.runconfig import read_run_config
    from mtpg.io.rundir import TESTS_FILE, RunDir

    folder = RunDir(Path(run_dir))
    config = read_run_config(folder.path)
    last = latest_checkpoint(folder.path)
    committed = (checkpoint_generation(last) or 0) if last is not None else 0

    def kept(rows: list[dict[str, Any]]) -> list[dict[str, Any]]:
        return [r for r in rows if int(r["generation"]) <= committed]

    metrics = kept(read_rows(folder.metrics))
    return Run(config, folder.path, metrics, kept(read_rows(folder.path / TESTS_FILE, ("subset",))))
