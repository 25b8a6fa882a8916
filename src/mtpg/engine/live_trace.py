"""Traced episodes of a task that steps in Python (a Gymnasium environment).

The compiled tracer (:mod:`mtpg.engine.trace`) records the episode loop of the compiled
tasks; a Gymnasium environment steps in Python, so its episodes are traced from Python:
per step one compiled call, :func:`trace_live_decision`, runs the engine's one decision
rule (:func:`~mtpg.engine.episode_kernels.decide_bank`) with a
:class:`~mtpg.engine.record.Recorder`, then the environment steps. The decision sees what
:class:`~mtpg.engine.live.LiveDecider` would show it (the scaled observation, inputs the
task lacks at 0, the banks zeroed at the episode start), so a traced episode plays the
same actions, and gets the same return, as ``mtpg evaluate`` (tested).

The task state is the environment's own: a :class:`GymTrace`'s ``trace.states`` has no
columns; the raw observations, the actions the environment received and the rewards are
recorded beside it.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from mtpg.engine.compile import CompiledPopulation
from mtpg.engine.episode_kernels import decide_bank, thread_buffers
from mtpg.engine.gym_play import _reset, _step
from mtpg.engine.record import (
    INSTRUCTIONS,
    MEMORY,
    PROGRAMS,
    STEP,
    TEAMS,
    record,
    record_decision,
)
from mtpg.engine.trace import Trace
from mtpg.envs.specs.gym_task import GymTask


@njit(cache=True, error_model="numpy")
def trace_live_decision(g, buf, root, t, obs, act_c, rec):
    """Decision ``t`` of an episode from ``obs``, recorded into ``rec``.

    Args:
        g: The compiled graph.
        buf: The episode's :class:`~mtpg.engine.episode_kernels.Buffers` (fresh at its
            start: every bank is reset, lazily, on first use, as in the batch kernels).
        root: Dense root team.
        t: The step (also the decision's stamp).
        obs: float64 ``[n_in]`` the scaled observation (inputs past ``n_in`` read 0).
        act_c: float64 ``[d]`` out: ``m[0..d)`` of the final program's bank.
        rec: The :class:`~mtpg.engine.record.Recorder`.

    Returns:
        The atomic action.
    """
    rec.n[STEP] = t
    slots = buf.obs
    for i in range(len(slots)):
        slots[i] = 0.0
    for s in range(min(len(obs), len(slots))):
        slots[s] = obs[s]
    a, at = decide_bank(g, buf, root, t, 0, rec)
    for j in range(len(act_c)):
        act_c[j] = buf.W[at + j]
    record_decision(rec, t, a, buf.W[at], buf, g, 0)
    return a


@dataclass(frozen=True)
class GymTrace:
    """One traced episode of a Gymnasium task.

    Attributes:
        trace: The decisions (:class:`~mtpg.engine.trace.Trace`): ``observations`` are the
            scaled inputs ``[n, n_obs]``, ``rewards`` the environment's, ``states`` has no
            columns (the environment's state is its own).
        raw_observations: float64 ``[n, n_obs]`` the observations as the environment gave them.
        env_actions_d: int64 ``[n]`` the discrete action the environment received (-1: none).
        env_actions_c: float64 ``[n, d]`` the Box action it received (``d = 0``: none).
    """

    trace: Trace
    raw_observations: np.ndarray
    env_actions_d: np.ndarray
    env_actions_c: np.ndarray


def trace_gym_episode(
    cp: CompiledPopulation, root_id: int, task: GymTask, seed: int, snapshot: bool = False
) -> GymTrace:
    """Plays and traces one episode of ``task`` from ``reset(seed=seed)``.

    Args:
        cp: Compiled with ``fold_constants=False`` (the tracer logs code as stated), in the
            memory mode to replay.
        root_id: Model id of the root team.
        task: The Gymnasium task.
        seed: The reset seed.
        snapshot: Record every bank after each decision.

    Raises:
        GymTaskError: One line, for an observation out of bounds or a failing environment.
        ValueError: For folded code.
    """
    if cp.folded:
        raise ValueError(
            "trace needs code compiled with compile_population(..., fold_constants=False)"
        )
    g, root = cp.graph, cp.team_index(root_id)
    logs: dict[str, list] = {}

    def run(rec) -> int:
        logs.clear()
        logs.update(obs=[], raw=[], reward=[], act_d=[], act_c=[])
        buf = thread_buffers(g)
        act_c = np.zeros(task.n_continuous)
        env = task.make()
        try:
            raw, t, done = _reset(task, env, seed), 0, False
            while not done:
                obs = task.scale(raw, seed)
                a = trace_live_decision(g, buf, root, t, obs, act_c, rec)
                action = task.action(a, act_c)
                o, reward, terminated, truncated, _ = _step(task, env, action, seed)
                d = (
                    action
                    if task.action_kind == "discrete"
                    else (action[0] if task.action_kind == "tuple" else -1)
                )
                c = action[-1] if task.action_kind == "tuple" else action
                logs["obs"].append(obs)
                logs["raw"].append(raw)
                logs["reward"].append(float(reward))
                logs["act_d"].append(int(d))
                logs["act_c"].append(np.asarray(c, dtype=np.float64) if task.continuous else ())
                t += 1
                done = terminated or truncated
                if not done:
                    raw = task.flat(o, seed)
        finally:
            env.close()
        return t

    rec, n = record(run, g, root, task.max_steps, snapshot)
    trace = Trace(
        actions=rec.actions[:n],
        rewards=np.array(logs["reward"]),
        team_log=rec.team_log[: rec.n[TEAMS]],
        prog_log=rec.prog_log[: rec.n[PROGRAMS]],
        bids=rec.bids[: rec.n[PROGRAMS]],
        instr_log=rec.instr_log[: rec.n[INSTRUCTIONS]],
        mem_log=rec.mem_log[: rec.n[MEMORY]],
        memory=rec.memory[:n],
        states=np.zeros((n + 1, 0)),
        observations=np.array(logs["obs"]).reshape(n, task.n_obs),
    )
    return GymTrace(
        trace,
        np.array(logs["raw"]).reshape(n, task.n_obs),
        np.array(logs["act_d"], dtype=np.int64),
        np.array(logs["act_c"], dtype=np.float64).reshape(n, task.n_continuous),
    )
