"""Parity of the compiled kernels with Gymnasium's classic-control environments.

Same start state and same action sequence must give the same states (1e-9; 1e-6 for
Pendulum and MountainCarContinuous), the same rewards and the same termination flags.
Documented exceptions:

- CartPole: our time limit is 200 (CartPole-v0); the raw Gymnasium env has none, so the
  comparison runs up to our 200 steps.
- Our "repeat previous force" action has no Gymnasium analogue; it is translated by
  tracking the force we applied (``state[PREV_FORCE_SLOT]``).
- Acrobot: Gymnasium only takes torques -1/0/+1, so discrete-torque episodes drive its
  ``step``; continuous-torque episodes drive its own ``rk4``/``_dsdt``/``wrap``/``bound``.
- MountainCarContinuous: Gymnasium penalises the raw action and stores the state as
  float32; actions stay in [-1, 1] (where the penalties coincide) and Gymnasium's state
  is re-synchronised to ours (float64) before every step, comparing one step at a time.
"""

from __future__ import annotations

import numpy as np
import pytest
from gymnasium.envs.classic_control import acrobot as gym_acrobot
from gymnasium.envs.classic_control.acrobot import AcrobotEnv
from gymnasium.envs.classic_control.cartpole import CartPoleEnv
from gymnasium.envs.classic_control.continuous_mountain_car import Continuous_MountainCarEnv
from gymnasium.envs.classic_control.mountain_car import MountainCarEnv
from gymnasium.envs.classic_control.pendulum import PendulumEnv

from mtpg.envs import (
    ACROBOT,
    CARTPOLE,
    MAX_STEPS,
    MOUNTAINCAR,
    MOUNTAINCARCONTINUOUS,
    PENDULUM,
    PREV_FORCE_SLOT,
    STATE_DIMS,
    TASK_PARAMS,
    env_reset,
    env_step,
    sample_start,
)

N_EPISODES = 24
GYM_CLASSES = {
    CARTPOLE: CartPoleEnv,
    ACROBOT: AcrobotEnv,
    PENDULUM: PendulumEnv,
    MOUNTAINCAR: MountainCarEnv,
    MOUNTAINCARCONTINUOUS: Continuous_MountainCarEnv,
}
TOL = {
    CARTPOLE: 1e-9,
    ACROBOT: 1e-9,
    PENDULUM: 1e-6,
    MOUNTAINCAR: 1e-9,
    MOUNTAINCARCONTINUOUS: 1e-6,
}


def policy(task: int, s: np.ndarray, rng: np.random.Generator, smart: bool) -> tuple[int, float]:
    """Random actions, or a simple controller that survives / reaches the goal."""
    if not smart:
        a_d = int(rng.integers(0, 3))
        if task == ACROBOT:
            return a_d, float(rng.integers(-1, 2))  # Gymnasium's discrete torques
        a_c = float(rng.uniform(-1.0, 1.0)) * (2.0 if task == PENDULUM else 1.0)
        return a_d, a_c
    if task == CARTPOLE:
        if rng.random() < 0.2:
            return 1, 0.0
        return (0 if s[2] + 0.5 * s[3] > 0 else 2), 0.0
    if task == ACROBOT:
        return 0, float(np.sign(s[3]))
    if task == PENDULUM:
        return 0, float(np.clip(-5.0 * np.sin(s[0]) - s[1], -2.0, 2.0))
    push = 0 if s[1] >= 0 else 2
    return push, (1.0 if push == 0 else -1.0)


def gym_action(task: int, s_after: np.ndarray, a_d: int, a_c: float):
    if task == CARTPOLE:
        return 1 if s_after[PREV_FORCE_SLOT] > 0 else 0
    if task == ACROBOT:
        return int(a_c) + 1
    if task == MOUNTAINCAR:
        return {0: 2, 1: 1, 2: 0}[a_d]
    return np.array([a_c], dtype=np.float64)


def run_pair(task: int, seed: int, smart: bool) -> tuple[bool, bool]:
    env = GYM_CLASSES[task]()
    env.reset(seed=seed)
    start = sample_start(task, np.random.default_rng(seed))
    dim = STATE_DIMS[task]
    # Our start draws are Gymnasium's reset draws.
    np.testing.assert_array_equal(start[:dim], np.asarray(env.state, dtype=np.float64))
    state = np.zeros_like(start)
    env_reset(task, TASK_PARAMS, start, state)
    env.state = state[:dim].copy()
    rng = np.random.default_rng(10_000 + seed)
    tol = TOL[task]
    for t in range(int(MAX_STEPS[task])):
        a_d, a_c = policy(task, state, rng, smart)
        if task == MOUNTAINCARCONTINUOUS:
            env.state = state[:dim].copy()
        reward, terminated, truncated = env_step(task, TASK_PARAMS, state, a_d, a_c)
        _, g_reward, g_terminated, _, _ = env.step(gym_action(task, state, a_d, a_c))
        g_state = np.asarray(env.state, dtype=np.float64)
        np.testing.assert_allclose(state[:dim], g_state, rtol=0, atol=tol, err_msg=f"step {t}")
        assert reward == pytest.approx(g_reward, abs=tol), t
        assert terminated == g_terminated, t
        assert truncated == (not terminated and t + 1 == MAX_STEPS[task])
        if terminated or truncated:
            return terminated, truncated
    raise AssertionError("episode did not end")


@pytest.mark.parametrize("task", sorted(GYM_CLASSES))
def test_parity_with_gymnasium(task: int) -> None:
    ends = [run_pair(task, seed, smart=seed % 2 == 1) for seed in range(N_EPISODES)]
    n_term = sum(te for te, _ in ends)
    n_trunc = sum(tr for _, tr in ends)
    assert n_term + n_trunc == N_EPISODES
    assert n_trunc > 0
    if task != PENDULUM:
        assert n_term > 0


def test_acrobot_continuous_torque_matches_gymnasium_rk4() -> None:
    env = AcrobotEnv()
    rng = np.random.default_rng(7)
    for seed in range(20):
        start = sample_start(ACROBOT, np.random.default_rng(seed))
        state = np.zeros_like(start)
        env_reset(ACROBOT, TASK_PARAMS, start, state)
        for t in range(int(MAX_STEPS[ACROBOT])):
            a_c = float(np.sign(state[3])) * rng.uniform(0.5, 1.5) if seed % 2 else rng.normal()
            torque = float(np.clip(a_c, -1.0, 1.0))
            ns = gym_acrobot.rk4(env._dsdt, np.append(state[:4], torque), [0, env.dt])
            ns[0] = gym_acrobot.wrap(ns[0], -np.pi, np.pi)
            ns[1] = gym_acrobot.wrap(ns[1], -np.pi, np.pi)
            ns[2] = gym_acrobot.bound(ns[2], -env.MAX_VEL_1, env.MAX_VEL_1)
            ns[3] = gym_acrobot.bound(ns[3], -env.MAX_VEL_2, env.MAX_VEL_2)
            env.state = ns
            g_terminated = env._terminal()
            reward, terminated, truncated = env_step(ACROBOT, TASK_PARAMS, state, 0, a_c)
            np.testing.assert_allclose(state[:4], ns, rtol=0, atol=1e-9, err_msg=f"step {t}")
            assert terminated == g_terminated
            assert reward == (0.0 if g_terminated else -1.0)
            if terminated or truncated:
                break
