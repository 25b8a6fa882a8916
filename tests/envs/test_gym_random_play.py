"""Random play on a Gymnasium task is measured with actions apart from the environment's draws."""

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from mtpg.envs.specs.gym_task import measure_random


class _Guess(gym.Env):
    """One step: reward +1 when the action equals a coin the reset drew, else -1."""

    observation_space = spaces.Box(-1.0, 1.0, (1,), dtype=np.float64)
    action_space = spaces.Discrete(2)

    def reset(self, *, seed=None, options=None):
        super().reset(seed=seed)
        self.coin = int(self.np_random.integers(2))
        return np.zeros(1), {}

    def step(self, action):
        return np.zeros(1), 1.0 if int(action) == self.coin else -1.0, True, False, {}


def test_random_play_does_not_share_the_environment_s_random_stream():
    gym.register("mtpgtest/Guess-v0", entry_point=_Guess, max_episode_steps=5)
    mean, std = measure_random("gym:mtpgtest/Guess-v0")
    # seeded alike, the action space drew the environment's own coin: always right
    assert abs(mean) < 0.3 and std > 0.9, (mean, std)
