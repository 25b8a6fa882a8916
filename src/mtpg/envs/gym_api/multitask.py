"""``mtpg/MultiTask-v0``: the paper's multi-task challenge as one Gymnasium environment.

One agent meets the tasks episode by episode and is never told which one it plays: at
each reset a task is drawn from the environment's seeded generator over the chosen tasks
(``order="random"``) or taken in turn (``order="cycle"``), and the episode is played by
that task's :class:`~mtpg.envs.gym_api.env.MtpgEnv`. The observation is the task's two inputs,
with no task label. ``info["task"]`` names the task, for logging only: an agent fed it no
longer faces the paper's problem.

Actions (``action=``):

- ``"box"`` (default): the paper's pair flattened into ``Box(-1, 1, (2,), float64)``, the
  symmetric, normalised space most libraries expect. Component 0 gives the discrete action
  by thirds: above 1/3 -> ``a_d = 0`` (+F / push +1), within [-1/3, 1/3] -> 1 (previous
  force / no push), below -1/3 -> 2 (-F / push -1). Component 1 times the current task's
  action bound is ``a_c`` (so [-1, 1] spans every continuous task's whole range, Pendulum's
  [-2, 2] included; the agent is not told the bound, only the environment applies it).
- ``"tuple"``: the paper's own ``Tuple(Discrete(3), Box(-inf, inf, (1,)))``.

Seeding: ``reset(seed=s)`` seeds the generator (and restarts the cycle); each reset then
draws the task (random order) and the episode seed ``integers(0, 2**63)`` of the task's
episode from it. ``reset(options={"task": name, "episode_seed": k})`` plays a chosen task
and episode seed instead: episode seed ``k`` is the episode of seed ``k`` everywhere in the
package, so an evaluation can replay TPG's held-out episodes (seeds ``1_000_000 + i``).
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from mtpg.envs.gym_api.env import MtpgEnv, paper_action_space
from mtpg.envs.specs.contract import N_OBS
from mtpg.envs.specs.registry import PAPER_TASKS, TASKS, task_id

#: The action interfaces of the multi-task environment.
MULTITASK_ACTIONS: tuple[str, ...] = ("box", "tuple")
#: The orders in which tasks are met.
ORDERS: tuple[str, ...] = ("random", "cycle")


def box_to_pair(action: Any, bound: float) -> tuple[int, float]:
    """The paper's ``(a_d, a_c)`` of a flattened ``box`` action (see the module docstring).

    Args:
        action: The two components in [-1, 1].
        bound: The current task's continuous action bound (any value for discrete tasks,
            which ignore ``a_c``).
    """
    a = np.asarray(action, dtype=np.float64).reshape(-1)
    a_d = 0 if a[0] > 1 / 3 else (2 if a[0] < -1 / 3 else 1)
    return a_d, float(a[1]) * bound


class MultiTaskEnv(gym.Env[np.ndarray, Any]):
    """The chosen tasks behind one unlabelled interface, one task per episode.

    Args:
        tasks: Task names (the paper's six by default), no repeats.
        order: ``"random"`` or ``"cycle"``.
        action: ``"box"`` or ``"tuple"``.
    """

    metadata = {"render_modes": []}

    def __init__(
        self,
        tasks: tuple[str, ...] | list[str] = PAPER_TASKS,
        order: str = "random",
        action: str = "box",
    ):
        tasks = tuple(tasks)
        if not tasks or len(set(tasks)) != len(tasks):
            raise ValueError(f"tasks must be non-empty, without repeats, got {tasks}")
        if order not in ORDERS:
            raise ValueError(f"order must be one of {', '.join(ORDERS)}, got {order!r}")
        if action not in MULTITASK_ACTIONS:
            msg = f"action must be one of {', '.join(MULTITASK_ACTIONS)}, got {action!r}"
            raise ValueError(msg)
        self.tasks = tasks
        self._ids = tuple(task_id(t) for t in tasks)
        self._envs = {t: MtpgEnv(i) for t, i in zip(tasks, self._ids, strict=True)}
        self._order = order
        self._box = action == "box"
        self._turn = 0
        self._current = tasks[0]
        self.observation_space = spaces.Box(-1.0, 1.0, (N_OBS,), dtype=np.float64)
        self._bounds = {t: TASKS[i].bound for t, i in zip(tasks, self._ids, strict=True)}
        self.action_space = (
            spaces.Box(-1.0, 1.0, (2,), dtype=np.float64) if self._box else paper_action_space()
        )

    @property
    def task(self) -> str:
        """The task of the current episode."""
        return self._current

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Starts an episode of the next task.

        Args:
            seed: Seeds the task draws and the episode seeds (and restarts the cycle).
            options: ``task`` (a name among the chosen tasks) and ``episode_seed`` to play
                a given episode instead of drawing one.

        Returns:
            (observation, info) with ``info["task"]``.
        """
        super().reset(seed=seed)
        if seed is not None:
            self._turn = 0
        options = options or {}
        if "task" in options:
            if options["task"] not in self._envs:
                raise ValueError(f"task {options['task']!r} is not among {', '.join(self.tasks)}")
            self._current = options["task"]
        elif self._order == "cycle":
            self._current = self.tasks[self._turn % len(self.tasks)]
            self._turn += 1
        else:
            self._current = self.tasks[int(self.np_random.integers(len(self.tasks)))]
        if "episode_seed" in options:
            episode_seed = int(options["episode_seed"])
        else:
            episode_seed = int(self.np_random.integers(0, 2**63))
        obs, _ = self._envs[self._current].reset(seed=episode_seed)
        return obs, {"task": self._current, "episode_seed": episode_seed}

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Advances the current task by one step.

        Args:
            action: A ``box`` or ``tuple`` action (see the module docstring).

        Returns:
            (observation, reward, terminated, truncated, info) with ``info["task"]``.
        """
        if self._box:
            a_d, a_c = box_to_pair(action, self._bounds[self._current])
        else:
            a_d, a_c = _pair(action)
        obs, reward, terminated, truncated, _ = self._envs[self._current].step(
            (a_d, np.array([a_c]))
        )
        return obs, reward, terminated, truncated, {"task": self._current}


def _pair(action: Any) -> tuple[int, float]:
    a_d, a_c = action
    return int(np.asarray(a_d).reshape(-1)[0]), float(np.asarray(a_c).reshape(-1)[0])


__all__ = ["MultiTaskEnv", "box_to_pair"]
