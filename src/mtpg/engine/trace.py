"""Traced execution: what every decision did, for the tests and the analyses of section 6.

The production :func:`~mtpg.engine.episode_kernels.decide` and
:func:`~mtpg.engine.episode_kernels.run_jobs_queue` with a :class:`~mtpg.engine.record.Recorder`
(the training path passes none, and Numba compiles the recording out of it): one compiled
copy of the decision semantics. Per decision it records the teams visited, every program
executed with its bid, every instruction executed, and every memory register read or
written together with the step at which its value was last written (-1: never written
since its bank was reset, it still holds the reset value 0).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from numba import njit

from mtpg.engine.batch import BatchResult, Episodes, Jobs
from mtpg.engine.compile import CompiledPopulation
from mtpg.engine.episode_kernels import decide, run_jobs_queue, thread_buffers
from mtpg.engine.record import (
    INSTRUCTIONS,
    MEMORY,
    PROGRAMS,
    TEAMS,
    Recorder,
    record,
    record_decision,
    record_observation,
)
from mtpg.engine.user_kernels import kernels as user_kernels
from mtpg.envs.dynamics.user_dispatch import USER_STATE_BASE
from mtpg.envs.specs.contract import STATE_SIZE
from mtpg.envs.taskset.task_table import GYM_ID_BASE, USER_ID_BASE


@njit(cache=True, error_model="numpy")
def trace_sequence_kernel(g, root, obs_seq, marks, rec):
    """Decides for each row of ``obs_seq`` from ``root``, recording into ``rec``.

    ``marks[t]`` is the episode mark of step ``t`` (non-decreasing): a new mark starts a
    new episode, so every bank reads zero again (the lazy reset of the batch kernels).
    No task runs: states and rewards stay zero.

    Returns:
        The number of decisions.
    """
    buf = thread_buffers(g)
    for t in range(len(obs_seq)):
        buf.obs[0] = obs_seq[t, 0]
        buf.obs[1] = obs_seq[t, 1]
        record_observation(rec, t, buf.obs)
        a_d, a_c = decide(g, buf, root, t, marks[t], rec)
        record_decision(rec, t, a_d, a_c, buf, g, marks[t])
    return len(obs_seq)


@dataclass(frozen=True)
class Trace:
    """A traced run; ids are dense indices of the :class:`CompiledPopulation`.

    Attributes:
        actions: float64 ``(n, 2)``: ``a_d, a_c`` per decision.
        rewards: float64 ``(n)`` (zeros for an observation sequence).
        team_log: int64 ``(k, 2)``: ``step, team`` for every team visited.
        prog_log: int64 ``(k, 2)``: ``step, program`` for every program executed.
        bids: float64 ``(k)``: the bid of each ``prog_log`` row.
        instr_log: int64 ``(k, 2)``: ``step, instruction`` (index into ``instrs``).
        mem_log: int64 ``(k, 5)``: ``step, bank, register, is_write, last_written_step``.
        memory: float64 ``(n, n_banks * M)``: all banks after each decision (if asked).
        states: float64 ``(n + 1, STATE_SIZE)``: task state before each step and at the end.
        observations: float64 ``(n, 2)``: the inputs ``s(t)`` each decision saw.
    """

    actions: np.ndarray
    rewards: np.ndarray
    team_log: np.ndarray
    prog_log: np.ndarray
    bids: np.ndarray
    instr_log: np.ndarray
    mem_log: np.ndarray
    memory: np.ndarray
    states: np.ndarray
    observations: np.ndarray

    def teams_per_decision(self) -> np.ndarray:
        """Number of teams visited in each decision."""
        return np.bincount(self.team_log[:, 0], minlength=len(self.actions))


def _trace(rec: Recorder, steps: int) -> Trace:
    """The recorded rows of a run of ``steps`` decisions."""
    n = rec.n
    return Trace(
        actions=rec.actions[:steps],
        rewards=rec.rewards[:steps],
        team_log=rec.team_log[: n[TEAMS]],
        prog_log=rec.prog_log[: n[PROGRAMS]],
        bids=rec.bids[: n[PROGRAMS]],
        instr_log=rec.instr_log[: n[INSTRUCTIONS]],
        mem_log=rec.mem_log[: n[MEMORY]],
        memory=rec.memory[:steps],
        states=rec.states[: steps + 1],
        observations=rec.observations[:steps],
    )


def _check_unfolded(cp: CompiledPopulation) -> None:
    """The tracer logs instructions as programs state them: it needs unfolded code."""
    if cp.folded:
        raise ValueError(
            "trace needs code compiled with compile_population(..., fold_constants=False)"
        )


def trace_sequence(
    cp: CompiledPopulation,
    root_id: int,
    observations: np.ndarray,
    no_memory: bool | None = None,
    snapshot: bool = True,
    episode_of_step: np.ndarray | None = None,
) -> Trace:
    """Traces decisions of root ``root_id`` on a fixed observation sequence ``(n, 2)``.

    Args:
        cp: The compiled population.
        root_id: Model id of the root team.
        observations: ``(n, 2)`` the input of each decision.
        no_memory: Deprecated: the ablation is ``cp``'s; a bool overrides it.
        snapshot: Record every bank after each decision.
        episode_of_step: Non-negative, non-decreasing episode marks, one per step (a new
            mark resets memory); default: one episode.

    Returns:
        The trace (states and rewards are zero: no task runs).
    """
    _check_unfolded(cp)
    obs = np.ascontiguousarray(observations, dtype=np.float64).reshape(-1, 2)
    if episode_of_step is None:
        episode_of_step = np.zeros(len(obs), dtype=np.int64)
    marks = np.ascontiguousarray(episode_of_step, dtype=np.int64)
    if len(marks) != len(obs) or np.any(np.diff(marks) < 0) or np.any(marks < 0):
        raise ValueError("episode_of_step must be non-negative, non-decreasing, one per step")
    root = cp.team_index(root_id)
    g = cp.with_memory_mode(no_memory).graph
    rec, steps = record(
        lambda rec: trace_sequence_kernel(g, root, obs, marks, rec),
        g,
        root,
        len(obs),
        snapshot,
    )
    return _trace(rec, steps)


def trace_episode(
    cp: CompiledPopulation,
    root_id: int,
    task: int,
    start: np.ndarray,
    noise: np.ndarray,
    no_memory: bool | None = None,
    snapshot: bool = False,
    obs_noise: np.ndarray | None = None,
    params: np.ndarray | None = None,
    user: tuple = (),
) -> Trace:
    """Traces one episode of ``task`` from ``start`` with the episode's ``noise`` row.

    ``obs_noise``: the episode's rows ``[T + 1, 2]``, for a variant with observation noise;
    ``params``: the parameter table ``task`` indexes (its task table's ``params``; the
    registered tasks' by default); ``user``: the table's compiled tasks of users' modules
    (its ``user``), needed to trace one of them: the engine's own loop compiled for them
    (:mod:`mtpg.engine.user_kernels`) plays the episode, and the trace's ``states`` are
    the task's own slots. ``no_memory`` is deprecated: the ablation is ``cp``'s; a bool
    overrides it.
    """
    _check_unfolded(cp)
    g = cp.with_memory_mode(no_memory).graph
    root = cp.team_index(root_id)
    table = Episodes.single(task, start, noise, obs_noise, params)
    jobs = Jobs(np.array([root], dtype=np.int64), np.zeros(1, dtype=np.int64))
    out = BatchResult.zeros(1)
    queue, width = run_jobs_queue, STATE_SIZE
    if USER_ID_BASE <= task < GYM_ID_BASE:  # the loop compiled for the set's compiled tasks
        if not 0 <= task - USER_ID_BASE < len(user):
            raise ValueError(f"task {task} is a compiled task's id: pass the table's user tasks")
        width = table.starts.shape[1]
        queue = user_kernels(tuple(user), USER_ID_BASE, width)[0]

    def run(rec: Recorder) -> int:
        queue(np.zeros(1, np.int64), 1, jobs, table, out, g, rec)
        return int(out.steps[0])

    rec, steps = record(run, g, root, table.noise.shape[1] - 1, snapshot, width)
    trace = _trace(rec, steps)
    if width == STATE_SIZE:
        return trace
    own = user[task - USER_ID_BASE].state_dim  # the task's own slots (user_dispatch's layout)
    states = trace.states[:, USER_STATE_BASE : USER_STATE_BASE + own]
    return dataclasses.replace(trace, states=np.ascontiguousarray(states))
