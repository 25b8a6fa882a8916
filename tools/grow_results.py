"""Grow the committed runs of ``results/`` for a wall-clock budget, then commit them.

Kept for the command lines that call it; the package does the work::

    mtpg experiment --plan results/plan.toml --budget 150 --only paper

is the same as ``.venv/bin/python tools/grow_results.py --budget 150`` (``--plan NAME``
here is ``--only NAME`` there: a group of ``results/plan.toml``; ``--results`` the folder
of that group's runs). The plan, the command lines of the runs and the growing are in
:mod:`mtpg.growing`; docs/runs.md ("Growing the committed experiments") describes them.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from mtpg.growing.checkout import GrowError
from mtpg.growing.grow import GrowOptions, grow
from mtpg.growing.plan import load_plan

#: The plan file of the committed experiments.
PLAN_FILE = Path(__file__).resolve().parents[1] / "results" / "plan.toml"


def main(argv: list[str] | None = None) -> int:
    """Runs the script (see the module docstring)."""
    plan = load_plan(PLAN_FILE)
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--budget", type=float, required=True, help="minutes of wall-clock time")
    p.add_argument("--slice", type=float, default=40, help="minutes between commits (40)")
    p.add_argument("--parallel", type=int, default=2, help="runs at a time (2)")
    p.add_argument("--workers", type=int, default=1, help="threads per run (1)")
    p.add_argument("--generations", type=int, default=1000, help="target (1000)")
    p.add_argument("--python", default=sys.executable, help="interpreter whose mtpg runs")
    p.add_argument(
        "--plan",
        choices=sorted(g.name for g in plan.groups),
        default="paper",
        help="a group of results/plan.toml (paper, robust, authors, demo, variants)",
    )
    p.add_argument("--results", type=Path, default=None, help="folder (default: the plan's)")
    p.add_argument("--no-commit", action="store_true", help="tidy and record, commit nothing")
    p.add_argument(
        "--train-arg",
        action="append",
        default=[],
        metavar="ARG",
        help="extra mtpg train argument for runs begun now (tests and trials only)",
    )
    p.add_argument(
        "--unchecked",
        action="store_true",
        help="skip the clean-checkout checks (trials only; provenance then says so)",
    )
    args = p.parse_args(argv)
    folder = args.results.resolve() if args.results is not None else None
    options = GrowOptions(
        budget_min=args.budget,
        slice_min=args.slice,
        parallel=args.parallel,
        workers=args.workers,
        generations=args.generations,
        python=args.python,
        commit=not args.no_commit,
        train_args=tuple(args.train_arg),
        unchecked=args.unchecked,
    )
    try:
        return grow(plan.group(args.plan).runs(folder), options, lambda m: print(m, flush=True))
    except GrowError as exc:
        raise SystemExit(f"grow_results: {exc}") from None


if __name__ == "__main__":
    sys.exit(main())
