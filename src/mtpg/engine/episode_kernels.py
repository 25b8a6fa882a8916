"""Compiled decision, episode and batch kernels.

Every kernel takes its arrays as a few named tuples, each unpacked once in the kernel: the
compiled graph (:class:`~mtpg.engine.compile.Graph`), the jobs and the episode table
(:class:`~mtpg.engine.batch.Jobs`, :class:`~mtpg.engine.batch.Episodes`), the outputs
(:class:`~mtpg.engine.batch.BatchResult`) and one thread's private :class:`Buffers`, whose
float64 workspace ``W`` is laid out as documented in :mod:`mtpg.engine.compile`.

This is the scalar engine: one episode at a time. Training, test points, ``evaluate`` and
``probe`` play the lane engine (:mod:`mtpg.engine.lanes`, many episodes of a root in
lockstep, its decision in :mod:`mtpg.engine.lane_decide`), which is tested to match this
kernel job by job; ``replay``, ``trace`` and ``analyze`` (:mod:`mtpg.engine.trace`), live
decisions (:mod:`mtpg.engine.live`, :mod:`mtpg.engine.live_trace`) and
``run_jobs(..., lanes=0)`` play this one. Both engines compare bids with the one rule,
:func:`mtpg.engine.bid_rule.takes_lead`, inlined. The scalar decision lives in
:func:`decide_bank` alone (:func:`decide` reads its continuous output) and the scalar
episode loop in :func:`run_jobs_queue` alone: the tracer runs the same two with a
:class:`~mtpg.engine.record.Recorder`, and the batch path passes ``rec=None``, with which
Numba compiles every recording branch out.

Memory banks are reset lazily: ``bank_stamp[b]`` records the episode in which bank ``b``
was last zeroed, and a program zeroes its bank before running when the stamp is stale.
Since a program touches only its own bank, this equals zeroing every bank at the start of
each episode. Visited teams are marked the same way with a per-decision stamp.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit, prange, types
from numba.core import cgutils
from numba.extending import intrinsic

from mtpg.engine.bid_rule import NO_BID, takes_lead
from mtpg.engine.ops import apply_op
from mtpg.engine.record import (
    record_decision,
    record_instruction,
    record_observation,
    record_program,
    record_reset,
    record_state,
    record_team,
)
from mtpg.envs.dynamics.dispatch import (
    add_obs_noise,
    env_reset,
    observe_kind,
    task_continuous,
    task_observe,
    task_step,
)
from mtpg.envs.specs.contract import STATE_SIZE
from mtpg.envs.specs.param_table import P_KIND, P_OBS_SD
from mtpg.model.instructions import CONSTANTS, N_CONSTANTS

_CONSTANTS = CONSTANTS.copy()


@intrinsic
def _fetch_add(typingctx, counter):
    """Atomically adds 1 to ``counter[0]`` (int64) and returns the value it had."""
    if not (isinstance(counter, types.Array) and counter.dtype == types.int64):
        return None

    def codegen(context, builder, signature, args):
        array = context.make_array(signature.args[0])(context, builder, args[0])
        ptr = cgutils.get_item_pointer(
            context, builder, signature.args[0], array, [context.get_constant(types.intp, 0)]
        )
        one = context.get_constant(types.int64, 1)
        # "monotonic": only the uniqueness of the values handed out matters; the outputs
        # each block writes are joined by the end of the parallel region.
        return builder.atomic_rmw("add", ptr, one, "monotonic")

    return types.int64(counter), codegen


@njit(cache=True, error_model="numpy")
def new_workspace(size: int, R: int) -> np.ndarray:
    """Allocates a zeroed workspace with the constants in place."""
    W = np.zeros(size)
    for i in range(N_CONSTANTS):
        W[R + i] = _CONSTANTS[i]
    return W


class Buffers(NamedTuple):
    """One thread's private state, allocated once per worker (:func:`thread_buffers`).

    Attributes:
        W: float64 workspace (registers, constants, observation, every bank).
        obs: The observation slots of ``W`` (a view).
        team_stamp: int64 ``[n_teams]`` visit marks (the decision's stamp: visited).
        bank_stamp: int64 ``[n_banks]`` episode marks of the banks' last reset.
        state: float64 ``[STATE_SIZE]`` the task state.
        counts: int64 ``[2]`` teams visited and instructions executed in the episode.
    """

    W: np.ndarray
    obs: np.ndarray
    team_stamp: np.ndarray
    bank_stamp: np.ndarray
    state: np.ndarray
    counts: np.ndarray


@njit(cache=True, error_model="numpy")
def thread_buffers(g) -> Buffers:
    """Allocates one thread's :class:`Buffers` for the compiled graph ``g``."""
    R, M, base = g.n_registers, g.n_memory, g.mem_base
    n_banks = (g.prog_bank.max() + 1) if len(g.prog_bank) else 0
    W = new_workspace(base + n_banks * M, R)
    K = len(g.folded)
    for i in range(K):  # the folded constants, just below bank 0
        W[base - K + i] = g.folded[i]
    n_obs = base - K - (R + N_CONSTANTS)  # the layout's observed inputs
    return Buffers(
        W,
        W[R + N_CONSTANTS : R + N_CONSTANTS + n_obs],
        np.full(len(g.team_offsets) - 1, -1, dtype=np.int64),
        np.full(n_banks, -1, dtype=np.int64),
        np.zeros(STATE_SIZE),
        np.zeros(2, dtype=np.int64),
    )


@njit(cache=True, error_model="numpy", inline="always")
def decide(g, buf, root, stamp, episode, rec):
    """Makes one decision (:func:`decide_bank`) and reads ``m[0]`` of the winner's bank.

    Returns:
        ``(a_d, a_c)``: the final program's atomic action and ``m[0]`` of its bank.
    """
    a_d, off = decide_bank(g, buf, root, stamp, episode, rec)
    return a_d, buf.W[np.uint64(off)]


@njit(cache=True, error_model="numpy", inline="always")
def decide_bank(g, buf, root, stamp, episode, rec):
    """Makes one decision: traverses the graph from ``root`` to an atomic action.

    Written as one flat loop nest on purpose: helper functions taking arrays cost an
    atomic reference-count update per call, about a fifth of the run time. It is inlined
    into its callers (``inline="always"``, as are ``apply_op`` and ``takes_lead``), so a
    decision passes no arguments (each array is seven machine words) and the instruction
    loop is compiled in place. Every index is unsigned (``np.uint64``): Numba then emits
    plain loads and stores, without the fix-up for negative (from-the-end) indices that a
    signed index costs at every access (and that turned the bank reset into scatter
    stores).

    Each visited team runs all its programs in order, then follows the winner of the
    engine's one bid rule, :func:`~mtpg.engine.bid_rule.takes_lead` (the highest bid among
    programs whose pointer is atomic or leads to a team not yet visited in this decision;
    ties go to the earlier program), the lane engine's rule too.

    Args:
        g: The compiled graph (:class:`~mtpg.engine.compile.Graph`).
        buf: The thread's :class:`Buffers`, the observation in place.
        root: Dense index of the root team.
        stamp: This decision's mark (new per decision).
        episode: This episode's mark (new per episode: the lazy bank reset).
        rec: ``None``, or the :class:`~mtpg.engine.record.Recorder` to log into.

    Returns:
        ``(a_d, off)``: the final program's atomic action and the workspace index of
        ``m[0]`` of its bank (the continuous outputs are ``W[off + j]``).
    """
    team_offsets, team_members, prog_offsets = g.team_offsets, g.team_members, g.prog_offsets
    instrs, prog_action, prog_bank, prog_count = g.instrs, g.prog_action, g.prog_bank, g.prog_count
    R, M, base = g.n_registers, g.n_memory, g.mem_base
    no_memory = g.no_memory  # the ablation: every bank zeroed before each program run
    W, team_stamp, bank_stamp, counts = buf.W, buf.team_stamp, buf.bank_stamp, buf.counts
    one = np.uint64(1)
    u_m = np.uint64(M)
    u_base = np.uint64(base)
    team = np.uint64(root)
    n_teams = 0
    n_instr = np.uint64(0)
    while True:
        team_stamp[team] = stamp
        n_teams += 1
        if rec is not None:
            record_team(rec, team)
        best_p = -1  # set by the first eligible program (every team has an atomic one)
        best = NO_BID
        for k in range(np.uint64(team_offsets[team]), np.uint64(team_offsets[team + one])):
            p = np.uint64(team_members[k])
            bank = np.uint64(prog_bank[p])
            if no_memory or bank_stamp[bank] != episode:  # lazy reset of the bank
                off = u_base + bank * u_m
                for j in range(off, off + u_m):
                    W[j] = 0.0
                bank_stamp[bank] = episode
                if rec is not None:
                    record_reset(rec, bank, M)
            if R == 8:  # the common size: one 64-byte clear (two vector stores)
                W[0] = W[1] = W[2] = W[3] = W[4] = W[5] = W[6] = W[7] = 0.0
            else:
                # +0.0 from a constant register, which the compiler cannot see is zero:
                # a loop storing a known 0.0 becomes a libc memset call per program run.
                zero = W[R] - W[R]
                for i in range(R):
                    W[i] = zero
            lo, hi = np.uint64(prog_offsets[p]), np.uint64(prog_offsets[p + one])
            for i in range(lo, hi):
                dst = instrs[i, 1]
                value = apply_op(instrs[i, 0], W[dst], W[instrs[i, 2]], W[instrs[i, 3]])
                if rec is not None:
                    record_instruction(rec, i, instrs[i], W[dst], value, base, M)
                W[dst] = value
            n_instr += np.uint64(prog_count[p])  # as stated, folded or not
            bid = W[0]
            if rec is not None:
                record_program(rec, p, bid)
            act = prog_action[p]
            if takes_lead(act, team_stamp, np.uint64(act), stamp, bid, best):
                best = bid
                best_p = np.int64(p)
        act = prog_action[np.uint64(best_p)]
        if act < 0:
            counts[0] += n_teams
            counts[1] += np.int64(n_instr)
            return -1 - act, np.int64(u_base + np.uint64(prog_bank[np.uint64(best_p)]) * u_m)
        team = np.uint64(act)


@njit(cache=True, error_model="numpy", nogil=True)
def run_jobs_queue(next_block, block, jobs, table, out, g, rec=None):
    """One worker: takes blocks of jobs from a shared queue and plays them serially.

    Holds the package's one compiled episode loop: the batch kernels run it with
    ``rec=None`` (Numba compiles the recording out), the tracer with a recorder.

    Jobs go in blocks of ``block`` consecutive jobs; block ``b`` is jobs
    ``b * block ... (b + 1) * block - 1``. The queue is the int64 counter ``next_block[0]``:
    the worker takes the next block with an atomic fetch-and-add until none is left, so
    workers sharing one counter (:func:`run_jobs_parallel`) balance long and short
    episodes among themselves whatever their speed, and a worker with a counter of its own
    plays every job in order. Consecutive jobs usually share a root (all its episodes), so a
    block keeps one graph's code and memory banks in cache. The private buffers are
    allocated once per worker, not per block.

    Results do not depend on which worker plays a job: every job starts from a fresh
    memory state (the lazy bank reset keyed by the job index).

    Releases the GIL, so several Python threads (e.g. of one Dask worker) run it at once.

    Args:
        next_block: int64 ``[1]``: the queue's counter.
        block: Jobs per block.
        jobs: :class:`~mtpg.engine.batch.Jobs`: job ``j`` plays episode row
            ``jobs.episodes[j]`` with root ``jobs.roots[j]``.
        table: :class:`~mtpg.engine.batch.Episodes`: task, start state and noise row of
            each episode, and the parameter table the task ids index.
        out: :class:`~mtpg.engine.batch.BatchResult`: job ``j``'s return, steps, teams
            visited and instructions executed are written at ``j``.
        g: The compiled graph (:class:`~mtpg.engine.compile.Graph`; its ``no_memory``
            field selects the ablation).
        rec: ``None``, or the :class:`~mtpg.engine.record.Recorder` of a one-job run
            (which also ends where the episode's noise row ends, as a time limit that
            would read past it cannot occur in a table of ``make_episodes``).
    """
    buf = thread_buffers(g)
    obs, state, counts = buf.obs, buf.state, buf.counts
    stamp = 0
    n_jobs = len(jobs.roots)
    while True:
        first = _fetch_add(next_block) * block
        if first >= n_jobs:
            break
        for j in range(first, min(first + block, n_jobs)):
            e = jobs.episodes[j]
            root = jobs.roots[j]
            task = table.tasks[e]
            p = table.params[task]  # the parameter row, taken once per episode
            kind = np.int64(p[P_KIND])  # the kernels playing it (the base task of a variant)
            okind = observe_kind(p)  # and observing it
            env_reset(task, table.params, table.starts[e], state)
            noisy = p[P_OBS_SD] != 0.0  # a variant with observation noise
            task_observe(okind, p, state, table.noise[e, 0], obs)
            if noisy:
                add_obs_noise(p, table.obs_noise[e, 0, 0], table.obs_noise[e, 0, 1], obs)
            counts[:] = 0
            total = 0.0
            t = 0
            if rec is not None:
                record_state(rec, 0, 0.0, state)
            while True:
                if rec is not None:
                    record_observation(rec, t, obs)
                a_d, off = decide_bank(g, buf, root, stamp, j, rec)
                a_c = buf.W[np.uint64(off)]
                stamp += 1
                if rec is not None:
                    record_decision(rec, t, a_d, a_c, buf, g, j)
                # The one task dispatch: step kernels, called without reference counts
                # (task_continuous hands m[1..] to a task of several continuous outputs).
                task_continuous(kind, p, state, buf.W, np.uint64(off), np.uint64(1))
                reward, terminated, truncated = task_step(kind, p, state, a_d, a_c)
                total += reward
                t += 1
                if rec is not None:
                    record_state(rec, t, reward, state)
                    if t == table.noise.shape[1] - 1:  # a traced row of noise ends the run
                        break
                if terminated or truncated:
                    break
                task_observe(okind, p, state, table.noise[e, t], obs)
                if noisy:
                    add_obs_noise(p, table.obs_noise[e, t, 0], table.obs_noise[e, t, 1], obs)
            out.returns[j] = total
            out.steps[j] = t
            out.teams[j] = counts[0]
            out.instructions[j] = counts[1]


@njit(cache=True, error_model="numpy", parallel=True)
def run_jobs_parallel(n_workers, next_block, block, jobs, table, out, g):
    """Runs all jobs on ``n_workers`` workers (one per Numba thread) sharing one queue.

    ``next_block`` is the queue's counter (int64 ``[1]``, 0 to start); once every job is
    played it holds the number of blocks plus ``n_workers`` (each worker's last take finds
    the queue empty).
    """
    for _ in prange(n_workers):
        run_jobs_queue(next_block, block, jobs, table, out, g)
