"""What every exporter needs: the reachable graph, introns removed, and its provenance.

:func:`prepare` turns a population and a root into an :class:`ExportGraph`: only the
teams reachable from the root (depth-first from it, the root first), the programs they
hold (in order of first use) with their introns removed exactly as the engine removes
them (:func:`mtpg.engine.compile.effective_mask`), and the memory banks those
programs point to, all renumbered densely from 0. The code generators then only print.

The execution semantics the generated code reproduces are those of
:func:`mtpg.engine.episode_kernels.decide` and :func:`mtpg.engine.ops.apply_op`:

* a decision starts at the root with no team visited; visiting a team marks it, then runs
  ALL its programs in team order (losers write memory too); each run zeroes the private
  registers ``r`` and, in no-memory mode, first zeroes the program's bank;
* the winner is the highest bid ``r[0]`` among programs whose action is atomic or points
  to a team not yet visited in this decision; ties go to the earlier program;
* an atomic winner ends the decision with ``(a_d, a_c)`` = its action and ``m[0]`` of its
  bank as it is after the whole team ran; a pointer winner moves to its team;
* banks are zeroed at the start of every episode (the engine zeroes lazily, which is the
  same thing because a program touches only its own bank).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from mtpg.engine.compile import effective_mask
from mtpg.export.lowering import Operand, Statement, lower
from mtpg.model.graph import Population
from mtpg.model.instructions import (
    BIG,
    DIV_EPS,
    LOG_BIG,
    LOG_TINY,
    RegisterLayout,
)

#: Numeric constants of the protected operation table, by the name the generated code uses.
TABLE_CONSTANTS: dict[str, float] = {
    "BIG": BIG,
    "LOG_BIG": LOG_BIG,
    "LOG_TINY": LOG_TINY,
    "DIV_EPS": DIV_EPS,
}

#: Observations of the paper's tasks (the generated code takes ``layout.n_obs``).
N_OBS = 2


def action_text(n_actions: int) -> str:
    """The atomic actions as the generated code's comments name them (``0, 1 or 2``)."""
    if n_actions == 1:
        return "0"
    names = [str(a) for a in range(n_actions)]
    if n_actions > 4:
        names = ["0", "...", str(n_actions - 1)]
    return ", ".join(names[:-1]) + " or " + names[-1]


@dataclass(frozen=True)
class ExportProgram:
    """One program of the exported graph.

    Attributes:
        id: Program id in the source population.
        code: int ``(n, 4)`` effective instructions (logical operand layout).
        n_total: Instructions before intron removal.
        bank: Dense bank index.
        target: Dense team index it points to, or ``-1 - a`` for atomic action ``a``.
        body: The statements to generate (:func:`mtpg.export.lowering.lower`).
        bid: The bid operand: ``("r", 0)`` or a literal ``("c", value)``.
        folded: Effective instructions evaluated at export time.
    """

    id: int
    code: np.ndarray
    n_total: int
    bank: int
    target: int
    body: list[Statement]
    bid: Operand
    folded: int

    @property
    def is_atomic(self) -> bool:
        """True when the program ends a decision."""
        return self.target < 0


@dataclass(frozen=True)
class ExportGraph:
    """A program graph reduced to what one root can execute.

    Attributes:
        layout: Register sizes.
        team_ids: Source team id of each dense team; index 0 is the root.
        teams: Dense program indices of each team, in execution order.
        programs: The programs, in order of first use.
        bank_ids: Source bank id of each dense bank.
        no_memory: Zero a program's bank before each of its runs (ablation mode).
        provenance: Ordered ``(label, value)`` facts printed in the generated header.
    """

    layout: RegisterLayout
    team_ids: list[int]
    teams: list[list[int]]
    programs: list[ExportProgram]
    bank_ids: list[int]
    no_memory: bool
    provenance: list[tuple[str, str]]

    @property
    def n_instructions(self) -> int:
        """Effective instructions over all programs."""
        return sum(len(p.code) for p in self.programs)

    @property
    def n_folded(self) -> int:
        """Effective instructions evaluated at export time."""
        return sum(p.folded for p in self.programs)

    @property
    def n_statements(self) -> int:
        """Assignments in the generated code."""
        return sum(len(p.body) for p in self.programs)

    @property
    def n_introns(self) -> int:
        """Instructions removed as introns."""
        return sum(p.n_total - len(p.code) for p in self.programs)

    def summary(self) -> str:
        """One line: teams, programs, banks, instructions and introns removed."""
        return (
            f"{len(self.teams)} teams, {len(self.programs)} programs, {len(self.bank_ids)} "
            f"memory banks, {self.n_instructions} instructions ({self.n_introns} introns "
            f"removed; {self.n_folded} evaluated at export time)"
        )


def prepare(
    pop: Population,
    root: int,
    *,
    no_memory: bool,
    source: str = "(in memory)",
    meta: dict[str, Any] | None = None,
    memory_description: str | None = None,
) -> ExportGraph:
    """Reduces a population to the graph of ``root``, ready for a code generator.

    Args:
        pop: The population holding the graph.
        root: Root team id.
        no_memory: Generate code that zeroes each bank before every program execution.
        source: Where the graph came from (printed as provenance).
        meta: The graph file's metadata (generation, seed, tasks, ``no_memory``).
        memory_description: How the memory setting was chosen (printed as provenance).

    Returns:
        The reduced graph.

    Raises:
        ValueError: When ``root`` is not a team of ``pop``.
    """
    if root not in pop.teams:
        raise ValueError(f"root team {root} is not in the population")
    layout = pop.layout
    team_ids = pop.reachable(root)
    team_index = {tid: k for k, tid in enumerate(team_ids)}
    prog_ids = list(dict.fromkeys(pid for tid in team_ids for pid in pop.teams[tid].programs))
    prog_index = {pid: k for k, pid in enumerate(prog_ids)}
    bank_ids = list(dict.fromkeys(pop.programs[pid].bank for pid in prog_ids))
    bank_index = {bid: k for k, bid in enumerate(bank_ids)}
    programs = []
    for pid in prog_ids:
        prog = pop.programs[pid]
        code = np.asarray(prog.instructions, dtype=np.int64)
        code = code[effective_mask(prog.instructions, layout)]
        target = prog.action if prog.is_atomic else team_index[prog.action]
        body, bid, folded = lower(code, layout, no_memory)
        programs.append(
            ExportProgram(
                pid, code, len(prog.instructions), bank_index[prog.bank], target, body, bid, folded
            )
        )
    teams = [[prog_index[pid] for pid in pop.teams[tid].programs] for tid in team_ids]
    meta = dict(meta or {})
    evolved_off = bool(meta.get("no_memory", False))
    provenance = [
        ("source", source),
        ("root team", str(root)),
        ("generation", str(meta.get("generation", "unknown"))),
        ("seed", str(meta.get("seed", "unknown"))),
        ("evolved", "without memory (TPG-NoMemory)" if evolved_off else "with memory"),
        (
            "exported",
            memory_description
            or ("memory off: banks zeroed before every program" if no_memory else "memory on"),
        ),
    ]
    if "tasks" in meta:
        provenance.append(("tasks", ", ".join(str(t) for t in meta["tasks"])))
    graph = ExportGraph(layout, team_ids, teams, programs, bank_ids, no_memory, provenance)
    graph.provenance.append(("graph", graph.summary()))
    return graph
