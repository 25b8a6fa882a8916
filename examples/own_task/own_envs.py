"""Two environments of a researcher's own, for ``mtpg train --tasks gym:own_envs:...``.

Put this folder on ``PYTHONPATH`` (``PYTHONPATH=examples/own_task``); importing the module
registers the environments with Gymnasium, which is what ``gym:own_envs:ID`` asks for.

- ``CartPoleNoVelocity-v0``: Gymnasium's CartPole-v1 with the two velocities hidden
  (observed: cart position and pole angle), so a policy must remember to infer them.
- ``CueMemory-v0``: a cue (+1 or -1) is shown on the first step only; after a delay of
  silent steps the agent is asked for it (the second input turns 1) and is rewarded +1
  for the action that matches the cue, -1 otherwise. Without memory the best policy
  guesses: expected return 0.

``DiscreteTorque`` is no task of mtpg's: it gives Pendulum-v1 a ``Discrete`` action space
for pytpg, which acts in no other (see study.py).
"""

from __future__ import annotations

import gymnasium as gym
import numpy as np
from gymnasium import spaces


class HideVelocities(gym.ObservationWrapper):
    """CartPole with observation (x, theta): the velocities hidden."""

    def __init__(self, env: gym.Env) -> None:
        super().__init__(env)
        box = env.observation_space
        self.observation_space = spaces.Box(box.low[[0, 2]], box.high[[0, 2]], dtype=box.dtype)

    def observation(self, observation: np.ndarray) -> np.ndarray:
        """The cart position and the pole angle."""
        return observation[[0, 2]]


def cartpole_no_velocity(**kwargs) -> gym.Env:
    """CartPole-v1 with its velocities hidden (Gymnasium's time limit included)."""
    return HideVelocities(gym.make("CartPole-v1", **kwargs))


class DiscreteTorque(gym.ActionWrapper):
    """A continuous-torque environment played through a few fixed torques.

    Args:
        env: An environment with a ``Box`` action of shape ``(1,)``.
        n: How many torques, evenly spaced from the lowest to the highest.
    """

    def __init__(self, env: gym.Env, n: int = 5) -> None:
        super().__init__(env)
        box = env.action_space
        self.torques = np.linspace(box.low[0], box.high[0], n).astype(box.dtype)
        self.action_space = spaces.Discrete(n)

    def action(self, action: int) -> np.ndarray:
        """Torque number ``action``."""
        return self.torques[[int(action)]]


class CueMemory(gym.Env):
    """Remember a cue over a delay (see the module docstring).

    Args:
        delay: Silent steps between the cue and the question.
    """

    def __init__(self, delay: int = 5) -> None:
        self.delay = delay
        self.observation_space = spaces.Box(-1.0, 1.0, (2,), dtype=np.float64)
        self.action_space = spaces.Discrete(2)
        self.t = 0
        self.cue = 1.0

    def reset(self, *, seed: int | None = None, options: dict | None = None):
        """A new cue, shown now."""
        super().reset(seed=seed)
        self.t = 0
        self.cue = 1.0 if self.np_random.random() < 0.5 else -1.0
        return np.array([self.cue, 0.0]), {}

    def step(self, action):
        """Silent until the question; the answer ends the episode."""
        self.t += 1
        if self.t <= self.delay:
            question = 1.0 if self.t == self.delay else 0.0
            return np.array([0.0, question]), 0.0, False, False, {}
        right = (int(action) == 1) == (self.cue > 0)
        return np.array([0.0, 0.0]), 1.0 if right else -1.0, True, False, {}


gym.register("CartPoleNoVelocity-v0", entry_point=cartpole_no_velocity, max_episode_steps=500)
gym.register("CueMemory-v0", entry_point=CueMemory, max_episode_steps=50)
