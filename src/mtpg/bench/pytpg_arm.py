"""pytpg 0.6 beside mtpg: the same task, the same number of environment steps.

pytpg is an independent TPG library; it is never a dependency of mtpg. Install it into the
environment that runs the benchmark (``pip install pytpg==0.6.0``); without it,
:func:`absent_line` says so in one line and the pytpg arm is left out.

The settings are those of pytpg's own CartPole example: graphs of one team of 4 learners,
programs of 4 instructions (at most 16) over 8 registers, tournament selection of 3, its
default mutation, one elite and 2 mutation steps per child; every graph is scored on the
same training episodes in every generation (pytpg's common random numbers). Training runs
generation by generation until the environment steps reach the budget (the generation
that crosses it is the last), so pytpg gets at least as many steps as the mtpg run it is
compared with, and at most one generation more.

pytpg's programs see the raw observation (it does not scale inputs), cannot write memory
(its registers are zeroed at every execution) and act only in a ``Discrete`` space.
"""

from __future__ import annotations

import importlib.util
import time
from collections.abc import Callable
from dataclasses import dataclass, field

#: Training episode ``k`` of every graph resets with this seed plus ``k`` (mtpg's training
#: seeds too); no test seed below 10^9 reaches it.
TRAIN_SEED = 10**9
#: pytpg's own example settings (see the module docstring).
SETTINGS = {
    "register_count": 8,
    "learners_per_team": 4,
    "program_length": 4,
    "max_program_length": 16,
    "tournament": 3,
    "elite_count": 1,
    "mutation_steps": 2,
}


def available() -> bool:
    """Whether pytpg is importable here."""
    return importlib.util.find_spec("pytpg") is not None


def absent_line() -> str:
    """The one line printed where pytpg is not installed."""
    return "pytpg: not installed here, arm left out (pip install pytpg==0.6.0 to add it)"


@dataclass
class PytpgRun:
    """One pytpg training run.

    Attributes:
        curve: ``(environment steps so far, best training return)`` per generation.
        steps: Environment steps of training.
        seconds: Seconds spent in fitness evaluation (decisions and environment steps).
        generations: Generations evaluated (generation 0 included).
        champion: The best graph of the last generation.
    """

    curve: list[tuple[int, float]] = field(default_factory=list)
    steps: int = 0
    seconds: float = 0.0
    generations: int = 0
    champion: object = None

    @property
    def decisions_per_s(self) -> float:
        """Decisions (one per environment step) per second of evaluation."""
        return self.steps / self.seconds if self.seconds else float("nan")


class _CountingFitness:
    """pytpg's ``GymnasiumFitness`` that also counts steps and evaluation seconds."""

    def __init__(self, make_env: Callable, seeds: tuple[int, ...]) -> None:
        from pytpg.adapters.gymnasium_evaluation import (
            GymnasiumEvaluationConfig,
            GymnasiumFitness,
        )

        self.inner = GymnasiumFitness(make_env, GymnasiumEvaluationConfig(seeds, 100_000))
        self.steps = 0
        self.seconds = 0.0

    def __call__(self, graph: object) -> float:
        start = time.perf_counter()
        results = self.inner.evaluate(graph)
        self.seconds += time.perf_counter() - start
        self.steps += sum(r.steps for r in results)
        return sum(r.total_reward for r in results) / len(results)


def _engine(input_size: int, n_actions: int, population: int, rng: object) -> tuple:
    """The initial population and pytpg's evolution engine with :data:`SETTINGS`."""
    from pytpg.evaluation import SequentialEvaluator
    from pytpg.evolution import (
        EvolutionEngine,
        GenomeConfig,
        GenomeFactory,
        GraphInitializer,
        InitializationConfig,
        PopulationInitializer,
        Reproducer,
        ReproductionConfig,
        TournamentSelection,
        default_mutation,
    )

    s = SETTINGS
    genome = GenomeConfig(
        input_size=input_size,
        register_count=s["register_count"],
        n_actions=n_actions,
        max_program_length=s["max_program_length"],
    )
    init = InitializationConfig(
        genome,
        population_size=population,
        learners_per_team=s["learners_per_team"],
        program_length=s["program_length"],
    )
    pop = PopulationInitializer(GraphInitializer(init)).initialize(rng)
    reproducer = Reproducer(
        TournamentSelection(s["tournament"]),
        default_mutation(GenomeFactory(genome)),
        ReproductionConfig(elite_count=s["elite_count"], mutation_steps=s["mutation_steps"]),
    )
    return pop, EvolutionEngine(SequentialEvaluator(), reproducer)


def train(
    make_env: Callable, budget_steps: int, episodes: int, population: int, seed: int
) -> PytpgRun:
    """Trains pytpg until its environment steps reach ``budget_steps``.

    Args:
        make_env: Makes a fresh Gymnasium environment (``Discrete`` actions).
        budget_steps: Environment steps to reach (the mtpg run's).
        episodes: Training episodes per graph and generation.
        population: Graphs in the population.
        seed: Seed of pytpg's numpy Generator.

    Returns:
        The run: its curve, steps, evaluation seconds and champion.
    """
    import numpy as np

    env = make_env()
    input_size = int(np.prod(env.observation_space.shape))
    n_actions = int(env.action_space.n)
    env.close()
    rng = np.random.default_rng(seed)
    pop, engine = _engine(input_size, n_actions, population, rng)
    fitness = _CountingFitness(make_env, tuple(TRAIN_SEED + k for k in range(episodes)))
    result = engine.run(pop, fitness, 0, rng)
    run = PytpgRun()
    while True:
        evaluated = result.evaluations[-1]
        run.generations += 1
        run.curve.append((fitness.steps, float(evaluated.best.fitness)))
        if fitness.steps >= budget_steps:
            break
        result = engine.resume(evaluated, fitness, 1, rng)
    run.steps, run.seconds, run.champion = fitness.steps, fitness.seconds, evaluated.best.graph
    return run


def score(make_env: Callable, graph: object, seeds: list[int]) -> list[float]:
    """Returns of ``graph`` on the episodes that reset with ``seeds``."""
    from pytpg.adapters.gymnasium_evaluation import (
        GymnasiumEvaluationConfig,
        GymnasiumFitness,
    )

    fit = GymnasiumFitness(make_env, GymnasiumEvaluationConfig(tuple(seeds), 100_000))
    return [r.total_reward for r in fit.evaluate(graph)]
