"""Constant folding: instructions whose result is known before the program runs.

The private registers ``r`` are zeroed before every execution and the constants never
change, so an instruction that reads only those (``r[3] <- cos(0.4)``, or ``exp(r[5])``
with ``r[5]`` not yet written in this execution) computes the same value at every
execution. The compiler (:func:`mtpg.engine.compile.compile_population`) computes such
values once, with the engine's own compiled :func:`~mtpg.engine.ops.apply_op` (so the very
same floating-point operations and math-library calls), and puts them in a pool of
*folded constants* in the workspace; the kernels then skip the instruction:

* a known result written to a private register is not executed at all: later reads of
  that register read the pool;
* a known result written to memory (stateful, seen by other programs and later steps)
  becomes one :data:`OP_COPY` of the pool value, and that memory register is then known
  for the rest of this execution;
* a conditional whose target is a private register of known value, but whose condition
  is not known, first gets the target's value copied in;
* a conditional whose condition is known to be false is not executed;
* at the end, when the bid ``r[0]`` is known but the register would not hold it, one
  copy writes it.

So every register the program leaves behind (the bid and its memory bank) holds the
same bits as without folding, and so does every value an executed instruction reads:
results are bit-identical. In an evolved population about 15% of the effective
instructions read only constants and zeroed registers, and about a quarter of the
math-library calls (``cos``, ``ln``, ``exp``, ``sin``, ``tanh``, ``pow``) go.

Folded code is for the batch kernels only: the tracer, which logs every instruction as
the program states it, compiles without folding.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from mtpg.engine.ops import OP_COPY, apply_op
from mtpg.model.graph import Program
from mtpg.model.instructions import (
    CONSTANTS,
    N_CONSTANTS,
    OP_READS,
    READS_A,
    READS_B,
    READS_TARGET,
    RegisterLayout,
)

_CONSTANTS = np.asarray(CONSTANTS, dtype=np.float64)


@njit(cache=True, error_model="numpy")
def _operand(x, known, is_known, constants, first_const):
    """``(known, value)`` of logical operand ``x``: a register, a constant or an input."""
    if x < first_const:
        return is_known[x], known[x]
    if x < first_const + len(constants):
        return True, constants[x - first_const]
    return False, 0.0  # the observation: known only when the program runs


@njit(cache=True, error_model="numpy", inline="always")
def _copy_row(out, n_out, dst, values, n_val, value, first_folded):
    """Writes row ``n_out`` of ``out``: a copy of pool value ``n_val`` into ``dst``.

    The row is one :data:`OP_COPY`; the pool value ``values[n_val]`` is set to ``value``.
    """
    values[n_val] = value
    out[n_out, 0], out[n_out, 1], out[n_out, 2] = OP_COPY, dst, dst
    out[n_out, 3] = first_folded + n_val


@njit(cache=True, error_model="numpy")
def _fold_kernel(code, n_r, first_const, constants, first_folded):
    """Folds one program's effective ``code`` (logical operands); see the module docstring.

    Returns:
        ``(folded code, values)``: operands ``first_folded + k`` read ``values[k]``.
    """
    n = len(code)
    out = np.empty((2 * n + 1, 4), dtype=np.int32)
    values = np.empty(4 * n + 1)
    # Value of each register of r and m, where known: r is zero before the program
    # runs; m is known once this execution has written a known value into it.
    known = np.zeros(first_const)
    is_known = np.zeros(first_const, dtype=np.bool_)
    is_known[:n_r] = True
    r0_written = False  # an executed instruction wrote r[0]
    n_out = 0
    n_val = 0
    for k in range(n):
        op, dst, a, b = code[k, 0], code[k, 1], code[k, 2], code[k, 3]
        reads = OP_READS[op]  # the operands the op reads
        reads_a = (reads & READS_A) != 0
        cond = (reads & READS_TARGET) != 0  # a conditional: reads (and may negate) its target
        # Each operand read: known (and its value) or not.
        ka, va = _operand(a, known, is_known, constants, first_const) if reads_a else (True, 0.0)
        kb, vb = (
            _operand(b, known, is_known, constants, first_const) if reads & READS_B else (True, 0.0)
        )
        kd, vd = (is_known[dst], known[dst]) if cond else (True, 0.0)
        if ka and kb and kd:
            v = apply_op(op, vd, va, vb)
            known[dst] = v
            is_known[dst] = True
            if dst < n_r:
                continue
            _copy_row(out, n_out, dst, values, n_val, v, first_folded)  # memory: written
            n_val += 1
            n_out += 1
            continue
        if cond and ka and kb and apply_op(op, 1.0, va, vb) == 1.0:
            continue  # a condition known to be false (1 not negated): changes nothing
        # Executed: reads of known private registers go to the pool instead.
        if cond and dst < n_r and is_known[dst]:
            _copy_row(out, n_out, dst, values, n_val, known[dst], first_folded)
            n_val += 1
            n_out += 1
        if reads_a and a < n_r and is_known[a]:
            values[n_val] = known[a]
            a = first_folded + n_val
            n_val += 1
        if reads & READS_B and b < n_r and is_known[b]:
            values[n_val] = known[b]
            b = first_folded + n_val
            n_val += 1
        out[n_out, 0], out[n_out, 1], out[n_out, 2], out[n_out, 3] = op, dst, a, b
        n_out += 1
        is_known[dst] = False
        if dst == 0:
            r0_written = True
    # The bid: r[0] must hold its value's bits (a zeroed register holds +0.0).
    if is_known[0] and (r0_written or known[0] != 0.0 or math.copysign(1.0, known[0]) < 0.0):
        _copy_row(out, n_out, 0, values, n_val, known[0], first_folded)
        n_val += 1
        n_out += 1
    return out[:n_out].copy(), values[:n_val].copy()


def first_folded(layout: RegisterLayout) -> int:
    """Logical index of folded constant 0 (after the observation)."""
    return layout.n_registers + layout.n_memory + N_CONSTANTS + layout.n_obs


def folded_code(
    prog: Program, effective: np.ndarray, layout: RegisterLayout
) -> tuple[np.ndarray, np.ndarray]:
    """The program's folded effective code and its pool values (cached on the program).

    Args:
        prog: The program (holds the cache; programs never change once made).
        effective: Its effective instructions (logical operands).
        layout: Register sizes.

    Returns:
        ``(code, values)``: int32 ``(n, 4)`` instructions whose operands
        ``first_folded(layout) + k`` read ``values[k]``.
    """
    if prog.folded is None:
        prog.folded = _fold_kernel(
            np.ascontiguousarray(effective, dtype=np.int32),
            layout.n_registers,
            layout.n_registers + layout.n_memory,
            _CONSTANTS,
            first_folded(layout),
        )
    return prog.folded
