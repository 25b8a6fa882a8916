"""Trains sb3-contrib's RecurrentPPO (an LSTM policy) on an mtpg task or on MultiTask-v0.

The deep-RL side of the paper's comparison, on the testbed any library can use: a single
task with its native action (``mtpg/<Task>-v0``, ``action="native"``) or the multi-task
challenge (``mtpg/MultiTask-v0``, one unlabelled task per episode). The trained policy is
evaluated on the held-out test episodes TPG is evaluated on (episode seeds 1,000,000 + i,
the same start states and noise), and the environment steps it trained on are counted,
so that it can be set against a TPG run at equal experience: a TPG run's experience is
the sum of the ``decisions`` column of its ``metrics.csv``.

Needs the optional extra: ``pip install torch==2.13.0`` (the CPU build) then
``pip install -e ".[rl]"``. Run from the repository root::

    python examples/recurrent_ppo.py --env CartPole --timesteps 200000
    python examples/recurrent_ppo.py --env MultiTask --timesteps 1000000

The last line printed is a JSON object: the steps trained and, per task, the mean test
return and its normalised score ((score - random) / (best - random), Fig. 5).
"""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

import gymnasium
import numpy as np

import mtpg.envs  # noqa: F401  (registers the mtpg/ ids)
from mtpg.envs.protocol import held_out_seeds
from mtpg.envs.reference import normalise
from mtpg.envs.registry import PAPER_TASKS, task_id


def make_env(env: str, tasks: tuple[str, ...]) -> gymnasium.Env:
    """The training environment: one task's native interface, or MultiTask-v0."""
    if env == "MultiTask":
        return gymnasium.make("mtpg/MultiTask-v0", tasks=tasks)
    return gymnasium.make(f"mtpg/{env}-v0", action="native")


def evaluate(model: Any, env: str, tasks: tuple[str, ...], episodes: int) -> dict[str, float]:
    """Mean return per task on the held-out test episodes, the LSTM state reset per episode.

    Args:
        model: A trained RecurrentPPO model.
        env: ``"MultiTask"`` or a task name.
        tasks: The tasks to evaluate (MultiTask) .
        episodes: Test episodes per task (seeds 1,000,000 + i).

    Returns:
        Mean return by task name.
    """
    out = {}
    for task in tasks if env == "MultiTask" else (env,):
        e = make_env(env, tasks).unwrapped
        returns = []
        for seed in held_out_seeds(episodes).tolist():
            if env == "MultiTask":
                obs, _ = e.reset(options={"task": task, "episode_seed": seed})
            else:
                obs, _ = e.reset(seed=seed)
            state, start, total, done = None, np.ones((1,), dtype=bool), 0.0, False
            while not done:
                action, state = model.predict(
                    obs, state=state, episode_start=start, deterministic=True
                )
                obs, reward, terminated, truncated, _ = e.step(action)
                total += float(reward)
                done = terminated or truncated
                start = np.zeros((1,), dtype=bool)
            returns.append(total)
        out[task] = float(np.mean(returns))
    return out


def run(
    env: str,
    timesteps: int,
    seed: int = 0,
    tasks: tuple[str, ...] = PAPER_TASKS,
    episodes: int = 100,
    n_steps: int = 512,
    threads: int = 1,
) -> dict[str, Any]:
    """Trains and evaluates; returns the summary printed as the last line.

    Args:
        env: ``"MultiTask"`` or a task name.
        timesteps: Environment steps to train on.
        seed: Seed of the model and of the training environment.
        tasks: Tasks of MultiTask-v0.
        episodes: Test episodes per task.
        n_steps: Steps per rollout (PPO's ``n_steps``).
        threads: Torch threads (1: a small LSTM gains nothing from more on a CPU).
    """
    import torch
    from sb3_contrib import RecurrentPPO

    torch.set_num_threads(threads)
    train_env = make_env(env, tasks)
    train_env.reset(seed=seed)
    model = RecurrentPPO(
        "MlpLstmPolicy",
        train_env,
        n_steps=n_steps,
        batch_size=min(128, n_steps),
        seed=seed,
        device="cpu",
        verbose=0,
    )
    model.learn(total_timesteps=timesteps)
    scores = evaluate(model, env, tasks, episodes)
    return {
        "env": env,
        "env_steps": int(model.num_timesteps),
        "test_episodes": episodes,
        "test": scores,
        "normalised": {t: float(normalise(task_id(t), s)) for t, s in scores.items()},
    }


def main(argv: list[str] | None = None) -> int:
    """Command line: see the module docstring."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--env", default="CartPole", help="a task name, or MultiTask")
    p.add_argument("--tasks", default=",".join(PAPER_TASKS), help="tasks of MultiTask")
    p.add_argument("--timesteps", type=int, default=200_000, help="environment steps")
    p.add_argument("--episodes", type=int, default=100, help="test episodes per task")
    p.add_argument("--n-steps", type=int, default=512, help="PPO rollout length")
    p.add_argument("--seed", type=int, default=0)
    p.add_argument("--threads", type=int, default=1, help="torch threads")
    a = p.parse_args(argv)
    tasks = tuple(t for t in a.tasks.split(",") if t)
    summary = run(a.env, a.timesteps, a.seed, tasks, a.episodes, a.n_steps, a.threads)
    print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    sys.exit(main())
