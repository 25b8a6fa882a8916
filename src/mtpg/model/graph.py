"""Programs, teams and the population that holds them as program graphs.

A :class:`Program` is a linear register machine plus two pointers: its *action* (an atomic
discrete action in {0, 1, 2} or another team) and its shared memory *bank*. A
:class:`Team` is an ordered list of program ids; several teams may hold the same program.
An edge runs from a team to every team its programs point to; cycles are allowed (the
engine never visits a team twice in one decision). Teams with in-degree 0 are *roots*:
the agents that evolution selects, deletes and varies.

Memory banks are a population of their own (paper section 4.1: "teams, programs, and
shared memory registers are each stored in separate populations and coevolved"): the
population holds the set of bank ids, a bank may exist with no program pointing to it
(a fresh bank, ready for a memory-pointer mutation), and evolution deletes banks no
program points to and tops the set up with fresh ones (:meth:`Population.prune`,
:meth:`Population.top_up_banks`). A bank's contents exist only while an episode runs.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from mtpg.model.instructions import RegisterLayout, valid_instructions

#: Number of atomic discrete actions.
N_ACTIONS = 3


class InvariantError(ValueError):
    """A population breaks one of its structural rules; the message names the rule."""


def atomic(action: int) -> int:
    """Encodes an atomic discrete action in {0, 1, 2} as a program action pointer."""
    return -1 - action


@dataclass(slots=True)
class Program:
    """A linear register program with its action and memory pointers.

    Attributes:
        id: Unique id within the population.
        instructions: int32 array ``(n, 4)`` of ``op, dst, src1, src2``.
        action: ``>= 0``: the id of the team it points to; ``< 0``: atomic action
            ``-1 - action``.
        bank: Id of its shared memory bank.
        effective: Cache of the effective (non-intron) instructions, filled by the
            compiler. Instructions are never changed in place (variation copies a
            program before mutating it), so the cache stays valid.
        folded: Cache of the constant-folded effective code and its pool values
            (:func:`mtpg.engine.fold.folded_code`), valid for the same reason.
    """

    id: int
    instructions: np.ndarray
    action: int
    bank: int
    effective: np.ndarray | None = field(default=None, repr=False, compare=False)
    folded: tuple[np.ndarray, np.ndarray] | None = field(default=None, repr=False, compare=False)

    @property
    def is_atomic(self) -> bool:
        """True when the action pointer is an atomic action."""
        return self.action < 0

    @property
    def atomic_action(self) -> int:
        """The discrete action of an atomic program."""
        return -1 - self.action


@dataclass(slots=True)
class Team:
    """An ordered group of programs; executing it runs them all in this order.

    Attributes:
        id: Unique id within the population.
        programs: Program ids, in execution order (no repeats).
        birth: Generation in which the team was created.
    """

    id: int
    programs: list[int]
    birth: int = 0


@dataclass(slots=True)
class Population:
    """Teams, programs and memory banks, coevolved as separate populations.

    Attributes:
        layout: Register sizes shared by all programs.
        programs: Programs by id.
        teams: Teams by id (insertion order is creation order).
        memory_banks: Ids of the memory banks (the bank population); every program's
            bank is one of them, and some may have no program pointing to them.
        next_program_id: Next fresh program id.
        next_team_id: Next fresh team id.
        next_bank_id: Next fresh memory bank id.
    """

    layout: RegisterLayout = field(default_factory=RegisterLayout)
    programs: dict[int, Program] = field(default_factory=dict)
    teams: dict[int, Team] = field(default_factory=dict)
    memory_banks: set[int] = field(default_factory=set)
    next_program_id: int = 0
    next_team_id: int = 0
    next_bank_id: int = 0

    def new_bank(self) -> int:
        """Adds a fresh memory bank to the bank population and returns its id."""
        bank = self.next_bank_id
        self.memory_banks.add(bank)
        self.next_bank_id += 1
        return bank

    def add_program(self, instructions: np.ndarray, action: int, bank: int) -> Program:
        """Creates and stores a program with a fresh id.

        A ``bank`` id not yet in the bank population joins it (and the bank counter moves
        past it), so a program always points to an existing bank.
        """
        bank = int(bank)
        if bank < 0:
            raise ValueError(f"memory bank id must be >= 0, got {bank}")
        if bank not in self.memory_banks:
            self.memory_banks.add(bank)
            self.next_bank_id = max(self.next_bank_id, bank + 1)
        prog = Program(
            self.next_program_id, np.asarray(instructions, dtype=np.int32), int(action), bank
        )
        self.programs[prog.id] = prog
        self.next_program_id += 1
        return prog

    def add_team(self, programs: list[int], birth: int = 0) -> Team:
        """Creates and stores a team with a fresh id."""
        team = Team(self.next_team_id, list(programs), birth)
        self.teams[team.id] = team
        self.next_team_id += 1
        return team

    def in_degree(self) -> dict[int, int]:
        """Number of (team, program) edges pointing at each team."""
        deg = dict.fromkeys(self.teams, 0)
        for team in self.teams.values():
            for pid in team.programs:
                target = self.programs[pid].action
                if target >= 0:
                    deg[target] += 1
        return deg

    def roots(self) -> list[int]:
        """Ids of the root teams (in-degree 0), in creation order."""
        return [tid for tid, d in self.in_degree().items() if d == 0]

    def banks(self) -> list[int]:
        """Ids of every memory bank of the population, ascending (fresh ones included)."""
        return sorted(self.memory_banks)

    def banks_in_use(self) -> set[int]:
        """Ids of the memory banks some program points to."""
        return {p.bank for p in self.programs.values()}

    def top_up_banks(self, minimum: int) -> list[int]:
        """Adds fresh (zeroed) banks until the bank population holds ``minimum`` banks.

        Args:
            minimum: The number of banks to reach (evolution passes the number of teams).

        Returns:
            The ids of the banks added, ascending.
        """
        return [self.new_bank() for _ in range(minimum - len(self.memory_banks))]

    def reachable(self, root: int) -> list[int]:
        """Team ids reachable from ``root`` (itself included), in depth-first order."""
        seen = {root}
        order = [root]
        stack = [root]
        while stack:
            for pid in self.teams[stack.pop()].programs:
                target = self.programs[pid].action
                if target >= 0 and target not in seen:
                    seen.add(target)
                    order.append(target)
                    stack.append(target)
        return order

    def prune(self) -> None:
        """Deletes programs no team holds, then memory banks no program points to."""
        held = {pid for team in self.teams.values() for pid in team.programs}
        for pid in [pid for pid in self.programs if pid not in held]:
            del self.programs[pid]
        self.memory_banks &= self.banks_in_use()


def _require(cond: bool, message: str) -> None:
    if not cond:
        raise InvariantError(message)


def check_invariants(pop: Population) -> None:
    """Checks every structural rule of the population.

    Rules: every team holds >= 2 distinct existing programs, at least one of them atomic;
    every program is held by some team, has valid instructions, an atomic action in
    {0, 1, 2} or a pointer to an existing team, and a bank of the bank population; ids
    are below their counters (bank ids too).

    Args:
        pop: The population to check.

    Raises:
        InvariantError: Naming the first rule broken.
    """
    held: set[int] = set()
    for tid, team in pop.teams.items():
        _require(team.id == tid, f"team key {tid} holds team {team.id}")
        _require(0 <= tid < pop.next_team_id, f"team id {tid} outside counter")
        _require(len(team.programs) >= 2, f"team {tid} has {len(team.programs)} programs")
        _require(len(set(team.programs)) == len(team.programs), f"team {tid} repeats a program")
        for pid in team.programs:
            _require(pid in pop.programs, f"team {tid} holds missing program {pid}")
        _require(
            any(pop.programs[pid].is_atomic for pid in team.programs),
            f"team {tid} has no atomic program",
        )
        held.update(team.programs)
    for pid, prog in pop.programs.items():
        _require(prog.id == pid, f"program key {pid} holds program {prog.id}")
        _require(0 <= pid < pop.next_program_id, f"program id {pid} outside counter")
        _require(pid in held, f"program {pid} is held by no team")
        problem = valid_instructions(prog.instructions, pop.layout)
        _require(problem is None, f"program {pid}: {problem}")
        if prog.is_atomic:
            n_act = pop.layout.n_actions
            _require(prog.atomic_action < n_act, f"program {pid} action {prog.action}")
        else:
            _require(prog.action in pop.teams, f"program {pid} points to missing team")
        _require(prog.bank in pop.memory_banks, f"program {pid} points to missing bank {prog.bank}")
    for bank in pop.memory_banks:
        _require(0 <= bank < pop.next_bank_id, f"bank id {bank} outside counter")
