"""Initialisation and variation of teams and programs (paper section 4.1, Table 3).

Every function takes the generator it draws from. Programs are never changed in place:
a mutated program is a new program (new id), so every team that held the original keeps
its behaviour.
"""

from __future__ import annotations

from bisect import bisect_left

import numpy as np

from mtpg.config import ProgramConfig, RunConfig, TeamConfig
from mtpg.model.graph import Population, atomic
from mtpg.model.instructions import RegisterLayout, random_instructions

#: Random instructions drawn at once by an :class:`InstructionPool` (part of the run's
#: definition: changing it changes the random stream).
POOL_BLOCK = 1024


class InstructionPool:
    """Random instructions drawn from ``rng`` in blocks, handed out in order.

    Each row is an independent draw of :func:`~mtpg.model.instructions.random_instructions`,
    so the distribution is unchanged; drawing a block of :data:`POOL_BLOCK` costs about
    what drawing one instruction does, which makes variation cheap. The generator is
    advanced only when a block is drawn, so the stream stays a function of the seed.

    Args:
        rng: The generator to draw from.
        layout: Register sizes.
    """

    def __init__(self, rng: np.random.Generator, layout: RegisterLayout) -> None:
        self.rng = rng
        self.layout = layout
        self.block = np.zeros((0, 4), np.int32)
        self.at = 0

    def take(self, n: int) -> np.ndarray:
        """The next ``n`` instructions, int32 ``(n, 4)`` (a fresh array)."""
        if self.at + n > len(self.block):
            rest = self.block[self.at :]
            new = random_instructions(self.rng, self.layout, max(POOL_BLOCK, n - len(rest)))
            self.block = np.concatenate([rest, new])
            self.at = 0
        out = self.block[self.at : self.at + n].copy()
        self.at += n
        return out


def init_population(config: RunConfig, rng: np.random.Generator) -> Population:
    """Creates ``root_size`` root teams of ``init_team_size`` new atomic programs each.

    Every program gets its own new memory bank, a random atomic action and a length
    uniform in 1..``init_max_length``.
    """
    n_obs, n_actions, _ = config.evaluation.task_table().shape
    layout = RegisterLayout(config.program.n_registers, config.program.n_memory, n_obs, n_actions)
    pop = Population(layout=layout)
    pool = InstructionPool(rng, layout)
    for _ in range(config.team.root_size):
        pids = []
        for _ in range(config.team.init_team_size):
            length = int(rng.integers(1, config.program.init_max_length + 1))
            code = pool.take(length)
            action = atomic(int(rng.integers(0, layout.n_actions)))
            pids.append(pop.add_program(code, action, pop.new_bank()).id)
        pop.add_team(pids, birth=0)
    return pop


def mutate_code(
    code: np.ndarray,
    cfg: ProgramConfig,
    layout: RegisterLayout,
    rng: np.random.Generator,
    pool: InstructionPool | None = None,
) -> np.ndarray:
    """Returns a mutated copy of a program's instructions.

    Four independent trials: delete a random instruction (``p_delete``, kept >= 1 long),
    insert a random instruction (``p_add``, up to ``max_length``), change one field of one
    instruction to a different valid value (``p_mutate``), swap two instructions
    (``p_swap``). New instructions and field values come from ``pool`` (a fresh one on
    ``rng`` when None).
    """
    pool = pool or InstructionPool(rng, layout)
    n = len(code)
    if rng.random() < cfg.p_delete and n > 1:
        k = int(rng.integers(0, n))
        code = np.concatenate([code[:k], code[k + 1 :]])
    else:
        code = code.copy()
    n = len(code)
    if rng.random() < cfg.p_add and n < cfg.max_length:
        at = int(rng.integers(0, n + 1))
        code = np.concatenate([code[:at], pool.take(1), code[at:]])
    n = len(code)
    if rng.random() < cfg.p_mutate:
        k = int(rng.integers(0, n))
        column = int(rng.integers(0, 4))
        for _ in range(16):  # redraw until the field changes (always possible for op)
            fresh = int(pool.take(1)[0, column])
            if fresh != code[k, column]:
                code[k, column] = fresh
                break
    if rng.random() < cfg.p_swap and n > 1:
        i = int(rng.integers(0, n))
        j = int(rng.integers(0, n - 1))
        j += j >= i  # two distinct positions, uniformly
        code[[i, j]] = code[[j, i]]
    return code


class Varier:
    """Creates the children of one generation.

    Args:
        pop: The population (changed in place: new programs and teams are added).
        config: The run configuration.
        rng: The variation generator.
        generation: The generation being created; children and clones are born in it.
    """

    def __init__(
        self, pop: Population, config: RunConfig, rng: np.random.Generator, generation: int
    ) -> None:
        self.pop = pop
        self.cfg: TeamConfig = config.team
        self.pcfg: ProgramConfig = config.program
        self.rng = rng
        self.generation = generation
        self.roots = set(pop.roots())
        self.targets = [tid for tid, t in pop.teams.items() if t.birth < generation]
        self.program_pool = list(pop.programs)
        self.banks = pop.banks()  # the whole bank population, ascending, fresh banks included
        self.pool = InstructionPool(rng, pop.layout)

    def child(self, parent1: int, parent2: int) -> int:
        """Creates one new root team from two parents and returns its id."""
        rng, cfg = self.rng, self.cfg
        first = self.pop.teams[parent1].programs
        if rng.random() < cfg.p_crossover:
            progs = self._crossover(first, self.pop.teams[parent2].programs)
        else:
            progs = list(first)
        self._delete_programs(progs)
        self._add_programs(progs)
        if rng.random() < cfg.p_reorder and len(progs) > 1:
            progs.insert(
                int(rng.integers(0, len(progs))), progs.pop(int(rng.integers(0, len(progs))))
            )
        changed = progs != list(first)
        for k in range(len(progs)):
            if rng.random() < cfg.p_new:
                progs[k] = self._mutated_copy(progs, k)
                changed = True
        if not changed:  # a child always differs from its parent
            k = int(rng.integers(0, len(progs)))
            progs[k] = self._mutated_copy(progs, k)
        return self.pop.add_team(progs, birth=self.generation).id

    def _is_atomic(self, pid: int) -> bool:
        return self.pop.programs[pid].action < 0

    def _crossover(self, a: list[int], b: list[int]) -> list[int]:
        """Interleaves both parents' programs in order, keeping each with probability 0.5.

        When the kept programs lack an atomic one, or number fewer than two, the first
        atomic program and then the first other programs of ``a`` are kept too; every
        program keeps its place in the interleaving.
        """
        order: list[int] = []
        for i in range(max(len(a), len(b))):
            for parent in (a, b):
                if i < len(parent) and parent[i] not in order:
                    order.append(parent[i])
        kept = {p for p in order if self.rng.random() < 0.5}
        if not any(self._is_atomic(p) for p in kept):
            kept.add(next(p for p in a if self._is_atomic(p)))
        for p in a:
            if len(kept) >= 2:
                break
            kept.add(p)
        return [p for p in order if p in kept]

    def _delete_programs(self, progs: list[int]) -> None:
        """Deletes programs in trials of decaying probability ``p_md, p_md^2, ...``."""
        p = self.cfg.p_delete
        while len(progs) > 2 and self.rng.random() < p:
            n_atomic = sum(self._is_atomic(q) for q in progs)
            deletable = [k for k, q in enumerate(progs) if n_atomic > 1 or not self._is_atomic(q)]
            progs.pop(deletable[int(self.rng.integers(0, len(deletable)))])
            p *= self.cfg.p_delete

    def _add_programs(self, progs: list[int]) -> None:
        """Adds programs drawn from the whole population, in trials of decaying probability."""
        p = self.cfg.p_add
        while len(progs) < self.cfg.max_team_size and self.rng.random() < p:
            pid = self.program_pool[int(self.rng.integers(0, len(self.program_pool)))]
            if pid not in progs:
                progs.insert(int(self.rng.integers(0, len(progs) + 1)), pid)
            p *= self.cfg.p_add

    def _mutated_copy(self, progs: list[int], k: int) -> int:
        """Replaces ``progs[k]`` by a mutated copy; returns the copy's id."""
        rng, old = self.rng, self.pop.programs[progs[k]]
        code = mutate_code(old.instructions, self.pcfg, self.pop.layout, rng, self.pool)
        action, bank = old.action, old.bank
        if rng.random() < self.cfg.p_action:
            last_atomic = action < 0 and sum(self._is_atomic(q) for q in progs) == 1
            action = self._new_action(force_atomic=last_atomic)
        if rng.random() < self.cfg.p_memory and len(self.banks) > 1:
            bank = self._other_bank(old.bank)
        return self.pop.add_program(code, action, bank).id

    def _other_bank(self, current: int) -> int:
        """Draws a bank uniformly from the bank population except ``current``.

        Every bank counts, including fresh ones no program points to yet (added by the
        top-up after selection), so a program can gain memory of its own.
        """
        k = bisect_left(self.banks, current)
        if k < len(self.banks) and self.banks[k] == current:
            i = int(self.rng.integers(0, len(self.banks) - 1))
            return self.banks[i + (i >= k)]
        return self.banks[int(self.rng.integers(0, len(self.banks)))]

    def _new_action(self, force_atomic: bool) -> int:
        """Draws a new action pointer: atomic with ``p_atomic``, else an older team.

        The draw does not depend on the current pointer (which may be drawn again);
        ``force_atomic`` keeps a team's last atomic program atomic.

        A root chosen as target is cloned first and the clone is pointed to ("clone when
        subsumed"), so the root stays an independent agent.
        """
        rng = self.rng
        if force_atomic or not self.targets or rng.random() < self.cfg.p_atomic:
            return atomic(int(rng.integers(0, self.pop.layout.n_actions)))
        target = self.targets[int(rng.integers(0, len(self.targets)))]
        if target in self.roots:
            clone = self.pop.add_team(list(self.pop.teams[target].programs), self.generation)
            target = clone.id
        return target
