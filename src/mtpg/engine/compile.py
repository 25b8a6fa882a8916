"""Compiles a :class:`~mtpg.model.Population` into the flat arrays the kernels execute.

The kernels work on one float64 *workspace* per thread:

=================================  ==========================================
``[0, R)``                         private registers ``r``
``[R, R+18)``                      the constants
``[R+18, R+18+n_obs)``             the observation
``[R+18+n_obs, BASE)``             the folded constants (``Graph.folded``)
``[BASE + b*M, BASE+(b+1)*M)``     memory bank ``b`` (dense index)
=================================  ==========================================

Instruction operands are rewritten from the logical layout of
:mod:`mtpg.model.instructions` to absolute workspace indices, so a program touches its
memory bank in place with no copying. Introns are dropped here (:func:`effective_mask`),
and instructions whose result is known before the program runs are folded into
constants (:mod:`mtpg.engine.fold`; on by default, off for the tracer).

Only banks some program points to are compiled: a bank of the population that no program
uses (a fresh bank) can never be read or written, so it needs no workspace.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import NamedTuple

import numpy as np
from numba import njit

from mtpg.engine.fold import first_folded, folded_code
from mtpg.model.graph import Population, Program
from mtpg.model.instructions import (
    N_CONSTANTS,
    OP_READS,
    READS_A,
    READS_B,
    READS_TARGET,
    RegisterLayout,
)


class Graph(NamedTuple):
    """The compiled graph as every kernel takes it: one argument, unpacked in the kernel.

    A named tuple of arrays and sizes (Numba passes it as one typed argument), so two
    arrays can never be swapped at a call. The kernels read it in
    :func:`mtpg.engine.episode_kernels.decide`; docs/engine.md says where a new array goes.

    Attributes:
        team_offsets: int64 ``[n_teams + 1]``: members of team ``t`` are
            ``team_members[team_offsets[t]:team_offsets[t + 1]]``.
        team_members: int64: dense program indices, in execution order.
        prog_offsets: int64 ``[n_programs + 1]``: effective instructions of program ``p``
            are ``instrs[prog_offsets[p]:prog_offsets[p + 1]]``.
        instrs: uint32 ``[n, 4]``: ``op, dst, src1, src2`` as workspace indices (unsigned:
            no negative-index fix-up in the kernels).
        prog_action: int64 ``[n_programs]``: dense team index, or ``-1 - a`` for atomic
            action ``a``.
        prog_bank: int64 ``[n_programs]``: dense memory bank index.
        prog_count: int64 ``[n_programs]``: effective instructions of each program before
            folding (what the kernels count as executed, folded or not).
        folded: float64 ``[K]``: the folded constants, at workspace ``mem_base - K``.
        n_registers: Private registers per program (``R``).
        n_memory: Registers per memory bank (``M``).
        mem_base: Workspace index of memory bank 0.
        no_memory: The TPG-NoMemory ablation: every bank is zeroed before each program
            execution. A property of the compiled graph, read once per decision by the
            kernels (set by :func:`compile_population`).
    """

    team_offsets: np.ndarray
    team_members: np.ndarray
    prog_offsets: np.ndarray
    instrs: np.ndarray
    prog_action: np.ndarray
    prog_bank: np.ndarray
    prog_count: np.ndarray
    folded: np.ndarray
    n_registers: int
    n_memory: int
    mem_base: int
    no_memory: bool = False


@dataclass(frozen=True)
class CompiledPopulation:
    """A population as flat arrays: the kernels' :class:`Graph` and the ids behind it.

    Attributes:
        layout: Register sizes.
        graph: What the kernels execute (dense indices throughout).
        team_ids: int64 ``[n_teams]``: model team id of each dense team index.
        program_ids: int64 ``[n_programs]``: model program id of each dense index.
        bank_ids: int64 ``[n_banks]``: model bank id of each dense bank index.
        n_instructions: int64 ``[n_programs]``: instructions before intron removal.
        folded: Compiled with constant folding (the tracer refuses such code).
    """

    layout: RegisterLayout
    graph: Graph
    team_ids: np.ndarray
    program_ids: np.ndarray
    bank_ids: np.ndarray
    n_instructions: np.ndarray
    folded: bool = False

    @property
    def no_memory(self) -> bool:
        """Whether the graph runs with the no-memory ablation (:attr:`Graph.no_memory`)."""
        return self.graph.no_memory

    def with_memory_mode(self, no_memory: bool | None) -> CompiledPopulation:
        """This compiled population in memory mode ``no_memory`` (the arrays are shared).

        ``None`` keeps the compiled mode: the old ``no_memory=`` arguments of the run
        functions pass through here (deprecated: compile with ``no_memory`` instead).
        """
        if no_memory is None or bool(no_memory) == self.graph.no_memory:
            return self
        return replace(self, graph=self.graph._replace(no_memory=bool(no_memory)))

    @property
    def mem_base(self) -> int:
        """Workspace index of the first memory register."""
        return self.graph.mem_base

    def team_index(self, team_id: int) -> int:
        """Dense index of a model team id."""
        return int(np.searchsorted(self.team_ids, team_id))

    def bank_index(self, bank_id: int) -> int:
        """Dense index of a model bank id."""
        return int(np.searchsorted(self.bank_ids, bank_id))


@njit(cache=True, error_model="numpy")
def _effective_kernel(code: np.ndarray, n_r: int) -> np.ndarray:
    """Backward liveness pass of :func:`effective_mask` over ``code`` (logical operands)."""
    live = np.zeros(n_r, dtype=np.bool_)
    live[0] = True
    mask = np.zeros(len(code), dtype=np.bool_)
    for k in range(len(code) - 1, -1, -1):
        op, dst, a, b = code[k, 0], code[k, 1], code[k, 2], code[k, 3]
        reads = OP_READS[op]  # the operands the op reads
        if dst < n_r:
            if not live[dst]:
                continue
            if not reads & READS_TARGET:
                live[dst] = False
        mask[k] = True
        if reads & READS_B and b < n_r:
            live[b] = True
        if reads & READS_A and a < n_r:
            live[a] = True
        if reads & READS_TARGET and dst < n_r:
            live[dst] = True
    return mask


def effective_mask(instructions: np.ndarray, layout: RegisterLayout) -> np.ndarray:
    """Marks the instructions that can affect ``r[0]`` or any memory register.

    A backward liveness pass: the live set starts as ``{r[0]}``; every write to memory is
    effective (memory is stateful and shared); a write to ``r[i]`` is effective only when
    ``r[i]`` is live. An effective write kills its target unless the op reads it, then
    the operands the op reads (:data:`~mtpg.model.instructions.OP_READS`) become live.

    Args:
        instructions: int array ``(n, 4)``.
        layout: Register sizes.

    Returns:
        Boolean array of length ``n``; False marks an intron.
    """
    return _effective_kernel(np.ascontiguousarray(instructions, dtype=np.int32), layout.n_registers)


def effective_code(prog: Program, layout: RegisterLayout) -> np.ndarray:
    """The program's effective instructions (cached on the program)."""
    if prog.effective is None:
        prog.effective = prog.instructions[effective_mask(prog.instructions, layout)]
    return prog.effective


def compile_population(
    pop: Population,
    remove_introns: bool = True,
    fold_constants: bool = True,
    no_memory: bool = False,
) -> CompiledPopulation:
    """Flattens a population for the kernels.

    Args:
        pop: The population (all teams are compiled; roots are chosen at run time).
        remove_introns: Drop instructions that affect neither ``r[0]`` nor memory.
        fold_constants: Fold instructions whose result is known before the program runs
            (:mod:`mtpg.engine.fold`; needs ``remove_introns``). Results are identical
            either way; the tracer needs the code unfolded.
        no_memory: Compile for the no-memory ablation (every bank zeroed before each
            program execution; :attr:`Graph.no_memory`).

    Returns:
        The compiled population.
    """
    layout = pop.layout
    r, m = layout.n_registers, layout.n_memory
    team_ids = np.fromiter(pop.teams, dtype=np.int64, count=len(pop.teams))
    team_ids.sort()
    program_ids = np.fromiter(pop.programs, dtype=np.int64, count=len(pop.programs))
    program_ids.sort()
    progs = [pop.programs[int(pid)] for pid in program_ids]
    bank_of = np.array([p.bank for p in progs], dtype=np.int64)
    bank_ids, prog_bank = np.unique(bank_of, return_inverse=True)
    action = np.array([p.action for p in progs], dtype=np.int64)
    pointer = action >= 0
    prog_action = action.copy()
    prog_action[pointer] = np.searchsorted(team_ids, action[pointer])

    teams = [pop.teams[int(tid)].programs for tid in team_ids]
    sizes = np.array([len(t) for t in teams], dtype=np.int64)
    flat = np.fromiter((pid for t in teams for pid in t), dtype=np.int64, count=int(sizes.sum()))
    team_members = np.searchsorted(program_ids, flat)

    if remove_introns:
        blocks = [effective_code(p, layout) for p in progs]
    else:
        blocks = [p.instructions for p in progs]
    counts = np.array([len(b) for b in blocks], dtype=np.int64)
    fold = fold_constants and remove_introns
    pool = np.zeros(0)
    if fold:
        blocks, pool = _fold_blocks(progs, blocks, layout)
    lengths = np.array([len(b) for b in blocks], dtype=np.int64)
    code = np.concatenate(blocks) if blocks else np.zeros((0, 4), np.int32)
    mem_base = r + N_CONSTANTS + layout.n_obs + len(pool)
    instrs = _workspace_code(code, np.repeat(prog_bank, lengths), r, m, mem_base)
    graph = Graph(
        team_offsets=np.concatenate([[0], np.cumsum(sizes)]).astype(np.int64),
        team_members=team_members.astype(np.int64),
        prog_offsets=np.concatenate([[0], np.cumsum(lengths)]).astype(np.int64),
        instrs=instrs,
        prog_action=prog_action,
        prog_bank=prog_bank.astype(np.int64),
        prog_count=counts,
        folded=pool,
        n_registers=r,
        n_memory=m,
        mem_base=mem_base,
        no_memory=bool(no_memory),
    )
    return CompiledPopulation(
        layout=layout,
        graph=graph,
        team_ids=team_ids,
        program_ids=program_ids,
        bank_ids=bank_ids.astype(np.int64),
        n_instructions=np.array([len(p.instructions) for p in progs], dtype=np.int64),
        folded=fold,
    )


def _workspace_code(
    code: np.ndarray, bank_per_instr: np.ndarray, r: int, m: int, mem_base: int
) -> np.ndarray:
    """The instructions with their operands as workspace indices (uint32 ``(n, 4)``).

    Logical operands (registers ``r``, then memory ``m``, then constants, inputs and
    folded constants) map to the workspace of :mod:`mtpg.engine.compile`: a register
    stays, memory register ``j`` of an instruction goes to its program's bank
    (``mem_base + bank * m + j``), and the rest move down by ``m`` (the banks sit last).
    """
    operands = code[:, 1:].astype(np.int64)
    bank = bank_per_instr[:, None]
    mapped = np.where(
        operands < r,
        operands,
        np.where(operands < r + m, mem_base + bank * m + operands - r, operands - m),
    )
    instrs = np.empty_like(code, dtype=np.uint32)
    instrs[:, 0] = code[:, 0]
    instrs[:, 1:] = mapped
    return instrs


def _fold_blocks(
    progs: list[Program], blocks: list[np.ndarray], layout: RegisterLayout
) -> tuple[list[np.ndarray], np.ndarray]:
    """Folds every program and merges their pool values into one pool of distinct values.

    Returns:
        The folded blocks, their pool operands numbered in the merged pool (logical index
        :func:`~mtpg.engine.fold.first_folded` ``+ k``), and the merged pool.
    """
    folded = [folded_code(p, b, layout) for p, b in zip(progs, blocks, strict=True)]
    values = [v for _, v in folded]
    if not values or not sum(len(v) for v in values):
        return [c for c, _ in folded], np.zeros(0)
    flat = np.concatenate(values)
    # Distinct by bits (0.0 and -0.0 stay apart); the pool is sorted by bit pattern.
    bits, slot = np.unique(flat.view(np.int64), return_inverse=True)
    first = first_folded(layout)
    out, offset = [], 0
    for c, v in folded:
        if len(v):
            c = c.copy()
            pooled = c[:, 1:] >= first
            c[:, 1:][pooled] = first + slot[offset + c[:, 1:][pooled] - first]
            offset += len(v)
        out.append(c)
    return out, bits.view(np.float64)
