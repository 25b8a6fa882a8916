"""Compare what two installs of mtpg write for the same run: a refactoring's byte check.

Each interpreter runs ``mtpg evaluate RUN --episodes 20 --json``, ``mtpg show RUN --dot``,
``mtpg report RUN`` and ``mtpg analyze RUN`` on a fresh copy of the run directory, always
at the same path (outputs may name it), and every file written is compared byte for
byte. The run directory itself is only read: it is copied first.

    python tools/compare_outputs.py --before OLD/bin/python --after .venv/bin/python
        RUN_DIR [--work /tmp/compare] [--repeat]

``--repeat`` runs the "before" interpreter twice and lists the files that already differ
between two runs of the same version (figures whose bytes carry a timestamp, say): a
difference there is not the refactoring's. The exit status is 0 when nothing else differs.
"""

from __future__ import annotations

import argparse
import filecmp
import shutil
import subprocess
import sys
from pathlib import Path

#: The commands, as ``(output name, arguments)``; ``RUN`` is the copy, ``OUT`` the outputs.
COMMANDS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("evaluate.json", ("evaluate", "RUN", "--episodes", "20", "--json")),
    ("show.txt", ("show", "RUN", "--dot", "OUT/show.dot")),
    ("report.txt", ("report", "RUN", "--out", "OUT/report")),
    ("analyze.txt", ("analyze", "RUN", "--episodes", "5", "--out", "OUT/analysis")),
)


def run_all(python: str, run: Path, work: Path, label: str) -> Path:
    """Runs every command with ``python`` on a fresh copy of ``run``; returns its outputs."""
    copy, out = work / "run", work / label
    shutil.rmtree(copy, ignore_errors=True)
    shutil.rmtree(out, ignore_errors=True)
    shutil.copytree(run, copy)
    out.mkdir(parents=True)
    for name, args in COMMANDS:
        argv = [a.replace("RUN", str(copy)).replace("OUT", str(out)) for a in args]
        done = subprocess.run(
            [python, "-m", "mtpg", *argv], capture_output=True, text=True, check=False
        )
        (out / name).write_text(done.stdout.replace(str(out), "OUT"))
        if done.returncode != 0:
            print(f"{label}: mtpg {' '.join(argv)} failed:\n{done.stderr}", file=sys.stderr)
    return out


def differing(a: Path, b: Path) -> list[str]:
    """Relative paths of files that differ, or exist on one side only."""
    names = {p.relative_to(a) for p in a.rglob("*") if p.is_file()}
    names |= {p.relative_to(b) for p in b.rglob("*") if p.is_file()}
    return sorted(
        str(n)
        for n in names
        if not ((a / n).is_file() and (b / n).is_file() and filecmp.cmp(a / n, b / n, False))
    )


def main() -> int:
    """Runs the comparison and prints the files that differ."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path, help="run directory (only read)")
    parser.add_argument("--before", required=True, help="python of the install before")
    parser.add_argument("--after", required=True, help="python of the install after")
    parser.add_argument("--work", type=Path, default=Path("/tmp/compare_outputs"))
    parser.add_argument("--repeat", action="store_true", help="run 'before' twice first")
    args = parser.parse_args()
    work = args.work / args.run.resolve().name
    before = run_all(args.before, args.run, work, "before")
    noise: set[str] = set()
    if args.repeat:
        again = run_all(args.before, args.run, work, "before-again")
        noise = set(differing(before, again))
        print(f"differ between two runs of 'before': {sorted(noise) or 'none'}")
    after = run_all(args.after, args.run, work, "after")
    files = sum(1 for p in before.rglob("*") if p.is_file())
    diff = differing(before, after)
    real = [d for d in diff if d not in noise]
    print(f"{files} files compared; differ: {diff or 'none'}")
    if noise and diff:
        print(f"differ beyond the repeat noise: {real or 'none'}")
    return 1 if real else 0


if __name__ == "__main__":
    sys.exit(main())
