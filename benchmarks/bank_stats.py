"""The memory-bank population of a training run over its generations, from ``metrics.csv``.

Usage::

    python benchmarks/bank_stats.py RUN_DIR [--generations 1,10,50,100,200,300]

Prints one Markdown row per chosen generation: teams, programs, banks, banks in use and
programs per bank in use (memory sharing). Runs written before the bank population existed
have only a ``banks`` column, which then counted the banks in use (there were no others).
"""

from __future__ import annotations

import argparse
import csv
from pathlib import Path


def main() -> None:
    """Reads the run's metrics and prints the table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dir", type=Path, help="a run directory with metrics.csv")
    parser.add_argument(
        "--generations", default="1,10,50,100,150,200,250,300", help="comma-separated"
    )
    args = parser.parse_args()
    with open(args.run_dir / "metrics.csv", newline="") as fh:
        rows = {int(r["generation"]): r for r in csv.DictReader(fh)}
    print("| generation | teams | programs | banks | banks in use | programs per bank in use |")
    print("|---|---|---|---|---|---|")
    for gen in (int(g) for g in args.generations.split(",")):
        if gen not in rows:
            continue
        r = rows[gen]
        in_use = int(r.get("banks_in_use") or r["banks"])
        print(
            f"| {gen} | {r['teams']} | {r['programs']} | {r['banks']} | {in_use} "
            f"| {int(r['programs']) / in_use:.1f} |"
        )


if __name__ == "__main__":
    main()
