"""Every task constant as arrays, derived from the registry (:mod:`mtpg.envs.specs.registry`).

``TASK_PARAMS[task]`` is one row per task id (see ``mtpg.envs.specs.contract``). Two columns are
common to all tasks:

======  ==================================================================
column  meaning
======  ==================================================================
0       the time limit in steps (equals ``MAX_STEPS[task]``)
1       the force magnitude ``F`` (discrete tasks) or the symmetric bound of
        the continuous action (continuous tasks)
======  ==================================================================

The other columns are task-specific; their names are the column constants of the task
modules (``mtpg.envs.dynamics.cartpole``, ``acrobot``, ``cartcentering``, ``pendulum`` and
``mountaincar``), and ``docs/envs.md`` lists them. Unused columns are 0.
"""

from __future__ import annotations

import numpy as np

from mtpg.envs.specs.registry import TASKS

#: Common column: the time limit in steps.
P_MAX_STEPS = 0
#: Common column: the discrete force magnitude or the continuous action bound.
P_FORCE = 1

#: Number of task columns (the longest parameter row of the registry).
N_TASK_COLUMNS = max(len(t.params) for t in TASKS)

# Interface columns, after every task's own: how the row is dispatched and observed.
#: The base task's id: the dispatch of ``mtpg.envs.dynamics.dispatch`` branches on it.
P_KIND = N_TASK_COLUMNS
#: 0: the task's own observation kernel; 1: a variant's observation (columns below).
P_OBS = N_TASK_COLUMNS + 1
#: Two columns: the state slot each input observes (-1: the U[0, 1] noise input).
P_OBS_SLOT = N_TASK_COLUMNS + 2
#: Two columns: the value each observed slot maps to -1.
P_OBS_LO = N_TASK_COLUMNS + 4
#: Two columns: the value each observed slot maps to +1.
P_OBS_HI = N_TASK_COLUMNS + 6
#: Two columns: what is taken of the observed slot before scaling (``OBS_AS_IS``,
#: ``OBS_WRAP``, ``OBS_COS`` or ``OBS_SIN``).
P_OBS_FN = N_TASK_COLUMNS + 8

#: The standard deviation of the Gaussian observation noise added to the inputs that
#: observe the state (0: none), in the inputs' [-1, 1] units.
P_OBS_SD = N_TASK_COLUMNS + 10
#: How many leading inputs observe the state (the others are the U[0, 1] noise input).
P_OBS_NOISY = N_TASK_COLUMNS + 11

#: The value an observed slot's ``P_OBS_LO`` maps to (-1 unless a variant's ``obs_low``).
P_OBS_OUT_LO = N_TASK_COLUMNS + 12
#: The value an observed slot's ``P_OBS_HI`` maps to (+1 unless a variant's ``obs_high``).
P_OBS_OUT_HI = N_TASK_COLUMNS + 13
#: The value the U[0, 1] noise draw 0 maps to (0 unless a variant's ``noise_low``).
P_NOISE_LO = N_TASK_COLUMNS + 14
#: The value the U[0, 1] noise draw 1 maps to (1 unless a variant's ``noise_high``).
P_NOISE_HI = N_TASK_COLUMNS + 15

#: Number of columns of ``TASK_PARAMS``.
N_PARAMS = N_TASK_COLUMNS + 16

#: ``P_OBS_FN`` codes: the slot's value as it is, wrapped into [-pi, pi), or its cosine or
#: sine (an angle observed as ``cos(theta)`` / ``sin(theta)``).
OBS_AS_IS, OBS_WRAP, OBS_COS, OBS_SIN = 0, 1, 2, 3
#: Number of tasks.
N_TASKS = len(TASKS)


def param_row(
    params: tuple[float, ...],
    kind: int,
    observe: tuple[tuple[int, float, float, int], ...] | None = None,
    obs_sd: float = 0.0,
    noisy_inputs: int = 0,
    out_range: tuple[float, float] = (-1.0, 1.0),
    noise_range: tuple[float, float] = (0.0, 1.0),
) -> np.ndarray:
    """One row of the parameter table: the task's columns, then the interface columns.

    Args:
        params: The task's parameter row.
        kind: The id of the task whose kernels play the row.
        observe: None for the task's own observation, else up to two
            ``(slot, low, high, fn)`` inputs (a missing second input is noise; ``fn`` a
            ``P_OBS_FN`` code).
        obs_sd: Standard deviation of the Gaussian observation noise (0: none).
        noisy_inputs: How many leading inputs observe the state (and get that noise).
        out_range: The values an observed slot's ``low`` and ``high`` map to.
        noise_range: The values the U[0, 1] noise draws 0 and 1 map to.

    Returns:
        float64 ``[N_PARAMS]``; unused task columns are 0.
    """
    row = np.zeros(N_PARAMS, dtype=np.float64)
    row[: len(params)] = params
    row[P_KIND] = kind
    if observe is not None:
        row[P_OBS] = 1.0
        row[P_OBS_SLOT : P_OBS_SLOT + 2] = -1.0
        for i, (slot, lo, hi, fn) in enumerate(observe):
            row[P_OBS_SLOT + i] = slot
            row[P_OBS_LO + i] = lo
            row[P_OBS_HI + i] = hi
            row[P_OBS_FN + i] = fn
    row[P_OBS_SD] = obs_sd
    row[P_OBS_NOISY] = noisy_inputs
    row[P_OBS_OUT_LO], row[P_OBS_OUT_HI] = out_range
    row[P_NOISE_LO], row[P_NOISE_HI] = noise_range
    return row


def params_table(rows: list[np.ndarray]) -> np.ndarray:
    """Stacks rows of :func:`param_row` into a read-only float64 table."""
    table = np.array(rows, dtype=np.float64).reshape(len(rows), N_PARAMS)
    table.setflags(write=False)
    return table


#: float64 [N_TASKS, N_PARAMS]: every task constant (read-only); a task table with variants
#: adds their rows (``mtpg.envs.taskset.task_table.TaskTable.params``).
TASK_PARAMS: np.ndarray = params_table([param_row(t.params, i) for i, t in enumerate(TASKS)])

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
