"""The bank population's bookkeeping on hand-made values (kills mutants of the model)."""

import numpy as np
import pytest

from mtpg.model.graph import InvariantError, Population, atomic, check_invariants

CODE = np.zeros((1, 4), dtype=np.int32)


def test_add_program_refuses_a_negative_bank():
    with pytest.raises(ValueError, match=r"^memory bank id must be >= 0, got -1$"):
        Population().add_program(CODE, atomic(0), -1)


def test_add_program_with_an_unknown_bank_adds_it_and_moves_the_counter_just_past_it():
    pop = Population()
    pop.add_program(CODE, atomic(0), 6)
    assert pop.memory_banks == {6} and pop.next_bank_id == 7
    pop.add_program(CODE, atomic(0), 2)  # below the counter: the counter stays
    assert pop.memory_banks == {2, 6} and pop.next_bank_id == 7
    assert pop.new_bank() == 7


def test_prune_deletes_programs_no_team_holds_then_banks_no_program_uses():
    pop = Population()
    a = pop.add_program(CODE, atomic(0), pop.new_bank()).id
    b = pop.add_program(CODE, atomic(1), pop.new_bank()).id
    pop.add_program(CODE, atomic(2), pop.new_bank())  # held by no team
    spare = pop.new_bank()  # no program points to it
    pop.add_team([a, b])
    pop.prune()
    assert sorted(pop.programs) == [a, b]
    assert pop.memory_banks == {0, 1} and spare not in pop.memory_banks
    check_invariants(pop)


def test_top_up_adds_fresh_banks_until_the_minimum():
    pop = Population()
    pop.add_program(CODE, atomic(0), 4)
    assert pop.top_up_banks(3) == [5, 6]
    assert pop.memory_banks == {4, 5, 6}
    assert pop.top_up_banks(2) == []  # already enough


def test_a_bank_id_at_the_counter_breaks_the_invariants():
    pop = Population()
    a = pop.add_program(CODE, atomic(0), pop.new_bank()).id
    b = pop.add_program(CODE, atomic(1), pop.new_bank()).id
    pop.add_team([a, b])
    check_invariants(pop)
    pop.memory_banks.add(pop.next_bank_id)
    with pytest.raises(InvariantError, match=r"^bank id 2 outside counter$"):
        check_invariants(pop)
