"""Arbitrary actions (NaN, +-inf, huge, out-of-range a_d) never break a task."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from mtpg.envs import (
    MAX_STEPS,
    N_OBS,
    STATE_SIZE,
    TASK_NAMES,
    TASK_PARAMS,
    env_observe,
    env_reset,
    env_step,
    make_episodes,
)

TASKS = range(len(TASK_NAMES))
A_C = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([math.nan, math.inf, -math.inf, 1e300, -1e300, 0.0, -0.0, 5e-324]),
)
A_D = st.integers(min_value=-(2**40), max_value=2**40)


def run_full_episode(task: int, seed: int, actions: list[tuple[int, float]]) -> int:
    starts, noise = make_episodes(np.array([task]), np.array([seed]))
    state = np.zeros(STATE_SIZE)
    obs = np.zeros(N_OBS)
    env_reset(task, TASK_PARAMS, starts[0], state)
    env_observe(task, TASK_PARAMS, state, noise[0, 0], obs)
    t = 0
    while True:
        assert np.all(np.abs(obs) <= 1.0), (t, obs)
        a_d, a_c = actions[t % len(actions)]
        reward, terminated, truncated = env_step(task, TASK_PARAMS, state, a_d, a_c)
        assert np.all(np.isfinite(state)), (t, state)
        assert math.isfinite(reward)
        if terminated or truncated:
            assert t + 1 <= MAX_STEPS[task]
            return t + 1
        t += 1
        env_observe(task, TASK_PARAMS, state, noise[0, t], obs)


@pytest.mark.parametrize("task", TASKS)
@settings(max_examples=40, deadline=None)
@given(
    seed=st.integers(min_value=0, max_value=2**32),
    actions=st.lists(st.tuples(A_D, A_C), min_size=1, max_size=20),
)
def test_arbitrary_actions_keep_obs_and_state_valid(
    task: int, seed: int, actions: list[tuple[int, float]]
) -> None:
    run_full_episode(task, seed, actions)


@pytest.mark.parametrize("task", TASKS)
@pytest.mark.parametrize("a_c", [math.nan, math.inf, -math.inf, 1e300, -1e300])
def test_extreme_constant_actions(task: int, a_c: float) -> None:
    run_full_episode(task, 0, [(0, a_c), (2, a_c), (1, a_c)])


@pytest.mark.parametrize("task", TASKS)
def test_non_finite_a_c_acts_as_zero_and_bad_a_d_as_one(task: int) -> None:
    starts, _ = make_episodes(np.array([task]), np.array([3]))
    a = np.zeros(STATE_SIZE)
    b = np.zeros(STATE_SIZE)
    env_reset(task, TASK_PARAMS, starts[0], a)
    env_reset(task, TASK_PARAMS, starts[0], b)
    for t in range(30):
        env_step(task, TASK_PARAMS, a, 1, 0.0)
        env_step(task, TASK_PARAMS, b, 7 if t % 2 else -3, math.nan if t % 2 else math.inf)
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("task", TASKS)
def test_a_c_clipped_to_bound(task: int) -> None:
    starts, _ = make_episodes(np.array([task]), np.array([4]))
    bound = TASK_PARAMS[task, 1]
    a = np.zeros(STATE_SIZE)
    b = np.zeros(STATE_SIZE)
    env_reset(task, TASK_PARAMS, starts[0], a)
    env_reset(task, TASK_PARAMS, starts[0], b)
    for _ in range(10):
        ra = env_step(task, TASK_PARAMS, a, 0, 1e9)
        rb = env_step(task, TASK_PARAMS, b, 0, bound)
        np.testing.assert_array_equal(a, b)
        assert ra == rb
