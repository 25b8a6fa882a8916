"""The generational loop (paper section 4.1): vary, evaluate new roots, select, delete.

:class:`Trainer` owns the run state and runs one generation at a time, doing no I/O;
:func:`train` runs the remaining generations and hands each completed one (a
:class:`Generation`) to every :class:`Reporter`, in order, in the spirit of neat-python's
reporters. Metrics rows, test results, champions and checkpoints are reporters
(:mod:`mtpg.evolve.reporters`), and so is the progress display: the library trains without
any run directory when given none, e.g. ``train(Trainer(config), [CallbackReporter(fn)])``.

A generation is a transaction. Reporters see it only once it is complete (varied,
evaluated, selected and, at a test point, tested), and :meth:`Reporter.end` runs only
after a complete generation, when the run is done or asked to stop: never from a
``finally`` with a generation half made.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from mtpg._faults import point
from mtpg.config import RunConfig
from mtpg.engine.batch import Episodes
from mtpg.engine.compile import CompiledPopulation, compile_population
from mtpg.engine.evaluator import Evaluator
from mtpg.envs.taskset.episode_seeds import resampled_training_seeds, validation_seeds
from mtpg.evolve.backend import make_evaluator
from mtpg.evolve.columns import metrics_row
from mtpg.evolve.heldout_test import play_test
from mtpg.evolve.lexicase import case_epsilons, lexicase_pick
from mtpg.evolve.selection import candidates, rankings, select, task_subsets
from mtpg.evolve.state import TrainerState
from mtpg.evolve.validation import choose
from mtpg.evolve.variation import Varier, init_population


class Trainer:
    """Runs generations of multi-task TPG.

    Args:
        config: The run configuration.
        state: A state to continue from (a fresh run when None).
        evaluator: The evaluation backend (:func:`~mtpg.evolve.backend.make_evaluator`
            of ``config`` when None); the trainer closes it.
    """

    def __init__(
        self,
        config: RunConfig,
        state: TrainerState | None = None,
        evaluator: Evaluator | None = None,
    ) -> None:
        self.config = config
        self.state = state or TrainerState.new(config)
        ev = config.evaluation
        self.tasks = ev.task_table()  # resolved once: ids, specs, parameter rows
        self.task_ids = list(self.tasks.ids)
        self.subsets = task_subsets(len(self.task_ids))
        self._block: tuple[int, Episodes] | None = None
        self._extra: dict[str, float] = {}
        self.validation_table = (
            Episodes.grid(self.task_ids, validation_seeds(ev.validation_episodes), self.tasks)
            if ev.validation_episodes > 0
            else None
        )
        self.evaluator = evaluator if evaluator is not None else make_evaluator(config)

    def training_block(self, gen: int) -> int:
        """The training block of generation ``gen``: 0 unless resampling is on.

        With ``evaluation.resample_interval = G``, generations 1..G use block 0 (seeds
        0..n-1, as the paper), G+1..2G block 1, and so on.
        """
        interval = self.config.evaluation.resample_interval
        return (gen - 1) // interval if interval > 0 else 0

    def training_episodes(self, gen: int) -> Episodes:
        """The training episodes of generation ``gen`` (the last block's table is cached)."""
        block = self.training_block(gen)
        if self._block is None or self._block[0] != block:
            ev = self.config.evaluation
            seeds = resampled_training_seeds(self.config.seed, block, ev.train_episodes)
            table = Episodes.grid(self.task_ids, seeds, self.tasks, training=True)
            self._block = (block, table)
        return self._block[1]

    def compile(self) -> CompiledPopulation:
        """The population compiled for the kernels, in the run's memory mode.

        The one place the ablation flag (``evaluation.no_memory``) flows from the config
        into the compiled graph: every evaluation plays what this returns.
        """
        return compile_population(self.state.population, no_memory=self.config.evaluation.no_memory)

    def close(self) -> None:
        """Releases the evaluation backend (a Dask cluster started for the run)."""
        self.evaluator.close()

    @property
    def done(self) -> bool:
        """True when the configured number of generations has run."""
        return self.state.generation >= self.config.generations

    def subset_names(self, k: int) -> tuple[str, ...]:
        """Task names of subset ``k``."""
        return tuple(self.tasks.names[i] for i in self.subsets[k])

    def run_generation(self) -> dict[str, float]:
        """Runs one generation and returns its metrics row.

        Generation 1 creates ``root_size`` random roots; every later generation creates,
        for each task subset, ``n_elite`` children of a parent drawn from that subset's
        elites and one drawn from all roots. Then every new root is evaluated on the
        training episodes of each task, every subset chooses its elites, and every other
        root is deleted, followed by internal teams no longer referenced, programs no
        team holds and banks no program points to; then fresh banks are added until there
        are at least as many banks as teams.

        Beyond the paper: when the generation starts a new training block (resampling
        on), the surviving roots are evaluated again with the children, on the new
        block's episodes; with validation on, the champions are then chosen on the
        validation episodes (:mod:`mtpg.evolve.validation`).
        """
        st, cfg = self.state, self.config
        self.evaluator.check()  # a lost cluster stops the run here, between generations
        gen = st.generation + 1
        self._extra = {}
        t0 = time.perf_counter()
        if gen == 1:
            st.population = init_population(cfg, st.rng)
        else:
            self._vary(gen)
        t1 = time.perf_counter()
        point("evaluate", gen)
        new_roots, result = self._evaluate(gen)
        t2 = time.perf_counter()
        point("select", gen)
        self._select()
        t3 = time.perf_counter()
        st.generation = gen
        return metrics_row(
            gen,
            st.population,
            st.scores,
            st.champions[-1],
            self.tasks.names,
            new_roots,
            result,
            self._extra,
            (t0, t1, t2, t3),
        )

    def held_out_due(self) -> bool:
        """True when the generation just completed is a test point.

        Test points are every ``test_interval`` generations and, whatever the interval, the
        run's last generation, so every run ends with test results of its final champions
        (a 12-generation run with interval 5 is tested at 5, 10 and 12).
        """
        interval = self.config.evaluation.test_interval
        gen = self.state.generation
        return interval > 0 and (gen % interval == 0 or gen == self.config.generations)

    def held_out_scores(self) -> list[dict[str, float | int | str]]:
        """Tests the champion of every task subset on held-out episodes of every task.

        Each distinct champion plays the test (:func:`mtpg.evolve.heldout_test.play_test`):
        ``test_episodes`` held-out episodes of each active task; nothing random is drawn,
        so testing leaves the run unchanged.

        Returns:
            One row per subset (``held_out_columns`` keys), in subset order.
        """
        st, ev = self.state, self.config.evaluation
        roots = sorted(set(st.champions))
        test = play_test(
            self.compile(),
            roots,
            self.task_ids,
            ev.test_episodes,
            evaluate=self.evaluator.evaluate,
            table=self.tasks,
        )
        means, per_decision = test.mean_returns(), test.teams_per_decision()
        rows = []
        for k, root in enumerate(st.champions):
            i = roots.index(root)
            row: dict[str, float | int | str] = {
                "generation": st.generation,
                "subset": "+".join(self.subset_names(k)),
                "root": root,
                "graph_teams": len(st.population.reachable(root)),
                "teams_per_decision": float(per_decision[i]),
            }
            for j, name in enumerate(self.tasks.names):
                row[f"test_{name}"] = float(means[i, j])
            rows.append(row)
        return rows

    def _vary(self, gen: int) -> None:
        st = self.state
        varier = Varier(st.population, self.config, st.rng, gen)
        roots = sorted(st.scores)
        lexicase = self.config.team.parent_selection == "lexicase"
        for k, elites in enumerate(st.elites):
            if k == len(st.elites) // 2:
                point("vary", gen)
            pool = elites or roots
            if lexicase:  # beyond the paper: parent 1 by epsilon-lexicase over episodes
                cases = np.array([st.returns[r][list(self.subsets[k])].ravel() for r in pool])
                eps = case_epsilons(cases)
            for _ in range(self.config.elites_per_subset):
                if lexicase:
                    parent1 = pool[lexicase_pick(cases, eps, st.rng)]
                else:
                    parent1 = pool[int(st.rng.integers(0, len(pool)))]
                parent2 = roots[int(st.rng.integers(0, len(roots)))]
                varier.child(parent1, parent2)

    def _evaluate(self, gen: int):
        st, ev = self.state, self.config.evaluation
        survivors: set[int] = set()
        if ev.resample_interval > 0:
            if gen > 1 and self.training_block(gen) != self.training_block(gen - 1):
                survivors = set(st.scores)
                st.scores.clear()  # new episodes: every surviving root is scored again
            self._extra["reevaluated_roots"] = len(survivors)
        todo = [r for r in st.population.roots() if r not in st.scores]
        cp = self.compile()
        returns, result = self.evaluator.evaluate(cp, todo, self.training_episodes(gen))
        per_episode = returns.reshape(len(todo), len(self.task_ids), ev.train_episodes)
        for root, row in zip(todo, per_episode.mean(axis=2), strict=True):
            if ev.resample_mean and root in survivors:  # the mean over its blocks
                n, total = st.blocks[root]
                st.blocks[root] = (n + 1, total + row)
                st.scores[root] = (total + row) / (n + 1)
                continue
            if ev.resample_mean:
                st.blocks[root] = (1, row)
            st.scores[root] = row
        if self.config.team.parent_selection == "lexicase":
            for root, table in zip(todo, per_episode, strict=True):
                st.returns[root] = table
        new_roots = [r for r in todo if r not in survivors]
        return new_roots, result

    def _select(self) -> None:
        st = self.state
        pop = st.population
        root_ids = np.array(sorted(st.scores), dtype=np.int64)
        scores = np.array([st.scores[int(r)] for r in root_ids])
        st.elites, st.champions = select(
            root_ids, scores, self.subsets, self.config.elites_per_subset
        )
        keep = {r for elites in st.elites for r in elites}
        for rid in root_ids.tolist():
            if rid not in keep:
                del pop.teams[rid]
                del st.scores[rid]
                st.validation.pop(rid, None)
                st.returns.pop(rid, None)
                st.blocks.pop(rid, None)
        while True:  # internal teams whose last referrer died: never agents, deleted
            orphans = [t for t, d in pop.in_degree().items() if d == 0 and t not in keep]
            if not orphans:
                break
            for t in orphans:
                del pop.teams[t]
        pop.prune()  # programs no team holds, then banks no program points to
        pop.top_up_banks(len(pop.teams))  # the bank population: at least one bank per team
        if self.validation_table is not None:
            orders = rankings(root_ids, scores, self.subsets)
            self._validate(
                candidates(root_ids, orders, keep, self.config.evaluation.validation_top_k)
            )

    def _validate(self, cands: list[list[int]]) -> None:
        """Chooses the champions among ``cands`` on the validation episodes."""
        st, ev = self.state, self.config.evaluation
        todo = sorted({r for c in cands for r in c} - set(st.validation))
        decisions = 0
        if todo:
            cp = self.compile()
            returns, result = self.evaluator.evaluate(cp, todo, self.validation_table)
            n_ep = ev.validation_episodes
            means = returns.reshape(len(todo), len(self.task_ids), n_ep).mean(axis=2)
            for root, row in zip(todo, means, strict=True):
                st.validation[root] = row
            decisions = int(result.steps.sum())
        st.champions = choose(cands, st.validation, self.subsets, self.task_ids, self.tasks)
        self._extra.update(validated_roots=len(todo), validation_decisions=decisions)


@dataclass(frozen=True)
class Generation:
    """One completed generation.

    Attributes:
        number: The generation (1-based).
        metrics: Its ``metrics.csv`` row (``metric_columns`` keys).
        tests: Its ``tests.csv`` rows when it was a test point, else None.
    """

    number: int
    metrics: dict[str, float]
    tests: list[dict[str, Any]] | None


class Reporter:
    """Observer of a training run; every method does nothing unless overridden."""

    def start(self, trainer: Trainer) -> None:
        """Called once before the first generation."""

    def generation(self, gen: Generation, trainer: Trainer) -> None:
        """Called after each completed generation, in reporter order."""

    def end(self, trainer: Trainer) -> None:
        """Called when the run is done or stopped at a generation boundary."""


def generations(
    trainer: Trainer, should_stop: Callable[[], bool] | None = None
) -> Iterator[Generation]:
    """Runs generations until the trainer is done or ``should_stop()`` says so.

    ``should_stop`` is asked before each generation, so a stop request is honoured at
    the next generation boundary. Test points are tested (their time enters ``t_test``
    and ``t_total``) before the generation is yielded.
    """
    while not trainer.done and not (should_stop and should_stop()):
        row = trainer.run_generation()
        tests = None
        if trainer.held_out_due():
            start = time.perf_counter()
            tests = trainer.held_out_scores()
            row["t_test"] = time.perf_counter() - start
            row["t_total"] += row["t_test"]
        yield Generation(trainer.state.generation, row, tests)


def train(
    trainer: Trainer,
    reporters: Sequence[Reporter] = (),
    should_stop: Callable[[], bool] | None = None,
) -> bool:
    """Runs the remaining generations, reporting each.

    Args:
        trainer: The trainer (fresh or restored).
        reporters: Observers, called in this order.
        should_stop: Asked before each generation; True stops the run there.

    Returns:
        True when every configured generation has run, False when stopped early.
        An exception raised by a generation or a reporter propagates without
        :meth:`Reporter.end` being called.
    """
    for r in reporters:
        r.start(trainer)
    for gen in generations(trainer, should_stop):
        for r in reporters:
            r.generation(gen, trainer)
    for r in reporters:
        r.end(trainer)
    return trainer.done
