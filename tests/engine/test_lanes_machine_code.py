"""The lane engine's machine code calls the scalar math library, never a vector one.

Every lane must compute what the scalar kernel computes, bit for bit. A vector math
library (Numba's SVML, when Intel's ``icc_rt`` is installed) computes ``cos`` and the
others to other bits, so the lane loops must not be vectorised into it. The check
compiles the lane kernel in a fresh process with an empty cache and reads the assembly of
its block loop (``play_block``, the decision steps inlined), which must also hold no
reference counting (it is compiled without, for speed).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

SCRIPT = """
import json
import numpy as np
from mtpg.engine.batch import BatchResult, Episodes, Jobs
from mtpg.engine.compile import compile_population
from mtpg.engine.lanes import play_block, run_lanes_queue
from mtpg.engine.random_populations import tangled_population
pop = tangled_population(np.random.default_rng(0), 3, 10, 8, 3, 0.5)
cp = compile_population(pop)
eps = Episodes.grid([0, 3], [0])
roots = np.array([cp.team_index(r) for r in pop.roots()][:1] * 2, dtype=np.int64)
out = BatchResult.zeros(2)
run_lanes_queue(np.zeros(1, np.int64), 2, 4, Jobs(roots, np.arange(2)), eps, out, cp.graph)
(sig,) = play_block.signatures  # the lane loops, every decision step inlined
asm = play_block.inspect_asm(sig)
print(json.dumps([len(asm), asm.lower().count("svml"), asm.count("cos"), asm.count("NRT_")]))
"""


def test_lane_kernel_uses_no_vector_math_library(tmp_path):
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    done = subprocess.run(
        [sys.executable, "-c", SCRIPT], env=env, capture_output=True, text=True, check=True
    )
    size, svml, cos, nrt = json.loads(done.stdout.strip().splitlines()[-1])
    assert size > 10_000, "no machine code shown"
    assert svml == 0
    assert cos > 0  # the scalar call is there
    assert nrt == 0  # compiled without reference counting: no NRT_incref, NRT_decref
