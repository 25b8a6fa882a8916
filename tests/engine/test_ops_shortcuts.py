"""The math short-cuts and the lane engine's per-op loops give the plain operation's bits.

``apply_op`` skips math-library calls whose result is known (an exact zero operand, a
``pow`` overflow test whose outcome is known) and the lane engine runs each op code in a
loop of its own (``lanes.lane_op``). Both must give, bit for bit (the sign of zero
included), what the plain-Python reference (``reference_op``, the plain operations of the
protection table) gives, on the values where a short-cut could slip: signed zeros,
subnormals, +-BIG, the division threshold, the edges of the ``pow`` safe range, and
random values over every scale.
"""

import itertools
import math

import numpy as np
import pytest

from mtpg.engine.lane_ops import lane_op
from mtpg.engine.ops import OP_COPY, POW_SAFE_HI, POW_SAFE_LO, apply_op
from mtpg.engine.oracle import reference_op
from mtpg.model.instructions import BIG, DIV_EPS, LOG_BIG, N_OPS


def _around(x: float) -> list[float]:
    return [np.nextafter(x, -np.inf), x, np.nextafter(x, np.inf)]


SPECIAL = sorted(
    {
        v
        for x in [
            0.0,
            5e-324,
            2.2250738585072014e-308,
            1e-300,
            DIV_EPS,
            1e-9,
            POW_SAFE_LO,
            0.1,
            0.5,
            1.0,
            2.0,
            math.pi,
            LOG_BIG,
            700.0,
            POW_SAFE_HI,
            1e9,
            BIG,
        ]
        for y in _around(x)
        for v in (y, -y)
        if abs(v) <= BIG
    }
    | {0.0, -0.0},
    key=lambda v: (v, math.copysign(1.0, v)),
)


def _bits(x: float) -> bytes:
    return np.float64(x).tobytes()


def _random_values(n: int) -> np.ndarray:
    rng = np.random.default_rng(20261204)
    mags = 10.0 ** rng.uniform(-320, 10, n)
    return np.where(rng.random(n) < 0.5, -mags, mags)


@pytest.mark.parametrize("op", range(N_OPS))
def test_short_cuts_equal_the_plain_operation_on_special_values(op):
    for d, a, b in itertools.product([0.0, -0.0, -2.5, BIG], SPECIAL, SPECIAL):
        assert _bits(apply_op(op, d, a, b)) == _bits(reference_op(op, d, a, b)), (op, d, a, b)


@pytest.mark.parametrize("op", [3, 4, 5, 6, 7, 9, 10])
def test_short_cuts_equal_the_plain_operation_on_random_values(op):
    values = _random_values(4000)
    for a, b in zip(values, values[::-1], strict=True):
        assert _bits(apply_op(op, 0.0, a, b)) == _bits(reference_op(op, 0.0, a, b)), (op, a, b)


def test_pow_safe_range_really_skips_nothing():
    """Inside the safe range the overflow test can never fire: |b ln x| < 18.5."""
    for x in _around(POW_SAFE_LO) + _around(POW_SAFE_HI):
        assert abs(1.0 * math.log(x)) < 18.5 < LOG_BIG


@pytest.mark.parametrize("op", [*range(N_OPS), OP_COPY])
def test_lane_loops_equal_apply_op(op):
    values = np.concatenate([np.array(SPECIAL), _random_values(200)])
    n_lanes = len(values)
    rng = np.random.default_rng(op)
    # workspace rows: 0 target, 1 first operand, 2 second operand; lanes in columns
    W = np.stack([rng.permutation(values), rng.permutation(values), values]).ravel()
    want = [apply_op(op, W[k], W[n_lanes + k], W[2 * n_lanes + k]) for k in range(n_lanes)]
    grp = rng.permutation(n_lanes).astype(np.uint64)[: n_lanes - 3]  # some lanes left out
    before = W.copy()
    every = ~np.uint64(0)
    code = np.array([op, 0, n_lanes, every, 2 * n_lanes, every], dtype=np.uint64)
    lane_op(W, code, grp, len(grp))
    in_grp = set(grp.tolist())
    for k in range(n_lanes):
        expect = want[k] if k in in_grp else before[k]
        assert _bits(W[k]) == _bits(expect), (op, k)
    # a shared operand (a constant): every lane reads the one value at its address
    W = before.copy()
    c = 2 * n_lanes + 5
    want = [apply_op(op, W[k], W[n_lanes + k], W[c]) for k in range(n_lanes)]
    code = np.array([op, 0, n_lanes, every, c, 0], dtype=np.uint64)
    lane_op(W, code, grp, len(grp))
    for k in range(n_lanes):
        expect = want[k] if k in in_grp else before[k]
        assert _bits(W[k]) == _bits(expect), (op, k)
