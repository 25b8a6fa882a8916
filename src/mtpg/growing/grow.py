"""Growing the runs of a plan for a wall-clock budget, committing them slice by slice.

:func:`grow` continues the unfinished runs in order, ``parallel`` at a time, each an
ordinary ``mtpg train --resume`` process (``mtpg train --out`` for a run not begun; the
command lines are :meth:`~mtpg.growing.plan.PlannedRun.command`'s) on ``workers`` threads.
The last run left takes the threads of the runs that finished (``parallel`` times
``workers``): it commits the generation under way and resumes on all of them, the same
run, since results do not depend on the thread count. Every ``slice`` minutes, and when
the budget is spent or the process is stopped (SIGTERM, SIGINT, SIGHUP), the runs are sent
SIGTERM, so each commits the generation under way and ends; then every run touched is
tidied (:func:`~mtpg.growing.tidy.tidy`), its sitting recorded in ``provenance.csv`` and
its ``runs`` folder committed with git.
"""

from __future__ import annotations

import logging
import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from mtpg.growing.checkout import GrowError, commit_runs, repository_of, source_commit
from mtpg.growing.plan import PlannedRun
from mtpg.growing.tidy import Sitting, last_generation, record, tidy

__all__ = ["STOP_GRACE_S", "GrowOptions", "Job", "grow", "start", "stop_all"]

_LOG = logging.getLogger(__name__)

#: Seconds a run is given to commit after SIGTERM before it is told to stop at once.
STOP_GRACE_S = 300
_IGNORE = "# written by mtpg experiment --plan: run logs and run locks\n*.log\n*/.lock\n"


@dataclass(frozen=True)
class GrowOptions:
    """How :func:`grow` grows the runs.

    Attributes:
        budget_min: Minutes of wall-clock time.
        slice_min: Minutes between commits.
        parallel: Runs at a time.
        workers: Threads per run.
        generations: Target generation for every run (None: each group's own).
        python: The interpreter whose ``mtpg`` runs the trainings.
        commit: Commit the grown runs (else only tidy and record them).
        train_args: More ``mtpg train`` arguments for runs begun now (trials and tests).
        unchecked: Skip the clean-checkout check (trials; provenance says ``unchecked``).
        keep_tests_every: Test folders of generations divisible by this are archived
            (None: :data:`mtpg.growing.tidy.KEEP_TESTS_EVERY`).
        stop_grace_s: Seconds a run is given to commit after SIGTERM.
    """

    budget_min: float
    slice_min: float = 40
    parallel: int = 2
    workers: int = 1
    generations: int | None = None
    python: str = field(default_factory=lambda: sys.executable)
    commit: bool = True
    train_args: tuple[str, ...] = ()
    unchecked: bool = False
    keep_tests_every: int | None = None
    stop_grace_s: float = STOP_GRACE_S

    def target(self, run: PlannedRun) -> int:
        """The generation ``run`` grows to."""
        return self.generations if self.generations is not None else run.generations


@dataclass
class Job:
    """One ``mtpg train`` process growing one run."""

    run: PlannedRun
    proc: subprocess.Popen
    start_gen: int
    workers: int = 1
    started: float = field(default_factory=time.time)
    status: int | None = None
    cpu_s: float = 0.0
    end_gen: int = 0
    ended: float = 0.0

    @property
    def name(self) -> str:
        """The run directory's name."""
        return self.run.name

    def poll(self) -> bool:
        """True once the process has ended (its status and CPU time then recorded)."""
        if self.status is None:
            pid, status, usage = os.wait4(self.proc.pid, os.WNOHANG)
            if pid:
                self.status = os.waitstatus_to_exitcode(status)
                self.proc.returncode = self.status
                self.cpu_s = usage.ru_utime + usage.ru_stime
                self.end_gen = last_generation(self.run.path)
                self.ended = time.time()
        return self.status is not None

    def sitting(self) -> Sitting:
        """What the ended process did, for ``provenance.csv``."""
        return Sitting(
            self.run.path,
            self.start_gen,
            self.end_gen,
            self.started,
            self.ended,
            self.cpu_s,
            self.workers,
        )


def began(run: PlannedRun) -> bool:
    """True once the run can be resumed (its ``config.toml`` is written)."""
    return (run.path / "config.toml").is_file()


def start(run: PlannedRun, options: GrowOptions, workers: int = 0) -> Job:
    """Starts (or resumes) one run, on ``workers`` threads (default: ``options.workers``)."""
    workers = workers or options.workers
    cmd = run.command(options.target(run), workers, began(run), options.train_args)
    with open(run.folder / "runs" / f"{run.name}.log", "a") as log:
        proc = subprocess.Popen(
            [options.python, "-m", "mtpg", *cmd],
            stdout=log,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
    return Job(run, proc, last_generation(run.path), workers)


def stop_all(jobs: Sequence[Job], grace_s: float = STOP_GRACE_S) -> None:
    """SIGTERM to every running job; waits for it to commit (SIGTERM again after a grace)."""
    for j in jobs:
        if not j.poll():
            j.proc.send_signal(signal.SIGTERM)
    deadline = time.time() + grace_s
    while not all(j.poll() for j in jobs):
        if time.time() > deadline:
            for j in jobs:
                if not j.poll():
                    j.proc.send_signal(signal.SIGTERM)
            deadline = float("inf")
        time.sleep(0.5)


def _prepare(runs: Sequence[PlannedRun]) -> None:
    for folder in dict.fromkeys(r.folder for r in runs):
        (folder / "runs").mkdir(parents=True, exist_ok=True)
        ignore = folder / "runs" / ".gitignore"
        if not ignore.exists():
            ignore.write_text(_IGNORE)


def _finish_slice(
    jobs: list[Job], repo: Path, commit: str, options: GrowOptions, say: Callable[[str], None]
) -> set[str]:
    """Tidies, records and commits the runs of a slice; the names of those that failed."""
    failed = set()
    for job in jobs:
        tidy(job.run.path, options.keep_tests_every)
        record(job.sitting(), commit)
        if last_generation(job.run.path) < options.target(job.run) and job.status not in (0, 143):
            say(f"{job.name}: failed ({job.status}); see {job.run.path}.log")
            failed.add(job.name)
    if options.commit:
        for folder in dict.fromkeys(j.run.folder for j in jobs):
            moved = [f"{j.name} {j.start_gen}->{j.end_gen}" for j in jobs if j.run.folder == folder]
            try:
                msg = commit_runs(repo, folder / "runs", moved)
            except GrowError as exc:
                say(f"commit FAILED: {exc}")
                continue
            if msg:
                say(f"committed: {msg}")
    return failed


def grow(
    runs: Sequence[PlannedRun],
    options: GrowOptions,
    say: Callable[[str], None] = _LOG.info,
) -> int:
    """Grows ``runs`` for ``options.budget_min`` minutes (see the module docstring).

    Args:
        runs: The runs, in the order they grow (:meth:`~mtpg.growing.plan.Group.runs`).
        options: Budget, slices, threads and the rest.
        say: Where progress lines go (default: the ``mtpg`` logger).

    Returns:
        0, or 128 + the signal number when a signal stopped it.

    Raises:
        GrowError: The checkout is not clean or not in the repository's history, or a
            git command failed.
    """
    if not runs:
        return 0
    _prepare(runs)
    repo = repository_of(runs[0].folder)
    commit = "unchecked" if options.unchecked else source_commit(options.python, repo)
    stop: list[int] = []
    signals = (signal.SIGTERM, signal.SIGINT, signal.SIGHUP)
    before = {sig: signal.signal(sig, lambda s, _f: stop.append(s)) for sig in signals}
    try:
        _grow(runs, options, repo, commit, stop, say)
    finally:
        for sig, handler in before.items():
            signal.signal(sig, handler)
    return 128 + stop[0] if stop else 0


def _grow(
    plan: Sequence[PlannedRun],
    options: GrowOptions,
    repo: Path,
    commit: str,
    stop: list[int],
    say: Callable[[str], None],
) -> None:
    end = time.time() + 60 * options.budget_min
    failed: set[str] = set()
    all_threads = options.parallel * options.workers

    def unfinished() -> list[PlannedRun]:
        return [
            r for r in plan if r.name not in failed and last_generation(r.path) < options.target(r)
        ]

    say(f"mtpg {commit[:12]}; unfinished: {', '.join(r.name for r in unfinished()) or 'none'}")
    while unfinished() and not stop and time.time() < end:
        slice_end = min(end, time.time() + 60 * options.slice_min)
        todo, jobs, running = unfinished(), [], []
        while (todo or running) and not stop and time.time() < slice_end:
            while todo and len(running) < options.parallel:
                alone = len(todo) == 1 and not running
                run = todo.pop(0)
                job = start(run, options, all_threads if alone else options.workers)
                say(f"{job.name}: generation {job.start_gen} -> {options.target(run)}")
                jobs.append(job)
                running.append(job)
            for job in [j for j in running if j.poll()]:
                running.remove(job)
                say(f"{job.name}: ended ({job.status}) at {job.end_gen}")
                last = running[0] if len(running) == 1 and not todo else None
                if last and last.workers < all_threads and not last.poll() and began(last.run):
                    # the last run takes the threads of those that finished: it commits
                    # the generation under way and resumes on all of them (same run)
                    alone = running.pop()
                    stop_all([alone], options.stop_grace_s)
                    job = start(alone.run, options, all_threads)
                    say(f"{job.name}: on {all_threads} threads from {job.start_gen}")
                    jobs.append(job)
                    running.append(job)
            time.sleep(1)
        stop_all(running, options.stop_grace_s)
        failed |= _finish_slice(jobs, repo, commit, options, say)
