"""One instruction over a group of lanes: a loop per op code (the lane engine's inner loop).

Each loop computes :func:`~mtpg.engine.ops.apply_op`'s value for its op code with the
same functions (the short-cuts included), so the op code is tested once per group, not
once per lane; tests/engine/test_ops_shortcuts.py checks every op code bit for bit.
"""

from __future__ import annotations

import math

from numba import njit

from mtpg.engine.lane_graph import C_A, C_B, C_DST, C_MA, C_MB, C_OP
from mtpg.engine.ops import _clamp, op_cos, op_div, op_exp, op_log, op_pow, op_sin, op_tanh


@njit(cache=True, error_model="numpy", inline="always")
def lane_op(Wf, c, grp, n):
    """Runs one instruction over the lanes ``grp[:n]``: one loop per op code.

    ``c`` is the instruction as :func:`~mtpg.engine.lane_graph.localise` translates it
    (uint64, ``C_*`` columns of :mod:`mtpg.engine.lane_graph`): op code, target address
    ``ud``, operand addresses ``ua``, ``ub`` and their lane masks ``ma``, ``mb``. Operand
    ``x`` of lane ``l`` is ``Wf[ux + (l & mx)]``: a lane's own value (``mx`` all ones) or
    one value shared by all lanes (``mx = 0``: a constant).

    Each loop computes :func:`~mtpg.engine.ops.apply_op`'s value for its op code with the
    same functions, so the op code is tested once per group, not once per lane. The loops
    are written in three steps by the operands they read: the binary ops, the unary ops,
    the conditionals and the copy.
    """
    op = c[C_OP]
    if op < 5:
        _binary(Wf, c, grp, n, op)
    elif op < 14:
        _unary(Wf, c, grp, n, op)
    else:
        _conditional_or_copy(Wf, c, grp, n, op)


@njit(cache=True, error_model="numpy", inline="always")
def _binary(Wf, c, grp, n, op):
    """Op codes 0 to 4 (``+ - * / pow``), over the lanes ``grp[:n]``."""
    ud, ua, ma, ub, mb = c[C_DST], c[C_A], c[C_MA], c[C_B], c[C_MB]
    if op == 0:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = _clamp(Wf[ua + (lane & ma)] + Wf[ub + (lane & mb)])
    elif op == 1:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = _clamp(Wf[ua + (lane & ma)] - Wf[ub + (lane & mb)])
    elif op == 2:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = _clamp(Wf[ua + (lane & ma)] * Wf[ub + (lane & mb)])
    elif op == 3:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = _clamp(op_div(Wf[ua + (lane & ma)], Wf[ub + (lane & mb)]))
    elif op == 4:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = _clamp(op_pow(Wf[ua + (lane & ma)], Wf[ub + (lane & mb)]))


@njit(cache=True, error_model="numpy", inline="always")
def _unary(Wf, c, grp, n, op):
    """Op codes 5 to 13 (the unary ops: each reads the second operand only)."""
    ud, ub, mb = c[C_DST], c[C_B], c[C_MB]
    if op == 5:
        for k in range(n):
            lane = grp[k]
            # within [-1, 1]: the clamp changes nothing
            Wf[ud + lane] = op_cos(Wf[ub + (lane & mb)])
    elif op == 6:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = _clamp(op_log(Wf[ub + (lane & mb)]))
    elif op == 7:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = _clamp(op_exp(Wf[ub + (lane & mb)]))
    elif op == 8:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = _clamp(math.sqrt(abs(Wf[ub + (lane & mb)])))
    elif op == 9:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = op_sin(Wf[ub + (lane & mb)])  # within [-1, 1]
    elif op == 10:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = op_tanh(Wf[ub + (lane & mb)])  # within [-1, 1]
    elif op == 11:
        for k in range(n):
            lane = grp[k]
            b = Wf[ub + (lane & mb)]
            Wf[ud + lane] = _clamp(b * b)
    elif op == 12:
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = abs(Wf[ub + (lane & mb)])  # operands are within [-BIG, BIG]
    elif op == 13:
        for k in range(n):
            lane = grp[k]
            b = Wf[ub + (lane & mb)]
            Wf[ud + lane] = _clamp(b * b * b)


@njit(cache=True, error_model="numpy", inline="always")
def _conditional_or_copy(Wf, c, grp, n, op):
    """Op codes 14 and 15 (the conditionals) and the engine's copy."""
    ud, ua, ma, ub, mb = c[C_DST], c[C_A], c[C_MA], c[C_B], c[C_MB]
    if op == 14:
        for k in range(n):
            lane = grp[k]
            d = Wf[ud + lane]
            Wf[ud + lane] = -d if Wf[ua + (lane & ma)] < Wf[ub + (lane & mb)] else d
    elif op == 15:
        for k in range(n):
            lane = grp[k]
            d = Wf[ud + lane]
            Wf[ud + lane] = -d if Wf[ua + (lane & ma)] > Wf[ub + (lane & mb)] else d
    else:  # OP_COPY
        for k in range(n):
            lane = grp[k]
            Wf[ud + lane] = Wf[ub + (lane & mb)]
