"""The six built-in tasks written as compiled tasks play and train exactly as the built-ins.

``mtpg.envs.dynamics.builtin_compiled`` writes each registered task with the public
compiled-task contract, from its own module's kernels. Here each one, through the user-task
path (the generated dispatch and the engine's loops compiled again with it), steps as the
registered dispatch does, action for action, and a run over all six trains and tests as the
run over the six registered tasks, number for number (the names differ: compared by task).
"""

from __future__ import annotations

import numpy as np
import pytest

from mtpg.envs.dynamics import builtin_compiled as bc
from mtpg.envs.dynamics import dispatch
from mtpg.envs.dynamics.user_dispatch import USER_STATE_BASE, generate
from mtpg.envs.specs.param_table import N_TASK_COLUMNS, TASK_PARAMS
from mtpg.envs.specs.registry import TASK_NAMES, TASKS
from mtpg.envs.taskset.episodes import make_episodes
from mtpg.envs.taskset.task_table import BUILTIN_SHAPE, REGISTERED, TaskTable

COMPILED = [bc.NAMES[name] for name in TASK_NAMES]
# the tiny demo run of tests/cli/test_compiled_tasks.py
SMALL = ["team.root_size=20", "team.n_elite=2", "team.min_elite_total=0"]
SMALL += ["evaluation.test_interval=2", "evaluation.test_episodes=4"]
TIMING = ("t_", "decisions_per_s")
#: Compiled name -> registered name, the longest first (MOUNTAINCAR is in MOUNTAINCARCONTINUOUS).
RENAME = sorted(zip(COMPILED, TASK_NAMES, strict=True), key=lambda pair: -len(pair[0]))


def test_each_is_its_registered_task_in_the_contracts_terms():
    table = TaskTable.from_names(COMPILED)
    assert table.shape == BUILTIN_SHAPE
    for k, spec in enumerate(TASKS):
        task = table.spec(table.ids[k])
        assert task.observe is spec.kernel("observe")  # one definition of the dynamics
        assert (task.n_obs, task.n_actions, task.continuous) == (2, 3, spec.continuous)
        assert task.max_steps == spec.max_steps
        row = table.params[table.ids[k], :N_TASK_COLUMNS]
        assert np.array_equal(row, TASK_PARAMS[k, :N_TASK_COLUMNS])


def _play(reset, observe, step, table, task, start, noise, a_d, a_c, base):
    """One episode through a dispatch: per step the physical state, inputs and outcome."""
    params = table.params
    p = params[task]
    state = np.zeros(start.shape[0])
    obs = np.zeros(2)
    reset(task, params, start, state)
    observe(np.int64(p[N_TASK_COLUMNS]), p, state, noise[0], obs)
    rows = []
    for t in range(a_d.shape[0]):
        reward, term, trunc = step(np.int64(p[N_TASK_COLUMNS]), p, state, a_d[t], a_c[t])
        observe(np.int64(p[N_TASK_COLUMNS]), p, state, noise[t + 1], obs)
        rows.append([*state[base : base + 4], *obs, reward, term, trunc])
        if term or trunc:
            break
    return np.array(rows)


def test_each_steps_as_the_registered_dispatch_action_for_action():
    table = TaskTable.from_names(COMPILED)
    user = generate(table.user, table.ids[0])[:3]
    builtin = (dispatch.env_reset, dispatch.task_observe, dispatch.task_step)
    rng = np.random.default_rng(54)
    seeds = np.arange(700, 704)
    for k, spec in enumerate(TASKS):
        ours = table.ids[k]
        starts, noise = make_episodes(np.full(len(seeds), k), seeds, REGISTERED)
        u_starts, u_noise = make_episodes(np.full(len(seeds), ours), seeds, table)
        assert np.array_equal(noise, u_noise)
        d = spec.state_dim
        assert np.array_equal(starts[:, :d], u_starts[:, USER_STATE_BASE : USER_STATE_BASE + d])
        for i in range(len(seeds)):
            a_d = rng.integers(0, 3, spec.max_steps)
            a_c = rng.normal(0.0, 2.0 * max(spec.bound, 1.0), spec.max_steps)
            a_c[rng.random(spec.max_steps) < 0.05] = np.nan  # made 0 by both
            a_c[rng.random(spec.max_steps) < 0.05] = np.inf
            theirs = _play(*builtin, REGISTERED, k, starts[i], noise[i], a_d, a_c, 0)
            mine = _play(*user, table, ours, u_starts[i], u_noise[i], a_d, a_c, USER_STATE_BASE)
            # slots past a task's physical state hold its bookkeeping, as in the built-in
            assert np.array_equal(mine[:, d:], theirs[:, d:], equal_nan=True), spec.name
            assert np.array_equal(mine[:, :d], theirs[:, :d]), spec.name


@pytest.fixture(scope="module")
def both_runs():
    import mtpg

    base = mtpg.preset("demo", *SMALL, tasks=list(TASK_NAMES), generations=6, workers=1)
    refs = "evaluation.references=" + repr(bc.references())
    user = mtpg.preset("demo", *SMALL, refs, tasks=COMPILED, generations=6, workers=1)
    return mtpg.train(base), mtpg.train(user)


def _renamed(row: dict) -> dict:
    out = {}
    for key, value in row.items():
        if key.startswith(TIMING):
            continue
        for compiled, name in RENAME:
            key = key.replace(compiled, name)
            if isinstance(value, str):  # a task subset: names joined by "+"
                value = value.replace(compiled, name)
        out[key] = value
    return out


def test_the_six_train_as_the_registered_six_bit_for_bit(both_runs):
    base, user = both_runs
    assert len(base.metrics) == len(user.metrics) == 6
    assert [_renamed(r) for r in user.metrics] == [_renamed(r) for r in base.metrics]
    assert user.tests and [_renamed(r) for r in user.tests] == [_renamed(r) for r in base.tests]


def test_the_champions_score_the_same_on_held_out_episodes(both_runs):
    import mtpg

    base, user = (mtpg.evaluate(run, episodes=10) for run in both_runs)
    for name, compiled in zip(TASK_NAMES, COMPILED, strict=True):
        ours, theirs = user[compiled], base[name]
        assert np.array_equal(ours.returns, theirs.returns), name
        assert (ours.mean, ours.std) == (theirs.mean, theirs.std)
        assert ours.normalised == theirs.normalised  # bc.references(): the registry's
