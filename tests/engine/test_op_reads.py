"""The one table of op semantics (``OP_READS``) and every consumer of it agree.

For every op code, each part of the package that needs to know which operands an
instruction reads is asked, through its own behaviour, and must answer what the table
says: the arithmetic (the compiled ``apply_op`` and the oracle's ``reference_op``: an
operand not read never changes the result, one read does for some values), intron
removal, constant folding, the lane engine's register zeroing, the tracer's memory log,
the exporters' lowering and generated operation functions, and the disassembler. The lane
loops are proved bit for bit equal to ``apply_op`` by test_ops_shortcuts.py.
"""

import math
import types

import numpy as np
import pytest

from mtpg.engine.compile import effective_mask
from mtpg.engine.fold import _fold_kernel
from mtpg.engine.lane_graph import registers_to_zero
from mtpg.engine.ops import OP_COPY, apply_op
from mtpg.engine.oracle import reference_op
from mtpg.engine.record import MEMORY, new_recorder, record_instruction
from mtpg.export import c as c_export
from mtpg.export import python as py_export
from mtpg.export.common import TABLE_CONSTANTS
from mtpg.export.lowering import lower
from mtpg.model.instructions import (
    BINARY_OPS,
    CONDITIONAL_OPS,
    CONSTANTS,
    N_OPS,
    OP_NAMES,
    OP_READS,
    OP_TABLE,
    READS_A,
    READS_B,
    READS_TARGET,
    UNARY_OPS,
    RegisterLayout,
    disassemble,
    operands_read,
)

LAY = RegisterLayout()
R, M = LAY.n_registers, LAY.n_memory
M0, CONST, OBS = LAY.mem_start, LAY.const_start, LAY.obs_start
PROGRAM_OPS = list(range(N_OPS))
ALL_OPS = [*PROGRAM_OPS, OP_COPY]
BITS = {"d": READS_TARGET, "a": READS_A, "b": READS_B}
VALUES = [-1.5, -0.4, 0.0, 0.3, 0.9, 2.0]


def _reads(op: int) -> set[str]:
    return {name for name, bit in BITS.items() if OP_READS[op] & bit}


def test_the_table_is_the_instruction_set():
    assert len(OP_TABLE) == N_OPS + 1 and OP_COPY == N_OPS
    assert OP_NAMES == tuple(name for name, _ in OP_TABLE[:N_OPS])
    assert OP_TABLE[OP_COPY][0] == "copy"
    assert BINARY_OPS | UNARY_OPS | CONDITIONAL_OPS == set(PROGRAM_OPS)
    for op in ALL_OPS:
        assert "b" in _reads(op)  # every op reads its second operand
        assert set(operands_read(op)) == _reads(op)
        assert list(operands_read(op)) == [x for x in "dab" if x in _reads(op)]


def _depends(fn, op: int, which: str) -> bool:
    """Whether ``fn(op, d, a, b)`` changes with operand ``which`` for some values."""
    for base in VALUES:
        for x in VALUES:
            for y in VALUES:
                args = {"d": base, "a": base, "b": base}
                results = set()
                for v in (x, y):
                    args[which] = v
                    results.add(fn(op, args["d"], args["a"], args["b"]))
                if len(results) > 1:
                    return True
    return False


@pytest.mark.parametrize("op", ALL_OPS)
def test_the_arithmetic_reads_what_the_table_says(op):
    fns = [apply_op] if op == OP_COPY else [apply_op, reference_op]
    for fn in fns:
        seen = {which for which in "dab" if _depends(fn, op, which)}
        assert seen == _reads(op), (fn.__name__, OP_TABLE[op][0])


@pytest.mark.parametrize("op", PROGRAM_OPS)
def test_intron_removal_keeps_the_writers_of_what_an_op_reads(op):
    # instruction 0 writes r2; instruction 1 reads r2 as operand `which` and writes r0
    # (or, for the target, writes r2 itself, then r0 <- r2 + r2 reads it)
    for which in "ab":
        operands = {"a": 3, "b": 3}
        operands[which] = 2
        code = np.array([[0, 2, OBS, OBS], [op, 0, operands["a"], operands["b"]]])
        assert bool(effective_mask(code, LAY)[0]) == (which in _reads(op)), which
    code = np.array([[0, 2, OBS, OBS], [op, 2, 3, 4], [0, 0, 2, 2]])
    assert bool(effective_mask(code, LAY)[0]) == ("d" in _reads(op))


def _fold(code) -> list[int]:
    out, _ = _fold_kernel(
        np.asarray(code, dtype=np.int32), R, R + M, np.asarray(CONSTANTS, float), LAY.size
    )
    return out[:, 0].tolist()


@pytest.mark.parametrize("op", PROGRAM_OPS)
def test_folding_waits_for_what_an_op_reads(op):
    # the observation is unknown until the program runs; r registers are known zeros
    assert (op in _fold([[op, 1, OBS, CONST]])) == ("a" in _reads(op))
    assert (op in _fold([[op, 1, CONST, OBS]])) == ("b" in _reads(op))
    # memory is unknown: an op not reading its target folds into one copy
    assert (_fold([[op, M0, CONST, CONST + 3]]) == [OP_COPY]) == ("d" not in _reads(op))


@pytest.mark.parametrize("op", ALL_OPS)
def test_lane_register_zeroing_zeroes_what_an_op_reads(op):
    instrs = np.array([[op, 1, 2, 3]], dtype=np.uint32)
    need = int(registers_to_zero(instrs, 0, 1, R))
    zeroed = {k for k in range(R) if need >> k & 1}
    want = {0} | {r for name, r in (("d", 1), ("a", 2), ("b", 3)) if name in _reads(op)}
    assert zeroed == want


@pytest.mark.parametrize("op", ALL_OPS)
def test_the_tracer_logs_the_memory_an_op_reads(op):
    graph = types.SimpleNamespace(prog_bank=np.zeros(1, dtype=np.int64), n_memory=M)
    rec = new_recorder(graph, np.array([4, 4, 4, 16]), 1, False)
    base = 100
    instr = np.array([op, base, base + 1, base + 2], dtype=np.uint32)
    record_instruction(rec, 0, instr, 1.0, 2.0, base, M)
    rows = rec.mem_log[: rec.n[MEMORY]]
    read = [int(r[2]) for r in rows if r[3] == 0]
    assert read == [k for k, name in enumerate("dab") if name in _reads(op)]
    assert [int(r[2]) for r in rows if r[3] == 1] == [0]  # the target, written


@pytest.mark.parametrize("op", PROGRAM_OPS)
def test_lowering_passes_the_operands_an_op_reads(op):
    code = np.array([[op, M0, M0 + 1, M0 + 2]])
    body, _, folded = lower(code, LAY, no_memory=False)
    assert folded == 0
    want = tuple(("m", k) for k, name in enumerate("dab") if name in _reads(op))
    assert body[0].args == want


def _exported_python(name: str):
    scope = {"math": math, **TABLE_CONSTANTS}
    exec("def _clamp(v):\n    return min(max(v, -BIG), BIG)", scope)
    exec(py_export.op_function(name), scope)
    return scope[f"_{name}"]


@pytest.mark.parametrize("op", PROGRAM_OPS)
def test_exported_functions_take_the_operands_an_op_reads(op):
    name = OP_NAMES[op]
    fn = _exported_python(name)
    params = list(operands_read(op))
    assert list(fn.__code__.co_varnames[: fn.__code__.co_argcount]) == params
    for d in VALUES:
        for a in VALUES:
            for b in VALUES:
                given = {"d": d, "a": a, "b": b}
                assert fn(*(given[x] for x in params)) == reference_op(op, d, a, b)
    head = c_export.op_function(name).splitlines()[0]
    assert head == f"static double mtpg_op_{name}({', '.join('double ' + x for x in params)})"


@pytest.mark.parametrize("op", PROGRAM_OPS)
def test_the_disassembler_shows_the_operands_an_op_reads(op):
    (line,) = disassemble(np.array([[op, 1, 2, 3]]), LAY)
    assert ("r[2]" in line) == ("a" in _reads(op))
    assert "r[3]" in line and "r[1]" in line
