"""The engine's episode loop on a task set with compiled tasks of users' modules.

The scalar episode loop (:func:`mtpg.engine.episode_kernels.run_jobs_queue`) and its
parallel driver are written once; this module compiles them again with the dispatch
generated for the set (:mod:`mtpg.envs.dynamics.user_dispatch`) bound in place of the
registered one, and with the set's state width. The loop's code, and so every decision,
is the same function's: only the names it calls resolve elsewhere. The copies are
compiled on first use in each process (a few seconds) and kept for the process.

The lane engine (:mod:`mtpg.engine.lanes`) is compiled again the same way; it reads the
layout's ``n_obs`` inputs, so it plays every set, whatever its tasks observe.
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
    """``fn`` (a Numba function) compiled again with some of its global names replaced.

    Every name must be one the function reads (a name it does not read would rebind
    nothing: a dispatch call moved into a helper then still calls the registered tasks).
    The copy keeps the original's compile options (``inline``, ``_nrt``, ...), but not
    its cache.
    """
    py = fn.py_func
    missing = set(names) - set(py.__code__.co_names)
    if missing:
        raise AssertionError(f"{py.__name__} reads no global {sorted(missing)}")
    scope = {**py.__globals__, **names}
    copy = types.FunctionType(py.__code__, scope, py.__name__, py.__defaults__, py.__closure__)
    copy.__doc__ = py.__doc__
    kept = {k: v for k, v in fn.targetoptions.items() if k != "nopython"}  # njit's own
    return njit(**{**kept, **options})(copy)


@cache
def kernels(tasks: tuple[CompiledTask, ...], first_id: int, width: int) -> tuple[Any, Any]:
    """The engine's episode loops and their parallel drivers for a set of compiled tasks.

    Every function of the loops that calls the dispatch, or allocates the state, is
    compiled again, and so is every function calling one of those: in the scalar loop
    ``thread_buffers`` and ``run_jobs_queue``; in the lane engine ``lane_buffers``,
    ``start_lanes``, ``step_lanes``, ``play_block`` (which inlines ``step_lanes``) and
    ``run_lanes_queue`` (the decision steps, :mod:`mtpg.engine.lane_decide`, call no
    task).

    Args:
        tasks: The compiled tasks; task ``k`` has id ``first_id + k``.
        first_id: The first task's id.
        width: Slots of the state array (the episode table's start states).

    Returns:
        ``(run_jobs_queue, run_jobs_parallel, run_lanes_queue, run_lanes_parallel)`` with
        the signatures of :mod:`mtpg.engine.episode_kernels` and :mod:`mtpg.engine.lanes`.
    """
    reset, observe, step, continuous = generate(tasks, first_id)
    dispatch = {
        "env_reset": reset,
        "task_observe": observe,
        "task_step": step,
        "task_continuous": continuous,
    }
    buffers = _rebound(episode_kernels.thread_buffers, {"STATE_SIZE": width})
    queue = _rebound(
        episode_kernels.run_jobs_queue, {**dispatch, "thread_buffers": buffers}, nogil=True
    )
    parallel = _rebound(episode_kernels.run_jobs_parallel, {"run_jobs_queue": queue}, parallel=True)
    lane_steps = {
        "lane_buffers": _rebound(lanes.lane_buffers, {"STATE_SIZE": width}),
        "start_lanes": _rebound(lanes.start_lanes, {"env_reset": reset, "task_observe": observe}),
    }
    step_lanes = _rebound(
        lanes.step_lanes,
        {"task_observe": observe, "task_step": step, "task_continuous": continuous},
    )
    lane_steps["play_block"] = _rebound(lanes.play_block, {"step_lanes": step_lanes})
    lane_queue = _rebound(lanes.run_lanes_queue, lane_steps, nogil=True)
    lane_parallel = _rebound(
        lanes.run_lanes_parallel, {"run_lanes_queue": lane_queue}, parallel=True
    )
    return queue, parallel, lane_queue, lane_parallel
