"""Seeded random populations for benchmarks and tests."""

from __future__ import annotations

import numpy as np

from mtpg.model.graph import Population, atomic
from mtpg.model.instructions import RegisterLayout, random_instructions


def layered_graphs(
    rng: np.random.Generator,
    n_graphs: int,
    teams: int = 3,
    programs: int = 10,
    instructions: int = 10,
    p_pointer: float = 0.6,
    layout: RegisterLayout | None = None,
) -> tuple[Population, list[int]]:
    """Builds independent graphs, each a chain of ``teams`` teams of new programs.

    In every team but the last, each program except the first (kept atomic) points to a
    random later team of its graph with probability ``p_pointer``; with the defaults
    about 36% of all programs are pointers. Every program has its own memory bank.

    Args:
        rng: Generator for every draw.
        n_graphs: Number of graphs.
        teams: Teams per graph.
        programs: Programs per team (>= 2).
        instructions: Instructions per program.
        p_pointer: Pointer probability in the non-final teams.
        layout: Register sizes.

    Returns:
        The population and the root team id of each graph.
    """
    pop = Population(layout=layout or RegisterLayout())
    roots = []
    for _ in range(n_graphs):
        first = pop.next_team_id
        for t in range(teams):
            pids = []
            for k in range(programs):
                action = atomic(int(rng.integers(0, 3)))
                if t < teams - 1 and k > 0 and rng.random() < p_pointer:
                    action = first + int(rng.integers(t + 1, teams))
                code = random_instructions(rng, pop.layout, instructions)
                pids.append(pop.add_program(code, action, pop.new_bank()).id)
            pop.add_team(pids)
        roots.append(first)
    return pop, roots


def tangled_population(
    rng: np.random.Generator,
    n_teams: int,
    n_programs: int,
    max_len: int,
    n_banks: int,
    p_pointer: float = 0.5,
    layout: RegisterLayout | None = None,
) -> Population:
    """Builds one tangled population: shared programs, shared banks, any cycles.

    Programs point to any team (itself included) with probability ``p_pointer``; teams
    draw 2..6 distinct programs from the pool and get an atomic one if they lack it.

    Args:
        rng: Generator for every draw.
        n_teams: Number of teams (>= 1).
        n_programs: Size of the program pool (>= 2).
        max_len: Maximum program length (lengths are uniform in 1..max_len).
        n_banks: Number of memory banks programs draw from.
        p_pointer: Probability that a program points to a team.
        layout: Register sizes.

    Returns:
        The population (unheld programs pruned).
    """
    pop = Population(layout=layout or RegisterLayout())
    banks = [pop.new_bank() for _ in range(n_banks)]
    for _ in range(n_programs):
        action = atomic(int(rng.integers(0, 3)))
        if rng.random() < p_pointer:
            action = int(rng.integers(0, n_teams))
        code = random_instructions(rng, pop.layout, int(rng.integers(1, max_len + 1)))
        pop.add_program(code, action, banks[int(rng.integers(0, n_banks))])
    atomics = [p.id for p in pop.programs.values() if p.is_atomic]
    if not atomics:
        atomics = [pop.add_program(random_instructions(rng, pop.layout, 1), atomic(0), banks[0]).id]
    pool = list(pop.programs)
    for _ in range(n_teams):
        size = int(rng.integers(2, min(6, len(pool)) + 1))
        members = [pool[i] for i in rng.choice(len(pool), size=size, replace=False)]
        if not any(pop.programs[p].is_atomic for p in members):
            pick = atomics[int(rng.integers(0, len(atomics)))]
            members[int(rng.integers(0, size))] = pick
            if len(set(members)) < len(members):
                members = list(dict.fromkeys(members)) + [p for p in pool if p not in members][:1]
        pop.add_team(members)
    pop.prune()
    return pop
