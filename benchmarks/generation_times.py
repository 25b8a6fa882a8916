"""Seconds per generation of a training run, per phase, from its ``metrics.csv``.

Usage::

    mtpg train --preset paper --generations 20 --workers 2 --out runs/paper20
    python benchmarks/generation_times.py runs/paper20

Prints, for each phase (variation, evaluation, selection, test, total), generation 1 and
the median and mean of the later generations, then the new roots and decisions per
generation and the decisions per second of the evaluation phase. Run it on an otherwise
idle machine: the figures are wall-clock times.
"""

from __future__ import annotations

import argparse
import csv
import statistics
from pathlib import Path

PHASES = (
    ("variation (Python)", "t_variation"),
    ("evaluation (compile + kernels)", "t_evaluation"),
    ("selection and deletion", "t_selection"),
    ("testing (test points only)", "t_test"),
    ("total", "t_total"),
)


def main() -> None:
    """Reads the run's metrics and prints the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dir", type=Path, help="a run directory with metrics.csv")
    args = parser.parse_args()
    with open(args.run_dir / "metrics.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    if len(rows) < 2:
        raise SystemExit(f"{args.run_dir}/metrics.csv: needs at least 2 generations")
    first, later = rows[0], rows[1:]
    span = f"{later[0]['generation']}-{later[-1]['generation']}"
    print(f"| phase | generation 1 | median of generations {span} | mean of generations {span} |")
    print("|---|---|---|---|")
    for name, col in PHASES:
        values = [float(r[col]) for r in later]
        print(
            f"| {name} | {float(first[col]):.2f} | {statistics.median(values):.2f} "
            f"| {statistics.mean(values):.2f} |"
        )
    new_roots = statistics.median(int(r["new_roots"]) for r in later)
    decisions = statistics.median(int(r["decisions"]) for r in later)
    speed = statistics.median(float(r["decisions_per_s"]) for r in later)
    print(
        f"\nnew roots per generation (median, generations {span}): {new_roots:.0f}; "
        f"decisions: {decisions:,.0f}; decisions/s in evaluation: {speed:,.0f}"
    )
    total = sum(float(r["t_total"]) for r in rows)
    print(f"training time of all {len(rows)} generations: {total:.0f} s")


if __name__ == "__main__":
    main()
