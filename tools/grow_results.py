"""Grow the committed runs of ``results/`` for a wall-clock budget, then commit them.

The paper's experiment (five seeds of the ``paper`` preset and one seed of each ablation,
1,000 generations each) takes longer than one sitting on a small machine, so its runs
grow over many sittings, machines and commits. Each call of this script::

    .venv/bin/python tools/grow_results.py --budget 150          # minutes

continues the unfinished runs of :data:`PLAN` (or, with ``--plan robust``, of
:data:`ROBUST_PLAN` beside them, ``--plan authors`` of :data:`AUTHORS_PLAN`; with
``--plan demo``, of :data:`DEMO_PLAN` in ``results/candidates``, ``--plan variants`` of
:data:`VARIANTS_PLAN` in ``results/variants``) in order, ``--parallel`` at a time, each an
ordinary ``mtpg train --resume`` process (``mtpg train --out`` for a run not begun) on
``--workers`` threads. The last run left takes the threads of the runs that finished
(``--parallel`` times ``--workers``): it commits the generation under way and resumes on
all of them, the same run, since results do not depend on the thread count. Every
``--slice`` minutes, and when the budget is spent or the script is stopped (SIGTERM,
SIGINT, SIGHUP), the runs are sent SIGTERM, so each commits the generation under way and
ends; then every run touched is tidied for the repository and committed with git:

* only its newest checkpoint is kept (``mtpg train --resume`` needs nothing else);
* ``champions/`` is packed into ``champions.tar.xz``, and of the test-point graph folders
  ``tests/gen-NNNNNN/`` every :data:`KEEP_TESTS_EVERY`-th generation is packed into
  ``tests/archive.tar.xz`` and the newest is kept as it is (the report and the analyses
  read it; ``tests.csv`` keeps every test point's scores);
* a row is appended to its ``provenance.csv``: generations from/to, the mtpg commit that
  ran them, start time, wall-clock and CPU seconds, workers, processor and host.

The mtpg that runs is the one installed for ``--python`` (default: this interpreter). It
must be a clean git checkout whose commit is in this repository's history, so that the
commit recorded reproduces the generations exactly; ``tests/evolve/test_paper_pin.py``
guards that later commits keep resuming them exactly.
"""

from __future__ import annotations

import argparse
import csv
import os
import platform
import shutil
import signal
import subprocess
import sys
import tarfile
import tempfile
import time
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path

#: The experiment: (run directory name, seed, ablation flag or None).
PLAN: tuple[tuple[str, int, str | None], ...] = (
    *((f"TPG-seed{s}", s, None) for s in range(1, 6)),
    ("TPG-NoXover-seed1", 1, "no-crossover"),
    ("TPG-NoMemory-seed1", 1, "no-memory"),
    ("TPG-NoHierarchy-seed1", 1, "no-hierarchy"),
)
#: TPG-robust at the paper's scale (issue 40, item 2): the ``robust`` preset (``paper`` with
#: the training episodes redrawn every 10 generations), seeds 1 to 5, beside the TPG runs
#: in ``results/runs`` (``--plan robust``).
ROBUST_PLAN: tuple[tuple[str, int, str | None], ...] = tuple(
    (f"TPG-robust-seed{s}", s, None) for s in range(1, 6)
)
#: The demo-scale candidates for the memorisation study (issue 40): six tasks, 1,000
#: generations, five seeds of ``demo`` as it is and with the training episodes redrawn
#: every 10 generations (``robust``'s rule), in ``results/candidates`` (``--plan demo``).
DEMO_PLAN: tuple[tuple[str, int, str | None], ...] = tuple(
    run
    for s in range(1, 6)  # seed by seed, so that the pairs to compare grow together
    for run in ((f"demo-seed{s}", s, None), (f"demo-resample10-seed{s}", s, "resample10"))
)
#: The interface study (issue 40, item 3, docs/variants-study.md): CartCentering +
#: MountainCar with the paper's interface and with the authors' code's, and the six tasks
#: with the authors' (the six with the paper's are the candidates' ``demo-seedN``), seeds
#: 1 to 3 of ``demo``, 1,000 generations, in ``results/variants`` (``--plan variants``).
VARIANTS_PLAN: tuple[tuple[str, int, str | None], ...] = tuple(
    run
    for s in range(1, 4)
    for run in (
        (f"ccmc-paper-seed{s}", s, "ccmc-paper"),
        (f"ccmc-authors-seed{s}", s, "ccmc-authors"),
        (f"six-authors-seed{s}", s, "six-authors"),
    )
)
#: The authors' code's observation interface, as variants of the paper's tasks
#: (../shared/reference/tpg-cpp-anchors.md, section 2: MountainCar's position in [0, 1] and
#: U[-pi, pi] noise, unnormalised; CartCentering's noise U[-pi, pi]/pi; Pendulum observing
#: cos and sin of its angle, 300 steps).
AUTHORS_TASKS = {
    "CartPole": "CartPole",
    "Acrobot": "Acrobot",
    "CartCentering": "CartCentering[noise_high=1;noise_low=-1]",
    "Pendulum": "Pendulum[max_steps=300;observe=cos(theta)+sin(theta)]",
    "MountainCar": "MountainCar[noise_high=pi;noise_low=-pi;obs_high=1;obs_low=0]",
    "MountainCarContinuous": (
        "MountainCarContinuous[noise_high=pi;noise_low=-pi;obs_high=1;obs_low=0]"
    ),
}
#: TPG-authors at the paper's scale (issue 52, item 1): the ``paper`` preset (fixed training
#: episodes, as the authors' code also has them) on the six tasks with the interface of the
#: authors' code (:data:`AUTHORS_TASKS`), seeds 1 to 5, beside TPG and TPG-robust in
#: ``results/runs`` (``--plan authors``).
AUTHORS_PLAN: tuple[tuple[str, int, str | None], ...] = tuple(
    (f"TPG-authors-seed{s}", s, "six-authors") for s in range(1, 6)
)
#: Each plan: its preset, and where its runs go unless ``--results`` says otherwise.
PLANS = {
    "paper": ("paper", "results"),
    "robust": ("robust", "results"),
    "authors": ("paper", "results"),
    "demo": ("demo", "results/candidates"),
    "variants": ("demo", "results/variants"),
}


def plan_runs(plan: str) -> tuple[tuple[str, int, str | None], ...]:
    """The runs of a plan (looked up when called, so tests may replace a plan)."""
    plans = {
        "paper": PLAN,
        "robust": ROBUST_PLAN,
        "authors": AUTHORS_PLAN,
        "demo": DEMO_PLAN,
        "variants": VARIANTS_PLAN,
    }
    return plans[plan]


#: What a plan entry's variant adds to ``mtpg train`` (any other: ``--VARIANT``).
VARIANT_ARGS = {
    "resample10": ["--set", "evaluation.resample_interval=10"],
    "ccmc-paper": ["--tasks", "CartCentering,MountainCar"],
    "ccmc-authors": [
        "--tasks",
        ",".join(AUTHORS_TASKS[t] for t in ("CartCentering", "MountainCar")),
    ],
    "six-authors": ["--tasks", ",".join(AUTHORS_TASKS.values())],
}
#: Test-point folders kept: generations divisible by this, and the newest.
KEEP_TESTS_EVERY = 100
#: Seconds a run is given to commit after SIGTERM before it is told to stop at once.
STOP_GRACE_S = 300
PROVENANCE = "provenance.csv"
#: The packed champion files and test-point folders of a run (see :func:`tidy`).
PACKED_CHAMPIONS = "champions.tar.xz"
PACKED_TESTS = "archive.tar.xz"
PROVENANCE_COLUMNS = (
    "from_generation",
    "to_generation",
    "mtpg_commit",
    "started_utc",
    "wall_s",
    "cpu_s",
    "workers",
    "processor",
    "host",
)


def sh(*cmd: str, cwd: Path | None = None, check: bool = True) -> str:
    """Runs a command and returns its standard output, stripped."""
    done = subprocess.run(cmd, cwd=cwd, capture_output=True, text=True)
    if check and done.returncode != 0:
        raise SystemExit(f"grow_results: {' '.join(cmd)}: {done.stderr.strip()}")
    return done.stdout.strip()


def processor() -> str:
    """The processor's model name (``/proc/cpuinfo``), or what ``platform`` says."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def source_commit(python: str, repo: Path) -> str:
    """The commit of the mtpg that ``python`` imports; refuses a dirty or foreign tree."""
    init = sh(python, "-c", "import mtpg; print(mtpg.__file__)")
    top = Path(sh("git", "rev-parse", "--show-toplevel", cwd=Path(init).parent))
    dirty = sh("git", "status", "--porcelain", "--untracked-files=no", "--", "src", cwd=top)
    if dirty:
        raise SystemExit(f"grow_results: {top} has uncommitted changes in src/:\n{dirty}")
    commit = sh("git", "rev-parse", "HEAD", cwd=top)
    known = subprocess.run(["git", "merge-base", "--is-ancestor", commit, "HEAD"], cwd=repo)
    if known.returncode != 0:
        raise SystemExit(f"grow_results: mtpg commit {commit[:12]} is not in {repo}'s history")
    return commit


def last_generation(run: Path) -> int:
    """Generation of the newest checkpoint of a run (0 when it has none)."""
    found = [int(p.name[4:10]) for p in (run / "checkpoints").glob("gen-??????.json.gz")]
    return max(found, default=0)


@dataclass
class Job:
    """One ``mtpg train`` process growing one run."""

    name: str
    path: Path
    proc: subprocess.Popen
    start_gen: int
    workers: int = 1
    started: float = field(default_factory=time.time)
    status: int | None = None
    cpu_s: float = 0.0
    end_gen: int = 0
    ended: float = 0.0

    def poll(self) -> bool:
        """True once the process has ended (its status and CPU time then recorded)."""
        if self.status is None:
            pid, status, usage = os.wait4(self.proc.pid, os.WNOHANG)
            if pid:
                self.status = os.waitstatus_to_exitcode(status)
                self.proc.returncode = self.status
                self.cpu_s = usage.ru_utime + usage.ru_stime
                self.end_gen = last_generation(self.path)
                self.ended = time.time()
        return self.status is not None


def start(
    name: str, seed: int, ablation: str | None, args: argparse.Namespace, workers: int = 0
) -> Job:
    """Starts (or resumes) one run of the plan, on ``workers`` threads (``--workers``)."""
    path = args.results / "runs" / name
    workers = workers or args.workers
    common = ["--generations", str(args.generations), "--workers", str(workers), "--quiet"]
    if (path / "config.toml").is_file():
        cmd = ["train", "--resume", str(path), *common]
    else:
        flag = VARIANT_ARGS.get(ablation, [f"--{ablation}"]) if ablation else []
        preset = PLANS[args.plan][0]
        cmd = ["train", "--preset", preset, "--seed", str(seed), *flag, *common]
        cmd += [*args.train_arg, "--out", str(path)]
    log = open(args.results / "runs" / f"{name}.log", "a")
    proc = subprocess.Popen(
        [args.python, "-m", "mtpg", *cmd],
        stdout=log,
        stderr=subprocess.STDOUT,
        start_new_session=True,
    )
    return Job(name, path, proc, last_generation(path), workers)


def began(job: Job) -> bool:
    """True once the job's run can be resumed (its ``config.toml`` is written)."""
    return (job.path / "config.toml").is_file()


def _pack(folder: Path, names: list[str], archive: Path) -> None:
    """Writes ``names`` (paths relative to ``folder``) into ``archive`` (tar, xz) atomically."""
    tmp = archive.with_name(archive.name + ".tmp")
    with tarfile.open(tmp, "w:xz") as tar:
        for name in sorted(names):
            tar.add(folder / name, arcname=name)
    os.replace(tmp, archive)


def tidy(run: Path) -> None:
    """Keeps the newest checkpoint and test folder; packs the champions and older tests.

    The 63 readable champion files of a run share most of their teams, so ``xz`` packs
    them about 80 times smaller: ``champions/`` becomes ``champions.tar.xz`` (a resume
    writes ``champions/`` anew from the checkpoint). Test folders of every
    ``KEEP_TESTS_EVERY``-th generation go into ``tests/archive.tar.xz``; the newest stays
    a folder, as the report and the analyses read it.
    """
    ckpts = sorted((run / "checkpoints").glob("gen-*"))
    for extra in ckpts[:-1]:
        extra.unlink()
    newest = last_generation(run)
    champions = run / "champions"
    if champions.is_dir() and any(champions.iterdir()):
        _pack(run, [f"champions/{p.name}" for p in champions.iterdir()], run / PACKED_CHAMPIONS)
        shutil.rmtree(champions)
    tests = run / "tests"
    folders = [f for f in sorted(tests.glob("gen-??????")) if int(f.name[4:]) <= newest]
    archive = tests / PACKED_TESTS
    old = folders[:-1]
    if not old:
        return
    with tempfile.TemporaryDirectory(dir=tests) as tmp:
        if archive.exists():
            with tarfile.open(archive) as tar:
                tar.extractall(tmp, filter="data")
        for f in old:
            if int(f.name[4:]) % KEEP_TESTS_EVERY == 0:
                shutil.rmtree(Path(tmp) / f.name, ignore_errors=True)
                shutil.copytree(f, Path(tmp) / f.name)
        kept = [p.name for p in Path(tmp).iterdir() if int(p.name[4:]) % KEEP_TESTS_EVERY == 0]
        _pack(Path(tmp), kept, archive)
    for f in old:
        shutil.rmtree(f)


def record(job: Job, commit: str) -> None:
    """Appends the ended job's row to its run's ``provenance.csv``."""
    end = job.end_gen
    if end == job.start_gen:
        return
    path = job.path / PROVENANCE
    new = not path.exists()
    with open(path, "a", newline="") as f:
        w = csv.writer(f)
        if new:
            w.writerow(PROVENANCE_COLUMNS)
        started = datetime.fromtimestamp(job.started, UTC).strftime("%Y-%m-%dT%H:%M:%SZ")
        wall = job.ended - job.started
        host = platform.node()
        w.writerow(
            [
                job.start_gen,
                end,
                commit,
                started,
                f"{wall:.0f}",
                f"{job.cpu_s:.0f}",
                job.workers,
                processor(),
                host,
            ]
        )


def commit_results(repo: Path, results: Path, jobs: list[Job]) -> None:
    """Commits ``results/runs`` (and nothing else that may be staged)."""
    moved = [f"{j.name} {j.start_gen}->{j.end_gen}" for j in jobs]
    runs = str((results / "runs").relative_to(repo))
    # run logs and lock files stay out, whatever the repository's ignore rules
    sh("git", "add", "-A", "--", runs, f":!{runs}/*.log", f":!{runs}/*/.lock", cwd=repo)
    if not sh("git", "status", "--porcelain", "--", runs, cwd=repo):
        return
    msg = "results: grow " + ", ".join(moved) + " (generations committed by the runs)"
    done = subprocess.run(["git", "commit", "-q", "-m", msg, "--", runs], cwd=repo)
    print(("committed: " if done.returncode == 0 else "commit FAILED: ") + msg, flush=True)


def stop_all(jobs: list[Job]) -> None:
    """SIGTERM to every running job; waits for it to commit (SIGTERM again after a grace)."""
    for j in jobs:
        if not j.poll():
            j.proc.send_signal(signal.SIGTERM)
    deadline = time.time() + STOP_GRACE_S
    while not all(j.poll() for j in jobs):
        if time.time() > deadline:
            for j in jobs:
                if not j.poll():
                    j.proc.send_signal(signal.SIGTERM)
            deadline = float("inf")
        time.sleep(0.5)


def main(argv: list[str] | None = None) -> int:
    """Runs the script (see the module docstring)."""
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--budget", type=float, required=True, help="minutes of wall-clock time")
    p.add_argument("--slice", type=float, default=40, help="minutes between commits (40)")
    p.add_argument("--parallel", type=int, default=2, help="runs at a time (2)")
    p.add_argument("--workers", type=int, default=1, help="threads per run (1)")
    p.add_argument("--generations", type=int, default=1000, help="target (1000)")
    p.add_argument("--python", default=sys.executable, help="interpreter whose mtpg runs")
    p.add_argument(
        "--plan",
        choices=sorted(PLANS),
        default="paper",
        help="the paper's experiment (paper), TPG-robust (robust), TPG-authors (authors), "
        "the demo-scale candidates (demo) or the interface study (variants)",
    )
    p.add_argument(
        "--results", type=Path, default=None, help="folder (results; demo: results/candidates)"
    )
    p.add_argument("--no-commit", action="store_true", help="tidy and record, commit nothing")
    p.add_argument(
        "--train-arg",
        action="append",
        default=[],
        metavar="ARG",
        help="extra mtpg train argument for runs begun now (tests and trials only)",
    )
    p.add_argument(
        "--unchecked",
        action="store_true",
        help="skip the clean-checkout checks (trials only; provenance then says so)",
    )
    args = p.parse_args(argv)
    args.results = (args.results or Path(PLANS[args.plan][1])).resolve()
    plan = plan_runs(args.plan)
    args.results.mkdir(parents=True, exist_ok=True)
    repo = Path(sh("git", "rev-parse", "--show-toplevel", cwd=args.results))
    commit = "unchecked" if args.unchecked else source_commit(args.python, repo)
    (args.results / "runs").mkdir(parents=True, exist_ok=True)
    ignore = args.results / "runs" / ".gitignore"
    if not ignore.exists():
        ignore.write_text(
            "# written by tools/grow_results.py: run logs and run locks\n*.log\n*/.lock\n"
        )
    stop: list[int] = []
    for sig in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
        signal.signal(sig, lambda s, _f: stop.append(s))
    end = time.time() + 60 * args.budget
    failed: set[str] = set()
    by_name = {r[0]: r for r in plan}
    all_threads = args.parallel * args.workers

    def unfinished() -> list[tuple[str, int, str | None]]:
        runs = args.results / "runs"
        return [
            r
            for r in plan
            if r[0] not in failed and last_generation(runs / r[0]) < args.generations
        ]

    print(f"mtpg {commit[:12]}; unfinished: {', '.join(r[0] for r in unfinished()) or 'none'}")
    while unfinished() and not stop and time.time() < end:
        slice_end, todo, jobs, running = (
            min(end, time.time() + 60 * args.slice),
            unfinished(),
            [],
            [],
        )
        while (todo or running) and not stop and time.time() < slice_end:
            while todo and len(running) < args.parallel:
                alone = len(todo) == 1 and not running
                job = start(*todo.pop(0), args, all_threads if alone else args.workers)
                print(f"{job.name}: generation {job.start_gen} -> {args.generations}", flush=True)
                jobs.append(job)
                running.append(job)
            for job in [j for j in running if j.poll()]:
                running.remove(job)
                print(f"{job.name}: ended ({job.status}) at {job.end_gen}")
                last = running[0] if len(running) == 1 and not todo else None
                if last and last.workers < all_threads and not last.poll() and began(last):
                    # the last run takes the threads of those that finished: it commits
                    # the generation under way and resumes on all of them (same run)
                    alone = running.pop()
                    stop_all([alone])
                    job = start(*by_name[alone.name], args, all_threads)
                    print(f"{job.name}: on {all_threads} threads from {job.start_gen}", flush=True)
                    jobs.append(job)
                    running.append(job)
            time.sleep(1)
        stop_all(running)
        for job in jobs:
            tidy(job.path)
            record(job, commit)
            if last_generation(job.path) < args.generations and job.status not in (0, 143):
                print(f"{job.name}: failed ({job.status}); see {job.path}.log", flush=True)
                failed.add(job.name)
        if not args.no_commit:
            commit_results(repo, args.results, jobs)
    return 128 + stop[0] if stop else 0


if __name__ == "__main__":
    sys.exit(main())
