"""The generational loop (paper section 4.1): vary, evaluate new roots, select, delete.

The trainer owns the run state and does no I/O: the loop over generations and the
reporters that write metrics, tests, checkpoints and champions from what
:meth:`Trainer.run_generation` returns are in :mod:`mtpg.evolve.reporters`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from mtpg._faults import point
from mtpg.config import EvaluationConfig, RunConfig
from mtpg.engine.batch import Episodes
from mtpg.engine.compile import CompiledPopulation, compile_population
from mtpg.engine.evaluator import Evaluator
from mtpg.envs.taskset.episode_seeds import resampled_training_seeds, validation_seeds
from mtpg.evolve.backend import make_evaluator
from mtpg.evolve.heldout_test import play_test
from mtpg.evolve.lexicase import case_epsilons, lexicase_pick
from mtpg.evolve.selection import candidates, rankings, select, task_subsets
from mtpg.evolve.validation import choose
from mtpg.evolve.variation import Varier, init_population
from mtpg.model.graph import Population

#: Metrics columns that measure time and so differ between otherwise identical runs.
TIMING_COLUMNS = (
    "decisions_per_s",
    "t_variation",
    "t_evaluation",
    "t_selection",
    "t_test",
    "t_total",
)


def held_out_columns(tasks: tuple[str, ...]) -> list[str]:
    """The ``tests.csv`` header for a run on ``tasks``."""
    return ["generation", "subset", "root", "graph_teams", "teams_per_decision"] + [
        f"test_{t}" for t in tasks
    ]


def extra_columns(evaluation: EvaluationConfig | None) -> list[str]:
    """Columns of the settings beyond the paper that are on (none in ``paper``).

    ``validated_roots`` and ``validation_decisions``: roots first measured on the
    validation episodes this generation and the decisions that took (validation on);
    ``reevaluated_roots``: surviving roots evaluated again on redrawn training episodes
    this generation (resampling on; their decisions are in ``decisions``).
    """
    if evaluation is None:
        return []
    cols = []
    if evaluation.validation_episodes > 0:
        cols += ["validated_roots", "validation_decisions"]
    if evaluation.resample_interval > 0:
        cols.append("reevaluated_roots")
    return cols


def metric_columns(tasks: tuple[str, ...], evaluation: EvaluationConfig | None = None) -> list[str]:
    """The ``metrics.csv`` header for a run on ``tasks`` (with ``evaluation``'s extras)."""
    cols = [
        "generation",
        "roots",
        "teams",
        "programs",
        "banks",
        "banks_in_use",
        "programs_per_bank",
        "new_roots",
        "decisions",
        "teams_per_decision",
        "instructions_per_decision",
        "champion_teams",
    ]
    for task in tasks:
        cols += [f"best_{task}", f"median_{task}"]
    return cols + extra_columns(evaluation) + list(TIMING_COLUMNS)


@dataclass
class TrainerState:
    """Everything a run needs to continue exactly as if never interrupted.

    Attributes:
        config: The run configuration.
        generation: Generations completed (0 before initialisation).
        population: Teams, programs and banks.
        scores: Mean training score per active task of every evaluated root.
        elites: Elite root ids of each task subset (``task_subsets`` order).
        champions: Best root id of each task subset.
        rng: The generator of every random draw of the run.
        validation: Mean validation score per active task of every root measured on the
            validation episodes (only with ``evaluation.validation_episodes > 0``).
        returns: Training return of every root per task and episode, ``[n_tasks,
            train_episodes]`` (only with ``team.parent_selection = "lexicase"``).
        blocks: Training blocks each root has played and the sum of its scores on them,
            whose quotient is its score (only with ``evaluation.resample_mean``).
    """

    config: RunConfig
    generation: int
    population: Population
    scores: dict[int, np.ndarray]
    elites: list[list[int]]
    champions: list[int]
    rng: np.random.Generator
    validation: dict[int, np.ndarray] = field(default_factory=dict)
    returns: dict[int, np.ndarray] = field(default_factory=dict)
    blocks: dict[int, tuple[int, np.ndarray]] = field(default_factory=dict)

    @classmethod
    def new(cls, config: RunConfig) -> TrainerState:
        """The state of a run that has not started."""
        rng = np.random.default_rng(np.random.SeedSequence(config.seed))
        return cls(config, 0, Population(), {}, [], [], rng)


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
            self._block = (block, Episodes.grid(self.task_ids, seeds, self.tasks))
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
        return self._metrics(new_roots, result, (t0, t1, t2, t3))

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

    def _metrics(self, new_roots, result, times) -> dict[str, float]:
        st, pop = self.state, self.state.population
        decisions = int(result.steps.sum())
        in_use = pop.banks_in_use()
        scores = np.array([st.scores[r] for r in sorted(st.scores)])
        row: dict[str, float] = {
            "generation": st.generation,
            "roots": len(st.scores),
            "teams": len(pop.teams),
            "programs": len(pop.programs),
            "banks": len(pop.memory_banks),
            "banks_in_use": len(in_use),
            "programs_per_bank": len(pop.programs) / max(len(in_use), 1),
            "new_roots": len(new_roots),
            "decisions": decisions,
            "teams_per_decision": result.teams.sum() / max(decisions, 1),
            "instructions_per_decision": result.instructions.sum() / max(decisions, 1),
            "champion_teams": len(pop.reachable(st.champions[-1])),
        }
        for k, name in enumerate(self.tasks.names):
            row[f"best_{name}"] = float(scores[:, k].max())
            row[f"median_{name}"] = float(np.median(scores[:, k]))
        row.update(self._extra)
        t0, t1, t2, t3 = times
        row.update(
            decisions_per_s=decisions / max(t2 - t1, 1e-9),
            t_variation=t1 - t0,
            t_evaluation=t2 - t1,
            t_selection=t3 - t2,
            t_test=0.0,
            t_total=t3 - t0,
        )
        return row
