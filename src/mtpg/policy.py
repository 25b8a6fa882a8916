"""A trained agent as a policy in your own loop: ``mtpg.Policy``.

::

    import gymnasium as gym
    import mtpg

    policy = mtpg.Policy.load("runs/cartpole")          # a run directory or a graph file
    env = gym.make("CartPole-v1")
    obs, _ = env.reset(seed=1_000_000)
    policy.reset()
    done = False
    while not done:
        obs, reward, terminated, truncated, _ = env.step(policy.act(obs))
        done = terminated or truncated

A policy decides with the engine's compiled decision rule (:mod:`mtpg.engine.live`, the
call that decides for every live episode of a Gymnasium task during training and
``mtpg evaluate``), so on the same episodes it plays the same actions and the same returns,
bit for bit. Its memory persists from step to step until :meth:`Policy.reset`; each
policy has its own, so several live side by side in one process.

``act`` takes the task's own observation and returns an action of the task's action space:
for a Gymnasium task (``gym:ID``) the environment's raw observation, scaled as in training
(:mod:`mtpg.envs.specs.gym_task`), and its own action; for one of the registered tasks the
observation of its ``mtpg/<Task>-v0`` environment (two inputs in [-1, 1]) and the paper's
pair ``(a_d, array([a_c]))``; for a compiled task (``module:ATTR``) what its ``observe``
writes and the pair ``(a_d, array([m0, ...]))``, ``a_d`` in its ``n_actions`` and the array
the raw memory values ``m[0..n)`` of its ``n_continuous`` dimensions (``m[0]`` alone for a
task of one or none), which its ``step`` gets made finite and clipped to its bound.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from mtpg.engine.compile import compile_population
from mtpg.engine.live import LiveDecider
from mtpg.envs.specs.compiled_task import CompiledTask
from mtpg.envs.specs.gym_task import GymTask


class Policy:
    """One root of a population, acting step by step (build it with :meth:`load`).

    Args:
        population: The population holding the agent.
        root: The agent's root team id.
        task: The task it acts in (a name of the registered tasks, a variant or ``gym:ID``).
        no_memory: Run without shared memory (the TPG-NoMemory ablation).
    """

    def __init__(self, population, root: int, task: str, no_memory: bool = False) -> None:
        from mtpg._kernel_cache import refresh
        from mtpg.envs.taskset.task_table import TaskTable

        refresh()  # a kernel is about to run: the cache must match the sources
        table = TaskTable.from_names([task])
        self.task = table.names[0]
        spec = table.spec(table.ids[0])
        self._gym: GymTask | None = spec if isinstance(spec, GymTask) else None
        #: A compiled task's discrete actions (its a_d is folded onto them), else 0.
        self._fold = spec.n_actions if isinstance(spec, CompiledTask) else 0
        # a compiled task's a_c holds its n_continuous dimensions m[0..n) (m[0] at least)
        n_cont = self._gym.n_continuous if self._gym else max(getattr(spec, "n_continuous", 1), 1)
        cp = compile_population(population, no_memory=no_memory)
        self.root = int(root)
        self._live = LiveDecider(cp, np.array([cp.team_index(root)]), n_continuous=n_cont)
        self._which = np.zeros(1, dtype=np.int64)
        self.reset()

    @classmethod
    def load(
        cls, source: str | os.PathLike[str], task: str | None = None, memory: bool | None = None
    ) -> Policy:
        """The all-task champion of a run directory, or the agent of a graph file.

        Args:
            source: A run directory (its champion of all tasks, as ``mtpg evaluate``
                scores it) or a graph ``.json`` file.
            task: The task to act in; may be left out where the run or graph has one task.
            memory: ``None`` as evolved (a TPG-NoMemory agent without memory), else on/off.

        Raises:
            ValueError: One line: no such source, or no task given where there are several.
        """
        from mtpg.io.serialize import load_graph

        path = Path(source)
        if not path.exists():
            raise ValueError(f"{path}: no such run directory or graph file")
        if path.is_dir():
            from mtpg.analysis.runs.champions import run_champion
            from mtpg.io.runconfig import read_run_config

            config = read_run_config(path)
            pop, root, meta = load_graph(run_champion(path))
            tasks = list(config.evaluation.tasks)
            evolved = bool(meta.get("no_memory", config.evaluation.no_memory))
        else:
            pop, root, meta = load_graph(path)
            tasks = list(meta.get("tasks", []))
            evolved = bool(meta.get("no_memory", False))
        if task is None:
            if len(tasks) != 1:
                raise ValueError(
                    f"{path}: name the task to act in (task=...), one of {', '.join(tasks)}"
                )
            task = tasks[0]
        no_memory = evolved if memory is None else not memory
        return cls(pop, root, task, no_memory=no_memory)

    def reset(self) -> None:
        """Starts an episode: every memory bank reads zero."""
        self._live.reset(0)

    def act(self, obs: Any) -> Any:
        """One decision: the action for observation ``obs`` (see the module docstring)."""
        if self._gym is not None:
            scaled = self._gym.scale(obs, seed=-1)
            a_d, a_c = self._live.decide(self._which, scaled.reshape(1, -1))
            return self._gym.action(a_d[0], a_c[0])
        o = np.asarray(obs, dtype=np.float64).reshape(1, -1)
        a_d, a_c = self._live.decide(self._which, o)
        a = int(a_d[0]) % self._fold if self._fold else int(a_d[0])
        return a, a_c[0].copy()
