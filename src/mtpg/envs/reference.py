"""Reference scores of the six tasks, the measurements behind them, and normalisation.

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
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from mtpg.envs.core import CARTCENTERING, TASK_NAMES
from mtpg.envs.protocol import (  # noqa: F401  (the seed bases live in protocol)
    N_TEST_EPISODES,
    RANDOM_SEED_BASE,
    TEST_SEED_BASE,
    held_out_seeds,
)

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


class Reference(NamedTuple):
    """Reference figures of one task.

    Attributes:
        random: Mean score of the random agent (see the module docstring).
        random_std: Standard deviation of that score.
        best: Reference best score (Fig. 6 normalisation).
        solved: Registered solved threshold, or NaN when there is none.
        source: Where ``best`` comes from.
    """

    random: float
    random_std: float
    best: float
    solved: float
    source: str


def measure_random(
    task: int,
    n: int = N_RANDOM_EPISODES,
    seed: int = RANDOM_ACTION_SEED,
    seed_base: int = RANDOM_SEED_BASE,
) -> tuple[float, float]:
    """Measures the random agent's mean score (the ``random`` of the normalisation).

    Args:
        task: The task id.
        n: Number of episodes.
        seed: Seed of the action generator.
        seed_base: Episode ``i`` uses episode seed ``seed_base + i``.

    Returns:
        (mean, standard deviation) of the episode returns.
    """
    from mtpg.envs.episodes import make_episodes
    from mtpg.envs.rollout import run_episodes
    from mtpg.envs.tasks import ACTION_BOUND, MAX_STEPS, TASK_PARAMS

    limit = int(MAX_STEPS[task])
    bound = float(ACTION_BOUND[task])
    rng = np.random.default_rng(seed)
    returns = np.zeros(n)
    for lo in range(0, n, _CHUNK):
        m = min(_CHUNK, n - lo)
        starts, noise = make_episodes(np.full(m, task), seed_base + lo + np.arange(m))
        a_d = rng.integers(0, 3, (m, limit))
        a_c = rng.uniform(-bound, bound, (m, limit))
        returns[lo : lo + m] = run_episodes(task, TASK_PARAMS, starts, noise, a_d, a_c)
    return float(returns.mean()), float(returns.std())


def measure_time_optimal_cartcentering(
    seeds: np.ndarray | None = None,
) -> tuple[float, float, int]:
    """Scores Koza's time-optimal law (``-x > v |v|`` -> +F) on CartCentering episodes.

    Args:
        seeds: Episode seeds; the test seeds by default.

    Returns:
        (mean score, mean steps, number of episodes ending by capture).
    """
    from mtpg.envs.episodes import make_episodes
    from mtpg.envs.rollout import run_time_optimal
    from mtpg.envs.tasks import TASK_PARAMS

    seeds = make_test_seeds() if seeds is None else np.asarray(seeds)
    starts, _ = make_episodes(np.full(seeds.shape[0], CARTCENTERING), seeds)
    returns, steps, captured = run_time_optimal(TASK_PARAMS, starts)
    return float(returns.mean()), float(steps.mean()), int(captured.sum())


_NONE = math.nan

# One entry per task id. ``random`` / ``random_std``: measured by this project with
# ``measure_random(task)`` (10,000 episodes, conventions in the module docstring), numpy 2.4,
# numba 0.68. Re-measured by ``tests/envs/test_reference.py`` (slow).
REFERENCE: tuple[Reference, ...] = (
    # CartPole: best = solved = 195, Gym/Gymnasium CartPole-v0 reward_threshold.
    Reference(18.9678, 10.431719089392697, 195.0, 195.0, "CartPole-v0 reward_threshold"),
    # Acrobot: best = solved = -100, Gym/Gymnasium Acrobot-v1 reward_threshold (the paper's
    # D4PG figure could not be traced for Gym's Acrobot; spec/environments.md).
    Reference(-500.0, 0.0, -100.0, -100.0, "Acrobot-v1 reward_threshold"),
    # CartCentering: best = mean score of Koza's time-optimal law under this implementation
    # on the test episodes (seeds 1_000_000..1_000_099), measure_time_optimal_cartcentering();
    # all 100 captured, mean 126.73 steps. No registered threshold.
    Reference(
        -0.9873404751314238,
        0.2377274856515104,
        -0.028608253024208153,
        _NONE,
        "time-optimal law, measured on the test seeds",
    ),
    # Pendulum: best = -123.11 +- 6.86, D4PG (msinto93), the top Pendulum-v0 entry of the
    # OpenAI Gym wiki leaderboard, 100 test episodes. No registered threshold.
    Reference(-1234.575608635256, 289.45830639340454, -123.11, _NONE, "Gym leaderboard, D4PG"),
    # MountainCar: best = solved = -110, Gym/Gymnasium MountainCar-v0 reward_threshold.
    Reference(-200.0, 0.0, -110.0, -110.0, "MountainCar-v0 reward_threshold"),
    # MountainCarContinuous: best = solved = 90, MountainCarContinuous-v0 reward_threshold.
    Reference(
        -33.10653758859584, 4.803512011466331, 90.0, 90.0, "MountainCarContinuous-v0 threshold"
    ),
)

assert len(REFERENCE) == len(TASK_NAMES)


def normalise(
    task: int, score: float | np.ndarray, best: float | None = None
) -> float | np.ndarray:
    """Normalises a score: ``(score - random) / (best - random)``.

    Args:
        task: The task id.
        score: A score, or an array of scores.
        best: The best score to normalise against (e.g. the best single-task agent of the
            run, Figs. 5 and 7); the reference best (Fig. 6) when None.

    Returns:
        0 for random play, 1 for ``best``; same shape as ``score``.

    Raises:
        ValueError: If ``best`` equals the random score.
    """
    ref = REFERENCE[int(task)]
    top = ref.best if best is None else float(best)
    span = top - ref.random
    if span == 0:
        raise ValueError(f"best equals the random score of {TASK_NAMES[int(task)]}")
    if isinstance(score, np.ndarray):
        return (score - ref.random) / span
    return (float(score) - ref.random) / span
