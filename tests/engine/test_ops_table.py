"""The protected-operation table against values derived by hand, at and around thresholds.

The numbers below are written from the table in ``mtpg.model.instructions`` (and
``docs/engine.md``), not imported from the code: saturation at 1e10, division skipped when
``|b| < 1e-12``, ``pow`` saturating when ``b ln|a| > ln 1e10`` and vanishing when
``b ln|a| < -700``, ``exp`` saturating when ``b > ln 1e10``, ``ln 0 = 0``, strict
comparisons for the two conditionals. Both the compiled operation and the plain-Python
reference interpreter must give these values, so a changed constant in either (or in the
shared module they import) is caught.
"""

from __future__ import annotations

import math

import pytest

from mtpg.engine.ops import apply_op
from mtpg.engine.oracle import reference_op

OPS = {
    name: k
    for k, name in enumerate(
        "add sub mul div pow cos ln exp sqrt sin tanh square abs cube if_lt if_gt".split()
    )
}
SAT = 1e10  # every register saturates at +-1e10
LN_SAT = 23.025850929940457  # ln(1e10), to the last digit of a float64

# (operation, d, a, b, expected result)
TABLE = [
    # + - *: plain IEEE result, clamped to [-1e10, 1e10]
    ("add", 0.0, 1.5, -0.25, 1.25),
    ("add", 0.0, 5e9, 5e9, 1e10),  # exactly at the bound
    ("add", 0.0, 5e9, 5.000001e9, SAT),  # just above
    ("add", 0.0, -5e9, -5.000001e9, -SAT),
    ("add", 0.0, 4.9999e9, 5e9, 9.9999e9),  # just below stays
    ("sub", 0.0, -6e9, 6e9, -SAT),
    ("sub", 0.0, 1e10, 1e10, 0.0),
    ("sub", 0.0, 0.5, 2.0, -1.5),
    ("mul", 0.0, 1e5, 1e5, 1e10),
    ("mul", 0.0, 1e5, 1.0001e5, SAT),
    ("mul", 0.0, -1e5, 1.0001e5, -SAT),
    ("mul", 0.0, 99999.0, 1e5, 9999900000.0),
    ("mul", 0.0, 1e10, 1e10, SAT),
    # /: a / b; a unchanged when |b| < 1e-12
    ("div", 0.0, 3.0, 0.0, 3.0),
    ("div", 0.0, 3.0, -0.0, 3.0),
    ("div", 0.0, 1e-3, 9.99e-13, 1e-3),  # just below the threshold: no division
    ("div", 0.0, 1e-3, -9.99e-13, 1e-3),
    ("div", 0.0, 1e-3, 1e-12, 1e-3 / 1e-12),  # at the threshold: divides
    ("div", 0.0, 1e-3, -1e-12, -1e-3 / 1e-12),
    ("div", 0.0, 1e-3, 1e-10, 1e-3 / 1e-10),  # well above: divides
    ("div", 0.0, 1.0, 1e-11, SAT),  # 1e11 saturates
    ("div", 0.0, -1.0, 1e-11, -SAT),
    ("div", 0.0, 7.0, -2.0, -3.5),
    # pow: |a| ** b; 0 when a == 0; 1e10 when b ln|a| > ln 1e10; 0 when b ln|a| < -700
    ("pow", 0.0, 0.0, -3.0, 0.0),
    ("pow", 0.0, 0.0, 2.0, 0.0),
    ("pow", 0.0, -2.0, 3.0, 8.0),
    ("pow", 0.0, -4.0, 0.5, 2.0),
    ("pow", 0.0, 10.0, 9.99, math.pow(10.0, 9.99)),  # just below saturation: exact
    ("pow", 0.0, 10.0, 10.001, SAT),
    ("pow", 0.0, 0.1, -10.001, SAT),
    ("pow", 0.0, math.e, 22.9, math.pow(math.e, 22.9)),
    ("pow", 0.0, math.e, -699.5, math.pow(math.e, -699.5)),  # tiny but not zero
    ("pow", 0.0, math.e, -650.0, math.pow(math.e, -650.0)),
    ("pow", 0.0, math.e, -700.5, 0.0),  # past -700: zero
    ("pow", 0.0, 1e10, -71.0, 0.0),  # 71 * ln 1e10 > 700
    ("pow", 0.0, 1e10, -30.0, math.pow(1e10, -30.0)),
    ("pow", 0.0, 1e5, 1e5, SAT),
    # unary operations read b
    ("cos", 0.0, 9.0, 0.0, 1.0),
    ("cos", 0.0, 9.0, math.pi, -1.0),
    ("ln", 0.0, 9.0, 0.0, 0.0),  # ln 0 := 0
    ("ln", 0.0, 9.0, -0.0, 0.0),
    ("ln", 0.0, 9.0, -math.e, 1.0),  # ln|b|
    ("ln", 0.0, 9.0, 1e-300, math.log(1e-300)),
    ("ln", 0.0, 9.0, 5e-324, math.log(5e-324)),  # the smallest subnormal is not 0
    ("exp", 0.0, 9.0, 0.0, 1.0),
    ("exp", 0.0, 9.0, 23.0, math.exp(23.0)),  # below ln 1e10: exact
    ("exp", 0.0, 9.0, 23.02585, math.exp(23.02585)),  # 1e-6 below ln 1e10: still exact
    ("exp", 0.0, 9.0, 23.0259, SAT),
    ("exp", 0.0, 9.0, 1e9, SAT),
    ("exp", 0.0, 9.0, -800.0, 0.0),
    ("sqrt", 0.0, 9.0, -4.0, 2.0),
    ("sqrt", 0.0, 9.0, 1e10, 1e5),
    ("sin", 0.0, 9.0, math.pi / 2, 1.0),
    ("sin", 0.0, 9.0, -math.pi / 2, -1.0),
    ("tanh", 0.0, 9.0, 1e10, 1.0),
    ("tanh", 0.0, 9.0, 0.5, math.tanh(0.5)),
    ("square", 0.0, 9.0, -3.0, 9.0),
    ("square", 0.0, 9.0, 1e5, 1e10),
    ("square", 0.0, 9.0, -100001.0, SAT),
    ("abs", 0.0, 9.0, -2.5, 2.5),
    ("abs", 0.0, 9.0, -1e10, 1e10),
    ("cube", 0.0, 9.0, -2.0, -8.0),
    ("cube", 0.0, 9.0, 2154.0, 2154.0**3),  # just below the bound
    ("cube", 0.0, 9.0, 2155.0, SAT),
    ("cube", 0.0, 9.0, -2155.0, -SAT),
    # conditionals: negate d when a < b (a > b), strictly
    ("if_lt", 3.0, 1.0, 2.0, -3.0),
    ("if_lt", 3.0, 2.0, 2.0, 3.0),
    ("if_lt", 3.0, 2.0, 1.0, 3.0),
    ("if_lt", -1e10, -1.0, 0.0, 1e10),
    ("if_gt", 3.0, 2.0, 1.0, -3.0),
    ("if_gt", 3.0, 2.0, 2.0, 3.0),
    ("if_gt", 3.0, 1.0, 2.0, 3.0),
    ("if_gt", 0.5, 0.0, -0.0, 0.5),  # 0 > -0 is false
]


def test_ln_saturation_constant_is_the_log_of_the_bound() -> None:
    assert math.log(SAT) == LN_SAT


@pytest.mark.parametrize("impl", [apply_op, reference_op], ids=["compiled", "reference"])
@pytest.mark.parametrize(("name", "d", "a", "b", "want"), TABLE)
def test_protected_operation_table(impl, name, d, a, b, want) -> None:
    got = impl(OPS[name], d, a, b)
    assert got == pytest.approx(want, rel=1e-15, abs=0.0), (name, d, a, b)
    assert math.copysign(1.0, got) == math.copysign(1.0, want) or want == 0.0


def test_every_operation_appears_in_the_table() -> None:
    assert {row[0] for row in TABLE} == set(OPS)
    assert len(OPS) == 16
