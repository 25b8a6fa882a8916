"""``mtpg analyze``: the figures of paper section 6 for one graph (or a run's champion)."""

from __future__ import annotations

import argparse
from pathlib import Path


def register(subparsers: argparse._SubParsersAction) -> None:
    """Adds the ``analyze`` command."""
    from mtpg.cli.memory_option import add_memory_option

    p = subparsers.add_parser(
        "analyze",
        help="look inside a graph: visits, memory, velocity, decomposition (section 6)",
        description="Replay a graph on test episodes of every task and write PNG figures, "
        "analysis.json, graph.dot and one self-contained index.html: the team graph with "
        "visit shares by task, memory register access by task, per-task run-time dynamics "
        "(teams, instructions, memory window, velocity prediction) and a task "
        "decomposition. Given a run directory, the all-task champion is analysed and the "
        "run's hierarchy statistics are added.",
    )
    p.add_argument("target", metavar="GRAPH_OR_RUN", help="a graph .json file or a run directory")
    p.add_argument("--tasks", help="comma-separated tasks (default: the graph's or run's tasks)")
    p.add_argument("--episodes", type=int, default=100, help="episodes per task (default 100)")
    p.add_argument("--seed", type=int, default=0, help="test seed offset (default 0)")
    p.add_argument("--decompose-task", help="task of the decomposition figure")
    p.add_argument(
        "--out",
        metavar="DIR",
        help="output directory (default: analysis/ inside a run directory, GRAPH_analysis/ "
        "beside a graph file)",
    )
    add_memory_option(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Runs the command."""
    from mtpg.analysis.graph.page import build_analysis, not_applicable
    from mtpg.cli.common import resolve_graph, task_list
    from mtpg.cli.main import UsageError
    from mtpg.cli.memory_option import resolve_no_memory
    from mtpg.envs.specs.contract import TASK_NAMES
    from mtpg.envs.taskset.variants import known

    if args.episodes < 1:
        raise UsageError(f"--episodes must be >= 1, got {args.episodes}")
    target = Path(args.target)
    pop, root, meta, tasks = resolve_graph(target)
    if args.tasks:
        tasks = task_list(args.tasks)
    for t in tasks + ([args.decompose_task] if args.decompose_task else []):
        if not known(t):
            raise UsageError(f"unknown task {t!r}; choose from {', '.join(TASK_NAMES)}")
    if args.decompose_task and args.decompose_task not in tasks:
        raise UsageError(f"--decompose-task {args.decompose_task} is not among {tasks}")
    if args.decompose_task in not_applicable(tasks):
        why = not_applicable(tasks)[args.decompose_task]
        raise UsageError(f"--decompose-task {args.decompose_task}: {why}")
    no_memory, memory_text = resolve_no_memory(args.memory, meta)
    if args.out:
        out = Path(args.out)
    elif target.is_dir():
        out = target / "analysis"
    else:
        out = target.with_name(target.stem + "_analysis")
    print(
        f"{target}: root team {root}; {args.episodes} test episodes per task of "
        f"{', '.join(tasks)} (seed offset {args.seed}); {memory_text}"
    )
    for task, note in not_applicable(tasks).items():
        print(f"  {task}: {note}")
    files = build_analysis(
        pop,
        root,
        tasks,
        out,
        args.episodes,
        args.seed,
        no_memory,
        args.decompose_task,
        run_dir=target if target.is_dir() else None,
        label=target.name if target.is_dir() else target.stem,
    )
    for name, path in files.items():
        if name != "index":
            print(f"  {path}")
    print(files["index"])
    return 0
