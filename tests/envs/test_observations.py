"""Observation values of every task at every step, against an independent oracle.

The expected observation is derived from Gymnasium's own state (CartCentering: from a
plain-Python copy of Koza's update) with the scaling written out by hand from the
specification (``shared/spec/environments.md``, table "The tasks"), never with the
project's constants:

=====================  =========================================  =================
task                   obs[0]                                     obs[1]
=====================  =========================================  =================
CartPole               x / 2.4                                    theta / 0.2094395
Acrobot                theta1 / pi                                theta2 / pi
CartCentering          x / 1.5                                    noise
Pendulum               wrap(theta) / pi                           noise
MountainCar(Cont.)     2 * (x + 1.2) / 1.8 - 1                    noise
=====================  =========================================  =================

each clipped to [-1, 1]. The noise is U[0, 1] from the episode's own generator: after
Gymnasium's ``reset(seed=s)`` has drawn the start state, the next ``np_random.random()``
values are the noise of the observations at reset and after every step.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from gymnasium.envs.classic_control.acrobot import AcrobotEnv
from gymnasium.envs.classic_control.cartpole import CartPoleEnv
from gymnasium.envs.classic_control.continuous_mountain_car import Continuous_MountainCarEnv
from gymnasium.envs.classic_control.mountain_car import MountainCarEnv
from gymnasium.envs.classic_control.pendulum import PendulumEnv

from mtpg.engine.compile import compile_population
from mtpg.engine.trace import trace_episode
from mtpg.envs import (
    ACROBOT,
    CARTCENTERING,
    CARTPOLE,
    MOUNTAINCAR,
    MOUNTAINCARCONTINUOUS,
    PENDULUM,
    MtpgEnv,
    make_episodes,
)
from mtpg.envs.dynamics.numeric import clip_obs
from mtpg.model.graph import Population, atomic
from mtpg.model.instructions import RegisterLayout

GYM = {
    CARTPOLE: CartPoleEnv,
    ACROBOT: AcrobotEnv,
    PENDULUM: PendulumEnv,
    MOUNTAINCAR: MountainCarEnv,
    MOUNTAINCARCONTINUOUS: Continuous_MountainCarEnv,
}
#: Gymnasium keeps Pendulum's and MountainCarContinuous's states in float32.
TOL = {CARTPOLE: 1e-7, ACROBOT: 1e-7, PENDULUM: 1e-5, MOUNTAINCAR: 1e-7}
TOL[MOUNTAINCARCONTINUOUS] = 1e-5
TOL[CARTCENTERING] = 1e-12
EPISODES = 6


def clip1(x: float) -> float:
    return min(1.0, max(-1.0, x))


def wrap(theta: float) -> float:
    """Angle in [-pi, pi), written independently of the code under test."""
    return theta - 2 * math.pi * math.floor((theta + math.pi) / (2 * math.pi))


def expected_position_obs(task: int, state) -> float:
    """obs[0] from a hidden state in Gymnasium's order, by the spec's scaling."""
    if task == CARTPOLE:
        return clip1(state[0] / 2.4)
    if task == ACROBOT:
        return clip1(state[0] / math.pi)
    if task == CARTCENTERING:
        return clip1(state[0] / 1.5)
    if task == PENDULUM:
        return clip1(wrap(state[0]) / math.pi)
    return clip1(2 * (state[0] + 1.2) / 1.8 - 1)


def expected_second_obs(task: int, state, noise: float) -> float:
    if task == CARTPOLE:
        return clip1(state[2] / 0.2094395)
    if task == ACROBOT:
        return clip1(state[1] / math.pi)
    return noise


def policy(task: int, state, t: int, rng: np.random.Generator, k: int) -> tuple[int, float]:
    """Random play (even episodes) or a controller that reaches far states (odd ones)."""
    if k % 2 == 0:
        if task == ACROBOT:  # Gymnasium's Acrobot takes only the torques -1, 0, +1
            return 0, float(rng.integers(-1, 2))
        return int(rng.integers(0, 3)), float(rng.uniform(-2.5, 2.5))
    if task in (CARTPOLE, CARTCENTERING):
        return (0 if t % 40 < 20 else 2), 0.0  # swing to large angles / drift far out
    if task == ACROBOT:
        return 0, float(np.sign(state[3]) or 1.0)  # pump energy: large angles, wrap-around
    if task == PENDULUM:
        return 0, 2.0 * float(np.sign(state[1]) or 1.0)  # spin the pendulum over the top
    push = 0 if state[1] >= 0 else 2  # swing up the hill
    return push, (1.0 if push == 0 else -1.0)


def gym_action(task: int, a_d: int, a_c: float, force_sign: float):
    if task == CARTPOLE:
        return 1 if force_sign > 0 else 0
    if task == ACROBOT:
        return int(np.clip(a_c, -1, 1)) + 1  # policy torques are -1 / +1
    if task == MOUNTAINCAR:
        return {0: 2, 1: 1, 2: 0}[a_d]
    return np.array([np.clip(a_c, -2.0 if task == PENDULUM else -1.0, 2.0)], dtype=np.float32)


def koza_step(x: float, v: float, force: float) -> tuple[float, float]:
    """CartCentering, Koza section 7.1: x += tau v, then v += tau F / m, |v| <= 6."""
    x = x + 0.02 * v
    v = min(6.0, max(-6.0, v + 0.02 * force / 2.0))
    return x, v


@pytest.mark.parametrize("task", sorted(GYM))
def test_observations_equal_gymnasium_state_scaled_by_the_spec(task: int) -> None:
    rng = np.random.default_rng(5)
    extremes = [0.0, 0.0, 0.0]  # largest |obs[0]|, |obs[1]|, |hidden state[0]|
    for k in range(EPISODES):
        seed = 300 + k
        ours = MtpgEnv(task)
        gym = GYM[task]()
        obs, info = ours.reset(seed=seed)
        gym.reset(seed=seed)
        force_sign = 1.0
        for t in range(1000):
            g_state = np.asarray(gym.state, dtype=np.float64)
            noise = float(gym.np_random.random())  # the next draw of the episode's generator
            want = [expected_position_obs(task, g_state), expected_second_obs(task, g_state, noise)]
            np.testing.assert_allclose(obs, want, rtol=0, atol=TOL[task], err_msg=f"step {t}")
            extremes = np.maximum(extremes, np.abs([want[0], want[1], g_state[0]]))
            a_d, a_c = policy(task, g_state, t, rng, k)
            if task == CARTPOLE:
                force_sign = {0: 1.0, 2: -1.0}.get(a_d, force_sign)
            if task in (PENDULUM, MOUNTAINCARCONTINUOUS):
                gym.state = info["state"].copy()  # Gymnasium rounds these states to float32
            obs, _, term, trunc, info = ours.step((a_d, np.array([a_c])))
            gym.step(gym_action(task, a_d, a_c, force_sign))
            if term or trunc:
                break
    # the episodes reach the regions where clipping and wrapping matter
    if task == CARTPOLE:
        assert extremes[1] > 0.9  # the pole falls past (or near) the threshold
    if task == ACROBOT:
        assert extremes[0] > 0.5
    if task == PENDULUM:
        assert extremes[2] > 2 * math.pi  # the raw angle left [-pi, pi]: wrap is exercised
    if task in (MOUNTAINCAR, MOUNTAINCARCONTINUOUS):
        assert extremes[0] > 0.9


def test_cartcentering_observations_follow_koza_state() -> None:
    rng = np.random.default_rng(6)
    for k in range(EPISODES):
        seed = 400 + k
        ours = MtpgEnv(CARTCENTERING)
        obs, info = ours.reset(seed=seed)
        episode_rng = np.random.default_rng(seed)
        while True:  # Koza's start: x, v ~ U[-0.75, 0.75], redrawn while captured
            x, v = episode_rng.uniform(-0.75, 0.75, size=2)
            if not (abs(x) <= 0.01 and abs(v) <= 0.01):
                break
        force = 1.0  # before the first step the previous force is +F
        for t in range(500):
            want = [clip1(x / 1.5), float(episode_rng.random())]
            np.testing.assert_allclose(obs, want, rtol=0, atol=1e-12, err_msg=f"step {t}")
            a_d, _ = policy(CARTCENTERING, (x, v), t, rng, k)
            force = {0: 1.0, 2: -1.0}.get(a_d, force)
            x, v = koza_step(x, v, force)
            obs, _, term, trunc, _ = ours.step((a_d, np.zeros(1)))
            if term or trunc:
                break


def copy_graph(source: int) -> tuple[Population, int]:
    """A root whose every program writes ``m[0] <- r[1] + s[source]``: a_c = s[source]."""
    layout = RegisterLayout()
    pop = Population(layout=layout)
    bank = pop.new_bank()
    code = np.array([[0, layout.mem_start, 1, layout.obs_start + source]], dtype=np.int32)
    pids = [pop.add_program(code, atomic(a), bank).id for a in (0, 2)]
    return pop, pop.add_team(pids).id


@pytest.mark.parametrize("task", sorted([*GYM, CARTCENTERING]))
def test_the_engine_feeds_programs_exactly_these_observations(task: int) -> None:
    starts, noise = make_episodes(np.full(3, task), np.arange(3) + 500)
    for source in (0, 1):
        pop, root = copy_graph(source)
        cp = compile_population(pop, fold_constants=False)
        for i in range(3):
            trace = trace_episode(cp, root, task, starts[i], noise[i])
            seen = trace.actions[:, 1]  # a_c of each decision = the observed value
            for t, value in enumerate(seen):
                state = trace.states[t]
                if source == 0:
                    want = expected_position_obs(task, state)
                else:
                    want = expected_second_obs(task, state, noise[i, t])
                assert value == pytest.approx(want, abs=TOL[task]), (source, i, t)


@pytest.mark.parametrize(
    ("raw", "want"),
    [(math.nan, 0.0), (math.inf, 1.0), (-math.inf, -1.0), (1.5, 1.0), (-0.25, -0.25)],
)
def test_observation_clip_maps_into_the_unit_interval(raw: float, want: float) -> None:
    assert clip_obs(raw) == want
