"""The protected operations of Table 2 as one compiled function.

The semantics (and the protection table) are documented in
:mod:`mtpg.model.instructions`; the reference interpreter implements the same table in
plain Python with the same floating-point operations.
"""

from __future__ import annotations

import math

from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

from mtpg.model.instructions import BIG, DIV_EPS, LOG_BIG, LOG_TINY, N_OPS

#: Engine-only op code (never in a program): ``dst <- src2``, the copy that constant
#: folding (:mod:`mtpg.engine.fold`) writes where a known value must reach a register.
OP_COPY = N_OPS


@intrinsic
def _clamp(typingctx, v):
    """``v`` limited to ``[-BIG, BIG]``, without a branch.

    The same value as ``-BIG if v < -BIG else (BIG if v > BIG else v)`` for every value an
    instruction computes (all finite: the operations of Table 2 are protected, so no NaN
    reaches it, where ``maxnum``/``minnum`` would differ). Written as the two LLVM
    intrinsics because the optimiser turns the two comparisons back into two branches per
    instruction; the intrinsics compile to one ``maxsd`` and one ``minsd`` on x86.
    """
    if v != types.float64:
        return None

    def codegen(context, builder, signature, args):
        f64 = ir.DoubleType()
        fnty = ir.FunctionType(f64, [f64, f64])
        fmax = cgutils.get_or_insert_function(builder.module, fnty, "llvm.maxnum.f64")
        fmin = cgutils.get_or_insert_function(builder.module, fnty, "llvm.minnum.f64")
        low = builder.call(fmax, [args[0], ir.Constant(f64, -BIG)])
        return builder.call(fmin, [low, ir.Constant(f64, BIG)])

    return types.float64(types.float64), codegen


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
    return _clamp(v)
