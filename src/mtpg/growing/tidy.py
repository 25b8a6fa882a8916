"""A grown run made fit to commit, and the provenance of its generations.

After each sitting a run keeps only its newest checkpoint (``mtpg train --resume`` needs
nothing else); ``champions/`` is packed into ``champions.tar.xz``, and of the test-point
graph folders ``tests/gen-NNNNNN/`` every :data:`KEEP_TESTS_EVERY`-th generation is
packed into ``tests/archive.tar.xz`` while the newest stays as it is (the report and the
analyses read it; ``tests.csv`` keeps every test point's scores). A row is appended to
its ``provenance.csv``: generations from/to, the mtpg commit that ran them, start time,
wall-clock and CPU seconds, workers, processor and host.
"""

from __future__ import annotations

import csv
import os
import platform
import shutil
import tarfile
import tempfile
from dataclasses import dataclass
from datetime import UTC, datetime
from pathlib import Path

__all__ = [
    "KEEP_TESTS_EVERY",
    "PACKED_CHAMPIONS",
    "PACKED_TESTS",
    "PROVENANCE",
    "PROVENANCE_COLUMNS",
    "Sitting",
    "last_generation",
    "processor",
    "record",
    "tidy",
]

#: Test-point folders kept: generations divisible by this, and the newest.
KEEP_TESTS_EVERY = 100
#: A run's provenance table.
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


def last_generation(run: Path) -> int:
    """Generation of the newest checkpoint of a run (0 when it has none)."""
    found = [int(p.name[4:10]) for p in (run / "checkpoints").glob("gen-??????.json.gz")]
    return max(found, default=0)


def processor() -> str:
    """The processor's model name (``/proc/cpuinfo``), or what ``platform`` says."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _pack(folder: Path, names: list[str], archive: Path) -> None:
    """Writes ``names`` (paths relative to ``folder``) into ``archive`` (tar, xz) atomically."""
    tmp = archive.with_name(archive.name + ".tmp")
    with tarfile.open(tmp, "w:xz") as tar:
        for name in sorted(names):
            tar.add(folder / name, arcname=name)
    os.replace(tmp, archive)


def tidy(run: Path, keep_tests_every: int | None = None) -> None:
    """Keeps the newest checkpoint and test folder; packs the champions and older tests.

    The 63 readable champion files of a run share most of their teams, so ``xz`` packs
    them about 80 times smaller: ``champions/`` becomes ``champions.tar.xz`` (a resume
    writes ``champions/`` anew from the checkpoint). Test folders of every
    ``keep_tests_every``-th generation go into ``tests/archive.tar.xz``; the newest stays
    a folder, as the report and the analyses read it.

    Args:
        run: The run directory.
        keep_tests_every: Test folders of generations divisible by this are archived
            (default: :data:`KEEP_TESTS_EVERY`).
    """
    every = KEEP_TESTS_EVERY if keep_tests_every is None else keep_tests_every
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
            if int(f.name[4:]) % every == 0:
                shutil.rmtree(Path(tmp) / f.name, ignore_errors=True)
                shutil.copytree(f, Path(tmp) / f.name)
        kept = [p.name for p in Path(tmp).iterdir() if int(p.name[4:]) % every == 0]
        _pack(Path(tmp), kept, archive)
    for f in old:
        shutil.rmtree(f)


@dataclass(frozen=True)
class Sitting:
    """What one ``mtpg train`` process did to a run: one row of its ``provenance.csv``.

    Attributes:
        run: The run directory.
        start_gen: Its newest checkpoint's generation when the process began.
        end_gen: Its newest checkpoint's generation when the process ended.
        started: Start time (seconds since the epoch).
        ended: End time (seconds since the epoch).
        cpu_s: The process's user and system time, seconds.
        workers: Threads it ran on.
    """

    run: Path
    start_gen: int
    end_gen: int
    started: float
    ended: float
    cpu_s: float
    workers: int


def record(sitting: Sitting, commit: str) -> None:
    """Appends a sitting's row to its run's ``provenance.csv`` (none if it added nothing).

    Args:
        sitting: What the process did.
        commit: The mtpg commit that ran it (``"unchecked"`` for trials).
    """
    if sitting.end_gen == sitting.start_gen:
        return
    path = sitting.run / PROVENANCE
    new = not path.exists()
    with open(path, "a", newline="") as f:
        w = csv.writer(f)
        if new:
            w.writerow(PROVENANCE_COLUMNS)
        started = datetime.fromtimestamp(sitting.started, UTC).strftime("%Y-%m-%dT%H:%M:%SZ")
        w.writerow(
            [
                sitting.start_gen,
                sitting.end_gen,
                commit,
                started,
                f"{sitting.ended - sitting.started:.0f}",
                f"{sitting.cpu_s:.0f}",
                sitting.workers,
                processor(),
                platform.node(),
            ]
        )
