"""CartPole: Gymnasium's CartPole dynamics (explicit Euler) with the paper's interface.

Observed: ``x / 2.4`` and ``theta / 0.2094395`` (clipped to [-1, 1]). Action: ``a_d``
(0 -> +10 N, 1 -> repeat the previous force, 2 -> -10 N). Reward +1 per step, the
terminating step included.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from mtpg.envs.dynamics.numeric import bang_bang_force, clip_obs
from mtpg.envs.specs import registry
from mtpg.envs.specs.contract import PREV_FORCE_SLOT

# Parameter columns: the spec's ``param_names`` upper-cased, in order (columns 0 and 1 are
# common to all tasks, see ``mtpg.envs.specs.param_table``); checked by
# tests/envs/test_param_columns.py.
(
    MAX_STEPS,
    FORCE,
    TAU,
    GRAVITY,
    MASSCART,
    MASSPOLE,
    LENGTH,
    X_THRESHOLD,
    THETA_THRESHOLD,
) = range(len(registry.CARTPOLE.param_names))

#: Parameter row, in column order (values and their meaning: ``mtpg.envs.specs.registry``).
PARAMS: tuple[float, ...] = registry.CARTPOLE.params

#: Number of hidden physical state variables (x, x_dot, theta, theta_dot).
STATE_DIM = registry.CARTPOLE.state_dim


def sample_start(rng: np.random.Generator) -> np.ndarray:
    """Draws a start state exactly as Gymnasium's ``CartPoleEnv.reset``.

    Args:
        rng: The episode's generator.

    Returns:
        The physical state (x, x_dot, theta, theta_dot).
    """
    return rng.uniform(low=-0.05, high=0.05, size=(4,))


@njit(cache=True, error_model="numpy")
def step(p: np.ndarray, s: np.ndarray, a_d: int) -> tuple[float, bool]:
    """Advances the state by one step (Gymnasium's operation order).

    Args:
        p: The task's parameter row.
        s: The state array, updated in place.
        a_d: The discrete action.

    Returns:
        (reward, terminated).
    """
    # cos and sin first: values read before a call must be kept across it (spilled to the
    # stack and read back), values read after it need not. The arithmetic is unchanged.
    theta = s[2]
    costheta = np.cos(theta)
    sintheta = np.sin(theta)
    force = bang_bang_force(a_d, s[PREV_FORCE_SLOT], p[FORCE])
    s[PREV_FORCE_SLOT] = force
    x, x_dot, theta_dot = s[0], s[1], s[3]
    masspole = p[MASSPOLE]
    length = p[LENGTH]
    total_mass = masspole + p[MASSCART]
    polemass_length = masspole * length
    tau = p[TAU]
    temp = (force + polemass_length * (theta_dot * theta_dot) * sintheta) / total_mass
    thetaacc = (p[GRAVITY] * sintheta - costheta * temp) / (
        length * (4.0 / 3.0 - masspole * (costheta * costheta) / total_mass)
    )
    xacc = temp - polemass_length * thetaacc * costheta / total_mass
    x = x + tau * x_dot
    x_dot = x_dot + tau * xacc
    theta = theta + tau * theta_dot
    theta_dot = theta_dot + tau * thetaacc
    s[0], s[1], s[2], s[3] = x, x_dot, theta, theta_dot
    xt = p[X_THRESHOLD]
    tt = p[THETA_THRESHOLD]
    terminated = x < -xt or x > xt or theta < -tt or theta > tt
    return 1.0, terminated


@njit(cache=True, error_model="numpy")
def observe(p: np.ndarray, s: np.ndarray, noise: float, obs: np.ndarray) -> None:
    """Writes the observation (x and theta, scaled by their failure thresholds).

    Args:
        p: The task's parameter row.
        s: The state array.
        noise: Unused (both inputs are observed).
        obs: Output array of two values in [-1, 1].
    """
    obs[0] = clip_obs(s[0] / p[X_THRESHOLD])
    obs[1] = clip_obs(s[2] / p[THETA_THRESHOLD])
