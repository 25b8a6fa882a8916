"""Experiments: several seeds of a preset plus the three ablations, run as processes.

Each run is an ordinary ``mtpg train`` process with its own run directory inside the
experiment folder; a run already finished is skipped and an unfinished one resumed, so an
interrupted experiment continues where it stopped.
"""

from __future__ import annotations

import logging
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from mtpg.ablations import ABLATION_TABLE, FULL_ALGORITHM, ablation
from mtpg.evolve.stopping import GracefulStop, StopNow
from mtpg.io.checkpoint import list_checkpoints
from mtpg.io.rundir import is_run_dir

_LOG = logging.getLogger(__name__)


@dataclass(frozen=True)
class PlannedRun:
    """One training run of an experiment.

    Attributes:
        path: Its run directory.
        seed: Its seed.
        ablation: The ablation switch (:data:`mtpg.ablations.ABLATION_TABLE`), or None for
            the full algorithm.
    """

    path: Path
    seed: int
    ablation: str | None

    def state(self, generations: int) -> str:
        """``"new"``, ``"partial"`` or ``"done"``."""
        if not is_run_dir(self.path):
            return "new"
        done = max((g for g, _ in list_checkpoints(self.path)), default=0)
        return "done" if done >= generations else "partial"

    def command(self, train_args: list[str], generations: int, workers: int) -> list[str]:
        """The ``mtpg train`` command line that starts or resumes this run."""
        base = [sys.executable, "-m", "mtpg", "train", "--quiet", "--workers", str(workers)]
        if is_run_dir(self.path):
            return [*base, "--resume", str(self.path), "--generations", str(generations)]
        extra = [ablation(self.ablation).flag] if self.ablation else []
        return [
            *base,
            *train_args,
            *extra,
            "--generations",
            str(generations),
            "--seed",
            str(self.seed),
            "--out",
            str(self.path),
        ]


def plan(folder: Path, seeds: int, ablation_seeds: int) -> list[PlannedRun]:
    """The runs of an experiment: ``seeds`` full runs and ``ablation_seeds`` per ablation.

    Each run directory is named by its experiment label (:mod:`mtpg.ablations`) and seed,
    ``TPG-seed0``, ``TPG-NoXover-seed0``, ...
    """
    runs = [PlannedRun(folder / f"{FULL_ALGORITHM}-seed{k}", k, None) for k in range(seeds)]
    for abl in ABLATION_TABLE:
        runs += [
            PlannedRun(folder / f"{abl.name}-seed{k}", k, abl.switch) for k in range(ablation_seeds)
        ]
    return runs


def execute(
    runs: list[PlannedRun],
    train_args: list[str],
    generations: int,
    parallel: int = 1,
    workers: int = 1,
    log: Callable[[str], None] | None = None,
    stop: GracefulStop | None = None,
) -> list[PlannedRun]:
    """Runs every unfinished run, ``parallel`` processes at a time.

    Each run's progress (done, starting, finished, stopped, failed) is one message to
    ``log``, by default the ``mtpg.evolve.experiment`` logger at INFO level.

    When ``stop`` receives a signal, it is passed on to the running processes (which
    stop at a generation boundary), no further run starts, and the running ones are
    waited for; stopped runs are not counted as failed. A second signal is passed on
    as well (they stop at once) before :class:`StopNow` propagates.

    Returns:
        The runs that failed (empty when all finished).
    """
    log = log or _LOG.info
    todo = [r for r in runs if r.state(generations) != "done"]
    for r in runs:
        if r not in todo:
            log(f"{r.path.name}: done")
    running: list[tuple[PlannedRun, subprocess.Popen]] = []
    failed = []
    forwarded = False
    try:
        while todo or running:
            if stop is not None and stop.signum is not None:
                todo.clear()
                if not forwarded:
                    for _, proc in running:
                        if proc.poll() is None:
                            proc.send_signal(stop.signum)
                    forwarded = True
            while todo and len(running) < parallel:
                run = todo.pop(0)
                log(f"{run.path.name}: {run.state(generations)} -> starting")
                run.path.parent.mkdir(parents=True, exist_ok=True)
                # the child holds its own copy of the log's descriptor: ours closes at once
                with open(run.path.parent / f"{run.path.name}.log", "a") as logfile:
                    proc = subprocess.Popen(
                        run.command(train_args, generations, workers),
                        stdout=logfile,
                        stderr=subprocess.STDOUT,
                        start_new_session=True,  # signals reach it once, passed on by us
                    )
                running.append((run, proc))
            time.sleep(0.2)
            for item in list(running):
                run, proc = item
                if proc.poll() is not None:
                    running.remove(item)
                    ok = proc.returncode == 0
                    stopped = forwarded and proc.returncode >= 128
                    code = proc.returncode
                    log(
                        f"{run.path.name}: "
                        + ("finished" if ok else "stopped" if stopped else f"failed ({code})")
                    )
                    if not (ok or stopped):
                        failed.append(run)
    except StopNow:  # a second signal: the trainings stop at once too
        for _, proc in running:
            if proc.poll() is None:
                proc.send_signal(stop.signum if stop and stop.signum else signal.SIGTERM)
        for _, proc in running:
            proc.wait()
        raise
    return failed
