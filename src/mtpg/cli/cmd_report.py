"""``mtpg report``: figures and an HTML page for one or more runs."""

from __future__ import annotations

import argparse


def register(subparsers: argparse._SubParsersAction) -> None:
    """Adds the ``report`` command."""
    p = subparsers.add_parser(
        "report",
        help="figures and an HTML page from run directories",
        description="Draw the figures of paper section 5 (learning curves, normalised scores, "
        "ablations, teams per decision) from the test results of one or more runs.",
    )
    p.add_argument("runs", nargs="+", metavar="RUN_DIR", help="run directories")
    p.add_argument("--out", metavar="DIR", help="output directory (default: RUN_DIR/report)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Runs the command."""
    from mtpg.analysis.report import build_report

    index = build_report(args.runs, args.out)
    print(index)
    return 0
