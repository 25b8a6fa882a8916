"""The task contract shared by the environment kernels and the execution engine.

A task is an integer id plus data: one row of a float64 parameter table, a time limit and
the action it reads. Task state lives in a flat float64 array of ``STATE_SIZE`` slots:

======  ================================================================
slot    meaning
======  ================================================================
0..3    the hidden physical state in Gymnasium's order (unused slots 0)
4       the previous force (discrete tasks with a "repeat" action)
5       the number of steps taken in this episode
======  ================================================================
"""

from __future__ import annotations

#: Task names in id order; the id of a task is its index here.
TASK_NAMES: tuple[str, ...] = (
    "CartPole",
    "Acrobot",
    "CartCentering",
    "Pendulum",
    "MountainCar",
    "MountainCarContinuous",
)

CARTPOLE, ACROBOT, CARTCENTERING, PENDULUM, MOUNTAINCAR, MOUNTAINCARCONTINUOUS = range(6)

#: Number of float64 slots of a task state array.
STATE_SIZE = 6
#: Slot holding the previous force.
PREV_FORCE_SLOT = 4
#: Slot holding the number of steps taken.
STEP_SLOT = 5
#: Number of observed inputs of every task.
N_OBS = 2
