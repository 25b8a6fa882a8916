from __future__ import annotations

import numpy as np
import pytest

from mtpg.envs import (
    MAX_STEPS,
    N_OBS,
    STATE_SIZE,
    TASK_NAMES,
    TASK_PARAMS,
    env_observe,
    env_reset,
    env_step,
    make_episodes,
)

TASKS = range(len(TASK_NAMES))


def play(task: int, start: np.ndarray, noise: np.ndarray, seed: int) -> np.ndarray:
    """Runs one episode with seeded random actions; returns the observations and rewards."""
    rng = np.random.default_rng(seed)
    state = np.zeros(STATE_SIZE)
    obs = np.zeros(N_OBS)
    env_reset(task, TASK_PARAMS, start, state)
    env_observe(task, TASK_PARAMS, state, noise[0], obs)
    log = [obs.copy()]
    t = 0
    while True:
        reward, terminated, truncated = env_step(
            task, TASK_PARAMS, state, int(rng.integers(0, 3)), rng.uniform(-2, 2)
        )
        log.append(np.array([reward, terminated, truncated]))
        if terminated or truncated:
            return np.concatenate(log)
        t += 1
        env_observe(task, TASK_PARAMS, state, noise[t], obs)
        log.append(obs.copy())


@pytest.mark.parametrize("task", TASKS)
def test_same_seed_same_episode(task: int) -> None:
    tasks = np.full(5, task)
    seeds = np.arange(40, 45)
    s1, n1 = make_episodes(tasks, seeds)
    s2, n2 = make_episodes(tasks, seeds)
    np.testing.assert_array_equal(s1, s2)
    np.testing.assert_array_equal(n1, n2)
    for i in range(5):
        np.testing.assert_array_equal(play(task, s1[i], n1[i], i), play(task, s2[i], n2[i], i))


@pytest.mark.parametrize("task", TASKS)
def test_different_seeds_different_starts(task: int) -> None:
    starts, noise = make_episodes(np.full(50, task), np.arange(50))
    assert len({tuple(s) for s in starts}) == 50
    assert len({tuple(n[:5]) for n in noise}) == 50


def test_noise_layout() -> None:
    tasks = np.array([0, 5, 2])
    starts, noise = make_episodes(tasks, np.array([1, 2, 3]))
    assert starts.shape == (3, STATE_SIZE)
    assert noise.shape == (3, 1000)
    for i, task in enumerate(tasks):
        k = int(MAX_STEPS[task]) + 1
        assert (noise[i, :k] >= 0).all() and (noise[i, :k] < 1).all()
        assert (noise[i, k:] == 0).all()
    # start, then noise: the same draws as one generator used in that order.
    rng = np.random.default_rng(2)
    rng.uniform(-0.6, -0.4)
    np.testing.assert_array_equal(noise[1, :1000], rng.random(1000))


def test_bad_arguments() -> None:
    with pytest.raises(ValueError):
        make_episodes(np.array([0, 1]), np.array([1]))
    with pytest.raises(ValueError):
        make_episodes(np.array([6]), np.array([1]))
