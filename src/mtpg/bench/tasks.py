"""``mtpg bench tasks``: training speed on a built-in, a compiled user and a Gymnasium task.

Three arms train the same preset from the same seed, each in a fresh process
(``mtpg train``): the built-in ``CartPole``; CartPole written as a compiled task of a user's
module (:mod:`mtpg.bench.user_cartpole`, which plays the built-in's episodes exactly, so the
two runs are identical, decision for decision); and Gymnasium's ``gym:CartPole-v1``,
stepped in Python (another task: four inputs, two actions, 500 steps). An arm's speed is
its decisions over its evaluation seconds (``decisions`` and ``t_evaluation`` of
metrics.csv), generation 1 left out (it compiles the kernels); the repeats run the arms in
turn and the median is reported.

A fourth arm, pytpg 0.6 (:mod:`mtpg.bench.pytpg_arm`), runs when pytpg is importable and is
left out with one line otherwise: after the rounds it trains on ``CartPole-v1`` with as many
graphs as the Gymnasium arm's roots until its environment steps reach that arm's last run,
once (it is about six times slower). Both champions then play the same 100 held-out
episodes (reset seeds ``1,000,000 + k``): the score at equal environment steps.
"""

from __future__ import annotations

import csv
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from mtpg.bench import pytpg_arm

#: The arms: a label and the task trained.
ARMS = (
    ("built-in", "CartPole"),
    ("compiled user task", "mtpg.bench.user_cartpole:CARTPOLE"),
    ("Gymnasium path", "gym:CartPole-v1"),
)


def _train(task: str, preset: str, generations: int, seed: int, folder: Path) -> dict:
    """Trains one arm in a fresh process and reads its speed from metrics.csv."""
    args = [sys.executable, "-m", "mtpg", "train", "--preset", preset, "--tasks", task]
    args += ["--generations", str(generations), "--seed", str(seed), "--workers", "1"]
    args += ["--quiet", "--out", str(folder)]
    done = subprocess.run(args, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{task}: {done.stderr.strip().splitlines()[-1]}")
    with open(folder / "metrics.csv", newline="") as f:
        rows = [r for r in csv.DictReader(f) if int(r["generation"]) > 1]
    decisions = sum(float(r["decisions"]) for r in rows)
    seconds = sum(float(r["t_evaluation"]) for r in rows)
    best = [float(v) for k, v in rows[-1].items() if k.startswith("best_")]
    roots = max(int(r["roots"]) for r in rows)
    return {
        "decisions": decisions,
        "seconds": seconds,
        "best": best[0] if best else None,
        "roots": roots,
        "folder": folder,
    }


#: Held-out test episodes of the score at equal steps: reset seeds TEST_SEED + k.
TEST_SEED, TEST_EPISODES = 1_000_000, 100


def _test_score(folder: Path) -> float:
    """The champion's mean return on the held-out episodes (``mtpg evaluate --seed 0``)."""
    args = [sys.executable, "-m", "mtpg", "evaluate", str(folder), "--seed", "0", "--json"]
    done = subprocess.run([*args, "--episodes", str(TEST_EPISODES)], capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"evaluate: {done.stderr.strip().splitlines()[-1]}")
    return float(next(iter(json.loads(done.stdout).values()))["mean"])


def _pytpg(gym_run: dict, seed: int, log) -> dict:
    """Trains pytpg to the Gymnasium arm's environment steps; both test scores."""
    import tomllib

    import gymnasium

    with open(gym_run["folder"] / "config.toml", "rb") as f:
        episodes = int(tomllib.load(f)["evaluation"]["train_episodes"])
    budget = int(gym_run["decisions"])
    log(f"pytpg: {gym_run['roots']} graphs, {episodes} episodes, to {budget:,} steps")
    run = pytpg_arm.train(
        lambda: gymnasium.make("CartPole-v1"), budget, episodes, gym_run["roots"], seed
    )
    seeds = [TEST_SEED + k for k in range(TEST_EPISODES)]
    scores = pytpg_arm.score(lambda: gymnasium.make("CartPole-v1"), run.champion, seeds)
    return {
        "task": "CartPole-v1 (pytpg 0.6)",
        "decisions_per_s": run.decisions_per_s,
        "runs": [run.decisions_per_s],
        "decisions": run.steps,
        "best": run.curve[-1][1],
        "generations": run.generations,
        "test_mean": sum(scores) / len(scores),
        "gym_test_mean": _test_score(gym_run["folder"]),
    }


def benchmark(
    preset: str = "demo",
    generations: int = 30,
    repeats: int = 3,
    seed: int = 1,
    log=print,
    pytpg: bool = True,
) -> dict:
    """Times the three arms, and pytpg where installed (see the module docstring).

    Args:
        preset: The preset trained.
        generations: Generations per run.
        repeats: Rounds; the median is reported.
        seed: The run seed (pytpg's Generator's too).
        log: Prints one progress line.
        pytpg: Whether to run the pytpg arm when pytpg is importable.

    Returns:
        Per arm: median decisions per evaluation second, the decisions of one run and the
        last generation's best training score; the compiled task's speed over the
        built-in's; and, with pytpg, its arm with both test scores at equal steps
        (``pytpg`` in ``arms``; ``pytpg_absent`` holds the line printed without it).
    """
    speeds: dict[str, list[float]] = {label: [] for label, _ in ARMS}
    facts: dict[str, dict] = {}
    extra: dict[str, dict] = {}
    absent = None
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(repeats):
            for k, (label, task) in enumerate(ARMS):
                got = _train(task, preset, generations, seed, Path(tmp) / f"round{r}-arm{k}")
                facts[label] = got
                speeds[label].append(got["decisions"] / got["seconds"])
                log(f"round {r + 1}/{repeats}: {label:<20} {speeds[label][-1]:,.0f} decisions/s")
        if pytpg and pytpg_arm.available():
            extra["pytpg"] = _pytpg(facts["Gymnasium path"], seed, log)
            log(f"pytpg: {extra['pytpg']['decisions_per_s']:,.0f} decisions/s")
        elif pytpg:
            absent = pytpg_arm.absent_line()
            log(absent)
    arms = {
        label: {
            "task": task,
            "decisions_per_s": statistics.median(speeds[label]),
            "runs": speeds[label],
            "decisions": facts[label]["decisions"],
            "best": facts[label]["best"],
        }
        for label, task in ARMS
    }
    arms.update(extra)
    ratio = arms["compiled user task"]["decisions_per_s"] / arms["built-in"]["decisions_per_s"]
    same = arms["compiled user task"]["decisions"] == arms["built-in"]["decisions"]
    return {
        "preset": preset,
        "generations": generations,
        "repeats": repeats,
        "seed": seed,
        "arms": arms,
        "compiled_vs_built_in": ratio,
        "compiled_run_identical_decisions": same,
        "pytpg_absent": absent,
    }
