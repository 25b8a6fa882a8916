"""The task contract shared by the environment kernels and the execution engine.

A task is an integer id plus data (its :class:`~mtpg.envs.specs.task_spec.TaskSpec` in
:mod:`mtpg.envs.specs.registry`): one row of a float64 parameter table, a time limit and the
action it reads. Task state lives in a flat float64 array of ``STATE_SIZE`` slots:

======  ================================================================
slot    meaning
======  ================================================================
0..3    the hidden physical state in Gymnasium's order (unused slots 0)
4       the previous force (discrete tasks with a "repeat" action)
5       the number of steps taken in this episode
======  ================================================================
"""

from __future__ import annotations

from mtpg.envs.specs.registry import TASK_NAMES, task_id

# The ids the compiled dispatch (mtpg.envs.dynamics.dispatch.task_step) branches on.
CARTPOLE = task_id("CartPole")
ACROBOT = task_id("Acrobot")
CARTCENTERING = task_id("CartCentering")
PENDULUM = task_id("Pendulum")
MOUNTAINCAR = task_id("MountainCar")
MOUNTAINCARCONTINUOUS = task_id("MountainCarContinuous")
#: Number of registered tasks.
N_TASKS = len(TASK_NAMES)

#: Number of float64 slots of a task state array.
STATE_SIZE = 6
#: Slot holding the previous force.
PREV_FORCE_SLOT = 4
#: Slot holding the number of steps taken.
STEP_SLOT = 5
#: Number of observed inputs of every task.
N_OBS = 2
