"""Compiled decision, episode and batch kernels.

Every kernel takes the compiled graph as the argument group
``team_offsets, team_members, prog_offsets, instrs, prog_action, prog_bank, R, M, base``
(see :class:`~mtpg.engine.compile.CompiledPopulation.kernel_args`) and a per-thread
float64 workspace ``W`` laid out as documented in :mod:`mtpg.engine.compile`.

Memory banks are reset lazily: ``bank_stamp[b]`` records the episode in which bank ``b``
was last zeroed, and a program zeroes its bank before running when the stamp is stale.
Since a program touches only its own bank, this equals zeroing every bank at the start of
each episode. Visited teams are marked the same way with a per-decision stamp.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange, types
from numba.core import cgutils
from numba.extending import intrinsic

from mtpg.engine.ops import apply_op
from mtpg.envs.core import STATE_SIZE
from mtpg.envs.kernels import env_observe_row, env_reset, observe_kind, task_step
from mtpg.envs.tasks import P_KIND
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
def new_workspace(size: int, R: int) -> np.ndarray:  # noqa: N803
    """Allocates a zeroed workspace with the constants in place."""
    W = np.zeros(size)  # noqa: N806
    for i in range(N_CONSTANTS):
        W[R + i] = _CONSTANTS[i]
    return W


@njit(cache=True, error_model="numpy")
def thread_buffers(team_offsets, prog_bank, R, M, base):  # noqa: N803
    """One thread's private state: workspace, visit and bank stamps, task state, counters."""
    n_banks = (prog_bank.max() + 1) if len(prog_bank) else 0
    W = new_workspace(base + n_banks * M, R)  # noqa: N806
    team_stamp = np.full(len(team_offsets) - 1, -1, dtype=np.int64)
    bank_stamp = np.full(n_banks, -1, dtype=np.int64)
    return W, team_stamp, bank_stamp, np.zeros(STATE_SIZE), np.zeros(2, dtype=np.int64)


@njit(cache=True, error_model="numpy", inline="always")
def decide(
    root,
    W,
    team_stamp,
    stamp,
    bank_stamp,
    episode,
    no_memory,
    counts,
    team_offsets,
    team_members,
    prog_offsets,
    instrs,
    prog_action,
    prog_bank,
    R,
    M,
    base,
):  # noqa: N803
    """Makes one decision: traverses the graph from ``root`` to an atomic action.

    Written as one flat loop nest on purpose: helper functions taking arrays cost an
    atomic reference-count update per call, about a fifth of the run time. It is inlined
    into its callers (``inline="always"``, as is ``apply_op``), so a decision passes no
    arguments (each array is seven machine words) and the instruction loop is compiled
    in place.

    Each visited team runs all its programs in order, then follows the highest bid among
    programs whose pointer is atomic or leads to a team not yet visited in this decision
    (ties go to the earlier program).

    Args:
        root: Dense index of the root team.
        W: Workspace with the observation in place.
        team_stamp: int64 ``[n_teams]`` visit marks; ``stamp`` must be new per decision.
        stamp: This decision's mark.
        bank_stamp: int64 ``[n_banks]`` episode marks of the banks.
        episode: This episode's mark.
        no_memory: Zero each bank before every program execution (ablation).
        counts: int64 ``[2]`` accumulators: teams visited, instructions executed.
        team_offsets: The compiled graph (see ``CompiledPopulation``).
        team_members: The compiled graph.
        prog_offsets: The compiled graph.
        instrs: The compiled graph.
        prog_action: The compiled graph.
        prog_bank: The compiled graph.
        R: Private registers per program.
        M: Registers per memory bank.
        base: Workspace index of memory bank 0.

    Returns:
        ``(a_d, a_c)``: the final program's atomic action and ``m[0]`` of its bank.
    """
    # Every index below is unsigned (np.uint64): Numba then emits plain loads and stores,
    # without the fix-up for negative (from-the-end) indices that a signed index costs at
    # every access (and that turned the bank reset into scatter stores).
    one = np.uint64(1)
    u_m = np.uint64(M)
    u_base = np.uint64(base)
    team = np.uint64(root)
    # +0.0, computed from a constant register so that the compiler cannot see it is zero:
    # zero stores of a known 0.0 are turned into a libc memset call per program run.
    zero = W[R] - W[R]
    n_teams = 0
    n_instr = np.uint64(0)
    while True:
        team_stamp[team] = stamp
        n_teams += 1
        found = False
        best_p = np.uint64(0)
        best = 0.0
        for k in range(np.uint64(team_offsets[team]), np.uint64(team_offsets[team + one])):
            p = np.uint64(team_members[k])
            bank = np.uint64(prog_bank[p])
            if no_memory or bank_stamp[bank] != episode:  # lazy reset of the bank
                off = u_base + bank * u_m
                for j in range(off, off + u_m):
                    W[j] = 0.0
                bank_stamp[bank] = episode
            if R == 8:  # the common size: straight-line stores
                W[0] = W[1] = W[2] = W[3] = W[4] = W[5] = W[6] = W[7] = zero
            else:
                for i in range(R):
                    W[i] = zero
            lo, hi = np.uint64(prog_offsets[p]), np.uint64(prog_offsets[p + one])
            for i in range(lo, hi):
                dst = instrs[i, 1]
                W[dst] = apply_op(instrs[i, 0], W[dst], W[instrs[i, 2]], W[instrs[i, 3]])
            n_instr += hi - lo
            bid = W[0]
            act = prog_action[p]
            if (act < 0 or team_stamp[np.uint64(act)] != stamp) and (not found or bid > best):
                best = bid
                best_p = p
                found = True
        act = prog_action[best_p]
        if act < 0:
            counts[0] += n_teams
            counts[1] += np.int64(n_instr)
            return -1 - act, W[u_base + np.uint64(prog_bank[best_p]) * u_m]
        team = np.uint64(act)


@njit(cache=True, error_model="numpy", nogil=True)
def run_jobs_queue(
    next_block,
    block,
    job_root,
    job_ep,
    ep_task,
    ep_start,
    ep_noise,
    params,
    no_memory,
    out_return,
    out_steps,
    out_teams,
    out_instr,
    team_offsets,
    team_members,
    prog_offsets,
    instrs,
    prog_action,
    prog_bank,
    R,
    M,
    base,
):  # noqa: N803
    """One worker: takes blocks of jobs from a shared queue and plays them serially.

    Jobs go in blocks of ``block`` consecutive jobs; block ``b`` is jobs
    ``b * block ... (b + 1) * block - 1``. The queue is the int64 counter ``next_block[0]``:
    the worker takes the next block with an atomic fetch-and-add until none is left, so
    workers sharing one counter (:func:`run_jobs_parallel`) balance long and short
    episodes among themselves whatever their speed, and a worker with a counter of its own
    plays every job in order. Consecutive jobs usually share a root (all its episodes), so a
    block keeps one graph's code and memory banks in cache. The private workspace is
    allocated once per worker, not per block.

    Results do not depend on which worker plays a job: every job starts from a fresh
    memory state (the lazy bank reset keyed by the job index).

    Releases the GIL, so several Python threads (e.g. of one Dask worker) run it at once.

    Job ``j`` plays episode ``job_ep[j]`` (task ``ep_task``, start state ``ep_start`` and
    noise ``ep_noise`` rows) with root ``job_root[j]`` and writes its return, steps,
    teams visited and instructions executed to the ``out_*`` arrays at ``j``.
    """
    W, team_stamp, bank_stamp, state, counts = thread_buffers(team_offsets, prog_bank, R, M, base)  # noqa: N806
    obs = W[R + N_CONSTANTS : R + N_CONSTANTS + 2]
    stamp = 0
    n_jobs = len(job_root)
    while True:
        first = _fetch_add(next_block) * block
        if first >= n_jobs:
            break
        for j in range(first, min(first + block, n_jobs)):
            e = job_ep[j]
            task = ep_task[e]
            p = params[task]  # the parameter row, taken once per episode
            kind = np.int64(p[P_KIND])  # the kernels playing it (the base task of a variant)
            okind = observe_kind(p)  # and observing it
            env_reset(task, params, ep_start[e], state)
            env_observe_row(okind, p, state, ep_noise[e, 0], obs)
            counts[:] = 0
            total = 0.0
            t = 0
            while True:
                a_d, a_c = decide(
                    job_root[j],
                    W,
                    team_stamp,
                    stamp,
                    bank_stamp,
                    j,
                    no_memory,
                    counts,
                    team_offsets,
                    team_members,
                    prog_offsets,
                    instrs,
                    prog_action,
                    prog_bank,
                    R,
                    M,
                    base,
                )
                stamp += 1
                # The one task dispatch, inlined (no call passing the arrays per step).
                reward, terminated, truncated = task_step(kind, p, state, a_d, a_c)
                total += reward
                t += 1
                if terminated or truncated:
                    break
                env_observe_row(okind, p, state, ep_noise[e, t], obs)
            out_return[j] = total
            out_steps[j] = t
            out_teams[j] = counts[0]
            out_instr[j] = counts[1]


@njit(cache=True, error_model="numpy", parallel=True)
def run_jobs_parallel(
    n_workers,
    next_block,
    block,
    job_root,
    job_ep,
    ep_task,
    ep_start,
    ep_noise,
    params,
    no_memory,
    out_return,
    out_steps,
    out_teams,
    out_instr,
    team_offsets,
    team_members,
    prog_offsets,
    instrs,
    prog_action,
    prog_bank,
    R,
    M,
    base,
):  # noqa: N803
    """Runs all jobs on ``n_workers`` workers (one per Numba thread) sharing one queue.

    ``next_block`` is the queue's counter (int64 ``[1]``, 0 to start); once every job is
    played it holds the number of blocks plus ``n_workers`` (each worker's last take finds
    the queue empty).
    """
    for _ in prange(n_workers):
        run_jobs_queue(
            next_block,
            block,
            job_root,
            job_ep,
            ep_task,
            ep_start,
            ep_noise,
            params,
            no_memory,
            out_return,
            out_steps,
            out_teams,
            out_instr,
            team_offsets,
            team_members,
            prog_offsets,
            instrs,
            prog_action,
            prog_bank,
            R,
            M,
            base,
        )
