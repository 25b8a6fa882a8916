"""The dispatch of a task set with compiled tasks of users' modules, generated per set.

The registered tasks' dispatch (:mod:`mtpg.envs.dynamics.dispatch`) is an if-chain compiled
once and cached. A run with compiled tasks (:mod:`mtpg.envs.specs.compiled_task`) gets a
dispatch generated for its tasks: one branch per compiled task, the registered dispatch
for every other kind, with the same four names and signatures (``env_reset``,
``task_observe``, ``task_step``, ``task_continuous``), so the engine's episode loop runs
unchanged on it (:mod:`mtpg.engine.user_kernels`). Generated code has no source file, so
it is compiled in each process (Numba caches by source file).

State layout of such a set: the registered tasks' ``STATE_SIZE`` slots (their bookkeeping,
the previous force and the step count, included), then the compiled task's own state at
``USER_STATE_BASE`` onwards; its functions see only their own slots (``s = state[6:6+d]``).
Inputs past a task's ``n_obs`` are set to 0 at every observation, so a program reading an
input its task lacks reads 0 (as for Gymnasium tasks).

Continuous outputs: a task of one continuous dimension gets ``a_c = m[0]`` (made 0 when not
finite, then clipped to ``[-p[1], p[1]]``) as a float, as the registered tasks do. A task of
``n > 1`` dimensions gets them as an array: before each step the engine calls
``task_continuous`` with the deciding bank, whose branch for the task copies ``m[0..n)``,
each made finite and clipped the same way, into the ``n`` slots after the task's own state
(``state[6+d : 6+d+n]``), and its ``step`` receives that slice as ``a_c``. The copy is a
decision: the engine's next decision overwrites it, so ``step`` may read it but keeps
nothing there.
"""

from __future__ import annotations

import re
from functools import cache

import numpy as np
from numba import njit

from mtpg.envs.dynamics import dispatch
from mtpg.envs.specs.compiled_task import CompiledTask, CompiledTaskError
from mtpg.envs.specs.contract import N_OBS, STATE_SIZE, STEP_SLOT

#: First slot of a compiled task's own state in the engine's state array.
USER_STATE_BASE = STATE_SIZE

_TEMPLATE = """
def env_reset(task, params, start, state):
    for i in range(len(start)):
        state[i] = start[i]
    if task < FIRST_USER:
        base_reset(task, params, start, state)

def task_observe(kind, p, state, noise, obs):
{observe}
    base_observe(kind, p, state, noise, obs)
    for i in range(N_OBS, len(obs)):
        obs[i] = 0.0

def task_step(kind, p, state, a_d, a_c):
{step}
    return base_step(kind, p, state, a_d, a_c)

def task_continuous(kind, p, state, W, off, stride):
{continuous}
    return None
"""

_OBSERVE = """    if kind == {kind}:
        u{k}_observe(p, state[BASE:BASE + {d}], noise, obs)
        for i in range({n_obs}, len(obs)):
            obs[i] = 0.0
        return
"""

_STEP = """    if kind == {kind}:
        state[STEP_SLOT] += 1.0
        a = a_c if a_c - a_c == 0.0 else 0.0
        a = min(max(a, -p[1]), p[1]) if {continuous} else 0.0
        r, term = u{k}_step(p, state[BASE:BASE + {d}], {a_d}, a)
        return r, term, (not term) and state[STEP_SLOT] >= p[0]
"""

_STEP_MANY = """    if kind == {kind}:
        state[STEP_SLOT] += 1.0
        r, term = u{k}_step(p, state[BASE:BASE + {d}], {a_d}, state[BASE + {d}:BASE + {e}])
        return r, term, (not term) and state[STEP_SLOT] >= p[0]
"""

_CONTINUOUS = """    if kind == {kind}:
        for j in range({n}):
            v = W[off + np.uint64(j) * stride]
            v = v if v - v == 0.0 else 0.0
            state[BASE + {d} + j] = min(max(v, -p[1]), p[1])
        return
"""


@cache
def generate(tasks: tuple[CompiledTask, ...], first_id: int) -> tuple:
    """The dispatch of a set of compiled tasks (task ``k`` has id ``first_id + k``).

    Returns:
        ``(env_reset, task_observe, task_step, task_continuous)``, Numba functions of the
        registered dispatch's signatures.
    """
    names: dict = {
        "FIRST_USER": first_id,
        "N_OBS": N_OBS,
        "BASE": USER_STATE_BASE,
        "STEP_SLOT": STEP_SLOT,
        "base_reset": dispatch.env_reset,
        "base_observe": dispatch.task_observe,
        "base_step": dispatch.task_step,
        "np": np,
    }
    observe, step, continuous = [], [], []
    for k, task in enumerate(tasks):
        names[f"u{k}_observe"], names[f"u{k}_step"] = task.observe, task.step
        a_d = f"a_d % {task.n_actions}" if task.n_actions else "0"
        fill = {"kind": first_id + k, "k": k, "d": task.state_dim, "n_obs": task.n_obs}
        observe.append(_OBSERVE.format(**fill))
        if task.n_continuous > 1:
            n = task.n_continuous
            step.append(_STEP_MANY.format(**fill, a_d=a_d, e=task.state_dim + n))
            continuous.append(_CONTINUOUS.format(**fill, n=n))
        else:
            step.append(_STEP.format(**fill, a_d=a_d, continuous=task.continuous))
    source = _TEMPLATE.format(
        observe="".join(observe), step="".join(step), continuous="".join(continuous)
    )
    exec(compile(source, f"<mtpg dispatch of {', '.join(t.name for t in tasks)}>", "exec"), names)
    jit = njit(error_model="numpy")
    fns = tuple(jit(names[f]) for f in ("env_reset", "task_observe", "task_step"))
    fns += (njit(error_model="numpy", inline="always")(names["task_continuous"]),)
    for k, task in enumerate(tasks):
        _try_compile(task, first_id + k, fns[1], fns[2], fns[3])
    return fns


def _try_compile(task: CompiledTask, kind: int, observe, step, continuous) -> None:
    """Compiles a task's branch by calling it once on a zero state (its errors, one line).

    Raises:
        CompiledTaskError: With Numba's message cut to what the user wrote wrong.
    """
    from numba.core.errors import NumbaError

    p = np.zeros(max(len(task.row()), 2))
    p[: len(task.row())] = task.row()
    p.setflags(write=False)  # as the kernels' parameter rows are
    state = np.zeros(USER_STATE_BASE + task.slots)
    obs = np.zeros(max(task.n_obs, N_OBS))
    bank = np.zeros(max(task.n_continuous, 1))
    try:
        with np.errstate(all="ignore"):
            observe(np.int64(kind), p, state, 0.5, obs)
            continuous(np.int64(kind), p, state, bank, np.uint64(0), np.uint64(1))
            step(np.int64(kind), p, state, np.int64(0), 0.0)
    except NumbaError as exc:
        raise CompiledTaskError(f"compiled task {task.name}: {short_numba_error(exc)}") from None


def short_numba_error(exc: Exception) -> str:
    """Numba's compile error in one line: what went wrong, and the line of the user's file.

    ``No implementation of function setitem found for signature: setitem(array(float64,
    1d, C), int64, unicode_type) -- badtask.py line 11: s[0] = "left"``.
    """
    raw = [re.sub(r"\x1b\[[0-9;]*m", "", line).rstrip() for line in str(exc).splitlines()]
    lines = [line.strip() for line in raw]
    skip = ("Failed in", "During:", "File ", ">>>", "^", "There are", "- Of which", "Overload")
    what = next((line for line in lines if line and not line.startswith(skip)), "")
    what = re.sub(r"Function\(<[^>]*function (\w+)>\)", r"\1", what)
    signature = next((line[3:].strip() for line in lines if line.startswith(">>>")), "")
    if signature:
        what = f"{what} {signature}"
    where = ""
    for k, line in enumerate(lines):
        found = re.match(r'File "(.*)", line (\d+):', line)
        if found:
            code = next((c for c in lines[k + 1 :] if c and not c.startswith("def ")), "")
            where = f" -- {found.group(1).rsplit('/', 1)[-1]} line {found.group(2)}: {code}"
            break
    return (what or type(exc).__name__) + where
