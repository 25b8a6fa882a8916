"""The lane engine: many episodes of one graph played in lockstep.

A block of up to ``lanes`` jobs (usually the episodes of one root) is played together,
one environment step at a time. At each step the live lanes decide together: the lanes
standing at the same team form a *group*, and each program of the team runs once over
its group, its instruction dispatched once for all the group's lanes (the inner loop
runs over lanes with the same op code, so its branch is predicted and its loads and
stores stride through lane-contiguous memory). Then each lane takes its own highest bid
under its own visited-team rule, exactly as :func:`mtpg.engine.episode_kernels.decide`, and the
lanes split into the groups of the teams they move to. When every lane has reached an
atomic action, each lane's task takes one step; a lane whose episode ends leaves.

Each lane computes exactly the operations the scalar kernel computes, in the same order,
with the same operation functions (:mod:`mtpg.engine.lane_ops`; no vector math library:
a lane's ``cos`` is the same scalar call), so every job's return, steps, teams visited and
instructions executed are bit for bit those of :func:`~mtpg.engine.episode_kernels.run_jobs_queue`
(tested), whatever the lane-block size, the order of the jobs or the threads.

Layout: each lane block plays its own compact copy of its graph
(:mod:`mtpg.engine.lane_graph`), whose workspace has a row per register, observation input
and bank register and a column per lane, so the lanes of one register are adjacent. All
lanes of a block start their episodes together, so a bank is zeroed for all lanes at its
first use in the block, which equals resetting it at each lane's episode start; visited
teams are stamped per lane with the step's mark.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

from mtpg.engine.episode_kernels import _fetch_add
from mtpg.engine.lane_graph import (
    C_A,
    C_B,
    C_DST,
    C_MA,
    C_MB,
    C_OP,
    P_ACT,
    P_BANK,
    P_COUNT,
    P_HI,
    P_LBANK,
    P_LO,
    P_ZERO,
    localise,
    unlocalise,
)
from mtpg.engine.lane_ops import lane_op
from mtpg.envs.dynamics.dispatch import (
    add_obs_noise,
    env_reset,
    observe_kind,
    task_observe,
    task_step,
)
from mtpg.envs.specs.contract import STATE_SIZE
from mtpg.envs.specs.param_table import P_KIND, P_OBS_SD
from mtpg.model.instructions import CONSTANTS, N_CONSTANTS

_CONSTANTS = CONSTANTS.copy()

#: Lanes of one block when the caller does not choose: one root's training episodes
#: (6 tasks x 5) fit in one block; results do not depend on it.
DEFAULT_LANES = 32


@njit(cache=True, error_model="numpy", nogil=True)
def run_lanes_queue(next_block, block, lanes, jobs, table, out, g):
    """One worker of the lane engine: takes blocks of jobs from a shared queue.

    The queue is :func:`~mtpg.engine.episode_kernels.run_jobs_queue`'s (block ``b`` is jobs
    ``b * block ... (b + 1) * block - 1``); each queue block is played in lane blocks of
    up to ``lanes`` consecutive jobs. Jobs of a lane block may have different roots.

    Args:
        next_block: int64 ``[1]``: the queue's counter.
        block: Jobs per queue block.
        lanes: Jobs played in lockstep (the lane-block size, at least 1).
        jobs: :class:`~mtpg.engine.batch.Jobs`.
        table: :class:`~mtpg.engine.batch.Episodes`.
        out: :class:`~mtpg.engine.batch.BatchResult`, written at each job's index.
        g: The compiled graph (:class:`~mtpg.engine.compile.Graph`; its ``no_memory``
            field selects the ablation).
    """
    R, M, base = g.n_registers, g.n_memory, g.mem_base
    no_memory = g.no_memory
    n_teams = len(g.team_offsets) - 1
    n_progs = len(g.prog_offsets) - 1
    n_banks = (g.prog_bank.max() + 1) if n_progs else 0
    K = len(g.folded)
    n_obs = base - K - (R + N_CONSTANTS)
    L = np.uint64(lanes)
    # the lane workspace (mtpg.engine.lane_graph): registers, observation and every bank a
    # block could use, a row per value and a column per lane; then the shared constants
    shared = (R + n_obs + n_banks * M) * lanes
    Wf = np.zeros(shared + N_CONSTANTS + K)
    for i in range(N_CONSTANTS):
        Wf[shared + i] = _CONSTANTS[i]
    for i in range(K):
        Wf[shared + N_CONSTANTS + i] = g.folded[i]
    u_obs = np.uint64(R) * L
    u_m = np.uint64(M)
    # the block's local graph (lane_graph.localise)
    maps = np.full((3, max(n_teams, n_progs, n_banks, 1)), -1, dtype=np.int64)
    lteam = np.zeros(n_teams, dtype=np.int64)
    lteam_off = np.zeros(n_teams + 1, dtype=np.int64)
    lprog = np.zeros((len(g.team_members), 8), dtype=np.int64)
    lcode = np.zeros((len(g.instrs), 6), dtype=np.uint64)
    lbank = np.zeros(max(n_banks, 1), dtype=np.int64)
    counts = np.zeros(4, dtype=np.int64)
    roots = np.zeros(lanes, dtype=np.int64)
    visited = np.full(n_teams * lanes, -1, dtype=np.int64)  # [local team * lanes + lane]
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
    start = np.zeros(lanes, dtype=np.int64)  # local root team of each lane
    pend_team = np.zeros(lanes, dtype=np.int64)
    pend_lane = np.zeros(lanes, dtype=np.int64)
    grp = np.zeros(lanes, dtype=np.uint64)
    bank_mark = np.zeros(max(n_banks, 1), dtype=np.int64)  # block of a local bank's zeroing
    n_blocks = 0
    stamp = 0
    n_jobs = len(jobs.roots)
    while True:
        first = _fetch_add(next_block) * block
        if first >= n_jobs:
            break
        last = min(first + block, n_jobs)
        for s in range(first, last, lanes):
            nl = min(lanes, last - s)
            n_roots = 0
            for k in range(nl):
                r = jobs.roots[s + k]
                if maps[0, r] < 0:  # a root not yet listed (marked until localise renumbers)
                    maps[0, r] = 0
                    roots[n_roots] = r
                    n_roots += 1
            for k in range(n_roots):
                maps[0, roots[k]] = -1
            localise(
                g,
                roots[:n_roots],
                lanes,
                shared,
                maps,
                lteam,
                lteam_off,
                lprog,
                lcode,
                lbank,
                counts,
            )
            n_blocks += 1  # the block's mark: its banks are zeroed when first used
            for k in range(nl):
                j = s + k
                e = jobs.episodes[j]
                p = table.params[table.tasks[e]]
                job[k] = j
                start[k] = maps[0, jobs.roots[j]]
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
                    pend_team[k] = start[live[k]]
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
                    for q in range(lteam_off[u_team], lteam_off[u_team + np.uint64(1)]):
                        row = lprog[q]
                        u_bank = np.uint64(row[P_BANK])
                        if no_memory:  # the ablation: the program's bank zeroed first
                            for r in range(u_m):
                                for k in range(n):
                                    Wf[u_bank + r * L + grp[k]] = 0.0
                        elif bank_mark[row[P_LBANK]] != n_blocks:
                            # first use in this block, where every lane's episode began:
                            # zeroed for every lane, as at each episode's start
                            for i in range(u_bank, u_bank + u_m * L):
                                Wf[i] = 0.0
                            bank_mark[row[P_LBANK]] = n_blocks
                        zm = row[P_ZERO]
                        if zm == -1:  # every private register
                            for r in range(np.uint64(R)):
                                for k in range(n):
                                    Wf[r * L + grp[k]] = 0.0
                        else:  # the registers the program reads before writing them
                            bits = np.uint64(zm)
                            r = np.uint64(0)
                            while bits != 0:
                                if bits & np.uint64(1):
                                    for k in range(n):
                                        Wf[r * L + grp[k]] = 0.0
                                bits >>= np.uint64(1)
                                r += np.uint64(1)
                        for i in range(row[P_LO], row[P_HI]):
                            c = lcode[i]
                            lane_op(Wf, c[C_OP], c[C_DST], c[C_A], c[C_MA], c[C_B], c[C_MB], grp, n)
                        team_ins += row[P_COUNT]
                        act = row[P_ACT]
                        # bids are finite, so starting from -inf the first eligible
                        # program wins and a later one only with a higher bid (ties: the
                        # earlier), as in the scalar kernel
                        if act < 0:
                            for k in range(n):
                                lane = grp[k]
                                if Wf[lane] > best[lane]:
                                    best[lane] = Wf[lane]
                                    best_p[lane] = q
                        else:
                            u_act = np.uint64(act) * L
                            for k in range(n):
                                lane = grp[k]
                                if visited[u_act + lane] != stamp and Wf[lane] > best[lane]:
                                    best[lane] = Wf[lane]
                                    best_p[lane] = q
                    for k in range(n):
                        lane = grp[k]
                        n_ins[lane] += team_ins
                        row = lprog[best_p[lane]]
                        act = row[P_ACT]
                        if act < 0:
                            a_d[lane] = -1 - act
                            a_c[lane] = Wf[np.uint64(row[P_BANK]) + lane]
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
            unlocalise(maps, lteam, lprog, lbank, counts)


@njit(cache=True, error_model="numpy", parallel=True)
def run_lanes_parallel(n_workers, next_block, block, lanes, jobs, table, out, g):
    """Runs all jobs on ``n_workers`` lane-engine workers sharing one queue."""
    for _ in prange(n_workers):
        run_lanes_queue(next_block, block, lanes, jobs, table, out, g)
