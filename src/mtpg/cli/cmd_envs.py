"""``mtpg envs``: the six tasks with their interface, time limits and reference scores.

With ``--tasks`` or ``--run``, the tasks named (or a run's) instead, Gymnasium tasks
included: their interface as mtpg reads it (observation size and scaling, the action
mapping), time limit and random-play score measured by mtpg.
"""

from __future__ import annotations

import argparse


def register(subparsers: argparse._SubParsersAction) -> None:
    """Adds the ``envs`` command.

    Args:
        subparsers: The top-level sub-parser collection.
    """
    parser = subparsers.add_parser(
        "envs",
        help="list the six tasks and their reference scores",
        description=(
            "Lists the six partially-observable tasks: observed inputs, the action each "
            "reads, time limit, random-agent mean, reference best, solved threshold and the "
            "source of the best. With --measure, re-measures the random-agent means and the "
            "CartCentering time-optimal score and prints them next to the stored figures. "
            "With --tasks or --run, lists those tasks instead, Gymnasium tasks (gym:ID) "
            "included: observation size and scaling, action mapping, time limit and the "
            "random-play score mtpg measures."
        ),
    )
    parser.add_argument(
        "--tasks",
        help="comma-separated tasks to list, registered or Gymnasium (gym:CartPole-v1)",
    )
    parser.add_argument("--run", metavar="DIR", help="list the tasks of this run directory")
    parser.add_argument(
        "--measure",
        action="store_true",
        help="re-measure the random-agent means and the CartCentering best (a few seconds)",
    )
    parser.set_defaults(func=run)


def _num(value: float) -> str:
    if value != value:  # NaN: no figure
        return "-"
    return f"{value:.4g}"


def run(args: argparse.Namespace) -> int:
    """Prints the task table (and the re-measurement with ``--measure``).

    Args:
        args: Parsed arguments.

    Returns:
        Exit code 0.
    """
    if args.tasks is not None or args.run is not None:
        from mtpg.cli.envs_listing import list_tasks

        return list_tasks(args)
    from mtpg.envs.specs.contract import CARTCENTERING, TASK_NAMES
    from mtpg.envs.specs.param_table import ACTION_USED, MAX_STEPS, OBSERVED
    from mtpg.envs.taskset.reference_scores import (
        REFERENCE,
        measure_random,
        measure_time_optimal_cartcentering,
    )

    header = (
        "id",
        "task",
        "observed",
        "action",
        "limit",
        "random",
        "best",
        "solved",
        "source of best",
    )
    rows = [
        (
            str(task),
            name,
            OBSERVED[task],
            ACTION_USED[task],
            str(int(MAX_STEPS[task])),
            _num(REFERENCE[task].random),
            _num(REFERENCE[task].best),
            _num(REFERENCE[task].solved),
            REFERENCE[task].source,
        )
        for task, name in enumerate(TASK_NAMES)
    ]
    widths = [max(len(r[i]) for r in (header, *rows)) for i in range(len(header))]
    for row in (header, *rows):
        print("  ".join(cell.ljust(w) for cell, w in zip(row, widths, strict=True)).rstrip())
    print("normalised = (score - random) / (best - random)")
    if args.measure:
        print()
        print("re-measured (stored -> measured):")
        for task, name in enumerate(TASK_NAMES):
            mean, std = measure_random(task)
            print(f"  {name:22s} random {REFERENCE[task].random:.6g} -> {mean:.6g} (sd {std:.4g})")
        score, steps, captured = measure_time_optimal_cartcentering()
        print(
            f"  {TASK_NAMES[CARTCENTERING]:22s} best   {REFERENCE[CARTCENTERING].best:.6g} -> "
            f"{score:.6g} ({captured}/100 captured, mean {steps:.1f} steps)"
        )
    return 0
