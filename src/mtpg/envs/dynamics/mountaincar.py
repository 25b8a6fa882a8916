"""MountainCar and MountainCarContinuous: Gymnasium's dynamics with the paper's interface.

Observed (both): ``2 * (x + 1.2) / 1.8 - 1`` and noise.

- MountainCar: ``a_d`` (0 -> push +1, 1 -> no push, 2 -> push -1); -1 per step; 200 steps.
- MountainCarContinuous: ``a_c``, force = clip(a_c, -1, 1); each step ``-0.1 * f**2`` with
  the *clipped* force (Gymnasium penalises the raw action), plus 100 on reaching the goal;
  999 steps.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from mtpg.envs.dynamics.numeric import clip_obs, continuous_action
from mtpg.envs.specs import registry

# Parameter columns: the spec's ``param_names`` upper-cased, in order (columns 0 and 1 are
# common to all tasks, see ``mtpg.envs.specs.param_table``); checked by
# tests/envs/test_param_columns.py.
(
    MAX_STEPS,
    FORCE,
    GRAVITY,
    MIN_POSITION,
    MAX_POSITION,
    MAX_SPEED,
    GOAL_POSITION,
    GOAL_VELOCITY,
    GOAL_REWARD,
    ACTION_COST,
    POWER,
) = range(len(registry.MOUNTAINCAR.param_names))

#: Parameter row of MountainCar, in column order.
PARAMS_DISCRETE: tuple[float, ...] = registry.MOUNTAINCAR.params

#: Parameter row of MountainCarContinuous, in column order.
PARAMS_CONTINUOUS: tuple[float, ...] = registry.MOUNTAINCARCONTINUOUS.params

STATE_DIM = registry.MOUNTAINCAR.state_dim


def sample_start(rng: np.random.Generator) -> np.ndarray:
    """Draws a start state exactly as Gymnasium's ``MountainCarEnv.reset``.

    Args:
        rng: The episode's generator.

    Returns:
        The physical state (position, velocity).
    """
    return np.array([rng.uniform(low=-0.6, high=-0.4), 0])


@njit(cache=True, error_model="numpy")
def _finish(p: np.ndarray, s: np.ndarray, position: float, velocity: float) -> bool:
    """Applies the position bounds and the inelastic left wall; returns goal reached."""
    if position > p[MAX_POSITION]:
        position = p[MAX_POSITION]
    if position < p[MIN_POSITION]:
        position = p[MIN_POSITION]
    if position == p[MIN_POSITION] and velocity < 0:
        velocity = 0.0
    s[0] = position
    s[1] = velocity
    return position >= p[GOAL_POSITION] and velocity >= p[GOAL_VELOCITY]


@njit(cache=True, error_model="numpy")
def step_discrete(p: np.ndarray, s: np.ndarray, a_d: int) -> tuple[float, bool]:
    """Advances MountainCar by one step (Gymnasium's operation order).

    Args:
        p: The task's parameter row.
        s: The state array, updated in place.
        a_d: The discrete action; values outside {0, 2} mean no push.

    Returns:
        (reward, terminated).
    """
    direction = 1.0 if a_d == 0 else (-1.0 if a_d == 2 else 0.0)
    position = s[0]
    # Gymnasium: ``velocity += (action - 1) * force + cos(3 x) * (-gravity)``.
    velocity = s[1] + (direction * p[FORCE] + math.cos(3 * position) * (-p[GRAVITY]))
    vmax = p[MAX_SPEED]
    if velocity > vmax:
        velocity = vmax
    if velocity < -vmax:
        velocity = -vmax
    position += velocity
    return -1.0, _finish(p, s, position, velocity)


@njit(cache=True, error_model="numpy")
def step_continuous(p: np.ndarray, s: np.ndarray, a_c: float) -> tuple[float, bool]:
    """Advances MountainCarContinuous by one step (Gymnasium's operation order).

    Args:
        p: The task's parameter row.
        s: The state array, updated in place.
        a_c: The continuous action (force before clipping).

    Returns:
        (reward, terminated); the action cost uses the clipped force.
    """
    force = continuous_action(a_c, p[FORCE])
    position = s[0]
    velocity = s[1] + (force * p[POWER] - p[GRAVITY] * math.cos(3 * position))
    vmax = p[MAX_SPEED]
    if velocity > vmax:
        velocity = vmax
    if velocity < -vmax:
        velocity = -vmax
    position += velocity
    terminated = _finish(p, s, position, velocity)
    reward = 0.0
    if terminated:
        reward = p[GOAL_REWARD]
    reward -= force * force * p[ACTION_COST]
    return reward, terminated


@njit(cache=True, error_model="numpy")
def observe(p: np.ndarray, s: np.ndarray, noise: float, obs: np.ndarray) -> None:
    """Writes the observation (position scaled to [-1, 1] and the noise value).

    Args:
        p: The task's parameter row.
        s: The state array.
        noise: The episode's U[0, 1] noise value for this step.
        obs: Output array of two values in [-1, 1].
    """
    lo = p[MIN_POSITION]
    obs[0] = clip_obs(2.0 * (s[0] - lo) / (p[MAX_POSITION] - lo) - 1.0)
    obs[1] = clip_obs(noise)
