"""One decision of every live lane of a block: the lane engine's decision, in named steps.

The lanes standing at the same team form a *group* (:func:`_take_group`); each program
of the team runs once over the group (:func:`run_team`: its bank and registers zeroed
where the program must see zeros, then its code, one :func:`~mtpg.engine.lane_ops.lane_op`
per instruction), and each lane keeps its own highest bid under its own visited-team
rule (:func:`_bid`); then each lane follows its winner (:func:`_follow`) to an atomic
action or into the group of the next team. The bid rule is the engine's one,
:func:`mtpg.engine.bid_rule.takes_lead`, which the scalar kernel
(:func:`mtpg.engine.episode_kernels.decide_bank`) calls too: each lane decides as the
scalar kernel does (tested job by job).

Every step is inlined into :func:`decide_lanes` (``inline="always"``), and that into the
lane engine's loop (:func:`mtpg.engine.lanes.run_lanes_queue`), so the steps cost no
call. They read the worker's buffers (:class:`~mtpg.engine.lanes.Lanes`, ``lb``) and the
block's graph (:class:`~mtpg.engine.lane_graph.LocalGraph`, ``lg``); ``lb.marks`` holds
the decision's mark (visited teams) and the block's mark (banks zeroed in this block).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from mtpg.engine.bid_rule import NO_BID, takes_lead
from mtpg.engine.lane_graph import P_ACT, P_BANK, P_COUNT, P_HI, P_LBANK, P_LO, P_ZERO
from mtpg.engine.lane_ops import lane_op

#: Slots of ``Lanes.marks``: the decision's mark and the block's mark.
STEP_MARK, BLOCK_MARK = 0, 1


@njit(cache=True, error_model="numpy", inline="always")
def _take_group(lb, team, n_pend):
    """Moves the pending lanes standing at ``team`` into ``lb.grp``.

    Returns:
        ``(n, n_pend)``: the group's size and the lanes still pending.
    """
    pend_team, pend_lane, grp = lb.pend_team, lb.pend_lane, lb.grp
    n = 0
    m = 0
    for k in range(n_pend):
        if pend_team[k] == team:
            grp[n] = np.uint64(pend_lane[k])
            n += 1
        else:
            pend_team[m] = pend_team[k]
            pend_lane[m] = pend_lane[k]
            m += 1
    return n, m


@njit(cache=True, error_model="numpy", inline="always")
def _enter(lb, u_team, n):
    """The group enters local team ``u_team``: marked visited, counted, no bid yet."""
    visited, n_team, best, grp = lb.visited, lb.n_team, lb.best, lb.grp
    L = np.uint64(len(lb.job))
    stamp = lb.marks[STEP_MARK]
    for k in range(n):
        lane = grp[k]
        visited[u_team * L + lane] = stamp
        n_team[lane] += 1
        best[lane] = NO_BID


@njit(cache=True, error_model="numpy", inline="always")
def _zero_memory(g, lb, row, n):
    """Zeroes the program's bank where the program must find it zeroed.

    In the no-memory ablation, for the group before every run. Otherwise at the bank's
    first use in the block, where every lane's episode began: for every lane, as at each
    episode's start.
    """
    W, grp, bank_mark = lb.W, lb.grp, lb.bank_mark
    L = np.uint64(len(lb.job))
    u_m = np.uint64(g.n_memory)
    u_bank = np.uint64(row[P_BANK])
    if g.no_memory:
        for r in range(u_m):
            for k in range(n):
                W[u_bank + r * L + grp[k]] = 0.0
    elif bank_mark[row[P_LBANK]] != lb.marks[BLOCK_MARK]:
        for i in range(u_bank, u_bank + u_m * L):
            W[i] = 0.0
        bank_mark[row[P_LBANK]] = lb.marks[BLOCK_MARK]


@njit(cache=True, error_model="numpy", inline="always")
def _zero_registers(g, lb, row, n):
    """Zeroes the group's private registers the program reads before writing them."""
    W, grp = lb.W, lb.grp
    L = np.uint64(len(lb.job))
    zm = row[P_ZERO]
    if zm == -1:  # every private register
        for r in range(np.uint64(g.n_registers)):
            for k in range(n):
                W[r * L + grp[k]] = 0.0
    else:  # the registers the program reads before writing them
        bits = np.uint64(zm)
        r = np.uint64(0)
        while bits != 0:
            if bits & np.uint64(1):
                for k in range(n):
                    W[r * L + grp[k]] = 0.0
            bits >>= np.uint64(1)
            r += np.uint64(1)


@njit(cache=True, error_model="numpy", inline="always")
def _bid(lb, row, q, n):
    """Each lane of the group takes program row ``q`` where the engine's bid rule says so.

    The rule is :func:`~mtpg.engine.bid_rule.takes_lead`, with each lane's own best bid
    (from :data:`~mtpg.engine.bid_rule.NO_BID`, set by :func:`_enter`) and its own visit
    marks. The atomic case is a loop of its own, so the group's loop reads no visit mark
    (the rule's ``act < 0`` is known there).
    """
    W, grp, best, best_p, visited = lb.W, lb.grp, lb.best, lb.best_p, lb.visited
    act = row[P_ACT]
    stamp = lb.marks[STEP_MARK]
    if act < 0:
        for k in range(n):
            lane = grp[k]
            if takes_lead(act, visited, lane, stamp, W[lane], best[lane]):
                best[lane] = W[lane]
                best_p[lane] = q
    else:
        u_act = np.uint64(act) * np.uint64(len(lb.job))
        for k in range(n):
            lane = grp[k]
            if takes_lead(act, visited, u_act + lane, stamp, W[lane], best[lane]):
                best[lane] = W[lane]
                best_p[lane] = q


@njit(cache=True, error_model="numpy", inline="always")
def run_team(g, lg, lb, team, n):
    """Runs every program of local team ``team`` over the group ``lb.grp[:n]``.

    Returns:
        The instructions the team counts (as stated, folded or not) for each lane.
    """
    u_team = np.uint64(team)
    _enter(lb, u_team, n)
    W, grp, code = lb.W, lb.grp, lg.code
    team_ins = 0
    for q in range(lg.team_offsets[u_team], lg.team_offsets[u_team + np.uint64(1)]):
        row = lg.programs[q]
        _zero_memory(g, lb, row, n)
        _zero_registers(g, lb, row, n)
        for i in range(row[P_LO], row[P_HI]):
            lane_op(W, code[i], grp, n)
        team_ins += row[P_COUNT]
        _bid(lb, row, q, n)
    return team_ins


@njit(cache=True, error_model="numpy", inline="always")
def _follow(lg, lb, n, team_ins, n_pend):
    """Each lane of the group follows its winner: an atomic action, or the next team.

    Returns:
        The lanes pending after the group's lanes that move to a team are appended.
    """
    W, grp, best_p = lb.W, lb.grp, lb.best_p
    pend_team, pend_lane, n_ins = lb.pend_team, lb.pend_lane, lb.n_ins
    for k in range(n):
        lane = grp[k]
        n_ins[lane] += team_ins
        row = lg.programs[best_p[lane]]
        act = row[P_ACT]
        if act < 0:
            lb.a_d[lane] = -1 - act
            at = np.uint64(row[P_BANK]) + lane  # m[0] of the bank; m[j] at at + j * L
            lb.a_off[lane] = at
            lb.a_c[lane] = W[at]
        else:
            pend_team[n_pend] = act
            pend_lane[n_pend] = np.int64(lane)
            n_pend += 1
    return n_pend


@njit(cache=True, error_model="numpy", inline="always")
def decide_lanes(g, lg, lb, n_live):
    """One decision for each of the live lanes ``lb.live[:n_live]``.

    Writes each lane's action to ``lb.a_d`` and ``lb.a_c`` and adds its teams visited and
    instructions executed to ``lb.n_team`` and ``lb.n_ins``.
    """
    live, start, pend_team, pend_lane = lb.live, lb.start, lb.pend_team, lb.pend_lane
    for k in range(n_live):
        pend_team[k] = start[live[k]]
        pend_lane[k] = live[k]
    n_pend = n_live
    while n_pend > 0:
        team = pend_team[0]
        n, n_pend = _take_group(lb, team, n_pend)
        team_ins = run_team(g, lg, lb, team, n)
        n_pend = _follow(lg, lb, n, team_ins, n_pend)
