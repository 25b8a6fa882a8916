"""A Gymnasium environment over the compiled kernels, one class for every task.

``gymnasium.make("mtpg/<Task>-v0")`` builds ``MtpgEnv(task=<id>)`` (see
``mtpg.envs.gym_api.registration``); ``gymnasium.make("mtpg/<Task>-v0", action="native")`` gives
the task's own single action instead of the paper's pair, for libraries that train on one
``Discrete`` or ``Box`` action. The environment uses exactly the kernels of the execution
engine and the episode draws of ``make_episodes``: ``reset(seed=s)`` seeds the generator
``np.random.default_rng(s)`` (Gymnasium's ``np_random``), draws the start state with
``sample_start`` and then one noise value per observation. A variant with observation
noise draws the episode's noise values and normal values at reset instead, in the order of
``draw_episodes``, so it plays the episode the engine plays.

``info["state"]`` holds the full hidden state in Gymnasium's order. It is for analysis
only and must never be fed to an agent.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from mtpg.envs.dynamics.dispatch import env_observe, env_reset, env_step
from mtpg.envs.specs.contract import N_OBS, STATE_SIZE, STEP_SLOT
from mtpg.envs.specs.task_spec import TaskSpec
from mtpg.envs.taskset.episodes import sample_start
from mtpg.envs.taskset.task_table import REGISTERED, TaskTable
from mtpg.envs.taskset.variants import obs_noise_sd, observation_bounds

#: The action interfaces: the paper's pair, or the task's own single action.
ACTIONS: tuple[str, ...] = ("paper", "native")


def _parse_action(action: Any) -> tuple[int, float]:
    """Splits an action ``(a_d, a_c)`` into an int and a float (a_c may be a 1-array)."""
    a_d, a_c = action
    a_d = int(np.asarray(a_d).reshape(-1)[0])
    a_c = float(np.asarray(a_c, dtype=np.float64).reshape(-1)[0])
    return a_d, a_c


def paper_action_space() -> spaces.Tuple:
    """The paper's pair: ``Tuple(Discrete(3), Box(-inf, inf, (1,), float64))``."""
    return spaces.Tuple((spaces.Discrete(3), spaces.Box(-np.inf, np.inf, (1,), dtype=np.float64)))


def native_action_space(task: TaskSpec) -> spaces.Space:
    """The task's own action: ``Discrete(3)``, or ``Box(-bound, bound, (1,), float64)``."""
    if task.continuous:
        return spaces.Box(-task.bound, task.bound, (1,), dtype=np.float64)
    return spaces.Discrete(3)


def native_to_pair(task: TaskSpec, action: Any) -> tuple[int, float]:
    """The paper's ``(a_d, a_c)`` of a native action (the unread one neutral: 1 or 0.0)."""
    if task.continuous:
        return 1, float(np.asarray(action, dtype=np.float64).reshape(-1)[0])
    return int(np.asarray(action).reshape(-1)[0]), 0.0


class MtpgEnv(gym.Env[np.ndarray, tuple[int, np.ndarray]]):
    """One of the six partially-observable tasks with the paper's interface.

    Observation: ``Box(-1, 1, (2,), float64)``. Action (``action="paper"``):
    ``Tuple(Discrete(3), Box(-inf, inf, (1,), float64))``; the task reads one of the two and
    ignores the other. With ``action="native"``: the one the task reads, ``Discrete(3)`` or
    ``Box(-bound, bound, (1,), float64)`` (:func:`native_action_space`); the dynamics are
    the same. The time limit is built in (``truncated``), so no ``TimeLimit`` wrapper is
    needed.

    Args:
        task: The task id (index into ``TASK_NAMES``), or a task or variant name
            (``"CartPole[max_steps=500]"``, see :mod:`mtpg.envs.taskset.variants`).
        render_mode: None or ``"rgb_array"``.
        action: ``"paper"`` or ``"native"``.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 50}

    def __init__(
        self,
        task: int | str,
        render_mode: str | None = None,
        action: str = "paper",
        table: TaskTable | None = None,
    ):
        if table is None:  # a name is a table of its own; an id is a registered task
            table = TaskTable.from_names([task]) if isinstance(task, str) else REGISTERED
        task = table.id_of(task) if isinstance(task, str) else int(task)
        if not table.valid_id(task):
            raise ValueError(f"unknown task id {task}")
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"unsupported render_mode {render_mode!r}")
        if action not in ACTIONS:
            raise ValueError(f"action must be one of {', '.join(ACTIONS)}, got {action!r}")
        self._task = int(task)
        self._table = table
        self._spec = table.spec(self._task)
        self._native = action == "native"
        self.render_mode = render_mode
        low, high = observation_bounds(self._spec)
        self.observation_space = spaces.Box(low, high, (N_OBS,), dtype=np.float64)
        self.action_space = (
            native_action_space(self._spec) if self._native else paper_action_space()
        )
        self._params = table.params
        self._state = np.zeros(STATE_SIZE, dtype=np.float64)
        self._obs = np.zeros(N_OBS, dtype=np.float64)
        self._dim = self._spec.state_dim
        self._continuous = self._spec.continuous
        self._last_action = 0.0
        self._renderer: Any = None
        self._noisy = obs_noise_sd(self._spec) > 0.0
        self._drawn: tuple[np.ndarray, np.ndarray] | None = None  # (noise, obs_noise)

    def _observe(self) -> np.ndarray:
        if self._drawn is None:
            noise = float(self.np_random.random())
            env_observe(self._task, self._params, self._state, noise, self._obs)
        else:
            t = min(int(self._state[STEP_SLOT]), len(self._drawn[0]) - 1)
            u, eps = self._drawn
            env_observe(self._task, self._params, self._state, u[t], self._obs, eps[t])
        return self._obs.copy()

    def _info(self) -> dict[str, Any]:
        return {"state": self._state[: self._dim].copy()}

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Starts an episode.

        Args:
            seed: The episode seed; the same seed gives the episode of ``make_episodes``.
            options: Unused.

        Returns:
            (observation, info) with ``info["state"]`` the hidden start state.
        """
        super().reset(seed=seed)
        start = sample_start(self._task, self.np_random, self._table)
        if self._noisy:
            k = self._spec.max_steps + 1
            self._drawn = (self.np_random.random(k), self.np_random.standard_normal((k, 2)))
        env_reset(self._task, self._params, start, self._state)
        self._last_action = 0.0
        return self._observe(), self._info()

    def step(
        self, action: tuple[int, np.ndarray]
    ) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Advances the task by one step.

        Args:
            action: ``(a_d, a_c)``, or the native action.

        Returns:
            (observation, reward, terminated, truncated, info).
        """
        a_d, a_c = native_to_pair(self._spec, action) if self._native else _parse_action(action)
        reward, terminated, truncated = env_step(self._task, self._params, self._state, a_d, a_c)
        self._last_action = a_c if self._continuous else 0.0
        return self._observe(), float(reward), bool(terminated), bool(truncated), self._info()

    def render(self) -> np.ndarray | None:
        """Draws the current state.

        Returns:
            An ``H x W x 3`` uint8 frame in ``rgb_array`` mode, else None.
        """
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode")
            return None
        if self._renderer is None:
            from mtpg.envs.gym_api.render import make_renderer

            self._renderer = make_renderer(self._spec)
        return self._renderer.frame(self._state, self._last_action)

    def close(self) -> None:
        """Releases the renderer."""
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None


__all__ = ["MtpgEnv"]
