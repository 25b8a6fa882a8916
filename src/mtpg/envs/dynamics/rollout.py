"""Compiled episode runners for measurements: pre-drawn actions or a fixed control law."""

from __future__ import annotations

import numpy as np
from numba import njit

from mtpg.envs.dynamics.cartcentering import time_optimal_action
from mtpg.envs.dynamics.dispatch import env_observe, env_reset, env_step
from mtpg.envs.specs.contract import CARTCENTERING, N_OBS, STATE_SIZE


@njit(cache=True, error_model="numpy")
def run_episodes(
    task: int,
    params: np.ndarray,
    starts: np.ndarray,
    noise: np.ndarray,
    a_d: np.ndarray,
    a_c: np.ndarray,
) -> np.ndarray:
    """Plays episodes with pre-drawn actions, following the engine's episode protocol.

    Args:
        task: The task id.
        params: ``TASK_PARAMS``.
        starts: float64 [n, STATE_SIZE] start states.
        noise: float64 [n, >= limit + 1] noise values.
        a_d: int64 [n, >= limit] discrete actions (action t of episode i at [i, t]).
        a_c: float64 [n, >= limit] continuous actions.

    Returns:
        float64 [n]: the return (sum of rewards) of every episode.
    """
    n = starts.shape[0]
    out = np.zeros(n)
    state = np.zeros(STATE_SIZE)
    obs = np.zeros(N_OBS)
    for i in range(n):
        env_reset(task, params, starts[i], state)
        env_observe(task, params, state, noise[i, 0], obs)
        total = 0.0
        t = 0
        while True:
            reward, terminated, truncated = env_step(task, params, state, a_d[i, t], a_c[i, t])
            total += reward
            if terminated or truncated:
                break
            t += 1
            env_observe(task, params, state, noise[i, t], obs)
        out[i] = total
    return out


@njit(cache=True, error_model="numpy")
def run_time_optimal(
    params: np.ndarray, starts: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Plays CartCentering episodes with Koza's time-optimal law on the hidden state.

    Args:
        params: ``TASK_PARAMS``.
        starts: float64 [n, STATE_SIZE] CartCentering start states.

    Returns:
        (returns float64 [n], steps int64 [n], captured bool [n]).
    """
    n = starts.shape[0]
    returns = np.zeros(n)
    steps = np.zeros(n, dtype=np.int64)
    captured = np.zeros(n, dtype=np.bool_)
    state = np.zeros(STATE_SIZE)
    for i in range(n):
        env_reset(CARTCENTERING, params, starts[i], state)
        total = 0.0
        t = 0
        while True:
            a_d = time_optimal_action(state)
            reward, terminated, truncated = env_step(CARTCENTERING, params, state, a_d, 0.0)
            total += reward
            t += 1
            if terminated or truncated:
                captured[i] = terminated and abs(state[0]) <= 1.0
                break
        returns[i] = total
        steps[i] = t
    return returns, steps, captured
