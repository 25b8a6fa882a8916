"""The batch kernel of another commit against this one, alternated in one process.

Separate benchmark invocations on a shared virtual machine drift by 20% or more, which
hides the few percent a kernel change makes. This script imports the engine of commit REV
as a second package (``git archive`` of ``src/mtpg`` into a temporary folder, renamed
``mtpg_rev`` with its imports rewritten), builds the same seeded workload with each, and
plays it with each package's batch kernel in turn (ABBA order), ``--rounds`` times; each
play is timed by process CPU time, and the per-round ratio of the two times is reported
(median and quartiles). The outcomes of both (returns, steps, teams and instructions of
every job) must be identical, so both do the same work.

    python benchmarks/engine_ab.py 4094452                  # CartPole workload
    python benchmarks/engine_ab.py 4094452 --mixed          # the six tasks in turn

``--mixed`` replaces the workload's CartPole episodes by the six tasks in turn (pool row
``i`` plays task ``i % 6`` with the same seed). Run it with nothing else running: it
times one thread.
"""

from __future__ import annotations

import argparse
import dataclasses
import importlib
import importlib.util
import re
import statistics
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

import numpy as np

FIELDS = ("returns", "steps", "teams", "instructions")


def import_commit(rev: str, folder: Path):
    """Imports ``src/mtpg`` of commit ``rev`` as the package ``mtpg_rev``."""
    root = Path(__file__).resolve().parent.parent
    archive = folder / "src.tar"
    with archive.open("wb") as f:
        subprocess.run(["git", "archive", rev, "src/mtpg"], cwd=root, stdout=f, check=True)
    with tarfile.open(archive) as tar:
        tar.extractall(folder, filter="data")
    package = folder / "mtpg_rev"
    (folder / "src" / "mtpg").rename(package)
    for path in package.rglob("*.py"):
        text = path.read_text()
        text = re.sub(r"\bmtpg\.", "mtpg_rev.", text)
        text = re.sub(r"\bfrom mtpg import\b", "from mtpg_rev import", text)
        text = re.sub(r"^import mtpg$", "import mtpg_rev", text, flags=re.M)
        path.write_text(text)
    # imported from its folder by a spec, so that sys.path stays as it was; its
    # submodules are then found through the package's own __path__
    spec = importlib.util.spec_from_file_location(
        "mtpg_rev", package / "__init__.py", submodule_search_locations=[str(package)]
    )
    module = importlib.util.module_from_spec(spec)
    sys.modules["mtpg_rev"] = module
    spec.loader.exec_module(module)
    return "mtpg_rev"


def workload(name: str, graphs: int, mixed: bool):
    """The seeded benchmark workload built by package ``name``, and its ``drive``."""
    wl = importlib.import_module(f"{name}.bench.workload")
    work = wl.make_workload(graphs)
    if mixed:
        batch = importlib.import_module(f"{name}.engine.batch")
        tasks = np.arange(len(work.pool.seeds)) % 6
        work = dataclasses.replace(work, pool=batch.Episodes.make(tasks, work.pool.seeds))
    wl.drive(work)  # compile or load the kernels
    return work, wl.drive


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("rev", help="the other commit")
    ap.add_argument("--graphs", type=int, default=300, help="graphs (300)")
    ap.add_argument("--rounds", type=int, default=41, help="rounds (41)")
    ap.add_argument("--mixed", action="store_true", help="the six tasks in turn")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        names = (import_commit(args.rev, Path(tmp)), "mtpg")
        runs = {n: workload(n, args.graphs, args.mixed) for n in names}
        seconds = {n: [] for n in names}
        outcome = {}
        for r in range(args.rounds):
            for n in names if r % 2 == 0 else names[::-1]:
                work, drive = runs[n]
                done = drive(work)
                seconds[n].append(done.cpu_seconds)
                outcome.setdefault(n, done.result)
    a, b = (outcome[n] for n in names)
    if not all(np.array_equal(getattr(a, f), getattr(b, f)) for f in FIELDS):
        raise SystemExit("engine_ab: the two engines' outcomes differ")
    decisions = int(a.steps.sum())
    for n in names:
        speed = decisions / statistics.median(seconds[n]) / 1e6
        print(f"{n}: median {speed:.3f} M decisions/s")
    ratio = np.array(seconds[names[0]]) / np.array(seconds[names[1]])
    q1, q2, q3 = np.quantile(ratio, [0.25, 0.5, 0.75])
    print(
        f"this commit / {args.rev}: speed ratio median {q2:.3f} (quartiles {q1:.3f} to "
        f"{q3:.3f}) over {args.rounds} rounds of {decisions:,} decisions, outcomes identical"
    )


if __name__ == "__main__":
    from mtpg._kernel_cache import refresh

    refresh()  # before the first kernel: a Numba cache older than the sources goes
    main()
