"""The recorder of a traced run: what :func:`~mtpg.engine.episode_kernels.decide` did, row by row.

The production kernels pass ``rec=None`` and Numba prunes every ``if rec is not None:``
branch, hooks included, from their compiled code (it can because ``rec`` is never
reassigned); the tracer (:mod:`mtpg.engine.trace`) passes a :class:`Recorder`, and the
same ``decide`` and the same episode loop then call the hooks below. So the decision
semantics are compiled from one source.

The buffers have a fixed size for one run. Every hook counts its rows but writes only
those that fit, so a run that needed more is played again with buffers of the counted
size (:func:`record`; runs are deterministic). The first size is the most a run can need
(:func:`decision_bounds` per decision), capped at :data:`FIRST_ROWS` rows per log.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from mtpg.envs.specs.contract import STATE_SIZE
from mtpg.model.instructions import OP_READS, READS_A, READS_B, READS_TARGET

#: Most rows per log a first run is given (a run needing more is played again).
FIRST_ROWS = 1 << 18

#: Slots of ``Recorder.n``: the step being decided, then the rows counted in each log.
STEP, TEAMS, PROGRAMS, INSTRUCTIONS, MEMORY = range(5)
_LOGS = (TEAMS, PROGRAMS, INSTRUCTIONS, MEMORY)


class Recorder(NamedTuple):
    """The buffers of a traced run (see :class:`~mtpg.engine.trace.Trace` for the rows).

    Attributes:
        n: int64 ``[5]``: the step being decided, then the rows counted in the four logs
            (those beyond a log's length were not written).
        team_log: int64 ``(k, 2)``: ``step, team``.
        prog_log: int64 ``(k, 2)``: ``step, program``.
        bids: float64 ``(k)``: the bid of each ``prog_log`` row.
        instr_log: int64 ``(k, 2)``: ``step, instruction``.
        mem_log: int64 ``(k, 5)``: ``step, bank, register, is_write, last_written_step``.
        last_write: int64 ``[n_banks * M]``: step of each memory register's last write (-1:
            none since its bank was reset).
        actions: float64 ``(n, 2)``.
        rewards: float64 ``(n)``.
        memory: float64 ``(n, n_banks * M)`` (no rows unless snapshotted).
        states: float64 ``(n + 1, STATE_SIZE)``.
        observations: float64 ``(n, 2)``.
    """

    n: np.ndarray
    team_log: np.ndarray
    prog_log: np.ndarray
    bids: np.ndarray
    instr_log: np.ndarray
    mem_log: np.ndarray
    last_write: np.ndarray
    actions: np.ndarray
    rewards: np.ndarray
    memory: np.ndarray
    states: np.ndarray
    observations: np.ndarray


def decision_bounds(graph, root: int) -> np.ndarray:
    """Most rows one decision from ``root`` writes to each log: int64 ``[4]``.

    A decision visits each team at most once, so the teams reachable from the root bound
    it: their number, their member programs, those programs' instructions and four
    memory accesses per instruction (three reads and a write at the most).
    """
    seen, todo = {int(root)}, [int(root)]
    teams = programs = instructions = 0
    while todo:
        team = todo.pop()
        teams += 1
        for p in graph.team_members[graph.team_offsets[team] : graph.team_offsets[team + 1]]:
            programs += 1
            instructions += int(graph.prog_offsets[p + 1] - graph.prog_offsets[p])
            act = int(graph.prog_action[p])
            if act >= 0 and act not in seen:
                seen.add(act)
                todo.append(act)
    return np.array([teams, programs, instructions, 4 * instructions], dtype=np.int64)


def new_recorder(
    graph, rows: np.ndarray, steps: int, snapshot: bool, state_width: int = STATE_SIZE
) -> Recorder:
    """Zeroed buffers: ``rows`` per log (teams, programs, instructions, memory), ``steps``.

    ``state_width``: slots of the task state (a set with compiled tasks of users' modules
    has more than the registered tasks' ``STATE_SIZE``).
    """
    n_banks = int(graph.prog_bank.max()) + 1 if len(graph.prog_bank) else 0
    width = n_banks * graph.n_memory
    return Recorder(
        n=np.zeros(5, dtype=np.int64),
        team_log=np.zeros((rows[0], 2), dtype=np.int64),
        prog_log=np.zeros((rows[1], 2), dtype=np.int64),
        bids=np.zeros(rows[1]),
        instr_log=np.zeros((rows[2], 2), dtype=np.int64),
        mem_log=np.zeros((rows[3], 5), dtype=np.int64),
        last_write=np.full(width, -1, dtype=np.int64),
        actions=np.zeros((steps, 2)),
        rewards=np.zeros(steps),
        memory=np.zeros((steps if snapshot else 0, width)),
        states=np.zeros((steps + 1, state_width)),
        observations=np.zeros((steps, 2)),
    )


def record(
    run, graph, root: int, steps: int, snapshot: bool, state_width: int = STATE_SIZE
) -> tuple[Recorder, int]:
    """Runs ``run(rec) -> decisions`` with a recorder, again with larger ones until all fit.

    Args:
        run: Plays the traced run into the recorder it is given; returns its decisions.
        graph: The compiled graph.
        root: Dense index of the root team.
        steps: Decisions expected (the first run's step rows).
        snapshot: Record every bank after each decision.
        state_width: Slots of the task state (:func:`new_recorder`).

    Returns:
        The recorder with every row written, and the number of decisions.
    """
    steps = max(int(steps), 1)
    rows = np.minimum(decision_bounds(graph, root) * steps, FIRST_ROWS)
    while True:
        rec = new_recorder(graph, rows, steps, snapshot, state_width)
        decisions = run(rec)
        counted = rec.n[list(_LOGS)]
        if decisions <= steps and np.all(counted <= rows):
            return rec, decisions
        rows, steps = np.maximum(rows, counted), max(steps, decisions)


@njit(cache=True)
def record_observation(rec: Recorder, t, obs) -> None:
    """Starts decision ``t``: its step, and the observation it sees."""
    rec.n[STEP] = t
    if t < rec.observations.shape[0]:
        rec.observations[t, 0] = obs[0]
        rec.observations[t, 1] = obs[1]


@njit(cache=True)
def _count(rec: Recorder, log: int, cap: int) -> int:
    """Counts a row of log ``log``; its index, or -1 when it does not fit in ``cap`` rows."""
    k = rec.n[log]
    rec.n[log] = k + 1
    return k if k < cap else -1


@njit(cache=True)
def record_team(rec: Recorder, team) -> None:
    """Appends ``[step, team]``: the decision enters ``team``."""
    k = _count(rec, TEAMS, rec.team_log.shape[0])
    if k >= 0:
        rec.team_log[k, 0] = rec.n[STEP]
        rec.team_log[k, 1] = team


@njit(cache=True)
def record_reset(rec: Recorder, bank, M) -> None:
    """Bank ``bank`` was zeroed: none of its registers has been written since."""
    start = np.int64(bank) * M
    rec.last_write[start : start + M] = -1


@njit(cache=True)
def _memory_access(rec: Recorder, cell, M, is_write) -> None:
    """Appends ``[step, bank, register, is_write, last_written_step]`` for memory ``cell``."""
    k = _count(rec, MEMORY, rec.mem_log.shape[0])
    if k >= 0:
        rec.mem_log[k, 0] = rec.n[STEP]
        rec.mem_log[k, 1] = cell // M
        rec.mem_log[k, 2] = cell % M
        rec.mem_log[k, 3] = is_write
        rec.mem_log[k, 4] = rec.last_write[cell]


@njit(cache=True)
def record_instruction(rec: Recorder, i, instr, old, value, base, M) -> None:
    """Instruction ``i`` (row ``instr``) turned its target from ``old`` into ``value``.

    Logs the instruction, then each memory register it read (target, first, second
    operand: those the op reads, :data:`~mtpg.model.instructions.OP_READS`), then its
    memory write: every write of an op that does not read its target, and a
    conditional's (which does) when it changed the value.
    """
    k = _count(rec, INSTRUCTIONS, rec.instr_log.shape[0])
    if k >= 0:
        rec.instr_log[k, 0] = rec.n[STEP]
        rec.instr_log[k, 1] = i
    reads = OP_READS[instr[0]]
    dst, a, b = np.int64(instr[1]), np.int64(instr[2]), np.int64(instr[3])
    for src, bit in ((dst, READS_TARGET), (a, READS_A), (b, READS_B)):
        if reads & bit and src >= base:
            _memory_access(rec, src - base, M, 0)
    if dst >= base and (value != old or not (reads & READS_TARGET)):
        _memory_access(rec, dst - base, M, 1)
        rec.last_write[dst - base] = rec.n[STEP]


@njit(cache=True)
def record_program(rec: Recorder, p, bid) -> None:
    """Appends ``[step, program]`` and the program's bid."""
    k = _count(rec, PROGRAMS, rec.prog_log.shape[0])
    if k >= 0:
        rec.prog_log[k, 0] = rec.n[STEP]
        rec.prog_log[k, 1] = p
        rec.bids[k] = bid


@njit(cache=True)
def record_decision(rec: Recorder, t, a_d, a_c, buf, g, episode) -> None:
    """Decision ``t``'s action and, if snapshotted, every bank as a program sees it.

    A bank not yet reset in episode ``episode`` (stale mark in ``buf.bank_stamp``) reads
    zero, whatever the workspace still holds from an earlier episode.
    """
    if t < rec.actions.shape[0]:
        rec.actions[t, 0] = a_d
        rec.actions[t, 1] = a_c
    if t < rec.memory.shape[0]:
        W, M, base = buf.W, g.n_memory, g.mem_base
        for b in range(len(buf.bank_stamp)):
            live = buf.bank_stamp[b] == episode
            for j in range(M):
                rec.memory[t, b * M + j] = W[base + b * M + j] if live else 0.0


@njit(cache=True)
def record_state(rec: Recorder, t, reward, state) -> None:
    """The task state after ``t`` steps, and the reward of step ``t - 1`` (if ``t > 0``)."""
    if t < rec.states.shape[0]:
        if t > 0:
            rec.rewards[t - 1] = reward
        rec.states[t] = state
