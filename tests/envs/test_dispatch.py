"""Every registered task is dispatched by every kernel: interface, training, tracing, export.

The oracle calls each task's own kernels, named by its spec (``TaskSpec.kernel``), from
Python, so it does not go through the dispatch under test. A task missing from the
dispatch's if-chain observes NaN and ends at once with a NaN reward (checked below on an
id without a branch), so it fails every comparison here.
"""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest

from mtpg.engine.batch import BatchResult, Episodes, Jobs, evaluate_roots
from mtpg.engine.compile import compile_population
from mtpg.engine.episode_kernels import run_jobs_queue
from mtpg.engine.random_populations import tangled_population
from mtpg.engine.record import new_recorder
from mtpg.engine.trace import trace_episode
from mtpg.envs import env_observe, env_reset, env_step
from mtpg.envs.specs.contract import N_TASKS, STATE_SIZE, STEP_SLOT
from mtpg.envs.specs.param_table import P_KIND, TASK_PARAMS
from mtpg.envs.specs.registry import TASKS
from mtpg.export.harness import engine_stream

SEEDS = [0, 1]


def oracle(task: int, start: np.ndarray, noise: np.ndarray, actions: np.ndarray):
    """Plays ``actions`` through the task's own kernels: states, observations, rewards."""
    spec = TASKS[task]
    step, observe = spec.kernel("step"), spec.kernel("observe")
    p = TASK_PARAMS[task]
    state = start.copy()
    state[STEP_SLOT] = 0.0
    obs = np.zeros(2)
    states, observations, rewards = [state.copy()], [], []
    observe(p, state, noise[0], obs)
    for t, (a_d, a_c) in enumerate(actions):
        observations.append(obs.copy())
        state[STEP_SLOT] += 1.0
        reward, terminated = (
            step(p, state, int(a_d)) if not spec.continuous else step(p, state, a_c)
        )
        rewards.append(reward)
        states.append(state.copy())
        if terminated or state[STEP_SLOT] >= spec.max_steps:
            assert t == len(actions) - 1
            break
        observe(p, state, noise[t + 1], obs)
    return np.array(states), np.array(observations), np.array(rewards)


@pytest.fixture(scope="module")
def graph():
    pop = tangled_population(np.random.default_rng(7), 6, 20, 12, 4, 0.5)
    return pop, next(iter(pop.teams))


@pytest.mark.parametrize("task", range(N_TASKS), ids=[t.name for t in TASKS])
def test_every_kernel_dispatches_the_task(task, graph):
    pop, root = graph
    cp = compile_population(pop, fold_constants=False)  # traced too
    episodes = Episodes.grid([task], SEEDS)
    returns, result = evaluate_roots(compile_population(pop), [root], episodes)  # training
    stream = engine_stream(pop, root, [task], SEEDS)  # export harness
    for e, seed in enumerate(SEEDS):
        # tracing kernel
        trace = trace_episode(cp, root, task, episodes.starts[e], episodes.noise[e])
        states, observations, rewards = oracle(
            task, episodes.starts[e], episodes.noise[e], trace.actions
        )
        n = len(trace.actions)
        assert np.array_equal(trace.states[: n + 1], states)
        assert np.array_equal(trace.observations, observations)
        assert np.array_equal(trace.rewards, rewards)
        # training kernel: same return and length
        assert returns[0, e] == sum(rewards.tolist(), 0.0)  # summed in step order
        assert result.steps[e] == n
        # export harness: the observations the exported code is checked on
        rows = slice(int(np.flatnonzero(stream.starts)[e]), None)
        assert np.array_equal(stream.obs[rows][:n], observations)
        # interface kernels and the Gymnasium environment
        env = gymnasium.make(TASKS[task].gym_id).unwrapped
        obs, _ = env.reset(seed=seed)
        state = np.zeros(STATE_SIZE)
        env_reset(task, TASK_PARAMS, episodes.starts[e], state)
        for t in range(n):
            assert np.array_equal(obs, observations[t])
            a_d, a_c = int(trace.actions[t, 0]), float(trace.actions[t, 1])
            obs, reward, *_ = env.step((a_d, np.array([a_c])))
            assert reward == rewards[t]
            got = env_step(task, TASK_PARAMS, state, a_d, a_c)
            assert got[0] == rewards[t]
            assert np.array_equal(state, states[t + 1])


def test_an_id_without_a_branch_is_loud(graph):
    """What a kernel missing a task does: NaN observation, NaN reward, episode over."""
    pop, root = graph
    missing = N_TASKS
    row = TASK_PARAMS[:1].copy()
    row[0, P_KIND] = missing  # a row whose kind has no branch
    params = np.vstack([TASK_PARAMS, row])
    state = np.zeros(STATE_SIZE)
    obs = np.zeros(2)
    env_reset(missing, params, np.zeros(STATE_SIZE), state)
    env_observe(missing, params, state, 0.5, obs)
    assert np.isnan(obs).all()
    reward, terminated, truncated = env_step(missing, params, state, 0, 0.0)
    assert np.isnan(reward) and terminated and not truncated
    cp = compile_population(pop, fold_constants=False)  # traced too
    table = Episodes(
        np.array([missing]), np.zeros(1, np.int64), np.zeros((1, STATE_SIZE)), np.zeros((1, 201)),
        np.zeros((1, 0, 2)), params,
    )  # fmt: skip
    jobs = Jobs(np.array([cp.team_index(root)]), np.zeros(1, np.int64))
    out = BatchResult.zeros(1)
    run_jobs_queue(np.zeros(1, np.int64), 1, jobs, table, out, cp.graph)
    assert np.isnan(out.returns[0]) and out.steps[0] == 1
    rec = new_recorder(cp.graph, np.full(4, 1000), 200, False)  # traced: the same loop
    run_jobs_queue(np.zeros(1, np.int64), 1, jobs, table, out, cp.graph, rec)
    assert np.isnan(rec.observations[0]).all() and np.isnan(rec.rewards[0])
