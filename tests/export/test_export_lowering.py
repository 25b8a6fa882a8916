"""Export-time evaluation of what does not vary between decisions."""

import math

import numpy as np

from mtpg.export.lowering import Statement, lower
from mtpg.model.instructions import OP_ADD, OP_EXP, OP_IF_LT, OP_MUL, RegisterLayout

LAY = RegisterLayout()
M0, S0 = LAY.mem_start, LAY.obs_start
MINUS_03 = LAY.const_start + 6  # the constants run -0.9 ... -0.1, 0.1 ... 0.9


def test_instructions_on_constants_and_zeroed_registers_become_literals():
    code = np.array(
        [
            [OP_EXP, 1, 0, MINUS_03],  # r1 = exp(-0.3): known
            [OP_IF_LT, 1, 2, 1],  # if r2 < r1: r1 = -r1 (0 < exp(-0.3)): known
            [OP_ADD, 0, 1, S0],  # r0 = r1 + s0: reads the observation
            [OP_MUL, M0, 1, 1],  # m0 = r1 * r1: known, but memory is always written
        ]
    )
    body, bid, folded = lower(code, LAY, no_memory=False)
    r1 = -math.exp(-0.3)
    assert folded == 3
    assert body == [
        Statement(("r", 0), "add", (("c", r1), ("s", 0))),
        Statement(("m", 0), None, (("c", r1 * r1),)),
    ]
    assert bid == ("r", 0)


def test_memory_is_unknown_with_memory_and_zero_without():
    code = np.array([[OP_ADD, 0, M0, MINUS_03]])  # r0 = m0 + (-0.3)
    body, bid, folded = lower(code, LAY, no_memory=False)
    assert body == [Statement(("r", 0), "add", (("m", 0), ("c", -0.3)))] and folded == 0
    body, bid, folded = lower(code, LAY, no_memory=True)
    assert body == [] and bid == ("c", -0.3) and folded == 1


def test_a_write_with_an_unknown_value_forgets_the_register():
    code = np.array([[OP_ADD, 3, S0, S0], [OP_ADD, 0, 3, 3]])
    body, bid, folded = lower(code, LAY, no_memory=False)
    assert [st.args for st in body] == [(("s", 0), ("s", 0)), (("r", 3), ("r", 3))]
    assert folded == 0
