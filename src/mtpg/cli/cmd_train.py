"""``mtpg train``: run (or resume) multi-task TPG training into a run directory."""

from __future__ import annotations

import argparse
import contextlib
import sys

from mtpg.ablations import ABLATION_TABLE
from mtpg.cli.common import overrides, preset_help
from mtpg.presets import BACKENDS


def register(subparsers: argparse._SubParsersAction) -> None:
    """Adds the ``train`` command."""
    p = subparsers.add_parser(
        "train",
        help="evolve program graphs on the tasks",
        description="Evolve multi-task program graphs. Settings come from a preset, then "
        "--config FILE, then --set and the named options.",
    )
    p.add_argument("--preset", default="demo", help=preset_help())
    p.add_argument("--config", metavar="FILE", help="TOML file of settings")
    p.add_argument("--tasks", help="comma-separated task names (default: the preset's)")
    p.add_argument(
        "--generations",
        type=int,
        help="generations to run (default: the preset's: 1000 paper and robust, 250 demo)",
    )
    p.add_argument("--seed", type=int, help="run seed (default 0)")
    p.add_argument(
        "--workers",
        type=int,
        help="threads evaluating episodes (default: the preset's: 1 paper and robust, 2 demo; "
        "give --workers 2 or more for paper runs; results do not depend on it)",
    )
    p.add_argument(
        "--backend",
        choices=BACKENDS,
        help="evaluate on this machine's threads (local) or a Dask cluster (dask)",
    )
    p.add_argument("--address", metavar="TCP://HOST:PORT", help="scheduler of a Dask cluster")
    p.add_argument(
        "--dask-workers", type=int, metavar="N", help="start a local Dask cluster of N processes"
    )
    p.add_argument(
        "--scheduler-wait",
        type=float,
        metavar="SECONDS",
        help="seconds to wait for a Dask scheduler to connect or come back before the "
        "generation is finished on this machine (default: 10, or $MTPG_SCHEDULER_WAIT); "
        "not stored with the run",
    )
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="SECTION.FIELD=VALUE",
        help="override any setting, e.g. --set team.n_elite=10; top-level fields take no "
        "section, e.g. --set checkpoint_interval=5 (repeatable; fields: mtpg.config)",
    )
    for abl in ABLATION_TABLE:
        p.add_argument(abl.flag, dest=abl.dest, action="store_true", help=abl.help)
    where = p.add_mutually_exclusive_group()
    where.add_argument(
        "--out", metavar="RUN_DIR", help="new run directory (default: runs/<preset>-seed<seed>)"
    )
    where.add_argument("--resume", metavar="RUN_DIR", help="continue the run in RUN_DIR")
    p.add_argument("--quiet", action="store_true", help="no progress output")
    p.add_argument(
        "--tensorboard",
        metavar="DIR",
        help="also log every generation's training scores, test scores, population sizes "
        "and timings to TensorBoard event files in DIR (needs the tensorboard extra; off by "
        "default; not stored with the run)",
    )
    p.set_defaults(func=run)


def _fresh_dir(base: str) -> str:
    """``base``, or ``base-2``, ``base-3``, ... when taken (the default run directory)."""
    from pathlib import Path

    path, k = base, 1
    while Path(path).exists():
        k += 1
        path = f"{base}-{k}"
    return path


def run(args: argparse.Namespace) -> int:
    """Runs the command; ``--scheduler-wait`` is checked here and given to the run's session."""
    from mtpg.cli.main import UsageError

    if args.scheduler_wait is not None and not 0 < args.scheduler_wait <= 3600:
        raise UsageError(
            f"--scheduler-wait must be in (0, 3600] seconds, got {args.scheduler_wait}"
        )
    return _train(args)


def _train(args: argparse.Namespace) -> int:
    """Trains or resumes.

    Stop signals (SIGTERM, SIGINT, SIGHUP) end the run after the generation under way is
    complete and committed; a second one stops at once. Either way the exit status is
    128 + the signal number (130 Ctrl-C, 143 SIGTERM, 129 SIGHUP) and the run resumes
    exactly with ``--resume``.
    """
    from mtpg.cli.progress import Progress
    from mtpg.config import build_config, merge_overrides
    from mtpg.engine.evaluator import BackendLost
    from mtpg.evolve.session import Session, read_run_config
    from mtpg.evolve.stopping import GracefulStop, StopNow, exit_code

    lost: BackendLost | None = None
    if args.tensorboard is not None:
        from mtpg.evolve.tensorboard import check_available

        check_available()  # before anything is written

    with GracefulStop("mtpg train", "the generation under way is committed") as stop:
        if args.resume:
            config = merge_overrides(read_run_config(args.resume, resuming=True), overrides(args))
            session = Session(args.resume, config, resume=True, scheduler_wait=args.scheduler_wait)
        else:
            config = build_config(args.preset, args.config, overrides(args))
            out = args.out or _fresh_dir(f"runs/{args.preset}-seed{config.seed}")
            session = Session(out, config, scheduler_wait=args.scheduler_wait)
        cfg, where = session.config, session.run.path
        print(
            f"run directory: {where}  (generation {session.trainer.state.generation}"
            f" of {cfg.generations}; tasks: {', '.join(cfg.evaluation.tasks)})",
            file=sys.stderr,
        )
        progress = None if args.quiet else Progress.for_session(session)
        extra = []
        if args.tensorboard is not None:
            from mtpg.evolve.tensorboard import TensorBoardReporter

            extra.append(TensorBoardReporter(args.tensorboard, tuple(cfg.evaluation.tasks)))
        try:
            # a signal stops at the next boundary; so does a lost cluster (run_all raises
            # BackendLost once the last generation is committed)
            # the progress display is the last reporter: it shows what the others committed
            shown = [*extra, progress] if progress is not None else extra
            # log messages go above a live progress line, not into it
            with progress.messages() if progress else contextlib.nullcontext():
                finished = session.run_all(None, stop.requested, shown)
        except BackendLost as exc:
            lost, finished = exc, False
        except StopNow as exc:
            if progress:
                progress.close()
            print(
                f"stopped at once by {exc}; the generation under way was abandoned; "
                f"mtpg train --resume {where} continues from generation "
                f"{session.saved_generation}",
                file=sys.stderr,
            )
            return exit_code(exc.signum)
        finally:
            session.trainer.close()  # stops a local Dask cluster started for the run
    if not finished and (lost is not None or stop.signum is not None):
        if progress:
            progress.close()
        why = f"stopped by {stop.name}"
        if lost is not None:
            why = f"lost the evaluation backend ({lost})"
        print(
            f"{why} after generation {session.saved_generation} (committed); "
            f"resume with: mtpg train --resume {where}",
            file=sys.stderr,
        )
        return 1 if lost is not None else exit_code(stop.signum)
    print(f"done: {where}", file=sys.stderr)
    return 0
