"""The measurements of docs/own-task.md: mtpg beside pytpg 0.6 on real tasks, 3 seeds.

Run from the repository root, with pytpg installed into the same environment
(``pip install pytpg==0.6.0``; it is no dependency of mtpg)::

    PYTHONPATH=examples/own_task python examples/own_task/study.py runs/own-task

For every task and seed, one after the other in this process:

1. mtpg trains (``mtpg train --preset demo`` with a small population, in a subprocess);
   its training environment steps are the sum of metrics.csv's ``decisions`` (on a
   Gymnasium task one decision is one environment step).
2. pytpg trains on the same task until its environment steps reach that number
   (:mod:`mtpg.bench.pytpg_arm`), with as many graphs as mtpg's roots.
3. Both champions play the same 100 held-out episodes, reset with seeds
   ``1,000,000 + k`` (``mtpg evaluate --seed 0``); training used seeds from 10^9.
4. Decisions per second: decisions over the seconds of training evaluation, environment
   steps included (mtpg's generation 1, which compiles, left out).

A finished (task, seed) is kept in ``OUT/records.json`` and skipped on a rerun. At the end
it writes ``summary.json``, ``summary.csv`` and ``curves.png`` into ``--docs``
(default docs/own-task) and prints the markdown table.
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import gymnasium as gym
import numpy as np

from mtpg.analysis.runs.statistics import aggregate_iqm
from mtpg.bench import pytpg_arm
from mtpg.envs.specs.gym_task import parse

#: Test episode k resets with TEST_SEED + k (``mtpg evaluate --seed 0``).
TEST_SEED = 1_000_000
TEST_EPISODES = 100

#: key: (label, mtpg task, generations, root_size, train episodes, extra mtpg arguments).
ARMS: dict[str, tuple[str, str, int, int, int, list[str]]] = {
    "cartpole": ("CartPole-v1", "gym:CartPole-v1", 20, 50, 2, []),
    "cartpole-novel": (
        "CartPole-v1, velocities hidden",
        "gym:own_envs:CartPoleNoVelocity-v0",
        20,
        50,
        2,
        [],
    ),
    "acrobot": ("Acrobot-v1", "gym:Acrobot-v1", 5, 20, 1, []),
    "pendulum": ("Pendulum-v1 (continuous)", "gym:Pendulum-v1", 15, 20, 1, []),
    "cue-memory": (
        "CueMemory (delay 1), memory",
        "gym:own_envs:CueMemory-v0[delay=1]",
        100,
        50,
        10,
        [],
    ),
    "cue-nomemory": (
        "CueMemory (delay 1), no memory",
        "gym:own_envs:CueMemory-v0[delay=1]",
        100,
        50,
        10,
        ["--no-memory"],
    ),
}
SEEDS = (1, 2, 3)
#: pytpg acts only in a Discrete space: Pendulum's torque in [-2, 2] becomes 5 torques.
PYTPG_TORQUES = 5


def pytpg_env(task: str):
    """A factory of the environment pytpg trains on for mtpg task ``task``."""
    env_id, kwargs = parse(task)

    def make() -> gym.Env:
        env = gym.make(env_id, **kwargs)
        if isinstance(env.action_space, gym.spaces.Box):
            from own_envs import DiscreteTorque

            env = DiscreteTorque(env, PYTPG_TORQUES)
        return env

    return make


def mtpg(*args: str) -> str:
    """Runs ``python -m mtpg ARGS`` (this process's environment) and returns its stdout."""
    done = subprocess.run([sys.executable, "-m", "mtpg", *args], capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"mtpg {' '.join(args)}: {done.stderr.strip()}")
    return done.stdout


def mtpg_arm(key: str, seed: int, run: Path) -> dict:
    """Trains and tests one mtpg run; returns its record (curve, steps, speed, score)."""
    _, task, gens, roots, episodes, extra = ARMS[key]
    if not (run / "metrics.csv").exists():
        mtpg(
            *("train", "--preset", "demo", "--workers", "1", "--quiet", *extra),
            *("--set", f"team.root_size={roots}", "--set", f"evaluation.train_episodes={episodes}"),
            *("--set", "evaluation.test_interval=0", "--tasks", task, "--seed", str(seed)),
            *("--generations", str(gens), "--out", str(run)),
        )
    with open(run / "metrics.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    steps = np.cumsum([int(r["decisions"]) for r in rows])
    best = [float(r[f"best_{task}"]) for r in rows]
    timed = rows[1:]
    seconds = sum(float(r["t_evaluation"]) for r in timed)
    scored = json.loads(
        mtpg("evaluate", str(run), "--episodes", str(TEST_EPISODES), "--seed", "0", "--json")
    )[task]
    return {
        "curve": [[int(s), b] for s, b in zip(steps, best, strict=True)],
        "steps": int(steps[-1]),
        "roots": max(int(r["roots"]) for r in rows),
        "decisions_per_s": sum(int(r["decisions"]) for r in timed) / seconds,
        "test_mean": scored["mean"],
        "random": scored["random"],
    }


def pytpg_side(key: str, seed: int, budget: int, population: int) -> dict:
    """Trains pytpg to ``budget`` environment steps and tests its champion."""
    _, task, _, _, episodes, _ = ARMS[key]
    make = pytpg_env(task)
    run = pytpg_arm.train(make, budget, episodes, population, seed)
    seeds = [TEST_SEED + k for k in range(TEST_EPISODES)]
    returns = pytpg_arm.score(make, run.champion, seeds)
    return {
        "curve": [[s, b] for s, b in run.curve],
        "steps": run.steps,
        "generations": run.generations,
        "decisions_per_s": run.decisions_per_s,
        "test_mean": float(np.mean(returns)),
    }


def estimate(values: list[float]) -> dict:
    """IQM over seeds with the project's 95% bootstrap interval."""
    e = aggregate_iqm(np.asarray(values, dtype=float)[:, None])
    return {"iqm": e.value, "low": e.low, "high": e.high, "text": e.text()}


def summarise(records: dict) -> dict:
    """Per arm: the IQM and interval of the test returns and the speeds, both sides."""
    out = {}
    for key, (label, task, gens, roots, episodes, extra) in ARMS.items():
        done = [records[f"{key}/{s}"] for s in SEEDS if f"{key}/{s}" in records]
        if not done:
            continue
        row = {"label": label, "task": task, "generations": gens, "seeds": len(done)}
        row["settings"] = {"root_size": roots, "train_episodes": episodes, "extra": extra}
        for side in ("mtpg", "pytpg"):
            row[side] = {
                "test": estimate([d[side]["test_mean"] for d in done]),
                "per_seed": [round(d[side]["test_mean"], 2) for d in done],
                "steps": [d[side]["steps"] for d in done],
                "decisions_per_s": float(np.median([d[side]["decisions_per_s"] for d in done])),
            }
        row["random"] = done[0]["mtpg"]["random"]
        out[key] = row
    return out


def table(summary: dict) -> str:
    """The markdown table of docs/own-task.md."""
    head = (
        "| task | env steps, mtpg / pytpg (mean) | test return, mtpg | test return, pytpg "
        "| per seed, mtpg / pytpg | decisions/s, mtpg / pytpg |\n"
        "|---|---:|---|---|---|---:|\n"
    )
    lines = []
    for row in summary.values():
        m, p = row["mtpg"], row["pytpg"]
        each = f"{', '.join(map(str, m['per_seed']))} / {', '.join(map(str, p['per_seed']))}"
        lines.append(
            f"| {row['label']} | {np.mean(m['steps']):,.0f} / {np.mean(p['steps']):,.0f} "
            f"| {m['test']['text']} | {p['test']['text']} | {each} "
            f"| {m['decisions_per_s']:,.0f} / {p['decisions_per_s']:,.0f} |"
        )
    return head + "\n".join(lines)


def plot(records: dict, path: Path) -> None:
    """Best training return against environment steps, every seed, both libraries."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 3, figsize=(13, 7.5))
    for ax, (key, arm) in zip(axes.flat, ARMS.items(), strict=True):
        for side, colour in (("mtpg", "tab:blue"), ("pytpg", "tab:orange")):
            for n, seed in enumerate(SEEDS):
                rec = records.get(f"{key}/{seed}")
                if rec is None:
                    continue
                x, y = np.asarray(rec[side]["curve"]).T
                ax.plot(x, y, color=colour, alpha=0.8, lw=1.2, label=side if n == 0 else None)
        ax.set_title(arm[0], fontsize=10)
        ax.set_xlabel("environment steps of training")
        ax.xaxis.set_major_formatter(lambda v, _: f"{v / 1000:.0f}k")  # labels that fit
        ax.set_ylabel("best training return")
        ax.legend(fontsize=8)
    fig.suptitle("mtpg and pytpg 0.6 at equal environment steps (one line per seed)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> None:
    """Runs every (task, seed) not yet recorded, then writes the summary and figure."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, nargs="?", default=Path("runs/own-task"))
    parser.add_argument("--docs", type=Path, default=Path("docs/own-task"))
    parser.add_argument("--arms", default=",".join(ARMS), help="comma-separated arm keys")
    args = parser.parse_args()
    if not pytpg_arm.available():
        raise SystemExit(pytpg_arm.absent_line())
    here = str(Path(__file__).resolve().parent)
    path = os.environ.get("PYTHONPATH", "")
    if here not in path.split(os.pathsep):  # the mtpg subprocesses import own_envs too
        os.environ["PYTHONPATH"] = os.pathsep.join(filter(None, [path, here]))
    args.out.mkdir(parents=True, exist_ok=True)
    store = args.out / "records.json"
    records = json.loads(store.read_text()) if store.exists() else {}
    for key in args.arms.split(","):
        for seed in SEEDS:
            if f"{key}/{seed}" in records:
                continue
            start = time.perf_counter()
            m = mtpg_arm(key, seed, args.out / f"{key}-seed{seed}")
            p = pytpg_side(key, seed, m["steps"], m["roots"])
            records[f"{key}/{seed}"] = {"mtpg": m, "pytpg": p}
            store.write_text(json.dumps(records))
            print(
                f"{key} seed {seed}: mtpg {m['test_mean']:.1f} ({m['steps']:,} steps), "
                f"pytpg {p['test_mean']:.1f} ({p['steps']:,} steps), "
                f"{time.perf_counter() - start:.0f} s",
                flush=True,
            )
    summary = summarise(records)
    args.docs.mkdir(parents=True, exist_ok=True)
    (args.docs / "summary.json").write_text(json.dumps(summary, indent=1) + "\n")
    with open(args.docs / "summary.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["arm", "side", "seed", "env_steps", "test_mean", "decisions_per_s"])
        for name, rec in records.items():
            arm, seed = name.split("/")
            for side in ("mtpg", "pytpg"):
                r = rec[side]
                speed = round(r["decisions_per_s"])
                w.writerow([arm, side, seed, r["steps"], round(r["test_mean"], 3), speed])
    plot(records, args.docs / "curves.png")
    print(table(summary))


if __name__ == "__main__":
    main()
