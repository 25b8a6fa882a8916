import itertools
import math

import numpy as np
import pytest

from mtpg.engine.ops import apply_op
from mtpg.engine.oracle import reference_op
from mtpg.model.instructions import BIG, N_OPS

EXTREMES = [
    0.0,
    -0.0,
    1e-320,
    -1e-320,
    1e-13,
    0.5,
    -0.5,
    1.0,
    -1.0,
    2.0,
    -3.7,
    23.0,
    24.0,
    700.0,
    -700.0,
    1e5,
    -1e5,
    BIG,
    -BIG,
]


@pytest.mark.parametrize("op", range(N_OPS))
def test_kernel_op_matches_reference_bit_for_bit_and_stays_finite(op):
    for d, a, b in itertools.product([0.0, -2.5, BIG], EXTREMES, EXTREMES):
        got = apply_op(op, d, a, b)
        want = reference_op(op, d, a, b)
        assert math.isfinite(got) and abs(got) <= BIG, (op, d, a, b, got)
        assert np.float64(got).tobytes() == np.float64(want).tobytes(), (op, d, a, b)


def test_ops_random_values_match():
    rng = np.random.default_rng(1)
    values = np.concatenate(
        [rng.normal(0, 1, 300), rng.normal(0, 1e6, 100), rng.uniform(-BIG, BIG, 100)]
    )
    for op in range(N_OPS):
        for a, b in rng.choice(values, size=(200, 2)):
            assert apply_op(op, 1.5, a, b) == reference_op(op, 1.5, a, b)


def test_protected_forms():
    assert apply_op(3, 0.0, 5.0, 0.0) == 5.0  # division by ~0 leaves the numerator
    assert apply_op(6, 0.0, 0.0, 0.0) == 0.0  # ln 0 := 0
    assert apply_op(6, 0.0, 0.0, -math.e) == pytest.approx(1.0)  # ln|x|
    assert apply_op(8, 0.0, 0.0, -4.0) == 2.0  # sqrt|x|
    assert apply_op(7, 0.0, 0.0, 1e9) == BIG  # capped exp
    assert apply_op(4, 0.0, -2.0, 3.0) == 8.0  # |a|^b
    assert apply_op(4, 0.0, 1e5, 1e5) == BIG
    assert apply_op(14, 3.0, 1.0, 2.0) == -3.0 and apply_op(14, 3.0, 2.0, 1.0) == 3.0
    assert apply_op(15, 3.0, 2.0, 1.0) == -3.0 and apply_op(15, 3.0, 1.0, 2.0) == 3.0
    assert apply_op(2, 0.0, BIG, BIG) == BIG and apply_op(13, 0.0, 0.0, -BIG) == -BIG
