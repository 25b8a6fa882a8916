"""Constant folding (mtpg.engine.fold): what it removes, and that results never change."""

import math

import numpy as np
import pytest
from hypothesis import given, settings

from graph_strategies import tangled_cases
from mtpg.engine.batch import Episodes, evaluate_roots
from mtpg.engine.compile import compile_population
from mtpg.engine.ops import OP_COPY
from mtpg.engine.random_populations import layered_graphs
from mtpg.engine.trace import trace_sequence
from mtpg.model.graph import Population, atomic
from mtpg.model.instructions import (
    CONSTANTS,
    OP_ADD,
    OP_COS,
    OP_CUBE,
    OP_EXP,
    OP_IF_LT,
    OP_MUL,
    OP_SIN,
    OP_SUB,
    RegisterLayout,
)

LAYOUT = RegisterLayout()
R, M = LAYOUT.n_registers, LAYOUT.n_memory
C = R + M  # logical index of the first constant (-0.9)
OBS = C + len(CONSTANTS)  # the observation
M0 = R  # m[0]


def const(value: float) -> int:
    """Logical index of a constant register."""
    return C + int(np.flatnonzero(np.isclose(CONSTANTS, value))[0])


def compiled(*code: tuple[int, int, int, int]):
    """One team of the program ``code`` (plus an empty second program), folded and not."""
    pop = Population()
    bank = pop.new_bank()
    a = pop.add_program(np.array(code, dtype=np.int32).reshape(-1, 4), atomic(0), bank)
    b = pop.add_program(np.zeros((0, 4), np.int32), atomic(1), pop.new_bank())
    pop.add_team([a.id, b.id])
    return pop, compile_population(pop), compile_population(pop, fold_constants=False)


def program_code(cp) -> np.ndarray:
    """The compiled instructions of the first program."""
    g = cp.graph
    return g.instrs[g.prog_offsets[0] : g.prog_offsets[1]]


def test_a_value_known_before_the_run_is_read_from_the_pool():
    # r1 <- cos(0.4) is known; m0 <- r1 * obs reads it from the pool, r1 is never computed
    _, cp, plain = compiled((OP_COS, 1, 0, const(0.4)), (OP_MUL, M0, 1, OBS))
    code = program_code(cp)
    assert len(program_code(plain)) == 2 and len(code) == 1
    assert code[0, 0] == OP_MUL
    assert cp.graph.prog_count[0] == 2  # counted as the program states it
    base = cp.graph.mem_base
    W_slot = int(code[0, 2])  # the pool slot holding cos(0.4)
    assert base - len(cp.graph.folded) <= W_slot < base
    assert cp.graph.folded[W_slot - (base - len(cp.graph.folded))] == math.cos(0.4)


def test_a_known_second_operand_is_read_from_the_pool_and_plays_the_same():
    # r2 <- (-0.1)^3 is known; m0 <- m0 - r2 must subtract -0.001 (not the zeroed r2)
    # at every step: m0 is the continuous action, the torque of Pendulum
    pop, cp, plain = compiled((OP_CUBE, 2, 0, const(-0.1)), (OP_SUB, M0, M0, 2))
    code = program_code(cp)
    assert code[:, 0].tolist() == [OP_SUB] and code[0, 3] >= cp.graph.mem_base - 1
    episodes = Episodes.grid([3], [0])  # Pendulum
    got, _ = evaluate_roots(cp, [0], episodes)
    want, _ = evaluate_roots(plain, [0], episodes)
    assert got.tobytes() == want.tobytes()


def test_a_known_value_written_to_memory_is_one_copy():
    _, cp, _ = compiled((OP_EXP, M0, 0, const(0.3)))
    code = program_code(cp)
    assert code[:, 0].tolist() == [OP_COPY]
    assert math.exp(0.3) in cp.graph.folded.tolist()


def test_a_known_bid_is_copied_and_an_untouched_bid_is_not():
    _, cp, _ = compiled((OP_SIN, 0, 0, const(0.2)))
    assert program_code(cp)[:, 0].tolist() == [OP_COPY]
    _, cp, _ = compiled((OP_ADD, M0, M0, OBS))  # r[0] stays the zeroed +0.0
    assert program_code(cp)[:, 0].tolist() == [OP_ADD]


def test_the_sign_of_a_known_zero_bid_is_kept():
    # IF -0.1 < 0.1 THEN r0 <- -r0: r0 is -0.0, which a zeroed register does not hold
    _, cp, _ = compiled((OP_IF_LT, 0, const(-0.1), const(0.1)))
    code = program_code(cp)
    assert code[:, 0].tolist() == [OP_COPY]
    pool = cp.graph.folded
    value = pool[int(code[0, 3]) - (cp.graph.mem_base - len(pool))]
    assert value == 0.0 and math.copysign(1.0, value) < 0


def test_a_conditional_on_a_known_target_gets_the_value_first():
    # r0 <- cos(0.1) is known, the condition (obs0 < obs1) is not
    _, cp, _ = compiled((OP_COS, 0, 0, const(0.1)), (OP_IF_LT, 0, OBS, OBS + 1))
    assert program_code(cp)[:, 0].tolist() == [OP_COPY, OP_IF_LT]


def test_a_conditional_known_to_be_false_is_dropped():
    # IF 0.1 < -0.1 THEN m0 <- -m0 never fires; IF -0.1 < 0.1 THEN m0 <- -m0 always does
    _, cp, _ = compiled((OP_IF_LT, M0, const(0.1), const(-0.1)), (OP_ADD, M0, M0, OBS))
    assert program_code(cp)[:, 0].tolist() == [OP_ADD]
    _, cp, _ = compiled((OP_IF_LT, M0, const(-0.1), const(0.1)), (OP_ADD, M0, M0, OBS))
    assert program_code(cp)[:, 0].tolist() == [OP_IF_LT, OP_ADD]


def test_the_tracer_refuses_folded_code():
    pop, cp, plain = compiled((OP_COS, 1, 0, const(0.4)), (OP_MUL, M0, 1, OBS))
    with pytest.raises(ValueError, match="fold_constants=False"):
        trace_sequence(cp, 0, np.zeros((2, 2)))
    assert len(trace_sequence(plain, 0, np.zeros((2, 2))).actions) == 2


def test_folding_removes_math_library_calls_from_random_code():
    """The point of it: on random programs, fewer cos/ln/exp/sin/tanh/pow are executed."""
    pop, _ = layered_graphs(np.random.default_rng(3), 40, teams=3, programs=10, instructions=20)
    libm = [4, 5, 6, 7, 9, 10]
    folded = compile_population(pop).graph.instrs[:, 0]
    plain = compile_population(pop, fold_constants=False).graph.instrs[:, 0]
    assert np.isin(folded, libm).sum() < 0.85 * np.isin(plain, libm).sum()


@settings(max_examples=25, deadline=None, derandomize=True)
@given(case=tangled_cases())
def test_folded_and_plain_code_play_every_task_identically(case):
    rng, pop, no_memory = case
    roots = sorted(pop.teams)  # every team, internal ones too, decides as a root
    episodes = Episodes.grid(list(range(6)), [int(rng.integers(0, 1000)), 7])
    folded, plain = compile_population(pop), compile_population(pop, fold_constants=False)
    got, a = evaluate_roots(folded, roots, episodes, no_memory=no_memory)
    want, b = evaluate_roots(plain, roots, episodes, no_memory=no_memory)
    assert got.tobytes() == want.tobytes()
    for name in ("steps", "teams", "instructions"):
        assert getattr(a, name).tolist() == getattr(b, name).tolist(), name
