"""The protected operations of Table 2 as one compiled function.

The semantics (and the protection table) are documented in
:mod:`mtpg.model.instructions`, which also holds the one table of the operands each op
reads (:data:`~mtpg.model.instructions.OP_READS`); the reference interpreter implements
the same arithmetic in plain Python with the same floating-point operations.
"""

from __future__ import annotations

import math

from llvmlite import ir
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic

from mtpg.model.instructions import BIG, DIV_EPS, LOG_BIG, LOG_TINY
from mtpg.model.instructions import OP_COPY as OP_COPY  # the engine-only op, re-exported


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


#: ``pow`` may skip its overflow test (``b * ln x`` against ``LOG_BIG`` and ``LOG_TINY``)
#: when ``|b| <= 1`` and ``x`` lies in ``[POW_SAFE_LO, POW_SAFE_HI]``: then
#: ``|b * ln x| <= ln(1e8) < 18.5``, far inside both limits, so the test always passes.
POW_SAFE_LO = 1e-8
POW_SAFE_HI = 1e8


# Short-cuts, same bits: each returns what the plain operation returns, without a
# math-library call where the result is known (an exact zero operand, or a test whose
# outcome is known). Proven by tests/engine/test_ops_shortcuts.py against the plain
# operations (-0, +-BIG, the division threshold, subnormals, random values).


@njit(cache=True, error_model="numpy", inline="always")
def op_div(a: float, b: float) -> float:
    """Protected division, before the clamp."""
    return a if abs(b) < DIV_EPS else a / b


@njit(cache=True, error_model="numpy", inline="always")
def op_pow(a: float, b: float) -> float:
    """Protected ``|a| ** b``, before the clamp.

    ``b == 0``: ``x ** 0`` is 1 for every ``x > 0`` (``0 * ln x`` is a zero, inside the
    limits). ``|b| <= 1`` with ``x`` in the safe range: the overflow test always passes
    (:data:`POW_SAFE_LO`), so ``ln x`` is not computed.
    """
    x = abs(a)
    if x == 0.0:
        return 0.0
    if b == 0.0:
        return 1.0
    if abs(b) <= 1.0 and POW_SAFE_LO <= x <= POW_SAFE_HI:
        return math.pow(x, b)
    e = b * math.log(x)
    if e > LOG_BIG:
        return BIG
    if e < LOG_TINY:
        return 0.0
    return math.pow(x, b)


@njit(cache=True, error_model="numpy", inline="always")
def op_cos(b: float) -> float:
    """``cos b``; ``cos(+-0) = 1`` exactly."""
    return 1.0 if b == 0.0 else math.cos(b)


@njit(cache=True, error_model="numpy", inline="always")
def op_log(b: float) -> float:
    """Protected ``ln |b|`` (``ln 0 := 0``)."""
    return 0.0 if b == 0.0 else math.log(abs(b))


@njit(cache=True, error_model="numpy", inline="always")
def op_exp(b: float) -> float:
    """Protected ``exp b``, before the clamp; ``exp(+-0) = 1`` exactly."""
    if b > LOG_BIG:
        return BIG
    return 1.0 if b == 0.0 else math.exp(b)


@njit(cache=True, error_model="numpy", inline="always")
def op_sin(b: float) -> float:
    """``sin b``; ``sin(+-0)`` is the operand itself (the sign of zero kept)."""
    return b if b == 0.0 else math.sin(b)


@njit(cache=True, error_model="numpy", inline="always")
def op_tanh(b: float) -> float:
    """``tanh b``; ``tanh(+-0)`` is the operand itself (the sign of zero kept)."""
    return b if b == 0.0 else math.tanh(b)


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
        v = op_div(a, b)
    elif op == 4:
        v = op_pow(a, b)
    elif op == 5:
        v = op_cos(b)
    elif op == 6:
        v = op_log(b)
    elif op == 7:
        v = op_exp(b)
    elif op == 8:
        v = math.sqrt(abs(b))
    elif op == 9:
        v = op_sin(b)
    elif op == 10:
        v = op_tanh(b)
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
