"""``mtpg show``: print a program graph as a researcher reads it, optionally as DOT."""

from __future__ import annotations

import argparse
from pathlib import Path


def register(subparsers: argparse._SubParsersAction) -> None:
    """Adds the ``show`` command."""
    p = subparsers.add_parser(
        "show",
        help="print a program graph: teams, programs, memory banks, pointers",
        description="List a graph file (or a run's all-task champion): every team with its "
        "programs in execution order, each program's action pointer, memory bank and "
        "disassembled instructions with introns marked, and the banks shared between "
        "programs. Team numbers are the ones every analysis figure uses (team 1 = root).",
    )
    p.add_argument("target", metavar="GRAPH_OR_RUN", help="a graph .json file or a run directory")
    p.add_argument("--dot", metavar="FILE", help="also write the team graph as GraphViz DOT")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Runs the command."""
    from mtpg.analysis.description.layout import render_svg
    from mtpg.analysis.description.listing import describe_graph, graph_dot
    from mtpg.cli.common import resolve_graph

    target = Path(args.target)
    pop, root, meta, tasks = resolve_graph(target)
    if target.is_dir():  # a run's champion file does not hold the run's tasks; show them
        meta = {"tasks": tasks, **meta}
    print(f"{target}: root team {root}")
    print(describe_graph(pop, root, meta))
    if args.dot:
        dot = Path(args.dot)
        dot.write_text(graph_dot(pop, root, title=target.name), encoding="utf-8")
        svg = render_svg(dot)
        print(f"wrote {dot}" + (f" and {svg}" if svg else " (install GraphViz for an SVG)"))
    return 0
