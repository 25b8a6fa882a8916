"""``mtpg experiment``: seeds of a preset plus the three ablations, then the report.

With ``--plan FILE`` it grows the committed experiments a plan file lists instead
(:mod:`mtpg.growing`): ``mtpg experiment --plan results/plan.toml --budget MINUTES``.
"""

from __future__ import annotations

import argparse


def register(subparsers: argparse._SubParsersAction) -> None:
    """Adds the ``experiment`` command."""
    from mtpg.cli.common import preset_help

    p = subparsers.add_parser(
        "experiment",
        help="several seeds plus the three ablations, then a report; or grow a plan's runs",
        description="Run SEEDS seeds of a preset and ABLATION_SEEDS seeds of each ablation "
        "(no crossover, no memory, no hierarchy) into one folder (--out), as separate "
        "processes, then write the report. Rerunning the command resumes unfinished runs. "
        "With --plan FILE instead: grow the runs of the plan file's groups (results/plan.toml "
        "lists the committed experiments) for --budget minutes, --parallel at a time on "
        "--workers threads each, committing them with git every --slice minutes "
        "(docs/runs.md, 'Growing the committed experiments').",
    )
    p.add_argument("--out", metavar="DIR", help="experiment folder (required without --plan)")
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
    p.add_argument(
        "--parallel", type=int, help="runs at the same time (1; with --plan: 2)", default=None
    )
    _register_plan(p)
    p.set_defaults(func=run)


def _register_plan(p: argparse.ArgumentParser) -> None:
    """The options of ``--plan`` mode."""
    g = p.add_argument_group("growing a plan's runs (--plan)")
    g.add_argument("--plan", metavar="FILE", help="plan file of groups of runs to grow")
    g.add_argument("--budget", type=float, metavar="MINUTES", help="wall-clock minutes")
    g.add_argument("--only", nargs="+", metavar="GROUP", help="grow these groups (default: all)")
    g.add_argument("--workers", type=int, help="threads per run (1)")
    g.add_argument("--slice", type=float, help="minutes between commits (40)")
    g.add_argument("--python", metavar="EXE", help="interpreter whose mtpg runs (this one)")
    g.add_argument(
        "--results", metavar="DIR", help="results folder of the one group grown (the plan's)"
    )
    g.add_argument("--no-commit", action="store_true", help="tidy and record, commit nothing")
    g.add_argument(
        "--train-arg",
        action="append",
        default=[],
        metavar="ARG",
        help="extra mtpg train argument for runs begun now (tests and trials only)",
    )
    g.add_argument(
        "--unchecked",
        action="store_true",
        help="skip the clean-checkout check (trials only; provenance then says so)",
    )


#: Options of ``--plan`` mode only, with the value each has when not given.
_PLAN_ONLY = {
    "budget": None,
    "only": None,
    "workers": None,
    "slice": None,
    "python": None,
    "results": None,
    "no_commit": False,
    "train_arg": [],
    "unchecked": False,
}
#: Options of the seeds mode only, with the value each has when not given.
_SEEDS_ONLY = {
    "out": None,
    "preset": "demo",
    "config": None,
    "tasks": None,
    "set": [],
    "seeds": 3,
    "ablation_seeds": 1,
}


def _refuse(args: argparse.Namespace, options: dict, mode: str) -> None:
    from mtpg.cli.main import UsageError

    for name, unset in options.items():
        if getattr(args, name) != unset:
            raise UsageError(f"--{name.replace('_', '-')} is an option of {mode}")


def run_plan(args: argparse.Namespace) -> int:
    """Grows the runs of a plan file's groups (``--plan``; :func:`mtpg.growing.grow.grow`)."""
    import sys
    from pathlib import Path

    from mtpg.cli.main import UsageError
    from mtpg.growing.grow import GrowOptions, grow
    from mtpg.growing.plan import load_plan

    _refuse(args, _SEEDS_ONLY, "mtpg experiment without --plan")
    if args.budget is None or args.budget <= 0:
        raise UsageError("--plan needs --budget MINUTES > 0")
    parallel = 2 if args.parallel is None else args.parallel
    workers = 1 if args.workers is None else args.workers
    if parallel < 1 or workers < 1 or (args.slice is not None and args.slice <= 0):
        raise UsageError("--parallel and --workers must be >= 1, --slice > 0")
    if args.generations is not None and args.generations < 1:
        raise UsageError("--generations must be >= 1")
    plan = load_plan(args.plan)
    groups = plan.select(args.only)
    if args.results is not None and len(groups) != 1:
        raise UsageError("--results needs a single group (--only GROUP)")
    folder = Path(args.results).resolve() if args.results is not None else None
    runs = [r for g in groups for r in g.runs(folder)]
    options = GrowOptions(
        budget_min=args.budget,
        slice_min=40 if args.slice is None else args.slice,
        parallel=parallel,
        workers=workers,
        generations=args.generations,
        python=args.python or sys.executable,
        commit=not args.no_commit,
        train_args=tuple(args.train_arg),
        unchecked=args.unchecked,
    )
    return grow(runs, options)


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

    if args.plan is not None:
        return run_plan(args)
    _refuse(args, _PLAN_ONLY, "mtpg experiment --plan")
    if args.out is None:
        raise UsageError("--out DIR is required (or --plan FILE)")
    args.parallel = 1 if args.parallel is None else args.parallel
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
