"""``mtpg probe``: the memorisation probe of a run's champion (or of a graph file of a run)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path


def register(subparsers: argparse._SubParsersAction) -> None:
    """Adds the ``probe`` command."""
    from mtpg.evolve.memorisation import DEFAULT_REDRAWS

    p = subparsers.add_parser(
        "probe",
        help="memorisation probe: training episodes, fresh noise, held-out episodes",
        description="Score a run's all-task champion (or a graph file inside a run "
        "directory) per task on (a) the training episodes it was last trained on, (b) the "
        "same start states with only the U[0, 1] noise input redrawn, (c) held-out "
        "episodes; print the drops between them, raw and normalised (0 = random play, "
        "1 = reference best). Reads the run directory and writes nothing into it.",
    )
    p.add_argument(
        "target", metavar="RUN_OR_GRAPH", help="a run directory or a graph file inside one"
    )
    p.add_argument(
        "--tasks",
        help="comma-separated tasks, among the run's (default: the run's tasks; for a "
        "subset's champion file, that subset's)",
    )
    p.add_argument(
        "--noise-seed",
        type=int,
        default=0,
        help="seed of the redrawn noise of (b) (default 0)",
    )
    p.add_argument(
        "--redraws",
        type=int,
        default=DEFAULT_REDRAWS,
        help=f"redraws of the noise of each training episode (default {DEFAULT_REDRAWS})",
    )
    p.add_argument(
        "--episodes",
        type=int,
        help="held-out episodes per task of (c) (default: the run's evaluation.test_episodes, "
        "so (c) equals its tests.csv)",
    )
    p.add_argument("--seed", type=int, default=0, help="held-out seed offset of (c) (default 0)")
    p.add_argument("--workers", type=int, default=1, help="threads (default 1)")
    p.add_argument("--json", action="store_true", help="print one JSON object instead")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Runs the command."""
    from mtpg.analysis.runs.champion_probe import probe_json, probe_target, probe_text
    from mtpg.cli.common import task_list
    from mtpg.cli.main import UsageError
    from mtpg.limits import LIMITS

    top = LIMITS["episodes"]
    if args.episodes is not None and not 1 <= args.episodes <= top:
        raise UsageError(f"--episodes must be in 1..{top:,}, got {args.episodes}")
    if not 1 <= args.redraws <= top:
        raise UsageError(f"--redraws must be in 1..{top:,}, got {args.redraws}")
    if not 0 <= args.noise_seed <= 2**63 - 1:
        raise UsageError(f"--noise-seed must be in 0..{2**63 - 1}, got {args.noise_seed}")
    if not 0 <= args.seed <= 2**62:  # test seeds are 1,000,000 + seed + k in int64
        raise UsageError(f"--seed must be in 0..{2**62}, got {args.seed}")
    if not 1 <= args.workers <= LIMITS["workers"]:
        raise UsageError(f"--workers must be in 1..{LIMITS['workers']}, got {args.workers}")
    tasks = task_list(args.tasks) if args.tasks is not None else None
    probe = probe_target(
        Path(args.target),
        tasks=tasks,
        noise_seed=args.noise_seed,
        redraws=args.redraws,
        test_episodes=args.episodes,
        test_offset=args.seed,
        workers=args.workers,
    )
    if args.json:
        print(json.dumps(probe_json(probe), allow_nan=False))
    else:
        print("\n".join(probe_text(probe)))
    return 0
