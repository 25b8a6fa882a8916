"""A lane block's own copy of its graph: compact, relocated, its operands pre-translated.

A lane block plays its roots' graphs for hundreds of steps, so before the first step the
lane engine copies what those graphs use out of the population's compiled arrays
(:class:`~mtpg.engine.compile.Graph`): the teams reachable from the block's roots
numbered from 0, each team's programs as rows of one table (code range, action as a local
team, bank, instruction count, registers to zero), each program's code once with its
operands translated to the lane workspace, and the banks numbered from 0. The decision
loop then reads one table row per program and no address arithmetic per instruction, and
its workspace holds only the block's banks.

Lane workspace (``Wf``, float64): row ``r`` of lane ``l`` is ``Wf[r * lanes + l]``; rows
``[0, R)`` are the private registers, ``[R, R + n_obs)`` the observation, then ``M`` rows
per local bank. The 18 constants and the folded constants, the same in every lane, are
stored once each after all rows (at ``shared``), and a lane reads them through a zero lane
mask (:func:`~mtpg.engine.lane_ops.lane_op`).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from mtpg.model.instructions import N_CONSTANTS, OP_READS, READS_A, READS_B, READS_TARGET

#: Columns of a program row of the local table.
P_LO, P_HI, P_ACT, P_BANK, P_COUNT, P_ZERO, P_GLOBAL, P_LBANK = range(8)
#: Columns of a translated instruction: op code, target, operands and their lane masks.
C_OP, C_DST, C_A, C_MA, C_B, C_MB = range(6)

ALL_LANES = np.uint64(0xFFFFFFFFFFFFFFFF)


@njit(cache=True, error_model="numpy")
def registers_to_zero(instrs, lo, hi, R):
    """The private registers a program may read before writing them, as a bit mask.

    The scalar kernel zeroes all ``R`` registers before every program run; a register the
    program writes before any read of it never shows the old value, so only the registers
    read first need the zero, and ``r[0]`` (the bid) when the program never writes it. The
    operands each op code reads are :data:`~mtpg.model.instructions.OP_READS`'s. Only for
    ``R <= 64``: the caller zeroes every register otherwise.
    """
    one = np.uint64(1)
    written = np.uint64(0)
    need = np.uint64(0)
    for i in range(lo, hi):
        op, dst, a, b = instrs[i, 0], instrs[i, 1], instrs[i, 2], instrs[i, 3]
        reads = OP_READS[op]
        for src, bit in ((b, READS_B), (a, READS_A), (dst, READS_TARGET)):
            if reads & bit and src < R and not (written >> np.uint64(src)) & one:
                need |= one << np.uint64(src)
        if dst < R:
            written |= one << np.uint64(dst)
    if not written & one:
        need |= one
    return need


@njit(cache=True, error_model="numpy", inline="always")
def _bank_of(bank, bank_map, lbank, counts):
    """The local number of global bank ``bank``, numbering it when new (``counts[3]``)."""
    if bank_map[bank] < 0:
        bank_map[bank] = counts[3]
        lbank[counts[3]] = bank
        counts[3] += 1
    return bank_map[bank]


@njit(cache=True, error_model="numpy", inline="always")
def _operand(x, g, lanes, shared, bank_map, lbank, counts):
    """Lane-workspace address and lane mask of scalar-workspace address ``x``."""
    R, M, base = g.n_registers, g.n_memory, g.mem_base
    K = len(g.folded)
    n_obs = base - K - (R + N_CONSTANTS)
    if x < R:
        return np.uint64(x * lanes), ALL_LANES
    if x < R + N_CONSTANTS:
        return np.uint64(shared + x - R), np.uint64(0)
    if x < R + N_CONSTANTS + n_obs:
        return np.uint64((x - N_CONSTANTS) * lanes), ALL_LANES
    if x < base:
        return np.uint64(shared + N_CONSTANTS + x - (base - K)), np.uint64(0)
    bank = _bank_of((x - base) // M, bank_map, lbank, counts)
    row = R + n_obs + bank * M + (x - base) % M
    return np.uint64(row * lanes), ALL_LANES


class LocalGraph(NamedTuple):
    """A lane block's own graph (:func:`localise`), one per worker, rewritten per block.

    Attributes:
        maps: int64 ``[3, max(n_teams, n_programs, n_banks)]``: global to local team,
            program (start of its code in ``code``) and bank; -1 where none, as
            :func:`unlocalise` leaves them.
        teams: int64: local team -> global team.
        team_offsets: int64: the programs of local team ``t`` are rows
            ``team_offsets[t]:team_offsets[t + 1]`` of ``programs``.
        programs: int64 ``[len(team_members), 8]``: program rows (``P_*`` columns; the
            action as ``-1 - a`` or a local team; the bank as the workspace index of its
            row 0).
        code: uint64 ``[n_instructions, 6]``: translated code (``C_*`` columns).
        banks: int64: local bank -> global bank.
        counts: int64 ``[4]``: teams, program rows, code rows and banks of the block.
    """

    maps: np.ndarray
    teams: np.ndarray
    team_offsets: np.ndarray
    programs: np.ndarray
    code: np.ndarray
    banks: np.ndarray
    counts: np.ndarray


@njit(cache=True, error_model="numpy")
def new_local_graph(g) -> LocalGraph:
    """Allocates a :class:`LocalGraph` large enough for any block of the graph ``g``.

    Only ``maps`` must hold -1 from the start; the other arrays are written by
    :func:`localise` before they are read, so they are left unfilled (and a large
    population's arrays cost no page of memory that a block does not use).
    """
    n_teams = len(g.team_offsets) - 1
    n_progs = len(g.prog_offsets) - 1
    n_banks = (g.prog_bank.max() + 1) if n_progs else 0
    return LocalGraph(
        np.full((3, max(n_teams, n_progs, n_banks, 1)), -1, dtype=np.int64),
        np.empty(n_teams, dtype=np.int64),
        np.empty(n_teams + 1, dtype=np.int64),
        np.empty((len(g.team_members), 8), dtype=np.int64),
        np.empty((len(g.instrs), 6), dtype=np.uint64),
        np.empty(max(n_banks, 1), dtype=np.int64),
        np.zeros(4, dtype=np.int64),
    )


@njit(cache=True, error_model="numpy", inline="always")
def _reachable(g, roots, lg):
    """Numbers the teams reachable from ``roots`` breadth first; returns their number."""
    team_map, lteam = lg.maps[0], lg.teams
    n_lt = 0
    for r in roots:
        if team_map[r] < 0:
            team_map[r] = n_lt
            lteam[n_lt] = r
            n_lt += 1
    i = 0
    while i < n_lt:
        t = lteam[i]
        i += 1
        for k in range(g.team_offsets[t], g.team_offsets[t + 1]):
            a = g.prog_action[g.team_members[k]]
            if a >= 0 and team_map[a] < 0:
                team_map[a] = n_lt
                lteam[n_lt] = a
                n_lt += 1
    return n_lt


@njit(cache=True, error_model="numpy", inline="always")
def _translate(g, p, lanes, shared, lg, n_lc):
    """Writes program ``p``'s code to ``lg.code`` from row ``n_lc``, operands translated."""
    bank_map, lbank, counts, lcode = lg.maps[2], lg.banks, lg.counts, lg.code
    for j in range(g.prog_offsets[p], g.prog_offsets[p + 1]):
        ins = g.instrs[j]
        d, _ = _operand(ins[1], g, lanes, shared, bank_map, lbank, counts)
        ua, ma = _operand(ins[2], g, lanes, shared, bank_map, lbank, counts)
        ub, mb = _operand(ins[3], g, lanes, shared, bank_map, lbank, counts)
        lcode[n_lc, C_OP] = ins[0]
        lcode[n_lc, C_DST] = d
        lcode[n_lc, C_A] = ua
        lcode[n_lc, C_MA] = ma
        lcode[n_lc, C_B] = ub
        lcode[n_lc, C_MB] = mb
        n_lc += 1
    return n_lc


@njit(cache=True, error_model="numpy")
def localise(g, roots, lanes, shared, lg):
    """Builds the block's local graph :class:`LocalGraph` ``lg`` from the dense roots.

    Args:
        g: The compiled graph.
        roots: int64 dense root teams of the block (distinct).
        lanes: Lanes per row of the workspace.
        shared: Workspace index of the shared constants.
        lg: The worker's :class:`LocalGraph`, its ``maps`` all -1 (written: the block's
            teams, programs, code and banks, and their ``counts``).
    """
    team_map, prog_map, bank_map = lg.maps[0], lg.maps[1], lg.maps[2]
    lteam_off, lprog, counts = lg.team_offsets, lg.programs, lg.counts
    R, M = g.n_registers, g.n_memory
    n_obs = g.mem_base - len(g.folded) - (R + N_CONSTANTS)
    n_lt = _reachable(g, roots, lg)
    counts[3] = 0  # the banks, numbered as programs name them
    n_lp = 0
    n_lc = 0
    for lt in range(n_lt):
        t = lg.teams[lt]
        lteam_off[lt] = n_lp
        for k in range(g.team_offsets[t], g.team_offsets[t + 1]):
            p = g.team_members[k]
            lo, hi = g.prog_offsets[p], g.prog_offsets[p + 1]
            if prog_map[p] < 0:  # the code once per program, however many teams hold it
                prog_map[p] = n_lc
                n_lc = _translate(g, p, lanes, shared, lg, n_lc)
            a = g.prog_action[p]
            bank = _bank_of(g.prog_bank[p], bank_map, lg.banks, counts)
            lprog[n_lp, P_LO] = prog_map[p]
            lprog[n_lp, P_HI] = prog_map[p] + (hi - lo)
            lprog[n_lp, P_ACT] = a if a < 0 else team_map[a]
            lprog[n_lp, P_BANK] = (R + n_obs + bank * M) * lanes
            lprog[n_lp, P_COUNT] = g.prog_count[p]
            lprog[n_lp, P_ZERO] = (
                np.int64(registers_to_zero(g.instrs, lo, hi, R)) if R <= 64 else -1
            )
            lprog[n_lp, P_GLOBAL] = p
            lprog[n_lp, P_LBANK] = bank
            n_lp += 1
    lteam_off[n_lt] = n_lp
    counts[0], counts[1], counts[2] = n_lt, n_lp, n_lc


@njit(cache=True, error_model="numpy")
def unlocalise(lg):
    """Resets the entries of ``lg.maps`` that :func:`localise` set, back to -1."""
    maps, counts = lg.maps, lg.counts
    for i in range(counts[0]):
        maps[0, lg.teams[i]] = -1
    for i in range(counts[1]):
        maps[1, lg.programs[i, P_GLOBAL]] = -1
    for i in range(counts[3]):
        maps[2, lg.banks[i]] = -1
