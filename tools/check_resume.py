"""Check that the committed runs of ``results/`` resume exactly from a fresh checkout.

The results page promises that ``mtpg train --resume results/runs/RUN`` continues any
committed run exactly. The repository's history keeps the evidence to test that promise
on the runs themselves: every commit of ``mtpg experiment --plan`` holds a run's newest
checkpoint, and a later commit holds the generations that followed it. For each run::

    .venv/bin/python tools/check_resume.py [RUN ...] [--generations K]

this script takes the newest commit whose checkpoint of the run (generation G) is older
than the run's last committed generation, writes the run as that commit holds it into an
empty folder (``git archive``, which is what a fresh clone of that commit holds), resumes
it with this interpreter's mtpg for K generations (default: up to the next test point,
so that test scores are checked too) and compares what it writes with the rows that
``HEAD`` holds for generations G+1 to G+K: ``metrics.csv`` in every column but the
timings, ``tests.csv`` value for value at the test points of the schedule. The
generations in ``HEAD`` were run by other processes, sittings and often other commits of
mtpg (``provenance.csv`` names them), so agreement shows that a resume from the
repository, with the code checked out now, repeats them. Exit status 1 when any run disagrees.

With ``--record`` each run's outcome replaces its row of ``results/resume_check.csv``
(run, the commit resumed from, generations, rows compared, result, the mtpg commit that
checked, when), which ``mtpg report --results`` shows on the results page.
"""

from __future__ import annotations

import argparse
import csv
import io
import subprocess
import sys
import tempfile
import tomllib
from datetime import UTC, datetime
from pathlib import Path

from mtpg.evolve.columns import TIMING_COLUMNS


def git(repo: Path, *args: str) -> str:
    """Runs git in ``repo`` and returns its standard output."""
    done = subprocess.run(["git", *args], cwd=repo, capture_output=True, text=True)
    if done.returncode != 0:
        raise SystemExit(f"check_resume: git {' '.join(args)}: {done.stderr.strip()}")
    return done.stdout


def rows(text: str, drop: frozenset[str] = frozenset()) -> dict[int, list[list[str]]]:
    """A CSV's rows by generation (first column), without the columns in ``drop``."""
    table = list(csv.reader(io.StringIO(text)))
    keep = [i for i, c in enumerate(table[0]) if c not in drop]
    out: dict[int, list[list[str]]] = {}
    for r in table[1:]:
        out.setdefault(int(r[0]), []).append([r[i] for i in keep])
    return out


def start_point(repo: Path, run: str, final: int) -> tuple[str, int] | None:
    """The newest commit holding a checkpoint of ``run`` older than ``final``, and its G."""
    folder = f"{run}/checkpoints"
    for commit in git(repo, "log", "--format=%H", "HEAD", "--", folder).split():
        names = git(repo, "ls-tree", "--name-only", commit, f"{folder}/").split()
        gens = [int(Path(n).name[4:10]) for n in names if Path(n).name.startswith("gen-")]
        if gens and max(gens) < final:
            return commit, max(gens)
    return None


def mtpg_commit() -> str:
    """The commit of the mtpg this interpreter imports (``+dirty`` with local changes)."""
    import mtpg

    top = Path(mtpg.__file__).parent
    commit = git(top, "rev-parse", "HEAD").strip()
    dirty = git(top, "status", "--porcelain", "--untracked-files=no", "--", ".").strip()
    return commit + ("+dirty" if dirty else "")


RECORD = "resume_check.csv"
RECORD_COLUMNS = (
    "run",
    "resumed_from_commit",
    "from_generation",
    "to_generation",
    "metrics_rows",
    "test_rows",
    "result",
    "mtpg_commit",
    "checked_utc",
)


def check(repo: Path, run: str, k: int | None, work: Path) -> dict[str, str] | None:
    """Resumes one run from its newest earlier commit and compares.

    Returns:
        The run's row for :data:`RECORD` (``result`` is ``equal`` or ``different``, or
        ``failed`` when the resume did not finish), or None when the run has no earlier
        committed checkpoint.
    """
    metrics_head = git(repo, "show", f"HEAD:{run}/metrics.csv")
    tests_head = git(repo, "show", f"HEAD:{run}/tests.csv")
    final = max(rows(metrics_head))
    found = start_point(repo, run, final)
    name = Path(run).name
    if found is None:
        print(f"{name}: no earlier committed checkpoint to resume from")
        return None
    commit, g = found
    config = tomllib.loads(git(repo, "show", f"{commit}:{run}/config.toml"))
    interval = int(config["evaluation"]["test_interval"])
    target = min(final, g + k if k else g + interval - g % interval)
    archive = subprocess.run(
        ["git", "archive", commit, run], cwd=repo, capture_output=True, check=True
    ).stdout
    subprocess.run(["tar", "-x", "-C", str(work)], input=archive, check=True)
    here = work / run
    argv = ["train", "--resume", str(here), "--generations", str(target)]
    done = subprocess.run(
        [sys.executable, "-m", "mtpg", *argv, "--workers", "1", "--quiet"],
        capture_output=True,
        text=True,
    )
    row = {"run": name, "resumed_from_commit": commit, "from_generation": str(g)}
    row |= {"to_generation": str(target), "mtpg_commit": mtpg_commit()}
    row["checked_utc"] = datetime.now(UTC).strftime("%Y-%m-%dT%H:%M:%SZ")
    if done.returncode != 0:
        print(f"{name}: mtpg train --resume failed: {done.stderr.strip()[-300:]}")
        return row | {"metrics_rows": "0", "test_rows": "0", "result": "failed"}
    span = range(g + 1, target + 1)
    timing = frozenset(TIMING_COLUMNS)
    new_m, old_m = rows((here / "metrics.csv").read_text(), timing), rows(metrics_head, timing)
    new_t, old_t = rows((here / "tests.csv").read_text()), rows(tests_head)
    # a run tests at its last generation too, so a resume that ends off the schedule has
    # test rows there that the committed run, which went on, does not
    scheduled = {x for x in span if x % interval == 0 or x == final}
    bad = [
        x
        for x in span
        if new_m.get(x) != old_m.get(x) or (x in scheduled and new_t.get(x) != old_t.get(x))
    ]
    tested = sum(len(old_t.get(x, [])) for x in scheduled)
    verdict = "EQUAL" if not bad else f"DIFFERENT at generations {bad}"
    print(
        f"{name}: resumed {g} -> {target} from {commit[:10]}: {verdict} "
        f"({len(span)} metrics rows, {tested} test rows compared)",
        flush=True,
    )
    result = "different" if bad else "equal"
    return row | {"metrics_rows": str(len(span)), "test_rows": str(tested), "result": result}


def record(path: Path, found: list[dict[str, str]]) -> None:
    """Replaces the checked runs' rows of the record at ``path`` (runs sorted by name)."""
    old = list(csv.DictReader(path.open())) if path.is_file() else []
    by_run = {r["run"]: r for r in old} | {r["run"]: r for r in found}
    with path.open("w", newline="") as f:
        writer = csv.DictWriter(f, RECORD_COLUMNS, lineterminator="\n")
        writer.writeheader()
        writer.writerows(by_run[k] for k in sorted(by_run))


def main(argv: list[str] | None = None) -> int:
    """Runs the script (see the module docstring)."""
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("runs", nargs="*", help="run names (default: every run in results/runs)")
    p.add_argument("--generations", type=int, default=None, help="K (next test point)")
    p.add_argument("--results", type=Path, default=Path("results"), help="folder (results)")
    p.add_argument("--record", action="store_true", help=f"write the outcomes to {RECORD}")
    args = p.parse_args(argv)
    results = args.results.resolve()
    repo = Path(git(results, "rev-parse", "--show-toplevel").strip())
    prefix = results.relative_to(repo) / "runs"
    names = args.runs or sorted(
        Path(n).parent.name for n in git(repo, "ls-files", "--", f"{prefix}/*/config.toml").split()
    )
    found = []
    for name in names:
        with tempfile.TemporaryDirectory() as work:
            row = check(repo, f"{prefix}/{name}", args.generations, Path(work))
        if row is not None:
            found.append(row)
            if args.record:  # after every run, so a stopped check keeps what it found
                record(results / RECORD, found)
    return 0 if all(r["result"] == "equal" for r in found) else 1


if __name__ == "__main__":
    sys.exit(main())
