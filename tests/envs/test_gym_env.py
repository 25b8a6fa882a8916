from __future__ import annotations

import subprocess
import sys

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import mtpg.envs
from mtpg.envs import GYM_IDS, MAX_STEPS, STATE_DIMS, TASK_NAMES, make_episodes


@pytest.mark.filterwarnings("ignore:.*Box action space.*:UserWarning")
@pytest.mark.parametrize("task", range(len(TASK_NAMES)))
def test_check_env_passes(task: int) -> None:
    env = gymnasium.make(GYM_IDS[task], render_mode="rgb_array")
    check_env(env.unwrapped)
    env.close()


def test_module_prefixed_id() -> None:
    env = gymnasium.make("mtpg.envs:mtpg/CartPole-v0")
    assert env.unwrapped.spec.id == "mtpg/CartPole-v0"
    env.close()


@pytest.mark.parametrize("task", range(len(TASK_NAMES)))
def test_render_gives_rgb_frame(task: int) -> None:
    env = gymnasium.make(GYM_IDS[task], render_mode="rgb_array")
    env.reset(seed=3)
    env.step((0, np.array([0.5])))
    frame = env.render()
    assert frame.ndim == 3 and frame.shape[2] == 3 and frame.dtype == np.uint8
    assert frame.min() < frame.max()
    env.close()


@pytest.mark.parametrize("task", range(len(TASK_NAMES)))
def test_reset_matches_make_episodes(task: int) -> None:
    """reset(seed) draws the start and then one noise value per observation."""
    seed = 123 + task
    starts, noise = make_episodes(np.array([task]), np.array([seed]))
    env = mtpg.envs.MtpgEnv(task)
    obs, info = env.reset(seed=seed)
    dim = STATE_DIMS[task]
    np.testing.assert_array_equal(info["state"], starts[0, :dim])
    assert set(info) == {"state"}
    rng = np.random.default_rng(99)
    for t in range(int(MAX_STEPS[task])):
        if task in (2, 3, 4, 5):  # one observed variable: obs[1] is the episode noise
            assert obs[1] == noise[0, t]
        action = (int(rng.integers(0, 3)), np.array([rng.uniform(-1, 1)]))
        obs, reward, terminated, truncated, info = env.step(action)
        assert env.observation_space.contains(obs)
        assert info["state"].shape == (dim,)
        assert isinstance(reward, float)
        if terminated or truncated:
            assert truncated == (t + 1 == MAX_STEPS[task] and not terminated)
            break


def test_block_noise_equals_one_at_a_time() -> None:
    a = np.random.default_rng(5).random(1000)
    rng = np.random.default_rng(5)
    b = np.array([rng.random() for _ in range(1000)])
    np.testing.assert_array_equal(a, b)


def test_time_limits() -> None:
    np.testing.assert_array_equal(MAX_STEPS, [200, 500, 500, 200, 200, 999])


def test_import_registers_without_numba() -> None:
    code = (
        "import sys, gymnasium, mtpg.envs\n"
        "assert 'numba' not in sys.modules\n"
        "assert all(i in gymnasium.registry for i in mtpg.envs.GYM_IDS)\n"
        "env = gymnasium.make('mtpg/CartPole-v0')\n"
        "obs, info = env.reset(seed=0)\n"
        "assert obs.shape == (2,)\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)
