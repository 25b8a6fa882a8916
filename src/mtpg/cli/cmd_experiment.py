"""``mtpg experiment``: seeds of a preset plus the three ablations, then the report."""

from __future__ import annotations

import argparse


def register(subparsers: argparse._SubParsersAction) -> None:
    """Adds the ``experiment`` command."""
    from mtpg.cli.common import preset_help

    p = subparsers.add_parser(
        "experiment",
        help="several seeds plus the three ablations, then a report",
        description="Run SEEDS seeds of a preset and ABLATION_SEEDS seeds of each ablation "
        "(no crossover, no memory, no hierarchy) into one folder, as separate processes, "
        "then write the report. Rerunning the command resumes unfinished runs.",
    )
    p.add_argument("--out", required=True, metavar="DIR", help="experiment folder")
    p.add_argument("--preset", default="demo", help=preset_help())
    p.add_argument("--config", metavar="FILE", help="TOML file of settings")
    p.add_argument("--tasks", help="comma-separated task names (default: the preset's)")
    p.add_argument("--generations", type=int, help="generations per run (default: the preset's)")
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="SECTION.FIELD=VALUE",
        help="override a setting (repeatable)",
    )
    p.add_argument("--seeds", type=int, default=3, help="seeds of the full algorithm (3)")
    p.add_argument("--ablation-seeds", type=int, default=1, help="seeds per ablation (1)")
    p.add_argument("--parallel", type=int, default=1, help="runs at the same time (1)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Runs the command.

    The experiment folder is locked for the whole command (a second experiment on it is
    refused at once). A stop signal is passed on to the running ``mtpg train`` processes,
    which stop at a generation boundary; no new run starts, and the command exits with
    128 + the signal number. Rerunning it resumes every unfinished run.
    """
    import sys
    from pathlib import Path

    from mtpg.cli.common import overrides
    from mtpg.cli.main import UsageError, build_parser
    from mtpg.cli.progress import ExperimentProgress
    from mtpg.config import build_config
    from mtpg.evolve.experiment import execute, plan
    from mtpg.evolve.stopping import GracefulStop, exit_code
    from mtpg.io.lock import lock_dir
    from mtpg.limits import check_training_fits

    if args.seeds < 1 or args.ablation_seeds < 0 or args.parallel < 1:
        raise UsageError("--seeds and --parallel must be >= 1, --ablation-seeds >= 0")
    if max(args.seeds, args.ablation_seeds, args.parallel) > 1000:
        raise UsageError("--seeds, --ablation-seeds and --parallel must be <= 1000")
    train_args = ["--preset", args.preset]
    if args.config:
        train_args += ["--config", args.config]
    if args.tasks is not None:
        train_args += ["--tasks", args.tasks]
    for text in args.set:
        train_args += ["--set", text]
    train_args_ns = build_parser().parse_args(["train", *train_args])
    if args.generations is not None:
        train_args_ns.generations = args.generations
    config = build_config(args.preset, args.config, overrides(train_args_ns))  # validate early
    check_training_fits(config)
    workers = max(1, config.workers // args.parallel)
    folder = Path(args.out)
    if folder.exists() and not folder.is_dir():
        raise UsageError(f"--out {folder}: exists and is not a directory")
    runs = plan(folder, args.seeds, args.ablation_seeds)
    folder.mkdir(parents=True, exist_ok=True)
    with (
        lock_dir(folder, "the experiment folder") as lock,
        GracefulStop("mtpg experiment", "the running trainings stop") as stop,
    ):
        lock.claim()
        watch = ExperimentProgress(runs, config.generations, lambda m: print(m, file=sys.stderr))
        watch.start()
        try:
            failed = execute(
                runs,
                train_args,
                config.generations,
                args.parallel,
                workers,
                stop=stop,  # the runs' progress: the mtpg logger, on stderr (cli.main)
            )
        finally:
            watch.stop()
    if stop.signum is not None:
        print(f"stopped by {stop.name}; rerun the command to resume", file=sys.stderr)
        return exit_code(stop.signum)
    if failed:
        names = ", ".join(r.path.name for r in failed)
        print(
            f"failed: {names} (see their .log files in {folder}); rerun to resume", file=sys.stderr
        )
        return 1
    from mtpg.cli.cmd_report import run as report

    return report(argparse.Namespace(runs=[str(r.path) for r in runs], out=str(folder / "report")))
