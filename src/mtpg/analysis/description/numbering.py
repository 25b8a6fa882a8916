"""The stable numbering of a program graph's teams, programs and banks.

Teams are numbered 1, 2, ... in the depth-first order of
:meth:`mtpg.model.graph.Population.reachable` from the root (the root is team 1), and
memory banks 1, 2, ... in order of first use by the programs of those teams. The
numbers depend on the graph alone, so every figure, listing
(:mod:`mtpg.analysis.description.listing`) and replay file of the same graph agrees on them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mtpg.engine.compile import effective_mask
from mtpg.model.graph import Population


@dataclass(frozen=True)
class GraphIndex:
    """Stable numbering of the teams, programs and banks of one graph.

    Attributes:
        root: Model id of the root team.
        teams: Model team ids in numbering order (``teams[0]`` is the root, number 1).
        programs: Model program ids in order of first use.
        banks: Model bank ids in order of first use.
    """

    root: int
    teams: tuple[int, ...]
    programs: tuple[int, ...]
    banks: tuple[int, ...]

    def team_number(self, team_id: int) -> int:
        """The 1-based number of a model team id."""
        return self.teams.index(team_id) + 1

    def bank_number(self, bank_id: int) -> int:
        """The 1-based number of a model bank id."""
        return self.banks.index(bank_id) + 1

    def edges(self, pop: Population) -> list[tuple[int, int, int]]:
        """``(from team, to team, program)`` model ids of every pointer between teams."""
        out = []
        for tid in self.teams:
            for pid in pop.teams[tid].programs:
                target = pop.programs[pid].action
                if target >= 0:
                    out.append((tid, target, pid))
        return out

    def depths(self, pop: Population) -> dict[int, int]:
        """Shortest number of edges from the root to each team (breadth-first)."""
        depth = {self.root: 0}
        frontier = [self.root]
        while frontier:
            nxt = []
            for tid in frontier:
                for pid in pop.teams[tid].programs:
                    target = pop.programs[pid].action
                    if target >= 0 and target not in depth:
                        depth[target] = depth[tid] + 1
                        nxt.append(target)
            frontier = nxt
        return depth


def index_graph(pop: Population, root: int) -> GraphIndex:
    """Numbers the teams, programs and banks reachable from ``root``.

    Raises:
        ValueError: When ``root`` is not a team of ``pop``.
    """
    if root not in pop.teams:
        raise ValueError(f"root team {root} is not in the population")
    teams = pop.reachable(root)
    programs = list(dict.fromkeys(pid for tid in teams for pid in pop.teams[tid].programs))
    banks = list(dict.fromkeys(pop.programs[pid].bank for pid in programs))
    return GraphIndex(root, tuple(teams), tuple(programs), tuple(banks))


def bank_users(pop: Population, index: GraphIndex) -> dict[int, list[tuple[int, int]]]:
    """Bank number -> ``(team number, program position 1..)`` of every program using it."""
    users: dict[int, list[tuple[int, int]]] = {k + 1: [] for k in range(len(index.banks))}
    for tid in index.teams:
        for k, pid in enumerate(pop.teams[tid].programs):
            bank = index.bank_number(pop.programs[pid].bank)
            users[bank].append((index.team_number(tid), k + 1))
    return users


def effective_instruction_map(pop: Population, program_ids: np.ndarray) -> tuple[np.ndarray, ...]:
    """For compiled instruction rows: the model program id and index of each instruction.

    The compiler keeps only effective instructions, in program order; this maps the
    compiled rows back to ``(program id, position in the program's full code)``.

    Args:
        pop: The population.
        program_ids: Model program ids in compiled (dense) order.

    Returns:
        ``(program, position)`` int64 arrays over all compiled instruction rows.
    """
    progs, positions = [], []
    for pid in program_ids:
        prog = pop.programs[int(pid)]
        where = np.flatnonzero(effective_mask(prog.instructions, pop.layout))
        progs.append(np.full(len(where), int(pid), dtype=np.int64))
        positions.append(where.astype(np.int64))
    if not progs:
        return np.zeros(0, np.int64), np.zeros(0, np.int64)
    return np.concatenate(progs), np.concatenate(positions)
