"""The lane engine: many episodes of one graph played in lockstep.

A block of up to ``lanes`` jobs (usually the episodes of one root) is played together,
one environment step at a time. At each step the live lanes decide together: the lanes
standing at the same team form a *group*, and each program of the team runs once over
its group, its instruction dispatched once for all the group's lanes (the inner loop
runs over lanes with the same op code, so its branch is predicted and its loads and
stores stride through lane-contiguous memory). Then each lane takes its own highest bid
under its own visited-team rule, exactly as :func:`mtpg.engine.kernels.decide`, and the
lanes split into the groups of the teams they move to. When every lane has reached an
atomic action, each lane's task takes one step; a lane whose episode ends leaves.

Each lane computes exactly the operations the scalar kernel computes, in the same order,
with the same compiled :func:`~mtpg.engine.ops.apply_op` (no vector math library: a lane's
``cos`` is the same scalar call), so every job's return, steps, teams visited and
instructions executed are bit for bit those of :func:`~mtpg.engine.kernels.run_jobs_queue`
(tested), whatever the lane-block size, the order of the jobs or the threads.

Layout: the workspace is a float64 ``[n_addresses, lanes]`` array: the address of every
operand is the scalar workspace's (:mod:`mtpg.engine.compile`) and a lane its column, so
the lanes of one register are adjacent. All lanes of a block start their episodes
together, so a bank is reset lazily for all lanes at once (its stamp is the block's),
which equals resetting it at each lane's episode start; visited teams are stamped per lane
with the step's mark.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from mtpg.engine.kernels import _fetch_add
from mtpg.engine.ops import _clamp, op_cos, op_div, op_exp, op_log, op_pow, op_sin, op_tanh
from mtpg.envs.core import STATE_SIZE
from mtpg.envs.kernels import add_obs_noise, env_reset, observe_kind, task_observe, task_step
from mtpg.envs.tasks import P_KIND, P_OBS_SD
from mtpg.model.instructions import CONSTANTS, N_CONSTANTS

_CONSTANTS = CONSTANTS.copy()

#: Lanes of one block when the caller does not choose: one root's training episodes
#: (6 tasks x 5) fit in one block; results do not depend on it.
DEFAULT_LANES = 32


@njit(cache=True, error_model="numpy", inline="always")
def lane_op(Wf, op, ud, ua, ub, grp, n):
    """Runs one instruction over the lanes ``grp[:n]``: one loop per op code.

    Each loop computes :func:`~mtpg.engine.ops.apply_op`'s value for its op code with the
    same functions, so the op code is tested once per group, not once per lane.
    """
    if op == 0:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = _clamp(Wf[ua + lane] + Wf[ub + lane])
    elif op == 1:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = _clamp(Wf[ua + lane] - Wf[ub + lane])
    elif op == 2:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = _clamp(Wf[ua + lane] * Wf[ub + lane])
    elif op == 3:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = _clamp(op_div(Wf[ua + lane], Wf[ub + lane]))
    elif op == 4:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = _clamp(op_pow(Wf[ua + lane], Wf[ub + lane]))
    elif op == 5:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = op_cos(Wf[ub + lane])  # within [-1, 1]: the clamp changes nothing
    elif op == 6:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = _clamp(op_log(Wf[ub + lane]))
    elif op == 7:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = _clamp(op_exp(Wf[ub + lane]))
    elif op == 8:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = _clamp(math.sqrt(abs(Wf[ub + lane])))
    elif op == 9:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = op_sin(Wf[ub + lane])  # within [-1, 1]
    elif op == 10:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = op_tanh(Wf[ub + lane])  # within [-1, 1]
    elif op == 11:
        for k in range(n):
            lane = grp[k]
            b = Wf[ub + lane]
            Wf[ud + lane] = _clamp(b * b)
    elif op == 12:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = abs(Wf[ub + lane])  # operands are within [-BIG, BIG]
    elif op == 13:
        for k in range(n):
            lane = grp[k]
            b = Wf[ub + lane]
            Wf[ud + lane] = _clamp(b * b * b)
    elif op == 14:
        for k in range(n):
            lane = grp[k]
            d = Wf[ud + lane]
            Wf[ud + lane] = -d if Wf[ua + lane] < Wf[ub + lane] else d
    elif op == 15:
        for k in range(n):
            lane = grp[k]
            d = Wf[ud + lane]
            Wf[ud + lane] = -d if Wf[ua + lane] > Wf[ub + lane] else d
    else:  # OP_COPY
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = Wf[ub + lane]


@njit(cache=True, error_model="numpy")
def registers_to_zero(instrs, prog_offsets, R):
    """For each program, the private registers it may read before writing them (a bit mask).

    The scalar kernel zeroes all ``R`` registers before every program run; a register the
    program writes before any read of it (its op code reads the target only for the
    conditionals 14 and 15) never shows the old value, so only the registers read first,
    and ``r[0]`` when the program never writes it (the bid), need the zero. With more than
    63 registers every register is zeroed.
    """
    n_progs = len(prog_offsets) - 1
    out = np.zeros(n_progs, dtype=np.uint64)
    one = np.uint64(1)
    for p in range(n_progs):
        if R > 63:
            out[p] = (one << np.uint64(63)) - one
            continue
        written = np.uint64(0)
        need = np.uint64(0)
        for i in range(prog_offsets[p], prog_offsets[p + 1]):
            op, dst, a, b = instrs[i, 0], instrs[i, 1], instrs[i, 2], instrs[i, 3]
            # what the op code reads: b always; a for the binary ops and the conditionals;
            # the target for the conditionals
            for src, read in (
                (b, True),
                (a, op <= 4 or op == 14 or op == 15),
                (dst, op == 14 or op == 15),
            ):
                if read and src < R and not (written >> np.uint64(src)) & one:
                    need |= one << np.uint64(src)
            if dst < R:
                written |= one << np.uint64(dst)
        if not written & one:
            need |= one  # the bid is r[0]
        out[p] = need
    return out


@njit(cache=True, error_model="numpy", nogil=True)
def run_lanes_queue(next_block, block, lanes, jobs, table, no_memory, out, g):
    """One worker of the lane engine: takes blocks of jobs from a shared queue.

    The queue is :func:`~mtpg.engine.kernels.run_jobs_queue`'s (block ``b`` is jobs
    ``b * block ... (b + 1) * block - 1``); each queue block is played in lane blocks of
    up to ``lanes`` consecutive jobs. Jobs of a lane block may have different roots.

    Args:
        next_block: int64 ``[1]``: the queue's counter.
        block: Jobs per queue block.
        lanes: Jobs played in lockstep (the lane-block size, at least 1).
        jobs: :class:`~mtpg.engine.batch.Jobs`.
        table: :class:`~mtpg.engine.batch.Episodes`.
        no_memory: The no-memory ablation.
        out: :class:`~mtpg.engine.batch.BatchResult`, written at each job's index.
        g: The compiled graph (:class:`~mtpg.engine.compile.Graph`).
    """
    team_offsets, team_members, prog_offsets = g.team_offsets, g.team_members, g.prog_offsets
    instrs, prog_action, prog_bank, prog_count = g.instrs, g.prog_action, g.prog_bank, g.prog_count
    R, M, base = g.n_registers, g.n_memory, g.mem_base
    n_teams = len(team_offsets) - 1
    n_banks = (prog_bank.max() + 1) if len(prog_bank) else 0
    L = np.uint64(lanes)
    n_addr = base + n_banks * M
    Wf = np.zeros(n_addr * lanes)  # Wf[address * lanes + lane]
    for i in range(N_CONSTANTS):
        for k in range(lanes):
            Wf[(R + i) * lanes + k] = _CONSTANTS[i]
    K = len(g.folded)
    for i in range(K):
        for k in range(lanes):
            Wf[(base - K + i) * lanes + k] = g.folded[i]
    u_obs = np.uint64(R + N_CONSTANTS) * L
    u_base = np.uint64(base)
    u_m = np.uint64(M)
    zero_mask = registers_to_zero(instrs, prog_offsets, R)
    visited = np.full(n_teams * lanes, -1, dtype=np.int64)  # [team * lanes + lane]
    bank_stamp = np.full(n_banks, -1, dtype=np.int64)
    state = np.zeros((lanes, STATE_SIZE))
    obs = np.zeros(2)
    # per lane
    job = np.zeros(lanes, dtype=np.int64)
    kind = np.zeros(lanes, dtype=np.int64)
    okind = np.zeros(lanes, dtype=np.int64)
    noisy = np.zeros(lanes, dtype=np.bool_)
    total = np.zeros(lanes)
    n_team = np.zeros(lanes, dtype=np.int64)
    n_ins = np.zeros(lanes, dtype=np.int64)
    best = np.zeros(lanes)
    best_p = np.zeros(lanes, dtype=np.int64)
    a_d = np.zeros(lanes, dtype=np.int64)
    a_c = np.zeros(lanes)
    live = np.zeros(lanes, dtype=np.int64)
    pend_team = np.zeros(lanes, dtype=np.int64)
    pend_lane = np.zeros(lanes, dtype=np.int64)
    grp = np.zeros(lanes, dtype=np.uint64)
    stamp = 0
    lane_block = 0
    n_jobs = len(jobs.roots)
    while True:
        first = _fetch_add(next_block) * block
        if first >= n_jobs:
            break
        last = min(first + block, n_jobs)
        for s in range(first, last, lanes):
            nl = min(lanes, last - s)
            lane_block += 1
            for k in range(nl):
                j = s + k
                e = jobs.episodes[j]
                p = table.params[table.tasks[e]]
                job[k] = j
                kind[k] = np.int64(p[P_KIND])
                okind[k] = observe_kind(p)
                noisy[k] = p[P_OBS_SD] != 0.0
                env_reset(table.tasks[e], table.params, table.starts[e], state[k])
                task_observe(okind[k], p, state[k], table.noise[e, 0], obs)
                if noisy[k]:
                    add_obs_noise(p, table.obs_noise[e, 0, 0], table.obs_noise[e, 0, 1], obs)
                Wf[u_obs + np.uint64(k)] = obs[0]
                Wf[u_obs + L + np.uint64(k)] = obs[1]
                total[k] = 0.0
                n_team[k] = 0
                n_ins[k] = 0
                live[k] = k
            n_live = nl
            t = 0
            while n_live > 0:
                stamp += 1
                # --- one decision for every live lane ---
                for k in range(n_live):
                    pend_team[k] = jobs.roots[job[live[k]]]
                    pend_lane[k] = live[k]
                n_pend = n_live
                while n_pend > 0:
                    team = pend_team[0]
                    n = 0
                    m = 0
                    for k in range(n_pend):  # take the lanes at `team` out of pending
                        if pend_team[k] == team:
                            grp[n] = np.uint64(pend_lane[k])
                            n += 1
                        else:
                            pend_team[m] = pend_team[k]
                            pend_lane[m] = pend_lane[k]
                            m += 1
                    n_pend = m
                    u_team = np.uint64(team)
                    for k in range(n):
                        lane = grp[k]
                        visited[u_team * L + lane] = stamp
                        n_team[lane] += 1
                        best[lane] = -np.inf
                    team_ins = 0
                    for kk in range(
                        np.uint64(team_offsets[u_team]), np.uint64(team_offsets[u_team + 1])
                    ):
                        p = np.uint64(team_members[kk])
                        bank = np.uint64(prog_bank[p])
                        off = (u_base + bank * u_m) * L
                        if no_memory:
                            for r in range(u_m):
                                for k in range(n):
                                    Wf[off + r * L + grp[k]] = 0.0
                        elif bank_stamp[bank] != lane_block:  # lazy reset, every lane at once
                            for i in range(off, off + u_m * L):
                                Wf[i] = 0.0
                            bank_stamp[bank] = lane_block
                        zm = zero_mask[p]
                        r = np.uint64(0)
                        while zm != 0:  # the private registers the program reads unwritten
                            if zm & 1:
                                for k in range(n):
                                    Wf[r * L + grp[k]] = 0.0
                            zm >>= np.uint64(1)
                            r += np.uint64(1)
                        for i in range(np.uint64(prog_offsets[p]), np.uint64(prog_offsets[p + 1])):
                            op = instrs[i, 0]
                            ud = np.uint64(instrs[i, 1]) * L
                            ua = np.uint64(instrs[i, 2]) * L
                            ub = np.uint64(instrs[i, 3]) * L
                            lane_op(Wf, op, ud, ua, ub, grp, n)
                        team_ins += prog_count[p]
                        act = prog_action[p]
                        # bids are finite, so starting from -inf the first eligible
                        # program wins and a later one only with a higher bid (ties: the
                        # earlier), as in the scalar kernel
                        if act < 0:
                            for k in range(n):
                                lane = grp[k]
                                if Wf[lane] > best[lane]:
                                    best[lane] = Wf[lane]
                                    best_p[lane] = np.int64(p)
                        else:
                            u_act = np.uint64(act) * L
                            for k in range(n):
                                lane = grp[k]
                                if visited[u_act + lane] != stamp and Wf[lane] > best[lane]:
                                    best[lane] = Wf[lane]
                                    best_p[lane] = np.int64(p)
                    for k in range(n):
                        lane = grp[k]
                        n_ins[lane] += team_ins
                        q = np.uint64(best_p[lane])
                        act = prog_action[q]
                        if act < 0:
                            a_d[lane] = -1 - act
                            a_c[lane] = Wf[(u_base + np.uint64(prog_bank[q]) * u_m) * L + lane]
                        else:
                            pend_team[n_pend] = act
                            pend_lane[n_pend] = np.int64(lane)
                            n_pend += 1
                # --- one step of every live lane's task ---
                t += 1
                m = 0
                for k in range(n_live):
                    lane = live[k]
                    j = job[lane]
                    e = jobs.episodes[j]
                    p = table.params[table.tasks[e]]
                    reward, terminated, truncated = task_step(
                        kind[lane], p, state[lane], a_d[lane], a_c[lane]
                    )
                    total[lane] += reward
                    if terminated or truncated:
                        out.returns[j] = total[lane]
                        out.steps[j] = t
                        out.teams[j] = n_team[lane]
                        out.instructions[j] = n_ins[lane]
                        continue
                    task_observe(okind[lane], p, state[lane], table.noise[e, t], obs)
                    if noisy[lane]:
                        add_obs_noise(p, table.obs_noise[e, t, 0], table.obs_noise[e, t, 1], obs)
                    u_l = np.uint64(lane)
                    Wf[u_obs + u_l] = obs[0]
                    Wf[u_obs + L + u_l] = obs[1]
                    live[m] = lane
                    m += 1
                n_live = m


@njit(cache=True, error_model="numpy", parallel=True)
def run_lanes_parallel(n_workers, next_block, block, lanes, jobs, table, no_memory, out, g):
    """Runs all jobs on ``n_workers`` lane-engine workers sharing one queue."""
    for _ in prange(n_workers):
        run_lanes_queue(next_block, block, lanes, jobs, table, no_memory, out, g)
