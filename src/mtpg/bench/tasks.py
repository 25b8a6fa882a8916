"""``mtpg bench tasks``: training speed on a built-in, a compiled user and a Gymnasium task.

Three arms train the same preset from the same seed, each in a fresh process
(``mtpg train``): the built-in ``CartPole``; CartPole written as a compiled task of a user's
module (:mod:`mtpg.bench.user_cartpole`, which plays the built-in's episodes exactly, so the
two runs are identical, decision for decision); and Gymnasium's ``gym:CartPole-v1``,
stepped in Python (another task: four inputs, two actions, 500 steps). An arm's speed is
its decisions over its evaluation seconds (``decisions`` and ``t_evaluation`` of
metrics.csv), generation 1 left out (it compiles the kernels); the repeats run the arms in
turn and the median is reported.
"""

from __future__ import annotations

import csv
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

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
    return {"decisions": decisions, "seconds": seconds, "best": best[0] if best else None}


def benchmark(
    preset: str = "demo", generations: int = 30, repeats: int = 3, seed: int = 1, log=print
) -> dict:
    """Times the three arms (see the module docstring).

    Returns:
        Per arm: median decisions per evaluation second, the decisions of one run and the
        last generation's best training score; and the compiled task's speed over the
        built-in's.
    """
    speeds: dict[str, list[float]] = {label: [] for label, _ in ARMS}
    facts: dict[str, dict] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(repeats):
            for k, (label, task) in enumerate(ARMS):
                got = _train(task, preset, generations, seed, Path(tmp) / f"round{r}-arm{k}")
                facts[label] = got
                speeds[label].append(got["decisions"] / got["seconds"])
                log(f"round {r + 1}/{repeats}: {label:<20} {speeds[label][-1]:,.0f} decisions/s")
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
    }
