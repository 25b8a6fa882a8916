"""Every task constant as data: the parameter table and the per-task action facts.

``TASK_PARAMS[task]`` is one row per task id (see ``mtpg.envs.core``). Two columns are
common to all tasks:

======  ==================================================================
column  meaning
======  ==================================================================
0       the time limit in steps (equals ``MAX_STEPS[task]``)
1       the force magnitude ``F`` (discrete tasks) or the symmetric bound of
        the continuous action (continuous tasks)
======  ==================================================================

The other columns are task-specific; their names are the column constants of the task
modules (``mtpg.envs.cartpole``, ``acrobot``, ``cartcentering``, ``pendulum`` and
``mountaincar``), and ``docs/envs.md`` lists them. Unused columns are 0.
"""

from __future__ import annotations

import numpy as np

from mtpg.envs import acrobot, cartcentering, cartpole, mountaincar, pendulum
from mtpg.envs.core import TASK_NAMES

#: Common column: the time limit in steps.
P_MAX_STEPS = 0
#: Common column: the discrete force magnitude or the continuous action bound.
P_FORCE = 1

_ROWS: tuple[tuple[float, ...], ...] = (
    cartpole.PARAMS,
    acrobot.PARAMS,
    cartcentering.PARAMS,
    pendulum.PARAMS,
    mountaincar.PARAMS_DISCRETE,
    mountaincar.PARAMS_CONTINUOUS,
)

#: Number of columns of ``TASK_PARAMS``.
N_PARAMS = max(len(r) for r in _ROWS)
#: Number of tasks.
N_TASKS = len(TASK_NAMES)


def _table() -> np.ndarray:
    table = np.zeros((N_TASKS, N_PARAMS), dtype=np.float64)
    for i, row in enumerate(_ROWS):
        table[i, : len(row)] = row
    table.setflags(write=False)
    return table


#: float64 [N_TASKS, N_PARAMS]: every task constant (read-only).
TASK_PARAMS: np.ndarray = _table()

#: int64 [N_TASKS]: time limits in steps (200, 500, 500, 200, 200, 999).
MAX_STEPS: np.ndarray = TASK_PARAMS[:, P_MAX_STEPS].astype(np.int64)

#: bool [N_TASKS]: whether the task reads the continuous action ``a_c`` (else ``a_d``).
USES_CONTINUOUS: np.ndarray = np.array([False, True, False, True, False, True])

#: float64 [N_TASKS]: bound of the continuous action (0 for discrete tasks).
ACTION_BOUND: np.ndarray = np.where(USES_CONTINUOUS, TASK_PARAMS[:, P_FORCE], 0.0)

#: int64 [N_TASKS]: number of physical state variables (slots 0.. of the state array).
STATE_DIMS: np.ndarray = np.array(
    [
        cartpole.STATE_DIM,
        acrobot.STATE_DIM,
        cartcentering.STATE_DIM,
        pendulum.STATE_DIM,
        mountaincar.STATE_DIM,
        mountaincar.STATE_DIM,
    ],
    dtype=np.int64,
)

#: Names of the physical state variables, in Gymnasium's order.
STATE_NAMES: tuple[tuple[str, ...], ...] = (
    ("x", "x_dot", "theta", "theta_dot"),
    ("theta1", "theta2", "dtheta1", "dtheta2"),
    ("x", "v"),
    ("theta", "theta_dot"),
    ("position", "velocity"),
    ("position", "velocity"),
)

#: What the two inputs observe, per task.
OBSERVED: tuple[str, ...] = (
    "x/2.4, theta/0.2094",
    "theta1/pi, theta2/pi",
    "x/1.5, noise",
    "wrap(theta)/pi, noise",
    "2(x+1.2)/1.8-1, noise",
    "2(x+1.2)/1.8-1, noise",
)

#: The action each task reads, and its meaning.
ACTION_USED: tuple[str, ...] = (
    "a_d: +10N/prev/-10N",
    "a_c: torque in [-1,1]",
    "a_d: +1N/prev/-1N",
    "a_c: torque in [-2,2]",
    "a_d: +1/0/-1 push",
    "a_c: force in [-1,1]",
)
