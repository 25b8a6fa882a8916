"""Acrobot: Gymnasium's Acrobot-v1 ("book" dynamics, one RK4 step of 0.2 s), continuous torque.

Observed: ``theta1 / pi`` and ``theta2 / pi``. Action: ``a_c``, torque = clip(a_c, -1, 1).
Reward -1 per step, 0 on the step that reaches the goal.
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
    LINK_LENGTH_1,
    LINK_MASS_1,
    LINK_MASS_2,
    LINK_COM_POS_1,
    LINK_COM_POS_2,
    LINK_MOI,
    GRAVITY,
    MAX_VEL_1,
    MAX_VEL_2,
) = range(len(registry.ACROBOT.param_names))

#: Parameter row, in column order (values and their meaning: ``mtpg.envs.specs.registry``).
PARAMS: tuple[float, ...] = registry.ACROBOT.params

STATE_DIM = registry.ACROBOT.state_dim

_PI = math.pi


def sample_start(rng: np.random.Generator) -> np.ndarray:
    """Draws a start state exactly as Gymnasium's ``AcrobotEnv.reset`` (float32-rounded).

    Args:
        rng: The episode's generator.

    Returns:
        The physical state (theta1, theta2, dtheta1, dtheta2).
    """
    return rng.uniform(low=-0.1, high=0.1, size=(4,)).astype(np.float32).astype(np.float64)


@njit(cache=True, error_model="numpy")
def dsdt(
    p: np.ndarray, theta1: float, theta2: float, dtheta1: float, dtheta2: float, a: float
) -> tuple[float, float, float, float]:
    """The time derivative of the state (Gymnasium's ``_dsdt``, "book" variant).

    Args:
        p: The task's parameter row.
        theta1: Angle of link 1 (0 = hanging down).
        theta2: Angle of link 2 relative to link 1.
        dtheta1: Angular velocity of link 1.
        dtheta2: Angular velocity of link 2.
        a: The torque on the joint.

    Returns:
        (dtheta1, dtheta2, ddtheta1, ddtheta2).
    """
    m1 = p[LINK_MASS_1]
    m2 = p[LINK_MASS_2]
    l1 = p[LINK_LENGTH_1]
    lc1 = p[LINK_COM_POS_1]
    lc2 = p[LINK_COM_POS_2]
    i1 = p[LINK_MOI]
    i2 = p[LINK_MOI]
    g = p[GRAVITY]
    d1 = m1 * lc1**2 + m2 * (l1**2 + lc2**2 + 2 * l1 * lc2 * np.cos(theta2)) + i1 + i2
    d2 = m2 * (lc2**2 + l1 * lc2 * np.cos(theta2)) + i2
    phi2 = m2 * lc2 * g * np.cos(theta1 + theta2 - _PI / 2.0)
    phi1 = (
        -m2 * l1 * lc2 * dtheta2**2 * np.sin(theta2)
        - 2 * m2 * l1 * lc2 * dtheta2 * dtheta1 * np.sin(theta2)
        + (m1 * lc1 + m2 * l1) * g * np.cos(theta1 - _PI / 2)
        + phi2
    )
    ddtheta2 = (a + d2 / d1 * phi1 - m2 * l1 * lc2 * dtheta1**2 * np.sin(theta2) - phi2) / (
        m2 * lc2**2 + i2 - d2**2 / d1
    )
    ddtheta1 = -(d2 * ddtheta2 + phi1) / d1
    return dtheta1, dtheta2, ddtheta1, ddtheta2


@njit(cache=True, error_model="numpy")
def wrap(x: float, m: float, big_m: float) -> float:
    """Wraps ``x`` into ``[m, big_m]`` by whole periods (Gymnasium's ``wrap``).

    Args:
        x: A finite value.
        m: The lower end.
        big_m: The upper end.

    Returns:
        The wrapped value.
    """
    diff = big_m - m
    while x > big_m:
        x = x - diff
    while x < m:
        x = x + diff
    return x


@njit(cache=True, error_model="numpy")
def step(p: np.ndarray, s: np.ndarray, a_c: float) -> tuple[float, bool]:
    """Advances the state by one RK4 step with the torque held constant.

    Args:
        p: The task's parameter row.
        s: The state array, updated in place.
        a_c: The continuous action (torque before clipping).

    Returns:
        (reward, terminated).
    """
    torque = continuous_action(a_c, p[MAX_TORQUE])
    y0, y1, y2, y3 = s[0], s[1], s[2], s[3]
    dt = p[DT]
    dt2 = dt / 2.0
    k10, k11, k12, k13 = dsdt(p, y0, y1, y2, y3, torque)
    k20, k21, k22, k23 = dsdt(
        p, y0 + dt2 * k10, y1 + dt2 * k11, y2 + dt2 * k12, y3 + dt2 * k13, torque
    )
    k30, k31, k32, k33 = dsdt(
        p, y0 + dt2 * k20, y1 + dt2 * k21, y2 + dt2 * k22, y3 + dt2 * k23, torque
    )
    k40, k41, k42, k43 = dsdt(p, y0 + dt * k30, y1 + dt * k31, y2 + dt * k32, y3 + dt * k33, torque)
    c = dt / 6.0
    n0 = y0 + c * (k10 + 2 * k20 + 2 * k30 + k40)
    n1 = y1 + c * (k11 + 2 * k21 + 2 * k31 + k41)
    n2 = y2 + c * (k12 + 2 * k22 + 2 * k32 + k42)
    n3 = y3 + c * (k13 + 2 * k23 + 2 * k33 + k43)
    s[0] = wrap(n0, -_PI, _PI)
    s[1] = wrap(n1, -_PI, _PI)
    s[2] = clip(n2, -p[MAX_VEL_1], p[MAX_VEL_1])
    s[3] = clip(n3, -p[MAX_VEL_2], p[MAX_VEL_2])
    terminated = -np.cos(s[0]) - np.cos(s[1] + s[0]) > 1.0
    return (0.0 if terminated else -1.0), terminated


@njit(cache=True, error_model="numpy")
def observe(p: np.ndarray, s: np.ndarray, noise: float, obs: np.ndarray) -> None:
    """Writes the observation (both joint angles divided by pi).

    Args:
        p: The task's parameter row.
        s: The state array.
        noise: Unused (both inputs are observed).
        obs: Output array of two values in [-1, 1].
    """
    obs[0] = clip_obs(s[0] / _PI)
    obs[1] = clip_obs(s[1] / _PI)
