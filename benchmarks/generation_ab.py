"""Whole generations of a committed run, this checkout against another, interleaved.

Resumes a copy of a committed run (default ``results/runs/TPG-seed3``, generation 1,000)
for ``--generations`` generations with each of two Python environments in turn (ABAB),
``--rounds`` times, each resume in a fresh copy of the run and timed by the CPU time of
its process (``resource.getrusage`` of the child: one thread, so CPU time is the work
done, whatever else the machine runs). The two resumes of a round must write the same
``metrics.csv`` rows (all but the timing columns) and the same ``tests.csv`` rows; the
script stops if they differ. It reports each side's CPU seconds per round and the median
of the per-round ratios.

    python benchmarks/generation_ab.py --baseline /path/to/old/.venv/bin/python \
        [--run results/runs/TPG-seed3] [--generations 10] [--rounds 3]

Make the baseline environment from the commit before a change with ``git worktree add``
and ``pip install -e`` in it. With ``--generations 10`` from a run at generation 1,000 the
resume includes two test points (every 5) and one commit (every 10), as a late
generation of a paper run does.
"""

from __future__ import annotations

import argparse
import csv
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

from mtpg.evolve.columns import TIMING_COLUMNS

ROOT = Path(__file__).resolve().parent.parent
TIMING = tuple(TIMING_COLUMNS)


def resume(
    python: str, run: Path, generations: int, folder: Path, extra: tuple[str, ...] = ()
) -> tuple[float, list, list]:
    """Resumes a fresh copy of ``run``; returns CPU seconds and the new rows."""
    copy = folder / run.name
    shutil.copytree(run, copy)
    last = _last_generation(copy / "metrics.csv")
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(
        [
            python,
            "-m",
            "mtpg.cli.main",
            "train",
            "--resume",
            str(copy),
            "--quiet",
            "--workers",
            "1",
            "--generations",
            str(last + generations),
            *extra,
        ],
        check=True,
    )
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return cpu, _rows(copy / "metrics.csv", last, TIMING), _rows(copy / "tests.csv", last, ())


def _last_generation(path: Path) -> int:
    with path.open() as f:
        return max(int(r[0]) for r in list(csv.reader(f))[1:])


def _rows(path: Path, after: int, drop: tuple[str, ...]) -> list[list[str]]:
    with path.open() as f:
        table = list(csv.reader(f))
    keep = [i for i, c in enumerate(table[0]) if c not in drop]
    return [[r[i] for i in keep] for r in table[1:] if int(r[0]) > after]


def main(argv: list[str] | None = None) -> int:
    """Runs the interleaved comparison; returns the exit status."""
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--baseline", required=True, help="python of the other environment")
    ap.add_argument("--current", default=sys.executable, help="python of this checkout")
    ap.add_argument("--run", default=str(ROOT / "results/runs/TPG-seed3"))
    ap.add_argument("--generations", type=int, default=10)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="SECTION.FIELD=VALUE",
        help="a resumable change passed to both resumes (e.g. checkpoint_interval=5)",
    )
    ap.add_argument(
        "--warm-up",
        action="store_true",
        help="first resume one generation with each side, untimed (compiles the kernels)",
    )
    args = ap.parse_args(argv)
    extra = [a for s in args.set for a in ("--set", s)]
    run = Path(args.run)
    if args.warm_up:
        for python in (args.baseline, args.current):
            with tempfile.TemporaryDirectory() as w:
                resume(python, run, 1, Path(w), tuple(extra))
    ratios = []
    for k in range(args.rounds):
        with tempfile.TemporaryDirectory() as a, tempfile.TemporaryDirectory() as b:
            base = resume(args.baseline, run, args.generations, Path(a), tuple(extra))
            cur = resume(args.current, run, args.generations, Path(b), tuple(extra))
        if base[1:] != cur[1:]:
            print(f"round {k + 1}: the two resumes wrote different rows", file=sys.stderr)
            return 1
        ratios.append(base[0] / cur[0])
        print(
            f"round {k + 1}: baseline {base[0]:.1f} s, current {cur[0]:.1f} s, "
            f"ratio {ratios[-1]:.3f} (rows identical: {len(cur[1])} metrics, {len(cur[2])} tests)",
            flush=True,
        )
    print(
        f"median ratio (baseline CPU / current CPU) over {len(ratios)} rounds: "
        f"{statistics.median(ratios):.3f}"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
