"""The engine's episode loop on a task set with compiled tasks of users' modules.

The scalar episode loop (:func:`mtpg.engine.episode_kernels.run_jobs_queue`) and its
parallel driver are written once; this module compiles them again with the dispatch
generated for the set (:mod:`mtpg.envs.dynamics.user_dispatch`) bound in place of the
registered one, and with the set's state width. The loop's code, and so every decision,
is the same function's: only the names it calls resolve elsewhere. The copies are
compiled on first use in each process (a few seconds) and kept for the process.

The lane engine (:mod:`mtpg.engine.lanes`) is compiled again the same way; it reads two
inputs, so it plays a set whose graphs observe two inputs, and the scalar loop any other.
"""

from __future__ import annotations

import types
from functools import cache
from typing import Any

from numba import njit

from mtpg.engine import episode_kernels, lanes
from mtpg.envs.dynamics.user_dispatch import generate
from mtpg.envs.specs.compiled_task import CompiledTask


def _rebound(fn: Any, names: dict, **options: Any) -> Any:
    """``fn`` (a Numba function) compiled again with some of its global names replaced."""
    py = fn.py_func
    scope = {**py.__globals__, **names}
    copy = types.FunctionType(py.__code__, scope, py.__name__, py.__defaults__, py.__closure__)
    copy.__doc__ = py.__doc__
    return njit(error_model="numpy", **options)(copy)


@cache
def kernels(tasks: tuple[CompiledTask, ...], first_id: int, width: int) -> tuple[Any, Any]:
    """The engine's episode loops and their parallel drivers for a set of compiled tasks.

    Args:
        tasks: The compiled tasks; task ``k`` has id ``first_id + k``.
        first_id: The first task's id.
        width: Slots of the state array (the episode table's start states).

    Returns:
        ``(run_jobs_queue, run_jobs_parallel, run_lanes_queue, run_lanes_parallel)`` with
        the signatures of :mod:`mtpg.engine.episode_kernels` and :mod:`mtpg.engine.lanes`.
    """
    reset, observe, step = generate(tasks, first_id)
    dispatch = {"env_reset": reset, "task_observe": observe, "task_step": step}
    buffers = _rebound(episode_kernels.thread_buffers, {"STATE_SIZE": width})
    queue = _rebound(
        episode_kernels.run_jobs_queue, {**dispatch, "thread_buffers": buffers}, nogil=True
    )
    parallel = _rebound(episode_kernels.run_jobs_parallel, {"run_jobs_queue": queue}, parallel=True)
    lane_queue = _rebound(lanes.run_lanes_queue, {**dispatch, "STATE_SIZE": width}, nogil=True)
    lane_parallel = _rebound(
        lanes.run_lanes_parallel, {"run_lanes_queue": lane_queue}, parallel=True
    )
    return queue, parallel, lane_queue, lane_parallel
