"""The representation on hand-made values: register layout, operand draws, validation,
disassembly, population bookkeeping and the structural invariants."""

from __future__ import annotations

import numpy as np
import pytest

from mtpg.model.graph import InvariantError, Population, atomic, check_invariants
from mtpg.model.instructions import (
    RegisterLayout,
    disassemble,
    random_instructions,
    valid_instructions,
)

L = RegisterLayout()
CODE = np.array([[0, 0, 1, 2]], dtype=np.int32)


def test_layout_ranges_of_the_paper_sizes() -> None:
    assert (L.n_registers, L.n_memory, L.n_obs) == (8, 8, 2)
    assert (L.mem_start, L.const_start, L.obs_start, L.size) == (8, 16, 34, 36)
    small = RegisterLayout(3, 2, 1)
    assert (small.mem_start, small.const_start, small.obs_start, small.size) == (3, 5, 23, 24)


def test_layout_names() -> None:
    names = [L.name(i) for i in (0, 7, 8, 15, 16, 24, 25, 33, 34, 35)]
    assert names == ["r[0]", "r[7]", "m[0]", "m[7]", "-0.9", "-0.1", "+0.1", "+0.9", "s[0]", "s[1]"]


@pytest.mark.parametrize("field", ["n_registers", "n_memory", "n_obs"])
def test_layout_sizes_must_be_positive(field: str) -> None:
    RegisterLayout(**{field: 1})
    with pytest.raises(ValueError, match=rf"^{field} must be >= 1, got 0$"):
        RegisterLayout(**{field: 0})


def test_operand_draws_follow_the_bank_first_rule() -> None:
    code = random_instructions(np.random.default_rng(1), L, 30000)
    assert code.dtype == np.int32 and code.shape == (30000, 4)
    op, dst, a, b = code.T
    # op uniform over 16
    assert np.allclose(np.bincount(op, minlength=16) / len(op), 1 / 16, atol=0.01)
    # target: r or m with probability 1/2 each, then uniform
    assert abs(np.mean(dst >= L.mem_start) - 0.5) < 0.02
    assert set(np.unique(dst)) == set(range(16))
    # first operand: bank r (with constants) or m, 1/2 each; never the observation
    in_m = (a >= L.mem_start) & (a < L.const_start)
    assert abs(np.mean(in_m) - 0.5) < 0.02
    assert set(np.unique(a)) == set(range(34))
    # within r-with-constants, uniform over the 26 readable cells
    r_side = a[~in_m]
    assert abs(np.mean(r_side < L.n_registers) - 8 / 26) < 0.02
    # second operand: r, m, s one third each
    in_s = b >= L.obs_start
    in_m2 = (b >= L.mem_start) & (b < L.const_start)
    assert abs(np.mean(in_s) - 1 / 3) < 0.02 and abs(np.mean(in_m2) - 1 / 3) < 0.02
    assert set(np.unique(b)) == set(range(36))
    assert abs(np.mean(b[in_s] == L.obs_start) - 0.5) < 0.03


@pytest.mark.parametrize(
    ("row", "problem"),
    [
        ([16, 0, 0, 0], "op out of range [0, 16)"),
        ([-1, 0, 0, 0], "op out of range [0, 16)"),
        ([0, 16, 0, 0], "dst out of range [0, 16)"),
        ([0, -1, 0, 0], "dst out of range [0, 16)"),
        ([0, 0, 34, 0], "src1 out of range [0, 34)"),
        ([0, 0, -1, 0], "src1 out of range [0, 34)"),
        ([0, 0, 0, 36], "src2 out of range [0, 36)"),
        ([0, 0, 0, -1], "src2 out of range [0, 36)"),
    ],
)
def test_valid_instructions_names_the_bad_field(row, problem) -> None:
    good = [15, 15, 33, 35]
    assert valid_instructions(np.array([good]), L) is None
    assert valid_instructions(np.array([good, row]), L) == problem


def test_valid_instructions_shape() -> None:
    for bad in (np.zeros((0, 4)), np.zeros((2, 3)), np.zeros(4)):
        msg = valid_instructions(bad.astype(np.int32), L)
        assert msg == f"instructions must be a non-empty (n, 4) array, got shape {bad.shape}"


def test_disassemble_every_instruction_form() -> None:
    code = np.array(
        [
            [0, 0, 8, 34],
            [1, 1, 16, 35],
            [2, 9, 33, 0],
            [3, 0, 0, 1],
            [4, 0, 0, 1],
            [7, 8, 0, 34],
            [12, 0, 5, 25],
            [14, 2, 3, 4],
            [15, 10, 11, 35],
        ]
    )
    assert disassemble(code, L) == [
        "r[0] <- m[0] + s[0]",
        "r[1] <- -0.9 - s[1]",
        "m[1] <- +0.9 * r[0]",
        "r[0] <- r[0] / r[1]",
        "r[0] <- r[0] ^ r[1]",
        "m[0] <- exp(s[0])",
        "r[0] <- abs(+0.1)",
        "if r[3] < r[4]: r[2] <- -r[2]",
        "if m[3] > s[1]: m[2] <- -m[2]",
    ]


def test_population_ids_counters_and_atomic_encoding() -> None:
    pop = Population()
    assert [pop.new_bank() for _ in range(3)] == [0, 1, 2]
    p = pop.add_program(CODE, atomic(2), 1)
    q = pop.add_program(CODE.tolist(), 0, 2)
    assert (p.id, q.id, pop.next_program_id) == (0, 1, 2)
    assert p.instructions.dtype == np.int32 and q.instructions.dtype == np.int32
    assert p.is_atomic and p.atomic_action == 2 and p.action == -3
    assert not q.is_atomic and q.action == 0
    assert [atomic(a) for a in range(3)] == [-1, -2, -3]
    t = pop.add_team([0, 1], birth=4)
    assert (t.id, t.birth, pop.next_team_id) == (0, 4, 1)
    programs = [0, 1]
    u = pop.add_team(programs)
    programs.append(5)
    assert u.programs == [0, 1] and u.birth == 0  # the team keeps its own copy


def chain() -> Population:
    """Teams 0 -> 1 -> 2, 0 -> 2, 3 alone; 2 -> 0 closes a cycle through 0."""
    pop = Population()
    bank = pop.new_bank()
    leaf = [pop.add_program(CODE, atomic(0), bank).id for _ in range(4)]
    to1 = pop.add_program(CODE, 1, bank).id
    to2 = pop.add_program(CODE, 2, bank).id
    to2b = pop.add_program(CODE, 2, bank).id
    pop.add_team([leaf[0], to1, to2])  # 0
    pop.add_team([leaf[1], to2b])  # 1
    pop.add_team([leaf[2], leaf[3]])  # 2
    pop.add_team([leaf[3], leaf[0]])  # 3
    return pop


def test_in_degree_roots_reachable_and_banks() -> None:
    pop = chain()
    assert pop.in_degree() == {0: 0, 1: 1, 2: 2, 3: 0}
    assert pop.roots() == [0, 3]
    assert pop.reachable(0) == [0, 1, 2]
    assert pop.reachable(1) == [1, 2]
    assert pop.reachable(3) == [3]
    assert pop.banks() == [0]
    to0 = pop.add_program(CODE, 0, pop.new_bank()).id
    pop.teams[2].programs.append(to0)  # a cycle: 0 is no longer a root
    assert pop.roots() == [3]
    assert pop.reachable(2) == [2, 0, 1]
    assert pop.banks() == [0, 1]


def test_prune_deletes_only_programs_no_team_holds() -> None:
    pop = chain()
    extra = pop.add_program(CODE, atomic(1), pop.new_bank()).id
    before = set(pop.programs)
    del pop.teams[3]
    pop.prune()
    assert set(pop.programs) == before - {extra}
    check_invariants(pop)


@pytest.mark.parametrize(
    ("break_it", "message"),
    [
        (lambda pop: pop.teams[1].programs.pop(0), "team 1 has 1 programs"),
        (lambda pop: pop.teams[2].programs.append(2), "team 2 repeats a program"),
        (lambda pop: pop.teams[3].programs.append(99), "team 3 holds missing program 99"),
        (lambda pop: setattr(pop.programs[1], "action", 2), "team 1 has no atomic program"),
        (lambda pop: pop.add_program(CODE, atomic(0), 0), "program 7 is held by no team"),
        (lambda pop: setattr(pop.programs[4], "action", 9), "program 4 points to missing team"),
        (lambda pop: setattr(pop.programs[0], "action", atomic(3)), "program 0 action -4"),
        (lambda pop: setattr(pop.programs[0], "bank", 5), "program 0 points to missing bank 5"),
        (
            lambda pop: setattr(pop.programs[0], "bank", 1),
            "program 0 points to missing bank 1",
        ),  # next id
        (lambda pop: setattr(pop.programs[0], "bank", -1), "program 0 points to missing bank -1"),
        (
            lambda pop: setattr(pop.programs[1], "instructions", np.array([[0, 40, 0, 0]])),
            "program 1: dst out of range",
        ),
        (lambda pop: setattr(pop.teams[3], "id", 7), "team key 3 holds team 7"),
        (lambda pop: setattr(pop.programs[3], "id", 8), "program key 3 holds program 8"),
        (lambda pop: setattr(pop, "next_team_id", 3), "team id 3 outside counter"),
        (lambda pop: setattr(pop, "next_program_id", 6), "program id 6 outside counter"),
    ],
)
def test_check_invariants_names_each_broken_rule(break_it, message) -> None:
    pop = chain()
    check_invariants(pop)
    break_it(pop)
    with pytest.raises(InvariantError, match=message.replace("[", r"\[")):
        check_invariants(pop)
