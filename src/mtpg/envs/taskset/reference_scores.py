"""Reference scores of the tasks, the measurements behind them, and normalisation.

``normalise(task, score) = (score - random) / (best - random)`` (paper, Figs. 5-7): 0 is
random play, 1 the reference best.

Conventions (used by the stored figures and by the re-measuring functions):

- Random agent: ``a_d`` uniform on {0, 1, 2} and ``a_c`` uniform on [-bound, bound] each step
  (``ACTION_BOUND``; 0 for discrete tasks, which ignore ``a_c``), over
  ``N_RANDOM_EPISODES`` = 10,000 episodes. Episode ``i`` uses the episode seed
  ``RANDOM_SEED_BASE + i`` (``make_episodes``); the actions come from
  ``np.random.default_rng(RANDOM_ACTION_SEED)``, drawn per block of 1,000 episodes as
  ``a_d = integers(0, 3, (m, T))`` then ``a_c = uniform(-bound, bound, (m, T))``, T the
  time limit.
- Test episodes: seeds ``TEST_SEED_BASE + i`` for i < ``N_TEST_EPISODES`` (1_000_000 ..
  1_000_099). The CartCentering reference best is the mean score of the time-optimal law on
  these episodes.

A variant's reference scores come from its task table (:mod:`mtpg.envs.taskset.task_table`): the
scores given for it there, else its base task's best and a random score measured on the
variant itself. The measurement is a pure function of the variant's name, memoised
(:func:`measured_random`); nothing else is kept between calls.
"""

from __future__ import annotations

from functools import cache

import numpy as np

from mtpg.envs.dynamics.rollout import run_episodes, run_time_optimal
from mtpg.envs.dynamics.user_dispatch import generate
from mtpg.envs.specs.compiled_task import CompiledTask
from mtpg.envs.specs.contract import CARTCENTERING
from mtpg.envs.specs.gym_task import GymTask
from mtpg.envs.specs.gym_task import measure_random as measure_gym_random
from mtpg.envs.specs.param_table import TASK_PARAMS
from mtpg.envs.specs.registry import TASKS
from mtpg.envs.specs.task_spec import NONE, Reference
from mtpg.envs.taskset.episode_seeds import (  # noqa: F401  (the seed bases live in protocol)
    N_TEST_EPISODES,
    RANDOM_SEED_BASE,
    TEST_SEED_BASE,
    held_out_seeds,
)
from mtpg.envs.taskset.episodes import make_episodes
from mtpg.envs.taskset.task_table import REGISTERED, GivenReference, TaskTable

#: Seed of the random agent's action generator.
RANDOM_ACTION_SEED = 12345
#: Episodes of the random-agent measurement.
N_RANDOM_EPISODES = 10_000
_CHUNK = 1000


def make_test_seeds(n: int = N_TEST_EPISODES) -> np.ndarray:
    """The test-episode seeds ``TEST_SEED_BASE + i``, i < n.

    Args:
        n: Number of seeds.

    Returns:
        int64 [n] seeds.
    """
    return held_out_seeds(n)


def measure_random(
    task: int,
    n: int = N_RANDOM_EPISODES,
    seed: int = RANDOM_ACTION_SEED,
    seed_base: int = RANDOM_SEED_BASE,
    table: TaskTable = REGISTERED,
) -> tuple[float, float]:
    """Measures the random agent's mean score (the ``random`` of the normalisation).

    Args:
        task: The task id in ``table`` (a variant's too: its reference scores are measured
            this way).
        n: Number of episodes.
        seed: Seed of the action generator.
        seed_base: Episode ``i`` uses episode seed ``seed_base + i``.
        table: The task table ``task`` belongs to.

    Returns:
        (mean, standard deviation) of the episode returns.
    """
    spec = table.spec(task)
    limit = spec.max_steps
    bound = spec.bound
    rng = np.random.default_rng(seed)
    returns = np.zeros(n)
    for lo in range(0, n, _CHUNK):
        m = min(_CHUNK, n - lo)
        starts, noise = make_episodes(np.full(m, task), seed_base + lo + np.arange(m), table)
        a_d = rng.integers(0, 3, (m, limit))
        a_c = rng.uniform(-bound, bound, (m, limit))
        returns[lo : lo + m] = run_episodes(task, table.params, starts, noise, a_d, a_c)
    return float(returns.mean()), float(returns.std())


@cache
def measured_random(name: str) -> tuple[float, float]:
    """The random agent's (mean, standard deviation) on a variant, measured once per name.

    A pure function of the canonical name (:func:`measure_random` on a table of the
    variant alone), so the memo changes no result.
    """
    table = TaskTable.from_names([name])
    return measure_random(table.ids[0], table=table)


def measure_time_optimal_cartcentering(
    seeds: np.ndarray | None = None,
) -> tuple[float, float, int]:
    """Scores Koza's time-optimal law (``-x > v |v|`` -> +F) on CartCentering episodes.

    Args:
        seeds: Episode seeds; the test seeds by default.

    Returns:
        (mean score, mean steps, number of episodes ending by capture).
    """
    seeds = make_test_seeds() if seeds is None else np.asarray(seeds)
    starts, _ = make_episodes(np.full(seeds.shape[0], CARTCENTERING), seeds)
    returns, steps, captured = run_time_optimal(TASK_PARAMS, starts)
    return float(returns.mean()), float(steps.mean()), int(captured.sum())


#: One entry per task id, from the registry (each spec's ``reference``, with its source
#: in ``mtpg.envs.specs.registry``). ``random`` / ``random_std``: measured by this project with
#: ``measure_random(task)`` (10,000 episodes, conventions in the module docstring).
#: Re-measured by ``tests/envs/test_reference.py`` (slow).
REFERENCE: tuple[Reference, ...] = tuple(t.reference for t in TASKS)


def reference_of(task: int | str, table: TaskTable = REGISTERED) -> Reference:
    """The reference scores of a task or variant of ``table``.

    A registered task's are its spec's. A variant's ``best`` is the one given for it in
    the table (``evaluation.references``) with its source, or else the base task's
    reference best, with the source saying so (the variant's own best is not known; a
    changed time limit may allow more). Its ``random`` / ``random_std`` are the given
    ``random`` (standard deviation unknown: NaN) or else measured by
    :func:`measure_random` on the variant itself (its own dynamics and time limit).

    Args:
        task: A task id or name of ``table``.
        table: The task table (the registered tasks by default).
    """
    spec = table.spec(task)
    if isinstance(spec, GymTask):
        return gym_reference(spec, table.given_reference(spec.name))
    if isinstance(spec, CompiledTask):
        return compiled_reference(spec, table.given_reference(spec.name))
    if not spec.base:
        return spec.reference
    given = table.given_reference(spec.name)
    if given is not None and given.random is not None:
        random = (given.random, NONE)
    else:
        random = measured_random(spec.name)
    how = "random given" if given is not None and given.random is not None else "random measured"
    if given is not None:
        return Reference(*random, given.best, NONE, f"{how}; best given: {given.source}")
    base = table.spec(spec.base).reference
    return Reference(*random, base.best, base.solved, f"{how}; best of {spec.base}: {base.source}")


def gym_reference(task: GymTask, given: GivenReference | None) -> Reference:
    """A Gymnasium task's reference scores (:func:`raw_or_given`)."""
    return raw_or_given(given, lambda: measure_gym_random(task.name))


def compiled_reference(task: CompiledTask, given: GivenReference | None) -> Reference:
    """A compiled task's reference scores (:func:`raw_or_given`)."""
    return raw_or_given(given, lambda: measure_compiled_random(task.name))


def raw_or_given(given: GivenReference | None, measure) -> Reference:
    """Reference scores of a task with no registered best: random play measured, best given.

    ``measure()`` gives the random agent's (mean, std) unless ``given`` holds a random
    score. Without a given best, ``best`` is NaN: scores are reported raw, not normalised.
    """
    if given is not None and given.random is not None:
        random, how = (given.random, NONE), "random given"
    else:
        random, how = measure(), "random measured"
    if given is None:
        return Reference(*random, NONE, NONE, f"{how}; no best given: scores are raw")
    return Reference(*random, given.best, NONE, f"{how}; best given: {given.source}")


#: Episodes of the random-agent measurement of a compiled task of a user's module.
N_COMPILED_RANDOM_EPISODES = 1000


@cache
def measure_compiled_random(name: str, n: int = N_COMPILED_RANDOM_EPISODES) -> tuple[float, float]:
    """The random agent's (mean, standard deviation) on a compiled task, measured once.

    The registered tasks' convention (module docstring) over ``n`` episodes, with ``a_d``
    uniform on the task's ``n_actions`` actions (and each continuous dimension uniform on
    its bound); the episodes step through the task's generated dispatch from Python. A
    pure function of the name (the task's module).
    """
    table = TaskTable.from_names([name])
    task = table.ids[0]
    spec = table.spec(task)
    reset, observe, step, continuous = generate(table.user, task)
    rng = np.random.default_rng(RANDOM_ACTION_SEED)
    starts, noise = make_episodes(np.full(n, task), RANDOM_SEED_BASE + np.arange(n), table)
    a_d = rng.integers(0, max(spec.n_actions, 1), (n, spec.max_steps))
    a_c = rng.uniform(-spec.bound, spec.bound, (n, spec.max_steps))
    # dimensions past the first, drawn after (one-dimensional tasks keep their draws)
    more = rng.uniform(-spec.bound, spec.bound, (n, spec.max_steps, max(spec.n_continuous, 1)))
    more[:, :, 0] = a_c
    zero, one = np.uint64(0), np.uint64(1)
    p = table.params[task]
    state = np.zeros(starts.shape[1])
    obs = np.zeros(spec.n_obs)
    returns = np.zeros(n)
    for i in range(n):
        reset(task, table.params, starts[i], state)
        observe(task, p, state, noise[i, 0], obs)
        for t in range(spec.max_steps):
            if spec.n_continuous > 1:
                continuous(task, p, state, more[i, t], zero, one)
            reward, terminated, truncated = step(task, p, state, a_d[i, t], a_c[i, t])
            returns[i] += reward
            if terminated or truncated:
                break
            observe(task, p, state, noise[i, t + 1], obs)
    return float(returns.mean()), float(returns.std())


def normalise(
    task: int | str,
    score: float | np.ndarray,
    best: float | None = None,
    table: TaskTable = REGISTERED,
) -> float | np.ndarray:
    """Normalises a score: ``(score - random) / (best - random)``.

    Args:
        task: The task id or name in ``table``.
        score: A score, or an array of scores.
        best: The best score to normalise against (e.g. the best single-task agent of the
            run, Figs. 5 and 7); the reference best (Fig. 6) when None.
        table: The task table (the registered tasks by default).

    Returns:
        0 for random play, 1 for ``best``; same shape as ``score``.

    Raises:
        ValueError: If ``best`` equals the random score.
    """
    ref = reference_of(task, table)
    top = ref.best if best is None else float(best)
    span = top - ref.random
    if span == 0:
        raise ValueError(f"best equals the random score of {table.spec(task).name}")
    if isinstance(score, np.ndarray):
        return (score - ref.random) / span
    return (float(score) - ref.random) / span
