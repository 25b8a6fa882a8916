"""``mtpg report``: figures and an HTML page for one or more runs; or the results pages.

With ``--results [DIR]`` it rewrites the committed pages of the results folder from its
runs instead (:mod:`mtpg.analysis.results.pages`).
"""

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
        "differ in more than the seed and the ablation switches are reported with a warning. "
        "With --results [DIR] instead of run directories: rewrite the committed pages of a "
        "results folder (results/README.md, its figures and the study pages in docs/) from "
        "its runs alone; with --out, into another results folder (and docs/ beside it).",
    )
    p.add_argument("runs", nargs="*", metavar="RUN_DIR", help="run directories")
    p.add_argument(
        "--out",
        metavar="DIR",
        help="output directory (default: report/ inside the first RUN_DIR; with --results: "
        "the results folder itself)",
    )
    p.add_argument(
        "--results",
        nargs="?",
        const="results",
        metavar="DIR",
        help="rewrite the results pages from the runs of DIR (default: results)",
    )
    p.add_argument(
        "--page",
        action="append",
        metavar="NAME",
        help="with --results: only this page (repeatable): results, candidates, variants, "
        "memorisation, robust-audit",
    )
    p.set_defaults(func=run)


def run_results(args: argparse.Namespace) -> int:
    """Rewrites the results pages (:func:`mtpg.analysis.results.pages.regenerate`)."""
    from pathlib import Path

    from mtpg.analysis.results.pages import regenerate
    from mtpg.cli.main import UsageError

    if args.runs:
        raise UsageError("give run directories or --results, not both")
    folder = Path(args.results)
    if not (folder / "runs").is_dir():
        raise UsageError(f"--results {folder}: no runs/ folder in it")
    for page in regenerate(folder, args.out, args.page):
        print(page)
    return 0


def run(args: argparse.Namespace) -> int:
    """Runs the command."""
    import sys
    import warnings

    from mtpg.analysis.runs.report import MixedRunsWarning, build_report
    from mtpg.cli.main import UsageError

    if getattr(args, "results", None) is not None:  # mtpg experiment calls it without
        return run_results(args)
    if getattr(args, "page", None):
        raise UsageError("--page needs --results")
    if not args.runs:
        raise UsageError("give one or more run directories (or --results)")
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
