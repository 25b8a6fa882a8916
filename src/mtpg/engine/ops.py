"""The protected operations of Table 2 as one compiled function.

The semantics (and the protection table) are documented in
:mod:`mtpg.model.instructions`; the reference interpreter implements the same table in
plain Python with the same floating-point operations.
"""

from __future__ import annotations

import math

from numba import njit

from mtpg.model.instructions import BIG, DIV_EPS, LOG_BIG, LOG_TINY, N_OPS

#: Engine-only op code (never in a program): ``dst <- src2``, the copy that constant
#: folding (:mod:`mtpg.engine.fold`) writes where a known value must reach a register.
OP_COPY = N_OPS


@njit(cache=True, error_model="numpy", inline="always")
def apply_op(op: int, d: float, a: float, b: float) -> float:
    """Computes one instruction's new target value (inlined into the decision kernel).

    Args:
        op: Op code (0..15, or :data:`OP_COPY`).
        d: Current value of the target (read by the conditionals).
        a: First operand.
        b: Second operand.

    Returns:
        The new target value, finite and within ``[-BIG, BIG]``.
    """
    if op == 0:
        v = a + b
    elif op == 1:
        v = a - b
    elif op == 2:
        v = a * b
    elif op == 3:
        v = a if abs(b) < DIV_EPS else a / b
    elif op == 4:
        x = abs(a)
        if x == 0.0:
            v = 0.0
        else:
            e = b * math.log(x)
            if e > LOG_BIG:
                v = BIG
            elif e < LOG_TINY:
                v = 0.0
            else:
                v = math.pow(x, b)
    elif op == 5:
        v = math.cos(b)
    elif op == 6:
        v = 0.0 if b == 0.0 else math.log(abs(b))
    elif op == 7:
        v = BIG if b > LOG_BIG else math.exp(b)
    elif op == 8:
        v = math.sqrt(abs(b))
    elif op == 9:
        v = math.sin(b)
    elif op == 10:
        v = math.tanh(b)
    elif op == 11:
        v = b * b
    elif op == 12:
        v = abs(b)
    elif op == 13:
        v = b * b * b
    elif op == 14:
        v = -d if a < b else d
    elif op == 15:
        v = -d if a > b else d
    else:  # OP_COPY: a value already within [-BIG, BIG]
        return b
    if v > BIG:
        return BIG
    if v < -BIG:
        return -BIG
    return v
