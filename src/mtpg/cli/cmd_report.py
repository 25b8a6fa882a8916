"""``mtpg report``: figures and an HTML page for one or more runs."""

from __future__ import annotations

import argparse


def register(subparsers: argparse._SubParsersAction) -> None:
    """Adds the ``report`` command."""
    p = subparsers.add_parser(
        "report",
        help="figures and an HTML page from run directories",
        description="Draw the figures of paper section 5 (learning curves, normalised scores, "
        "ablations, teams per decision) and the statistics across seeds (interquartile mean "
        "with 95% stratified bootstrap confidence intervals, performance profile, probability "
        "of improvement between experiments) from the test results of one or more runs, and "
        "training curves (training scores, population and bank sizes) from their "
        "metrics.csv. Runs are grouped by configuration; runs that "
        "differ in more than the seed and the ablation switches are reported with a warning.",
    )
    p.add_argument("runs", nargs="+", metavar="RUN_DIR", help="run directories")
    p.add_argument(
        "--out",
        metavar="DIR",
        help="output directory (default: report/ inside the first RUN_DIR)",
    )
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Runs the command."""
    import sys
    import warnings

    from mtpg.analysis.runs.report import MixedRunsWarning, build_report

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", MixedRunsWarning)
        index = build_report(args.runs, args.out)
    for w in caught:
        if issubclass(w.category, MixedRunsWarning):
            print(f"warning: {w.message}", file=sys.stderr)
        else:
            warnings.showwarning(w.message, w.category, w.filename, w.lineno)
    print(index)
    return 0
