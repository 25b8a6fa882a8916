"""CartCentering: Koza (1992, section 7.1) cart-centering as an episodic control task.

A cart of mass 2 kg on a frictionless track is pushed by a bang-bang force of +-1 N and
must come to rest at the origin. Update (Koza): ``x += tau * v`` then ``v += tau * F / m``,
``v`` clipped to +-6. The episode ends on capture (``|x| <= 0.01`` and ``|v| <= 0.01``),
when ``|x| > 1.5``, or at the time limit (500 steps = 10 s). The reward is 0 on every step
except the last, which gets ``-(|x| / 1.5 + |v| / 12 + 0.1 * t / 500)``, t = steps taken.

Observed: ``x / 1.5`` and noise. Action: ``a_d`` (0 -> +1 N, 1 -> repeat the previous
force, 2 -> -1 N).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from mtpg.envs.dynamics.numeric import bang_bang_force, clip, clip_obs
from mtpg.envs.specs import registry
from mtpg.envs.specs.contract import PREV_FORCE_SLOT, STEP_SLOT

# Parameter columns: the spec's ``param_names`` upper-cased, in order (columns 0 and 1 are
# common to all tasks, see ``mtpg.envs.specs.param_table``); checked by
# tests/envs/test_param_columns.py.
(
    MAX_STEPS,
    FORCE,
    TAU,
    MASS,
    MAX_SPEED,
    X_BOUND,
    CAPTURE,
    START_RANGE,
    TIME_COST,
) = range(len(registry.CARTCENTERING.param_names))

#: Parameter row, in column order (values and their meaning: ``mtpg.envs.specs.registry``).
PARAMS: tuple[float, ...] = registry.CARTCENTERING.params

STATE_DIM = registry.CARTCENTERING.state_dim


def is_captured(x: float, v: float) -> bool:
    """Whether a state lies in the capture box.

    Args:
        x: The position.
        v: The velocity.

    Returns:
        True when ``|x| <= 0.01`` and ``|v| <= 0.01``.
    """
    c = PARAMS[CAPTURE]
    return abs(x) <= c and abs(v) <= c


def sample_start(rng: np.random.Generator) -> np.ndarray:
    """Draws x, v ~ U[-0.75, 0.75], redrawn while the start is already captured.

    Args:
        rng: The episode's generator.

    Returns:
        The physical state (x, v).
    """
    r = PARAMS[START_RANGE]
    while True:
        s = rng.uniform(low=-r, high=r, size=(2,))
        if not is_captured(s[0], s[1]):
            return s


@njit(cache=True, error_model="numpy")
def step(p: np.ndarray, s: np.ndarray, a_d: int) -> tuple[float, bool]:
    """Advances the state by one step; ``s[STEP_SLOT]`` must already count this step.

    Args:
        p: The task's parameter row.
        s: The state array, updated in place.
        a_d: The discrete action.

    Returns:
        (reward, terminated); the terminal penalty is also paid on the time-limit step.
    """
    force = bang_bang_force(a_d, s[PREV_FORCE_SLOT], p[FORCE])
    s[PREV_FORCE_SLOT] = force
    tau = p[TAU]
    vmax = p[MAX_SPEED]
    x = s[0] + tau * s[1]
    v = clip(s[1] + tau * force / p[MASS], -vmax, vmax)
    s[0] = x
    s[1] = v
    cap = p[CAPTURE]
    xb = p[X_BOUND]
    terminated = (abs(x) <= cap and abs(v) <= cap) or abs(x) > xb
    t = s[STEP_SLOT]
    if terminated or t >= p[MAX_STEPS]:
        reward = -(abs(x) / xb + abs(v) / (2.0 * vmax) + p[TIME_COST] * t / p[MAX_STEPS])
        return reward, terminated
    return 0.0, terminated


@njit(cache=True, error_model="numpy")
def observe(p: np.ndarray, s: np.ndarray, noise: float, obs: np.ndarray) -> None:
    """Writes the observation (x / 1.5 and the noise value).

    Args:
        p: The task's parameter row.
        s: The state array.
        noise: The episode's U[0, 1] noise value for this step.
        obs: Output array of two values in [-1, 1].
    """
    obs[0] = clip_obs(s[0] / p[X_BOUND])
    obs[1] = clip_obs(noise)


@njit(cache=True, error_model="numpy")
def time_optimal_action(s: np.ndarray) -> int:
    """Koza's time-optimal bang-bang law on the hidden state: +F iff ``-x > v * |v|``.

    The switching curve ``-x = v |v| / (2 F / m)`` has divisor 1 for F = 1 N, m = 2 kg.

    Args:
        s: The state array.

    Returns:
        The discrete action (0 for +F, 2 for -F).
    """
    x = s[0]
    v = s[1]
    return 0 if -x > v * abs(v) else 2
