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

A long budget can be trained over several sittings: with ``--save DIR`` the model is saved
to ``DIR/model.zip`` every ``--save-every`` steps and when the process is stopped (SIGTERM,
SIGINT: training ends at the next step and the model is saved; the test is then skipped);
the same command with ``--resume`` loads it and trains the steps still missing. Unlike an
mtpg run, a resumed RecurrentPPO run is not bit-identical to an uninterrupted one:
stable-baselines3 saves the weights, the optimiser and the step count, not the random
generators, the environment's episode nor the rollout under way (which is discarded).
``DIR/progress.json`` records every sitting's steps and CPU seconds.
"""

from __future__ import annotations

import argparse
import json
import signal
import sys
import time
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np

import mtpg.envs  # noqa: F401  (registers the mtpg/ ids)
from mtpg.envs.specs.registry import PAPER_TASKS, task_id
from mtpg.envs.taskset.episode_seeds import held_out_seeds
from mtpg.envs.taskset.reference_scores import normalise


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


#: Signals that stop training cleanly (the model is saved, the test skipped).
STOP_SIGNALS = (signal.SIGTERM, signal.SIGINT)


def _callback(save: Path | None, every: int) -> Any:
    """A stable-baselines3 callback: periodic saves, and a clean stop on SIGTERM or SIGINT."""
    from stable_baselines3.common.callbacks import BaseCallback

    class SaveAndStop(BaseCallback):
        def __init__(self) -> None:
            super().__init__()
            self.stop = False
            self.last_save = 0

        def _on_training_start(self) -> None:
            self.last_save = self.num_timesteps
            self.previous = {s: signal.signal(s, self._request_stop) for s in STOP_SIGNALS}

        def _on_training_end(self) -> None:
            for s, handler in self.previous.items():
                signal.signal(s, handler)

        def _request_stop(self, *_: Any) -> None:
            self.stop = True

        def _on_step(self) -> bool:
            if save is not None and self.num_timesteps - self.last_save >= every:
                self.model.save(save / "model.zip")
                self.last_save = self.num_timesteps
            return not self.stop

    return SaveAndStop()


def run(
    env: str,
    timesteps: int,
    seed: int = 0,
    tasks: tuple[str, ...] = PAPER_TASKS,
    episodes: int = 100,
    n_steps: int = 512,
    threads: int = 1,
    save: Path | None = None,
    save_every: int = 50_000,
    resume: bool = False,
) -> dict[str, Any]:
    """Trains and evaluates; returns the summary printed as the last line.

    Args:
        env: ``"MultiTask"`` or a task name.
        timesteps: Environment steps to train on (in all, over every sitting).
        seed: Seed of the model and of the training environment.
        tasks: Tasks of MultiTask-v0.
        episodes: Test episodes per task.
        n_steps: Steps per rollout (PPO's ``n_steps``).
        threads: Torch threads (1: a small LSTM gains nothing from more on a CPU).
        save: Folder for ``model.zip`` and ``progress.json`` (None: nothing saved).
        save_every: Steps between saves.
        resume: Continue the model saved in ``save``.
    """
    import torch
    from sb3_contrib import RecurrentPPO

    torch.set_num_threads(threads)
    train_env = make_env(env, tasks)
    sittings: list[dict[str, Any]] = []
    if resume:
        if save is None or not (save / "model.zip").is_file():
            raise SystemExit(f"--resume: no saved model in {save}")
        model = RecurrentPPO.load(save / "model.zip", env=train_env, device="cpu")
        progress = save / "progress.json"
        sittings = json.loads(progress.read_text())["sittings"] if progress.is_file() else []
        # A new sitting gets fresh episodes: the saved model holds no generator state.
        train_env.reset(seed=seed + 1 + len(sittings))
    else:
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
    if save is not None:
        save.mkdir(parents=True, exist_ok=True)
    start_steps, cpu0 = int(model.num_timesteps), time.process_time()
    callback = _callback(save, save_every)
    if timesteps > start_steps:
        model.learn(
            total_timesteps=timesteps - start_steps,
            callback=callback,
            reset_num_timesteps=not resume,
        )
    if save is not None:
        model.save(save / "model.zip")
        sittings.append(
            {
                "from": start_steps,
                "to": int(model.num_timesteps),
                "cpu_s": round(time.process_time() - cpu0, 1),
            }
        )
        (save / "progress.json").write_text(json.dumps({"sittings": sittings}, indent=1))
    summary: dict[str, Any] = {
        "env": env,
        "env_steps": int(model.num_timesteps),
        "train_cpu_s": round(sum(x["cpu_s"] for x in sittings), 1) if sittings else None,
    }
    if callback.stop:
        summary["stopped"] = True
        return summary
    scores = evaluate(model, env, tasks, episodes)
    summary.update(
        test_episodes=episodes,
        test=scores,
        normalised={t: float(normalise(task_id(t), s)) for t, s in scores.items()},
    )
    return summary


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
    p.add_argument("--save", type=Path, help="folder for the model, saved as it trains")
    p.add_argument("--save-every", type=int, default=50_000, help="steps between saves")
    p.add_argument("--resume", action="store_true", help="continue the model in --save")
    a = p.parse_args(argv)
    tasks = tuple(t for t in a.tasks.split(",") if t)
    summary = run(
        a.env,
        a.timesteps,
        a.seed,
        tasks,
        a.episodes,
        a.n_steps,
        a.threads,
        a.save,
        a.save_every,
        a.resume,
    )
    print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    sys.exit(main())
