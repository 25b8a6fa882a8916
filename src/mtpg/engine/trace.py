"""Traced execution: what every decision did, for the tests and the analyses of section 6.

A separate kernel from :mod:`mtpg.engine.kernels`, so tracing costs the untraced path
nothing. Per decision it records the teams visited, every program executed with its bid,
every instruction executed, and every memory register read or written together with the
step at which its value was last written (-1: never written in this episode, it still
holds the reset value 0).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from mtpg.engine.compile import CompiledPopulation
from mtpg.engine.kernels import new_workspace
from mtpg.engine.ops import apply_op
from mtpg.envs import env_observe, env_reset, env_step
from mtpg.envs.core import STATE_SIZE
from mtpg.envs.tasks import TASK_PARAMS
from mtpg.envs.variants import task_params
from mtpg.model.instructions import CONDITIONAL_OPS, N_CONSTANTS, UNARY_OPS

_FIRST_UNARY = min(UNARY_OPS)
_LAST_UNARY = max(UNARY_OPS)
_FIRST_COND = min(CONDITIONAL_OPS)


@njit(cache=True)
def _grow_int(buf: np.ndarray, n: int) -> np.ndarray:
    """Returns ``buf`` or a copy with twice the rows when row ``n`` does not fit."""
    if n < buf.shape[0]:
        return buf
    out = np.empty((buf.shape[0] * 2, buf.shape[1]), dtype=buf.dtype)
    out[: buf.shape[0]] = buf
    return out


@njit(cache=True)
def _grow_float(buf: np.ndarray, n: int) -> np.ndarray:
    """1-D float version of :func:`_grow_int`."""
    if n < buf.shape[0]:
        return buf
    out = np.empty(buf.shape[0] * 2)
    out[: buf.shape[0]] = buf
    return out


@njit(cache=True)
def _log_mem(buf, n, t, cell, M, is_write, last_write):  # noqa: N803
    """Appends row ``n`` = ``[t, bank, register, is_write, last_written_step]``."""
    buf = _grow_int(buf, n)
    buf[n, 0] = t
    buf[n, 1] = cell // M
    buf[n, 2] = cell % M
    buf[n, 3] = is_write
    buf[n, 4] = last_write[cell]
    return buf


@njit(cache=True, error_model="numpy")
def trace_kernel(
    root,
    task,
    params,
    start,
    noise,
    obs_seq,
    no_memory,
    snapshot,
    team_offsets,
    team_members,
    prog_offsets,
    instrs,
    prog_action,
    prog_bank,
    R,
    M,
    base,
):  # noqa: N803, C901
    """Runs one traced episode (``task >= 0``) or an observation sequence (``task < 0``).

    Returns:
        ``actions (n, 2)``, ``rewards (n)``, ``team_log (k, 2)`` [step, team],
        ``prog_log (k, 2)`` [step, program], ``bids (k)``, ``instr_log (k, 2)``
        [step, instruction], ``mem_log (k, 5)`` [step, bank, register, is_write,
        last_written_step], ``memory (n, n_banks * M)`` after each step (empty unless
        ``snapshot``), ``states (n + 1, STATE_SIZE)``, ``observations (n, 2)``.
    """
    n_teams = len(team_offsets) - 1
    n_banks = (prog_bank.max() + 1) if len(prog_bank) else 0
    W = new_workspace(base + n_banks * M, R)  # noqa: N806
    obs = W[R + N_CONSTANTS : R + N_CONSTANTS + 2]
    last_write = np.full(n_banks * M, -1, dtype=np.int64)
    visited = np.zeros(n_teams, dtype=np.bool_)
    state = np.zeros(STATE_SIZE)
    max_steps = len(obs_seq) if task < 0 else len(noise) - 1
    actions = np.zeros((max_steps, 2))
    rewards = np.zeros(max_steps)
    states = np.zeros((max_steps + 1, STATE_SIZE))
    observations = np.zeros((max_steps, 2))
    memory = np.zeros((max_steps if snapshot else 0, n_banks * M))
    team_log = np.empty((64, 2), dtype=np.int64)
    prog_log = np.empty((64, 2), dtype=np.int64)
    bids = np.empty(64)
    instr_log = np.empty((64, 2), dtype=np.int64)
    mem_log = np.empty((64, 5), dtype=np.int64)
    n_team = n_prog = n_instr = n_mem = 0
    if task >= 0:
        env_reset(task, params, start, state)
        env_observe(task, params, state, noise[0], obs)
        states[0] = state
    t = 0
    while t < max_steps:
        if task < 0:
            obs[0] = obs_seq[t, 0]
            obs[1] = obs_seq[t, 1]
        observations[t, 0] = obs[0]
        observations[t, 1] = obs[1]
        visited[:] = False
        team = root
        while True:
            visited[team] = True
            team_log = _grow_int(team_log, n_team)
            team_log[n_team, 0] = t
            team_log[n_team, 1] = team
            n_team += 1
            best_p = -1
            best = 0.0
            for k in range(team_offsets[team], team_offsets[team + 1]):
                p = team_members[k]
                bank = prog_bank[p]
                if no_memory:
                    W[base + bank * M : base + (bank + 1) * M] = 0.0
                    last_write[bank * M : (bank + 1) * M] = -1
                W[:R] = 0.0
                for i in range(prog_offsets[p], prog_offsets[p + 1]):
                    op = instrs[i, 0]
                    dst, a, b = (
                        np.int64(instrs[i, 1]),
                        np.int64(instrs[i, 2]),
                        np.int64(instrs[i, 3]),
                    )
                    instr_log = _grow_int(instr_log, n_instr)
                    instr_log[n_instr, 0] = t
                    instr_log[n_instr, 1] = i
                    n_instr += 1
                    cond = op >= _FIRST_COND
                    unary = _FIRST_UNARY <= op <= _LAST_UNARY
                    for src in (dst if cond else np.int64(-1), np.int64(-1) if unary else a, b):
                        if src >= base:
                            mem_log = _log_mem(mem_log, n_mem, t, src - base, M, 0, last_write)
                            n_mem += 1
                    value = apply_op(op, W[dst], W[a], W[b])
                    written = value != W[dst] or not cond
                    W[dst] = value
                    if dst >= base and written:
                        mem_log = _log_mem(mem_log, n_mem, t, dst - base, M, 1, last_write)
                        n_mem += 1
                        last_write[dst - base] = t
                prog_log = _grow_int(prog_log, n_prog)
                bids = _grow_float(bids, n_prog)
                prog_log[n_prog, 0] = t
                prog_log[n_prog, 1] = p
                bids[n_prog] = W[0]
                n_prog += 1
                act = prog_action[p]
                if (act < 0 or not visited[act]) and (best_p < 0 or W[0] > best):
                    best = W[0]
                    best_p = p
            act = prog_action[best_p]
            if act < 0:
                actions[t, 0] = -1 - act
                actions[t, 1] = W[base + prog_bank[best_p] * M]
                break
            team = act
        if snapshot:
            memory[t] = W[base:]
        t += 1
        if task >= 0:
            reward, terminated, truncated = env_step(
                task, params, state, int(actions[t - 1, 0]), actions[t - 1, 1]
            )
            rewards[t - 1] = reward
            states[t] = state
            if terminated or truncated:
                break
            env_observe(task, params, state, noise[t], obs)
    return (
        actions[:t],
        rewards[:t],
        team_log[:n_team],
        prog_log[:n_prog],
        bids[:n_prog],
        instr_log[:n_instr],
        mem_log[:n_mem],
        memory[:t],
        states[: t + 1],
        observations[:t],
    )


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


def trace_sequence(
    cp: CompiledPopulation,
    root_id: int,
    observations: np.ndarray,
    no_memory: bool = False,
    snapshot: bool = True,
) -> Trace:
    """Traces decisions of root ``root_id`` on a fixed observation sequence ``(n, 2)``."""
    obs = np.ascontiguousarray(observations, dtype=np.float64).reshape(-1, 2)
    out = trace_kernel(
        cp.team_index(root_id),
        -1,
        TASK_PARAMS,
        np.zeros(STATE_SIZE),
        np.zeros(1),
        obs,
        no_memory,
        snapshot,
        *cp.kernel_args(),
    )
    return Trace(*out)


def trace_episode(
    cp: CompiledPopulation,
    root_id: int,
    task: int,
    start: np.ndarray,
    noise: np.ndarray,
    no_memory: bool = False,
    snapshot: bool = False,
) -> Trace:
    """Traces one episode of ``task`` from ``start`` with the episode's ``noise`` row."""
    out = trace_kernel(
        cp.team_index(root_id),
        task,
        task_params(),
        np.ascontiguousarray(start, dtype=np.float64),
        np.ascontiguousarray(noise, dtype=np.float64),
        np.zeros((0, 2)),
        no_memory,
        snapshot,
        *cp.kernel_args(),
    )
    return Trace(*out)
