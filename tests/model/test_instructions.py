import numpy as np

from mtpg.engine.compile import effective_mask
from mtpg.model.instructions import (
    RegisterLayout,
    disassemble,
    random_instructions,
    valid_instructions,
)

L = RegisterLayout()


def test_random_instructions_obey_operand_rules():
    code = random_instructions(np.random.default_rng(0), L, 5000)
    assert valid_instructions(code, L) is None
    assert set(np.unique(code[:, 0])) == set(range(16))
    # targets only in r or m; the first operand never reads the observation
    assert code[:, 1].max() < L.const_start
    assert code[:, 2].max() < L.obs_start
    # about one third of second operands read the observation
    frac = np.mean(code[:, 3] >= L.obs_start)
    assert 0.3 < frac < 0.37


def test_effective_mask_example_of_algorithm_1():
    m0, m2, m7, r0, r1, r7, s1 = (
        L.mem_start,
        L.mem_start + 2,
        L.mem_start + 7,
        0,
        1,
        7,
        L.obs_start + 1,
    )
    code = np.array(
        [
            [3, m0, m7, s1],  # m[0] <- m[7] / s[1]      effective (memory)
            [3, r1, m0, r7],  # r[1] <- m[0] / r[7]      intron
            [5, r0, 0, m0],  # r[0] <- cos(m[0])        effective
            [14, r0, r0, m2],  # if r[0] < m[2]: negate   effective
        ],
        dtype=np.int32,
    )
    assert effective_mask(code, L).tolist() == [True, False, True, True]
    assert disassemble(code, L)[0] == "m[0] <- m[7] / s[1]"


def test_effective_mask_liveness_chain():
    code = np.array(
        [
            [0, 2, 3, 4],  # r2 <- r3 + r4   effective: r2 read below
            [0, 5, 2, 2],  # r5 <- r2 + r2   intron: r5 never read
            [5, 0, 0, 2],  # r0 <- cos(r2)   effective (unary reads only src2)
            [0, 3, 0, 0],  # r3 <- ...       intron: after the last read of r3
        ],
        dtype=np.int32,
    )
    assert effective_mask(code, L).tolist() == [True, False, True, False]


def test_model_imports_no_numba():
    import subprocess
    import sys

    code = "import sys, mtpg.model, mtpg.model.graph; print('numba' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "False"
