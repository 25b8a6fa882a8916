"""The compiled task interface the execution engine calls: reset, observe and step.

:func:`task_observe` and :func:`task_step` are the one dispatch on the task id: an if-chain
to the task modules, with a branch per task of the registry (:mod:`mtpg.envs.registry`).
Every kernel (these, the batch kernel of training, the traced kernel) reaches the task
modules through them. An id without a branch observes NaN and ends its episode at once
with a NaN reward, so a task missing from the chain cannot pass for another task
(``tests/envs/test_dispatch.py`` plays every registered task through every kernel). State lives
in a float64 array of ``STATE_SIZE`` slots (see ``mtpg.envs.core``); parameters are
``TASK_PARAMS`` (see ``mtpg.envs.tasks``).

Action conventions: a non-finite ``a_c`` is treated as 0 and then clipped to the task's
bound; an ``a_d`` outside {0, 1, 2} is treated as 1 ("repeat the previous force" in
CartPole and CartCentering, "no push" in MountainCar).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from mtpg.envs import acrobot, cartcentering, cartpole, mountaincar, pendulum
from mtpg.envs.core import (
    ACROBOT,
    CARTCENTERING,
    CARTPOLE,
    MOUNTAINCAR,
    MOUNTAINCARCONTINUOUS,
    PENDULUM,
    PREV_FORCE_SLOT,
    STATE_SIZE,
    STEP_SLOT,
)
from mtpg.envs.tasks import P_FORCE, P_MAX_STEPS


@njit(cache=True, error_model="numpy")
def env_reset(task: int, params: np.ndarray, start: np.ndarray, state: np.ndarray) -> None:
    """Starts an episode: copies the start state and resets the bookkeeping slots.

    Args:
        task: The task id.
        params: ``TASK_PARAMS``.
        start: A start state of ``STATE_SIZE`` slots (from ``sample_start``).
        state: The state array to initialise (``STATE_SIZE`` slots).
    """
    for i in range(STATE_SIZE):
        state[i] = start[i]
    state[PREV_FORCE_SLOT] = params[task, P_FORCE]
    state[STEP_SLOT] = 0.0


@njit(cache=True, error_model="numpy")
def env_observe(
    task: int, params: np.ndarray, state: np.ndarray, noise: float, obs: np.ndarray
) -> None:
    """Writes the two observed inputs, each in [-1, 1].

    Args:
        task: The task id.
        params: ``TASK_PARAMS``.
        state: The current state array.
        noise: The episode's U[0, 1] noise value for this step (used by one-input tasks).
        obs: Output array of at least two slots.
    """
    env_observe_row(task, params[task], state, noise, obs)


@njit(cache=True, error_model="numpy", inline="always")
def task_observe(
    task: int, p: np.ndarray, state: np.ndarray, noise: float, obs: np.ndarray
) -> None:
    """The observation dispatch: writes the two inputs of task ``task``.

    Args:
        task: The task id.
        p: The task's parameter row.
        state: The current state array.
        noise: The episode's U[0, 1] noise value for this step.
        obs: Output array of at least two slots (NaN for an id without a branch).
    """
    if task == CARTPOLE:
        cartpole.observe(p, state, noise, obs)
    elif task == ACROBOT:
        acrobot.observe(p, state, noise, obs)
    elif task == CARTCENTERING:
        cartcentering.observe(p, state, noise, obs)
    elif task == PENDULUM:
        pendulum.observe(p, state, noise, obs)
    elif task == MOUNTAINCAR or task == MOUNTAINCARCONTINUOUS:
        mountaincar.observe(p, state, noise, obs)
    else:
        obs[0] = np.nan
        obs[1] = np.nan


@njit(cache=True, error_model="numpy", inline="always")
def task_step(
    task: int, p: np.ndarray, state: np.ndarray, a_d: int, a_c: float
) -> tuple[float, bool, bool]:
    """The step dispatch: advances task ``task`` by one step in place.

    Inlined into its callers (``inline="always"``), so that the batch kernel's episode
    loop pays no call passing the state and parameter arrays (each such call costs atomic
    reference-count updates).

    Args:
        task: The task id.
        p: The task's parameter row.
        state: The state array, updated in place.
        a_d: The discrete action (read by the discrete tasks).
        a_c: The continuous action (read by the continuous tasks).

    Returns:
        (reward, terminated, truncated); an id without a branch gives (NaN, True, False).
    """
    state[STEP_SLOT] += 1.0
    if task == CARTPOLE:
        reward, terminated = cartpole.step(p, state, a_d)
    elif task == ACROBOT:
        reward, terminated = acrobot.step(p, state, a_c)
    elif task == CARTCENTERING:
        reward, terminated = cartcentering.step(p, state, a_d)
    elif task == PENDULUM:
        reward, terminated = pendulum.step(p, state, a_c)
    elif task == MOUNTAINCAR:
        reward, terminated = mountaincar.step_discrete(p, state, a_d)
    elif task == MOUNTAINCARCONTINUOUS:
        reward, terminated = mountaincar.step_continuous(p, state, a_c)
    else:
        reward, terminated = np.nan, True
    truncated = (not terminated) and state[STEP_SLOT] >= p[P_MAX_STEPS]
    return reward, terminated, truncated


@njit(cache=True, error_model="numpy")
def env_observe_row(
    task: int, p: np.ndarray, state: np.ndarray, noise: float, obs: np.ndarray
) -> None:
    """:func:`env_observe` given the task's parameter row ``p = params[task]``.

    The batch kernel takes the row once per episode: making it (an array view) at every
    step costs reference-count updates.
    """
    task_observe(task, p, state, noise, obs)


@njit(cache=True, error_model="numpy")
def env_step(
    task: int, params: np.ndarray, state: np.ndarray, a_d: int, a_c: float
) -> tuple[float, bool, bool]:
    """Advances the task by one step in place.

    Args:
        task: The task id.
        params: ``TASK_PARAMS``.
        state: The state array, updated in place.
        a_d: The discrete action (read by CartPole, CartCentering, MountainCar).
        a_c: The continuous action (read by Acrobot, Pendulum, MountainCarContinuous).

    Returns:
        (reward, terminated, truncated); truncated is True when the step count reaches the
        task's time limit without termination.
    """
    return task_step(task, params[task], state, a_d, a_c)
