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

from typing import NamedTuple

import numpy as np
from numba import njit, prange

from mtpg.engine.episode_kernels import _fetch_add
from mtpg.engine.lane_decide import BLOCK_MARK, STEP_MARK, decide_lanes
from mtpg.engine.lane_graph import localise, new_local_graph, unlocalise
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

#: Lanes of one block when the caller does not choose: one root's training episodes
#: (6 tasks x 5) fit in one block; results do not depend on it.
DEFAULT_LANES = 32


class Lanes(NamedTuple):
    """One lane-engine worker's buffers (:func:`lane_buffers`), allocated once per worker.

    Per-lane arrays have one entry per lane of a block (``len(job)`` is the lane count).

    Attributes:
        W: float64 lane workspace (:mod:`mtpg.engine.lane_graph`: a row per register,
            observation input and bank register, a column per lane; then the constants).
        state: float64 ``[lanes, STATE_SIZE]``: each lane's task state.
        obs: float64 ``[n_obs]``: one lane's observation as its task writes it.
        visited: int64 ``[n_teams * lanes]``: decision mark per local team and lane.
        bank_mark: int64 ``[n_banks]``: block mark of each local bank's last zeroing.
        roots: int64 ``[lanes]``: the block's distinct roots.
        marks: int64 ``[2]``: the decision's and the block's marks
            (:data:`~mtpg.engine.lane_decide.STEP_MARK`, ``BLOCK_MARK``).
        job: int64: each lane's job.
        kind: int64: each lane's task kind (its step kernel).
        okind: int64: each lane's observation kind.
        noisy: bool: each lane's task adds observation noise.
        start: int64: each lane's root, as a local team.
        live: int64: the live lanes (the first ``n_live``).
        total: float64: each lane's return so far.
        n_team: int64: teams each lane visited in its episode.
        n_ins: int64: instructions each lane executed in its episode.
        best: float64: each lane's best bid in the team being run.
        best_p: int64: the program row of that bid.
        a_d: int64: each lane's atomic action of the decision.
        a_c: float64: each lane's continuous action of the decision.
        a_off: uint64: each lane's index in ``W`` of ``m[0]`` of the decision's bank
            (``m[j]`` at ``a_off + j * lanes``).
        pend_team: int64: the local team of each pending lane of the decision.
        pend_lane: int64: the pending lanes.
        grp: uint64: the lanes of the group being run.
    """

    W: np.ndarray
    state: np.ndarray
    obs: np.ndarray
    visited: np.ndarray
    bank_mark: np.ndarray
    roots: np.ndarray
    marks: np.ndarray
    job: np.ndarray
    kind: np.ndarray
    okind: np.ndarray
    noisy: np.ndarray
    start: np.ndarray
    live: np.ndarray
    total: np.ndarray
    n_team: np.ndarray
    n_ins: np.ndarray
    best: np.ndarray
    best_p: np.ndarray
    a_d: np.ndarray
    a_c: np.ndarray
    a_off: np.ndarray
    pend_team: np.ndarray
    pend_lane: np.ndarray
    grp: np.ndarray


@njit(cache=True, error_model="numpy")
def lane_buffers(g, lanes) -> Lanes:
    """Allocates one worker's :class:`Lanes` for ``lanes`` lanes of the compiled graph ``g``.

    The workspace has a row for every bank of the population, but a block uses only its
    own banks' rows (numbered from 0): it is left unfilled (what a block reads it has
    written or zeroed first), so its untouched pages cost no memory and no page fault.
    """
    R, M, base = g.n_registers, g.n_memory, g.mem_base
    n_teams = len(g.team_offsets) - 1
    n_banks = (g.prog_bank.max() + 1) if len(g.prog_bank) else 0
    K = len(g.folded)
    n_obs = base - K - (R + N_CONSTANTS)
    shared = (R + n_obs + n_banks * M) * lanes
    W = np.empty(shared + N_CONSTANTS + K)
    for i in range(N_CONSTANTS):
        W[shared + i] = _CONSTANTS[i]
    for i in range(K):
        W[shared + N_CONSTANTS + i] = g.folded[i]
    return Lanes(
        W=W,
        state=np.zeros((lanes, STATE_SIZE)),
        obs=np.zeros(n_obs),
        visited=np.full(n_teams * lanes, -1, dtype=np.int64),
        bank_mark=np.zeros(max(n_banks, 1), dtype=np.int64),
        roots=np.zeros(lanes, dtype=np.int64),
        marks=np.zeros(2, dtype=np.int64),
        job=np.zeros(lanes, dtype=np.int64),
        kind=np.zeros(lanes, dtype=np.int64),
        okind=np.zeros(lanes, dtype=np.int64),
        noisy=np.zeros(lanes, dtype=np.bool_),
        start=np.zeros(lanes, dtype=np.int64),
        live=np.zeros(lanes, dtype=np.int64),
        total=np.zeros(lanes),
        n_team=np.zeros(lanes, dtype=np.int64),
        n_ins=np.zeros(lanes, dtype=np.int64),
        best=np.zeros(lanes),
        best_p=np.zeros(lanes, dtype=np.int64),
        a_d=np.zeros(lanes, dtype=np.int64),
        a_c=np.zeros(lanes),
        a_off=np.zeros(lanes, dtype=np.uint64),
        pend_team=np.zeros(lanes, dtype=np.int64),
        pend_lane=np.zeros(lanes, dtype=np.int64),
        grp=np.zeros(lanes, dtype=np.uint64),
    )


@njit(cache=True, error_model="numpy", inline="always")
def _write_obs(W, obs, at, L):
    """Writes the observation ``obs`` into a lane's column: input ``i`` at ``at + i * L``.

    ``obs`` has the layout's ``n_obs`` slots (a task observing fewer has zeroed the rest,
    as in the scalar loop, where ``obs`` is a view of the workspace).
    """
    for i in range(len(obs)):
        W[at + np.uint64(i) * L] = obs[i]


@njit(cache=True, error_model="numpy", inline="always")
def _block_roots(jobs, s, nl, lg, roots):
    """Lists the distinct roots of jobs ``s .. s + nl - 1`` in ``roots``; returns how many."""
    team_map = lg.maps[0]
    n_roots = 0
    for k in range(nl):
        r = jobs.roots[s + k]
        if team_map[r] < 0:  # a root not yet listed (marked until localise renumbers)
            team_map[r] = 0
            roots[n_roots] = r
            n_roots += 1
    for k in range(n_roots):
        team_map[roots[k]] = -1
    return n_roots


@njit(cache=True, error_model="numpy")
def start_lanes(g, jobs, table, s, nl, lb, lg):
    """Starts the episodes of jobs ``s .. s + nl - 1`` in lanes ``0 .. nl - 1``.

    Each lane's task is reset and observed (the observation written to the lane's column
    of the workspace), its root is taken as a local team of ``lg`` and its counts are
    zeroed; every lane is live.
    """
    W, state, obs = lb.W, lb.state, lb.obs
    L = np.uint64(len(lb.job))
    u_obs = np.uint64(g.n_registers) * L
    for k in range(nl):
        j = s + k
        e = jobs.episodes[j]
        p = table.params[table.tasks[e]]
        lb.job[k] = j
        lb.start[k] = lg.maps[0, jobs.roots[j]]
        lb.kind[k] = np.int64(p[P_KIND])
        lb.okind[k] = observe_kind(p)
        lb.noisy[k] = p[P_OBS_SD] != 0.0
        env_reset(table.tasks[e], table.params, table.starts[e], state[k])
        task_observe(lb.okind[k], p, state[k], table.noise[e, 0], obs)
        if lb.noisy[k]:
            add_obs_noise(p, table.obs_noise[e, 0, 0], table.obs_noise[e, 0, 1], obs)
        _write_obs(W, obs, u_obs + np.uint64(k), L)
        lb.total[k] = 0.0
        lb.n_team[k] = 0
        lb.n_ins[k] = 0
        lb.live[k] = k


@njit(cache=True, error_model="numpy", inline="always")
def step_lanes(g, jobs, table, out, lb, n_live, t):
    """Steps each live lane's task with its action; writes the results of ended episodes.

    Args:
        g: The compiled graph.
        jobs: :class:`~mtpg.engine.batch.Jobs`.
        table: :class:`~mtpg.engine.batch.Episodes`.
        out: :class:`~mtpg.engine.batch.BatchResult`, written at each ended job's index.
        lb: The worker's :class:`Lanes`, the decision's actions in ``a_d`` and ``a_c``.
        n_live: Live lanes (``lb.live[:n_live]``).
        t: Steps taken, this one included.

    Returns:
        The lanes still live (the first of ``lb.live``), each observing its next state.
    """
    W, state, obs, live = lb.W, lb.state, lb.obs, lb.live
    L = np.uint64(len(lb.job))
    u_obs = np.uint64(g.n_registers) * L
    m = 0
    for k in range(n_live):
        lane = live[k]
        j = lb.job[lane]
        e = jobs.episodes[j]
        p = table.params[table.tasks[e]]
        task_continuous(lb.kind[lane], p, state[lane], W, lb.a_off[lane], L)
        reward, terminated, truncated = task_step(
            lb.kind[lane], p, state[lane], lb.a_d[lane], lb.a_c[lane]
        )
        lb.total[lane] += reward
        if terminated or truncated:
            out.returns[j] = lb.total[lane]
            out.steps[j] = t
            out.teams[j] = lb.n_team[lane]
            out.instructions[j] = lb.n_ins[lane]
            continue
        task_observe(lb.okind[lane], p, state[lane], table.noise[e, t], obs)
        if lb.noisy[lane]:
            add_obs_noise(p, table.obs_noise[e, t, 0], table.obs_noise[e, t, 1], obs)
        _write_obs(W, obs, u_obs + np.uint64(lane), L)
        live[m] = lane
        m += 1
    return m


@njit(cache=True, error_model="numpy", _nrt=False)
def play_block(g, jobs, table, out, lg, lb, nl):
    """Plays the started episodes of a lane block's ``nl`` lanes to their ends.

    Until every episode has ended: one decision of every live lane
    (:func:`~mtpg.engine.lane_decide.decide_lanes`), then one step of their tasks
    (:func:`step_lanes`), both inlined here. Compiled without Numba's reference counting
    (``_nrt=False``, as the task dispatch, :data:`~mtpg.envs.dynamics.dispatch.step_kernel`):
    the steps read the buffers of named tuples and take views of them, and with reference
    counting each such read costs an atomic increment and decrement (the engine ran at
    3/4 of the speed). It allocates nothing, so it needs none.
    """
    n_live = nl
    t = 0
    while n_live > 0:
        lb.marks[STEP_MARK] += 1  # the decision's mark: the teams it visited
        decide_lanes(g, lg, lb, n_live)
        t += 1
        n_live = step_lanes(g, jobs, table, out, lb, n_live, t)


@njit(cache=True, error_model="numpy", nogil=True)
def run_lanes_queue(next_block, block, lanes, jobs, table, out, g):
    """One worker of the lane engine: takes blocks of jobs from a shared queue.

    The queue is :func:`~mtpg.engine.episode_kernels.run_jobs_queue`'s (block ``b`` is jobs
    ``b * block ... (b + 1) * block - 1``); each queue block is played in lane blocks of
    up to ``lanes`` consecutive jobs. Jobs of a lane block may have different roots. Per
    lane block: its local graph (:func:`~mtpg.engine.lane_graph.localise`), its lanes'
    episodes started (:func:`start_lanes`) and played to their ends (:func:`play_block`).
    The buffers are allocated once per worker (:func:`lane_buffers`).

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
    lb = lane_buffers(g, lanes)
    lg = new_local_graph(g)
    shared = len(lb.W) - N_CONSTANTS - len(g.folded)  # the shared constants' index
    n_jobs = len(jobs.roots)
    while True:
        first = _fetch_add(next_block) * block
        if first >= n_jobs:
            break
        last = min(first + block, n_jobs)
        for s in range(first, last, lanes):
            nl = min(lanes, last - s)
            n_roots = _block_roots(jobs, s, nl, lg, lb.roots)
            localise(g, lb.roots[:n_roots], lanes, shared, lg)
            lb.marks[BLOCK_MARK] += 1  # the block's mark: its banks are zeroed when first used
            start_lanes(g, jobs, table, s, nl, lb, lg)
            play_block(g, jobs, table, out, lg, lb, nl)
            unlocalise(lg)


@njit(cache=True, error_model="numpy", parallel=True)
def run_lanes_parallel(n_workers, next_block, block, lanes, jobs, table, out, g):
    """Runs all jobs on ``n_workers`` lane-engine workers sharing one queue."""
    for _ in prange(n_workers):
        run_lanes_queue(next_block, block, lanes, jobs, table, out, g)
