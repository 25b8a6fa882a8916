"""The memorisation probe: does a champion play its task, or its training episodes?

A champion is chosen on a few training episodes, each a start state and a sequence of
U[0, 1] values that fill the second input of the one-observable tasks (CartCentering,
Pendulum, MountainCar, MountainCarContinuous). Both are fixed by the episode seed, so a
root that replays the same episodes every generation can learn them by heart, the noise
included. The probe scores one graph per task on three sets of episodes:

- **(a) training**: the episodes the champion was last trained on, exactly as the run
  played them: seeds :func:`champion_training_seeds` (``0 .. train_episodes - 1``, or with
  ``evaluation.resample_interval`` the resampled block of the champion's generation);
- **(b) fresh noise**: the same episodes (same start states, same observation noise of a
  variant with ``noise``) with only the U[0, 1] noise input redrawn, ``redraws`` times
  (:func:`fresh_noise_episodes`, from an explicit noise seed);
- **(c) test**: held-out episodes, as the run's test points (``tests.csv``).

``(a) - (b)`` is what the noise input was worth: 0 exactly on a task that does not observe
it (CartPole, Acrobot) or for a graph that never reads it. ``(b) - (c)`` is what the
training start states were worth. Scores are mean returns, also normalised against the
reference best (0 = random play, 1 = reference best) and, given a denominator, against a
single-task champion. Which graph of a run, and its episodes:
:mod:`mtpg.analysis.runs.champion_probe`.
"""

from __future__ import annotations

import zlib
from collections.abc import Sequence
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from mtpg.config import RunConfig
from mtpg.engine.batch import Episodes
from mtpg.engine.compile import compile_population
from mtpg.envs.taskset.episode_seeds import held_out_seeds, resampled_training_seeds
from mtpg.envs.taskset.reference_scores import reference_of
from mtpg.envs.taskset.task_table import TaskTable
from mtpg.evolve.heldout_test import local_evaluate
from mtpg.model.graph import Population

#: First element of the ``SeedSequence`` spawn key of a redrawn noise row (ASCII "nois"):
#: no generator of a run is spawned with it.
NOISE_SPAWN_TAG = 0x6E6F6973
#: Redraws of the noise of every training episode (5 training episodes: 100 per task).
DEFAULT_REDRAWS = 20
#: The three sets of episodes, in order.
SETS = ("train", "fresh_noise", "test")


def observes_noise(task: str) -> bool:
    """Whether a task's second input is the U[0, 1] noise input (one observed variable)."""
    table = TaskTable.from_names([task])
    if table.is_gym(table.ids[0]):  # a Gymnasium task has no noise input
        return False
    if table.is_user(table.ids[0]):  # a compiled task says whether it reads one
        return table.specs[0].noise_input
    return len(table.specs[0].observed_slots) < 2


def training_block(config: RunConfig, generation: int) -> int:
    """The training block a run played at ``generation``: 0 unless resampling is on.

    As the trainer: with ``evaluation.resample_interval = G``, generations 1..G play block
    0, G+1..2G block 1, and so on.

    Args:
        config: The run's configuration.
        generation: A generation of the run (1, 2, ...).

    Returns:
        The block number.
    """
    interval = config.evaluation.resample_interval
    return (max(generation, 1) - 1) // interval if interval > 0 else 0


def champion_training_seeds(config: RunConfig, generation: int) -> np.ndarray:
    """Seeds of the training episodes a champion of ``generation`` was last scored on.

    Every surviving root is scored again when a block starts, so every root alive at
    ``generation`` was last scored on that generation's block (with
    ``evaluation.resample_mean`` its selection score also averages earlier blocks).

    Args:
        config: The run's configuration.
        generation: The generation the champion was chosen at.

    Returns:
        int64 ``[train_episodes]`` seeds.
    """
    ev = config.evaluation
    block = training_block(config, generation)
    return resampled_training_seeds(config.seed, block, ev.train_episodes)


def fresh_noise_episodes(
    tasks: Sequence[str],
    seeds: np.ndarray,
    noise_seed: int,
    redraws: int,
    table: TaskTable | None = None,
) -> Episodes:
    """The episodes ``seeds`` of every task, ``redraws`` times, with the noise row redrawn.

    Row ``(i * redraws + r) * len(seeds) + k`` is task ``tasks[i]`` from the start state of
    seed ``seeds[k]`` (and its observation noise, if any), with ``MAX_STEPS + 1`` fresh
    U[0, 1] values drawn by ``default_rng(SeedSequence(noise_seed, spawn_key=(
    NOISE_SPAWN_TAG, r, crc32(task name), seeds[k])))``: independent of the other tasks,
    redraws and episodes, and of everything a run draws.

    Args:
        tasks: Task names.
        seeds: int64 seeds of the episodes whose start states are kept.
        noise_seed: Seed of the redrawn noise (>= 0).
        redraws: Redraws of every episode's noise (>= 1).
        table: A task table holding ``tasks``; the table of ``tasks`` alone when None.

    Returns:
        The episode table, ``len(tasks) * redraws * len(seeds)`` rows.

    Raises:
        ValueError: If ``noise_seed`` is negative or ``redraws`` < 1.
    """
    if noise_seed < 0:
        raise ValueError(f"noise seed must be >= 0, got {noise_seed}")
    if redraws < 1:
        raise ValueError(f"redraws must be >= 1, got {redraws}")
    seeds = np.asarray(seeds, dtype=np.int64)
    table = TaskTable.from_names(tasks) if table is None else table
    ids = [table.id_of(t) for t in tasks]
    grid = Episodes.grid(ids, np.tile(seeds, redraws), table, training=True)
    noise = np.zeros_like(grid.noise)
    row = 0
    for spec in (table.spec(i) for i in ids):
        if table.is_gym(table.id_of(spec.name)):  # nothing to redraw: (b) replays (a)
            row += redraws * len(seeds)
            continue
        key = zlib.crc32(spec.name.encode("utf-8"))
        width = spec.max_steps + 1
        for r in range(redraws):
            for s in seeds.tolist():
                seq = np.random.SeedSequence(noise_seed, spawn_key=(NOISE_SPAWN_TAG, r, key, s))
                noise[row, :width] = np.random.default_rng(seq).random(width)
                row += 1
    return grid.with_noise(noise)


@dataclass(frozen=True)
class TaskProbe:
    """The probe of one task.

    Attributes:
        task: Task name.
        observes_noise: Whether the task's second input is the noise input.
        train: Mean return on (a), the training episodes.
        fresh_noise: Mean return on (b), every redraw together.
        test: Mean return on (c), the held-out episodes.
        redraw_means: Mean return of each redraw of (b).
        single: The run's single-task champion's test score (NaN: none known).
        random: The random agent's score of the task (its reference scores).
        reference_best: The reference best score of the task.

    (a), (c) and each redraw's mean are means as the trainer and ``tests.csv`` take them;
    (b) is the exact mean of the redraws' means (:func:`exact_mean`), so a task whose
    noise changes nothing has (b) equal to (a) to the last bit.
    """

    task: str
    observes_noise: bool
    train: float
    fresh_noise: float
    test: float
    redraw_means: tuple[float, ...]
    single: float = float("nan")
    random: float = float("nan")
    reference_best: float = float("nan")

    def raw(self) -> dict[str, float]:
        """Mean return per set (:data:`SETS`)."""
        return {"train": self.train, "fresh_noise": self.fresh_noise, "test": self.test}

    def normalise(self, score: float, best: float | None = None) -> float:
        """``(score - random) / (best - random)``, ``best`` the reference best when None.

        Raises:
            ValueError: If ``best`` equals the random score.
        """
        top = self.reference_best if best is None else float(best)
        span = top - self.random
        if span == 0:
            raise ValueError(f"best equals the random score of {self.task}")
        return (float(score) - self.random) / span

    def normalised(self) -> dict[str, float]:
        """Per set: 0 = random play, 1 = reference best."""
        return {k: self.normalise(v) for k, v in self.raw().items()}

    def vs_single(self) -> dict[str, float]:
        """Per set: 0 = random play, 1 = :attr:`single` (NaN where undefined or unknown)."""
        if self.single != self.single:
            return dict.fromkeys(SETS, float("nan"))
        out = {}
        for k, v in self.raw().items():
            try:
                out[k] = self.normalise(v, self.single)
            except ValueError:  # the champion equals random play: undefined
                out[k] = float("nan")
        return out

    def drops(self, scores: dict[str, float]) -> dict[str, float]:
        """``noise`` = (a) - (b), ``start_states`` = (b) - (c), ``total`` = (a) - (c)."""
        a, b, c = (scores[k] for k in SETS)
        return {"noise": a - b, "start_states": b - c, "total": a - c}


def exact_mean(values: np.ndarray) -> float:
    """The mean of ``values`` rounded once from its exact rational value.

    So equal values have their value as mean, whatever their number.
    """
    values = np.asarray(values, dtype=np.float64).ravel()
    return float(sum(map(Fraction, values.tolist())) / len(values))


def probe_graph(
    pop: Population,
    root: int,
    tasks: Sequence[str],
    train_seeds: np.ndarray,
    test_episodes: int,
    *,
    test_offset: int = 0,
    noise_seed: int = 0,
    redraws: int = DEFAULT_REDRAWS,
    no_memory: bool = False,
    workers: int = 1,
    single: dict[str, float] | None = None,
    table: TaskTable | None = None,
) -> dict[str, TaskProbe]:
    """Plays one graph on (a), (b) and (c) of every task (see the module docstring).

    Args:
        pop: The population holding the graph.
        root: Its root team id.
        tasks: Task names.
        train_seeds: Seeds of (a), the training episodes.
        test_episodes: Held-out episodes per task of (c).
        test_offset: Offset of their seeds (0: the run's own test episodes).
        noise_seed: Seed of the redrawn noise of (b).
        redraws: Redraws of the noise of each training episode.
        no_memory: Play with the no-memory ablation semantics (as the graph was trained).
        workers: Threads.
        single: The single-task champions' test scores to normalise against, by task.
        table: A task table holding ``tasks`` (a run's: its given reference scores); the
            table of ``tasks`` alone when None.

    Returns:
        The probe of each task, in the order given.
    """
    tasks = list(tasks)
    if table is None:
        table = TaskTable.from_names(tasks)
    ids = [table.id_of(t) for t in tasks]
    train_seeds = np.asarray(train_seeds, dtype=np.int64)
    play = local_evaluate(workers)
    cp = compile_population(pop, no_memory=no_memory)
    tables = (
        Episodes.grid(ids, train_seeds, table, training=True),
        fresh_noise_episodes(tasks, train_seeds, noise_seed, redraws, table),
        Episodes.grid(ids, held_out_seeds(test_episodes, test_offset), table),
    )
    train, fresh, test = (
        np.asarray(play(cp, [root], table)[0]).reshape(len(tasks), -1) for table in tables
    )
    per_redraw = fresh.reshape(len(tasks), redraws, len(train_seeds))
    return {
        t: TaskProbe(
            t,
            observes_noise(t),
            float(train[i].mean()),
            exact_mean(np.array([row.mean() for row in per_redraw[i]])),
            float(test[i].mean()),
            tuple(float(row.mean()) for row in per_redraw[i]),
            float((single or {}).get(t, float("nan"))),
            reference_of(ids[i], table).random,
            reference_of(ids[i], table).best,
        )
        for i, t in enumerate(tasks)
    }
