"""Crossover on hand-made teams whose program ids are not in ascending order.

Paper section 4.1 step 2: crossover interleaves both parents' programs *in order*
(parent 1's first, parent 2's first, parent 1's second, ...), each kept with probability
0.5. Program ids here are deliberately out of order, so a child sorted by id, or built
parent by parent, differs from the interleaving.
"""

from __future__ import annotations

import numpy as np

from mtpg.config import build_config
from mtpg.evolve.variation import Varier
from mtpg.model.graph import Population, atomic, check_invariants

# Program ids of the two parents, in team order; 40 is in both.
ORDER_A = [7, 3, 40, 5, 1]
ORDER_B = [6, 0, 2, 40, 4, 8]


def interleaving(a: list[int], b: list[int]) -> list[int]:
    """a0, b0, a1, b1, ...; a program held by both parents appears at its first place."""
    out: list[int] = []
    for i in range(max(len(a), len(b))):
        for parent in (a, b):
            if i < len(parent) and parent[i] not in out:
                out.append(parent[i])
    return out


def hand_made_parents() -> tuple[Population, int, int]:
    """Two root teams holding programs with the ids above (every program atomic)."""
    pop = Population()
    code = np.array([[0, 0, 1, 2]], dtype=np.int32)
    for pid in range(max(ORDER_A + ORDER_B) + 1):
        prog = pop.add_program(code, atomic(pid % 3), pop.new_bank())
        assert prog.id == pid
    a = pop.add_team(ORDER_A).id
    b = pop.add_team(ORDER_B).id
    for pid in [p for p in pop.programs if p not in ORDER_A + ORDER_B]:
        del pop.programs[pid]
    check_invariants(pop)
    return pop, a, b


def crossover_only(p_crossover: float = 1.0):
    return build_config(
        "paper",
        overrides=[
            f"team.p_crossover={p_crossover}",
            "team.p_delete=0.0",
            "team.p_add=0.0",
            "team.p_reorder=0.0",
            "team.p_new=0.0",
        ],
    )


def children(n: int, p_crossover: float = 1.0, seed: int = 0):
    pop, a, b = hand_made_parents()
    varier = Varier(pop, crossover_only(p_crossover), np.random.default_rng(seed), 2)
    parents = set(ORDER_A + ORDER_B)
    out = []
    for _ in range(n):
        progs = pop.teams[varier.child(a, b)].programs
        if set(progs) <= parents:  # a child equal to parent 1 gets one program mutated
            out.append(progs)
    return out


def test_ids_are_out_of_order_so_sorting_would_fail() -> None:
    full = interleaving(ORDER_A, ORDER_B)
    assert full == [7, 6, 3, 0, 40, 2, 5, 1, 4, 8]
    assert full != sorted(full)


def test_crossover_children_follow_the_interleaving_of_both_parents() -> None:
    kids = children(300)
    assert len(kids) > 250
    full = interleaving(ORDER_A, ORDER_B)
    for kid in kids:
        assert kid == [p for p in full if p in kid]
        assert len(set(kid)) == len(kid)
    mixed = [k for k in kids if set(k) & set(ORDER_A) and set(k) & (set(ORDER_B) - {40})]
    assert len(mixed) > 200  # most children hold programs of both parents


def test_each_parent_program_is_kept_with_probability_one_half() -> None:
    kids = children(600, seed=1)
    counts = {p: sum(p in k for k in kids) / len(kids) for p in set(ORDER_A + ORDER_B)}
    for pid, freq in counts.items():  # 40, held by both parents, is drawn once
        assert 0.38 < freq < 0.62, (pid, freq)


def test_without_crossover_a_child_is_parent_one_with_one_program_mutated() -> None:
    pop, a, b = hand_made_parents()
    varier = Varier(pop, crossover_only(0.0), np.random.default_rng(3), 2)
    for _ in range(30):
        kid = pop.teams[varier.child(a, b)].programs
        assert len(kid) == len(ORDER_A)
        same = [x == y for x, y in zip(kid, ORDER_A, strict=True)]
        assert sum(same) == len(ORDER_A) - 1  # a child always differs from its parent
        new = kid[same.index(False)]
        assert new not in ORDER_A + ORDER_B and new in pop.programs
        assert not set(kid) & (set(ORDER_B) - set(ORDER_A))


def test_crossover_keeps_an_atomic_program_and_at_least_two() -> None:
    pop, a, b = hand_made_parents()
    # make every program of parent 2 point to parent 1 (not atomic)
    for pid in set(ORDER_B) - set(ORDER_A):
        pop.programs[pid].action = a
    varier = Varier(pop, crossover_only(), np.random.default_rng(4), 2)
    for _ in range(100):
        kid = pop.teams[varier.child(a, b)].programs
        assert len(kid) >= 2
        assert any(pop.programs[p].is_atomic for p in kid)


def test_initial_population_follows_the_configured_sizes() -> None:
    from mtpg.evolve.variation import init_population
    from mtpg.model.instructions import RegisterLayout

    config = build_config(
        "paper",
        overrides=[
            "team.root_size=30",
            "team.init_team_size=4",
            "program.n_registers=4",
            "program.n_memory=6",
            "program.init_max_length=3",
        ],
    )
    pop = init_population(config, np.random.default_rng(0))
    assert pop.layout == RegisterLayout(4, 6)
    assert len(pop.roots()) == 30 and all(len(t.programs) == 4 for t in pop.teams.values())
    assert {len(p.instructions) for p in pop.programs.values()} == {1, 2, 3}
    assert {p.atomic_action for p in pop.programs.values()} == {0, 1, 2}
    assert len({p.bank for p in pop.programs.values()}) == len(pop.programs) == 120
    check_invariants(pop)


def program_config(**probs):
    settings = {"p_delete": 0.0, "p_add": 0.0, "p_mutate": 0.0, "p_swap": 0.0, **probs}
    overrides = [f"program.{k}={v}" for k, v in settings.items()]
    return build_config("paper", overrides=overrides).program


def test_mutate_code_deletes_inserts_changes_and_swaps_as_configured() -> None:
    from mtpg.evolve.variation import mutate_code
    from mtpg.model.instructions import RegisterLayout, random_instructions

    layout = RegisterLayout()
    rng = np.random.default_rng(0)
    code = random_instructions(rng, layout, 5)
    deleted = set()
    for _ in range(200):  # delete only: one instruction, any position
        out = mutate_code(code, program_config(p_delete=1.0), layout, rng)
        assert len(out) == 4
        gone = [k for k in range(5) if not any((out == code[k]).all(axis=1))]
        deleted.update(gone)
    assert deleted == set(range(5))
    two = code[:2]
    assert len(mutate_code(two, program_config(p_delete=1.0), layout, rng)) == 1
    one = code[:1]
    assert np.array_equal(mutate_code(one, program_config(p_delete=1.0), layout, rng), one)
    # nothing switched on: an identical copy
    same = mutate_code(code, program_config(), layout, rng)
    assert np.array_equal(same, code) and same is not code
    # insert only: one longer, but never beyond max_length
    assert len(mutate_code(code, program_config(p_add=1.0), layout, rng)) == 6
    limits = ["program.max_length=10", "program.p_add=1.0", "program.p_delete=0.0"]
    limits += ["program.p_mutate=0.0", "program.p_swap=0.0"]
    capped = build_config("paper", overrides=limits).program
    full = random_instructions(rng, layout, 10)
    assert len(mutate_code(full, capped, layout, rng)) == 10
    # change one field only: exactly one entry differs
    for _ in range(50):
        out = mutate_code(code, program_config(p_mutate=1.0), layout, rng)
        assert out.shape == code.shape and (out != code).sum() == 1
    # swap only: the same rows, two of them exchanged
    for _ in range(50):
        out = mutate_code(code, program_config(p_swap=1.0), layout, rng)
        moved = [k for k in range(5) if not (out[k] == code[k]).all()]
        assert len(moved) in (0, 2)  # 0 only if the two rows were equal
        assert sorted(map(tuple, out)) == sorted(map(tuple, code))


def test_initial_roots_are_born_in_generation_zero() -> None:
    from mtpg.evolve.variation import init_population

    config = build_config("paper", overrides=["team.root_size=5", "team.init_team_size=2"])
    pop = init_population(config, np.random.default_rng(1))
    assert [t.birth for t in pop.teams.values()] == [0] * 5
