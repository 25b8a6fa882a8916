"""The per-step dispatch compiles without reference counting (docs/engine.md).

The batch kernel calls :func:`~mtpg.envs.dynamics.dispatch.task_step` and
:func:`~mtpg.envs.dynamics.dispatch.task_observe` once per step, passing the state, the parameter
row and the observation. Compiled with Numba's reference counting, each call would pay an
atomic increment and decrement per array (about ten per step); compiled as step kernels,
their machine code, with the task functions inlined into it, calls neither.

Numba cannot show the machine code of a function loaded from its cache, so the check
compiles in a fresh process with an empty cache directory.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

SCRIPT = """
import json
import numpy as np
from mtpg.envs import TASK_PARAMS
from mtpg.envs.specs.contract import STATE_SIZE
from mtpg.envs.dynamics.dispatch import add_obs_noise, task_observe, task_step
p = TASK_PARAMS[0].copy()
p.flags.writeable = False  # the batch kernel's parameter table is read-only
state, obs = np.zeros(STATE_SIZE), np.zeros(2)
task_step(np.int64(0), p, state, np.int64(1), 0.0)
task_observe(np.int64(0), p, state, 0.5, obs)
add_obs_noise(p, 0.0, 0.0, obs)
out = {}
for fn in (task_step, task_observe, add_obs_noise):
    (sig,) = fn.signatures
    asm = fn.inspect_asm(sig)
    out[fn.__name__] = [len(asm), asm.count("NRT_incref"), asm.count("NRT_decref")]
print(json.dumps(out))
"""


def test_dispatch_has_no_reference_counting(tmp_path):
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path)}
    done = subprocess.run(
        [sys.executable, "-c", SCRIPT], env=env, capture_output=True, text=True, check=True
    )
    assert "Inspection disabled" not in done.stderr
    found = json.loads(done.stdout.strip().splitlines()[-1])
    for name, (size, increfs, decrefs) in found.items():
        assert size > 1000, f"no machine code shown for {name}"
        assert (increfs, decrefs) == (0, 0), f"{name} calls NRT_incref/NRT_decref"
