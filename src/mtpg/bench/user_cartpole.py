"""CartPole written as a compiled task of a user's module (the contract of docs/own-task.md).

The same dynamics and interface as mtpg's built-in CartPole: two inputs (``x / 2.4`` and
``theta / 0.2094395``, clipped to [-1, 1]) and three actions (push right, repeat the
previous force, push left). Because it draws its start state as the built-in does, a graph
plays the same episodes and returns on ``mtpg.bench.user_cartpole:CARTPOLE`` as on
``CartPole``. Train it with::

    mtpg train --preset demo --tasks mtpg.bench.user_cartpole:CARTPOLE
"""

import numpy as np
from numba import njit

from mtpg import CompiledTask

FORCE, TAU, GRAVITY, MASSCART, MASSPOLE, LENGTH, X_LIMIT, THETA_LIMIT = range(2, 10)


@njit(cache=True)
def observe(p, s, noise, obs):
    """Writes the cart's position and the pole's angle, scaled by their limits."""
    obs[0] = min(max(s[0] / p[X_LIMIT], -1.0), 1.0)
    obs[1] = min(max(s[2] / p[THETA_LIMIT], -1.0), 1.0)


@njit(cache=True)
def step(p, s, a_d, a_c):
    """One explicit-Euler step of Gymnasium's CartPole; s[4] is the previous force."""
    theta = s[2]
    costheta = np.cos(theta)
    sintheta = np.sin(theta)
    if a_d == 0:
        force = p[FORCE]
    elif a_d == 2:
        force = -p[FORCE]
    else:
        force = s[4]
    s[4] = force
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
    s[0] = x + tau * x_dot
    s[1] = x_dot + tau * xacc
    s[2] = theta + tau * theta_dot
    s[3] = theta_dot + tau * thetaacc
    xt, tt = p[X_LIMIT], p[THETA_LIMIT]
    return 1.0, s[0] < -xt or s[0] > xt or s[2] < -tt or s[2] > tt


def sample_start(rng):
    """Gymnasium's CartPole reset draw, and the first 'previous force' (+10 N)."""
    return np.append(rng.uniform(low=-0.05, high=0.05, size=(4,)), 10.0)


CARTPOLE = CompiledTask(
    "CartPoleUser",
    observe,
    step,
    sample_start,
    n_obs=2,
    n_actions=3,
    state_dim=5,
    max_steps=200,
    params=(10.0, 0.02, 9.8, 1.0, 0.1, 0.5, 2.4, 12 * 2 * np.pi / 360),
)
