"""Replays of a Gymnasium task: the ``.npz`` schema of :mod:`mtpg.analysis.graph.replay`.

The held-out episodes ``mtpg evaluate`` plays (episode ``k`` resets with seed
``1,000,000 + offset + k``), traced from Python (:mod:`mtpg.engine.live_trace`), so the
returns are ``mtpg evaluate``'s. Every key of the schema is written; for a Gymnasium task

- ``observation`` is ``(N, n_obs)``: the scaled inputs the decision saw;
- ``hidden_state`` is ``(N, 0)`` and ``final_state`` ``(E, 0)``: the environment's state is
  its own, mtpg does not see it;
- ``a_c`` is ``m[0]`` of the final program's bank (the first continuous output);

and three keys are added: ``raw_observation`` ``(N, n_obs)`` the observations as the
environment gave them, ``env_action_d`` ``(N,)`` the discrete action it received (-1 for a
task without one) and ``env_action_c`` ``(N, d)`` the Box action it received (``d = 0``
without one).

Frames for a video come from the environment itself (``render_mode="rgb_array"``), by
playing the episode's recorded actions again from the same reset seed
(:func:`gym_frames`); an environment that cannot render so is refused in one line.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING

import numpy as np

from mtpg.engine.compile import CompiledPopulation
from mtpg.engine.live_trace import GymTrace, trace_gym_episode
from mtpg.envs.specs.gym_task import GymTask, GymTaskError, _make

if TYPE_CHECKING:  # replay.py imports this module: the type only, no cycle
    from mtpg.analysis.graph.replay import Replay

#: The render mode frames are taken in.
RENDER_MODE = "rgb_array"


def trace_gym_episodes(
    cp: CompiledPopulation, root: int, task: GymTask, seeds: np.ndarray, n_mem_eps: int
) -> list[GymTrace]:
    """Plays and traces the episodes of ``seeds`` (reset seeds) of a Gymnasium task.

    Args:
        cp: Compiled unfolded, in the memory mode to replay.
        root: Root team id.
        task: The task.
        seeds: The episodes' reset seeds (the held-out seeds of ``mtpg evaluate``).
        n_mem_eps: Record every memory register for this many leading episodes.

    Raises:
        GymTaskError: One line, for an environment that fails or leaves its bounds.
    """
    return [
        trace_gym_episode(cp, root, task, int(s), snapshot=e < n_mem_eps)
        for e, s in enumerate(seeds)
    ]


def gym_keys(played: list[GymTrace]) -> dict[str, np.ndarray]:
    """The keys a Gymnasium task's replay adds (see the module docstring)."""
    return {
        "raw_observation": np.concatenate([p.raw_observations for p in played]),
        "env_action_d": np.concatenate([p.env_actions_d for p in played]),
        "env_action_c": np.concatenate([p.env_actions_c for p in played]),
    }


def render_refusal(task: GymTask) -> str | None:
    """Why ``task`` cannot give video frames, in one line; None when it can."""
    env = task.make()
    try:
        modes = list(env.metadata.get("render_modes") or [])
    finally:
        env.close()
    if RENDER_MODE in modes:
        return None
    return (
        f"task {task.name} cannot render video frames (its render_modes are {modes}, "
        f"without {RENDER_MODE!r}); replay it without --video for the trace alone"
    )


def gym_frames(
    task: GymTask, replay: Replay, episode: int = 0, max_frames: int | None = None
) -> list[np.ndarray]:
    """The environment's frames before each decision of one replayed episode.

    The episode is played again from its reset seed with the actions the replay recorded,
    in an environment made with ``render_mode="rgb_array"``.

    Raises:
        GymTaskError: When the environment cannot render frames (one line).
    """
    refusal = render_refusal(task)
    if refusal:
        raise GymTaskError(refusal)
    # frames are drawn off-screen: no display is needed (and SDL stays quiet without one)
    os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
    os.environ.setdefault("SDL_AUDIODRIVER", "dummy")
    env = _make(task.name, task.env_id, {**task.kwargs, "render_mode": RENDER_MODE})
    sl = replay.episode_slice(episode)
    stop = sl.stop if max_frames is None else min(sl.stop, sl.start + max_frames)
    frames: list[np.ndarray] = []
    try:
        env.reset(seed=int(replay["episode_seeds"][episode]))
        for i in range(sl.start, stop):
            frame = env.render()
            if not isinstance(frame, np.ndarray) or frame.ndim != 3:
                raise GymTaskError(f"task {task.name}: render() gave no RGB image")
            frames.append(frame)
            d, c = int(replay["env_action_d"][i]), replay["env_action_c"][i].astype(np.float32)
            kind = task.action_kind
            env.step(d if kind == "discrete" else (c if kind == "box" else (d, c)))
    finally:
        env.close()
    return frames
