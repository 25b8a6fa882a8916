"""Was the champion the limit, or the population? Tests every surviving root of a run.

For each finished single-task run folder, loads its last checkpoint and plays every
surviving root on the same held-out episodes as the run's test (seeds 1,000,000 + k), then
prints the champion's reference-normalised score beside the best, median and worst
surviving root's. When the best root is little better than the champion, no better choice
among the roots would have helped: the population never held a better graph. This is an
analysis after the fact (it looks at test episodes); nothing it computes reaches a run::

    python tools/population_oracle.py OUT/pendulum/resampling-6ep/seed*
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np


def oracle(run_dir: Path, episodes: int) -> dict[str, float]:
    """Champion and surviving roots of ``run_dir``'s last checkpoint, tested."""
    from mtpg.envs.taskset.reference_scores import normalise
    from mtpg.evolve.heldout_test import play_test
    from mtpg.evolve.persist import state_from_payload
    from mtpg.io.checkpoint import latest_checkpoint, load_checkpoint

    path = latest_checkpoint(run_dir)
    if path is None:
        raise ValueError(f"{run_dir}: no checkpoint")
    state, config = state_from_payload(load_checkpoint(path))
    task_ids = list(config.evaluation.task_ids)
    if len(task_ids) != 1:
        raise ValueError(f"{run_dir}: a single-task run is needed, it has {len(task_ids)} tasks")
    roots = sorted(state.scores)
    played = play_test(state.population, roots, task_ids, episodes, 0, config.evaluation.no_memory)
    means = played.returns.mean(axis=2)[:, 0]
    scores = np.array([normalise(task_ids[0], m) for m in means])
    champion = scores[roots.index(state.champions[-1])]
    return {
        "generation": state.generation,
        "roots": len(roots),
        "champion": float(champion),
        "best": float(scores.max()),
        "median": float(np.median(scores)),
        "worst": float(scores.min()),
    }


def main(argv: list[str] | None = None) -> int:
    """Prints the table of the runs given on the command line."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("runs", nargs="+", type=Path, help="run folders")
    parser.add_argument("--episodes", type=int, default=100, help="held-out episodes (100)")
    args = parser.parse_args(argv)
    rows = []
    print("| run | generation | roots | champion | best root | median root | worst root |")
    print("|---|---|---|---|---|---|---|")
    for run in args.runs:
        try:
            r = oracle(run, args.episodes)
        except (OSError, ValueError) as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 1
        rows.append(r)
        print(
            f"| {run} | {r['generation']} | {r['roots']} | {r['champion']:.2f} | {r['best']:.2f} "
            f"| {r['median']:.2f} | {r['worst']:.2f} |"
        )
    mean = {k: np.mean([r[k] for r in rows]) for k in ("champion", "best", "median", "worst")}
    print(
        f"| mean of {len(rows)} | | | {mean['champion']:.2f} | {mean['best']:.2f} "
        f"| {mean['median']:.2f} | {mean['worst']:.2f} |"
    )
    return 0


if __name__ == "__main__":
    from mtpg._kernel_cache import refresh

    refresh()  # before the first kernel: a Numba cache older than the sources goes
    sys.exit(main())
