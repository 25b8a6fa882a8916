"""Every task constant as arrays, derived from the registry (:mod:`mtpg.envs.registry`).

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

from mtpg.envs.registry import TASKS

#: Common column: the time limit in steps.
P_MAX_STEPS = 0
#: Common column: the discrete force magnitude or the continuous action bound.
P_FORCE = 1

#: Number of columns of ``TASK_PARAMS``.
N_PARAMS = max(len(t.params) for t in TASKS)
#: Number of tasks.
N_TASKS = len(TASKS)


def params_table(rows: tuple[tuple[float, ...], ...]) -> np.ndarray:
    """Stacks parameter rows into a read-only float64 table, unused columns 0.

    Args:
        rows: One parameter row per task.

    Returns:
        float64 ``[len(rows), max(N_PARAMS, longest row)]``.
    """
    table = np.zeros((len(rows), max([N_PARAMS, *map(len, rows)])), dtype=np.float64)
    for i, row in enumerate(rows):
        table[i, : len(row)] = row
    table.setflags(write=False)
    return table


#: float64 [N_TASKS, N_PARAMS]: every task constant (read-only).
TASK_PARAMS: np.ndarray = params_table(tuple(t.params for t in TASKS))

#: int64 [N_TASKS]: time limits in steps (200, 500, 500, 200, 200, 999).
MAX_STEPS: np.ndarray = np.array([t.max_steps for t in TASKS], dtype=np.int64)

#: bool [N_TASKS]: whether the task reads the continuous action ``a_c`` (else ``a_d``).
USES_CONTINUOUS: np.ndarray = np.array([t.continuous for t in TASKS])

#: float64 [N_TASKS]: bound of the continuous action (0 for discrete tasks).
ACTION_BOUND: np.ndarray = np.array([t.bound for t in TASKS], dtype=np.float64)

#: int64 [N_TASKS]: number of physical state variables (slots 0.. of the state array).
STATE_DIMS: np.ndarray = np.array([t.state_dim for t in TASKS], dtype=np.int64)

#: Names of the physical state variables, in Gymnasium's order.
STATE_NAMES: tuple[tuple[str, ...], ...] = tuple(t.state_names for t in TASKS)

#: What the two inputs observe, per task.
OBSERVED: tuple[str, ...] = tuple(t.observed for t in TASKS)

#: The action each task reads, and its meaning.
ACTION_USED: tuple[str, ...] = tuple(t.action_text for t in TASKS)
