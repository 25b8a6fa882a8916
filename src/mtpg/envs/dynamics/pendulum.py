"""Pendulum: Gymnasium's Pendulum-v1 with the paper's interface.

Observed: ``angle_normalize(theta) / pi`` and noise. Action: ``a_c``, torque =
clip(a_c, -2, 2). Gymnasium's reward; never terminates; 200 steps.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from mtpg.envs.dynamics.numeric import clip, clip_obs, continuous_action
from mtpg.envs.specs import registry

# Parameter columns: the spec's ``param_names`` upper-cased, in order (columns 0 and 1 are
# common to all tasks, see ``mtpg.envs.specs.param_table``); checked by
# tests/envs/test_param_columns.py.
(
    MAX_STEPS,
    MAX_TORQUE,
    DT,
    GRAVITY,
    MASS,
    LENGTH,
    MAX_SPEED,
) = range(len(registry.PENDULUM.param_names))

#: Parameter row, in column order (values and their meaning: ``mtpg.envs.specs.registry``).
PARAMS: tuple[float, ...] = registry.PENDULUM.params

STATE_DIM = registry.PENDULUM.state_dim

_PI = math.pi


def sample_start(rng: np.random.Generator) -> np.ndarray:
    """Draws a start state exactly as Gymnasium's ``PendulumEnv.reset``.

    Args:
        rng: The episode's generator.

    Returns:
        The physical state (theta, theta_dot); theta = 0 is upright.
    """
    high = np.array([np.pi, 1.0])
    return rng.uniform(low=-high, high=high)


@njit(cache=True, error_model="numpy")
def angle_normalize(x: float) -> float:
    """Wraps an angle into ``[-pi, pi)`` (Gymnasium's ``angle_normalize``).

    Args:
        x: The angle.

    Returns:
        The wrapped angle.
    """
    return ((x + _PI) % (2 * _PI)) - _PI


@njit(cache=True, error_model="numpy")
def step(p: np.ndarray, s: np.ndarray, a_c: float) -> tuple[float, bool]:
    """Advances the state by one semi-implicit Euler step (v1 clip order).

    Args:
        p: The task's parameter row.
        s: The state array, updated in place.
        a_c: The continuous action (torque before clipping).

    Returns:
        (reward, terminated); terminated is always False.
    """
    u = continuous_action(a_c, p[MAX_TORQUE])
    th = s[0]
    thdot = s[1]
    g = p[GRAVITY]
    m = p[MASS]
    ln = p[LENGTH]
    dt = p[DT]
    an = angle_normalize(th)
    costs = an**2 + 0.1 * thdot**2 + 0.001 * (u**2)
    newthdot = thdot + (3 * g / (2 * ln) * np.sin(th) + 3.0 / (m * ln**2) * u) * dt
    newthdot = clip(newthdot, -p[MAX_SPEED], p[MAX_SPEED])
    s[0] = th + newthdot * dt
    s[1] = newthdot
    return -costs, False


@njit(cache=True, error_model="numpy")
def observe(p: np.ndarray, s: np.ndarray, noise: float, obs: np.ndarray) -> None:
    """Writes the observation (wrapped angle / pi and the noise value).

    Args:
        p: The task's parameter row.
        s: The state array.
        noise: The episode's U[0, 1] noise value for this step.
        obs: Output array of two values in [-1, 1].
    """
    obs[0] = clip_obs(angle_normalize(s[0]) / _PI)
    obs[1] = clip_obs(noise)
