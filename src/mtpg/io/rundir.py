"""The run directory: configuration, metrics, checkpoints and champion graphs.

Layout::

    RUN_DIR/format.json        the schema version of the directory (mtpg.io.runschema)
    RUN_DIR/config.toml        the resolved configuration of the run
    RUN_DIR/metrics.csv        one row per generation (fixed header)
    RUN_DIR/checkpoints/       gen-NNNNNN.json.gz (see mtpg.io.checkpoint)
    RUN_DIR/champions/         one graph file per task subset, e.g. CartPole+Acrobot.json
    RUN_DIR/.lock              held by the process writing the run (mtpg.io.lock)

A directory is an mtpg run directory when it holds ``config.toml`` and ``checkpoints/``.
"""

from __future__ import annotations

import csv
import hashlib
import io
import os
import re
import shutil
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mtpg._faults import point
from mtpg.envs.specs.compiled_task import is_compiled_name
from mtpg.envs.specs.contract import TASK_NAMES
from mtpg.envs.specs.gym_task import is_gym
from mtpg.io._atomic import atomic_write_bytes, is_temp_file
from mtpg.io.checkpoint import CHECKPOINT_DIR
from mtpg.io.lock import LOCK_FILE
from mtpg.io.runschema import SCHEMA_FILE, check_schema, stamp_schema, write_schema
from mtpg.io.serialize import load_graph, save_graph
from mtpg.model.graph import Population

CONFIG_FILE = "config.toml"
METRICS_FILE = "metrics.csv"
CHAMPION_DIR = "champions"
#: Test results of the champions, one row per task subset and test point.
TESTS_FILE = "tests.csv"
#: Graph files of the tested champions per test point: ``tests/gen-NNNNNN/``.
TESTS_DIR = "tests"


class RunDirError(ValueError):
    """A run directory cannot be used as asked; the message names it and says why."""


@dataclass(frozen=True)
class RunDir:
    """Paths of a run directory."""

    path: Path
    """The run directory itself."""

    @property
    def config(self) -> Path:
        """``config.toml``."""
        return self.path / CONFIG_FILE

    @property
    def metrics(self) -> Path:
        """``metrics.csv``."""
        return self.path / METRICS_FILE

    @property
    def checkpoints(self) -> Path:
        """``checkpoints/``."""
        return self.path / CHECKPOINT_DIR

    @property
    def champions(self) -> Path:
        """``champions/``."""
        return self.path / CHAMPION_DIR


def is_run_dir(path: str | os.PathLike[str]) -> bool:
    """True when ``path`` holds an mtpg run (``config.toml`` and ``checkpoints/``)."""
    run = RunDir(Path(path))
    return run.config.is_file() and run.checkpoints.is_dir()


#: What a run directory may hold: a directory of only these names and no checkpoint is a
#: run that committed nothing (or whose creation was interrupted), which may be restarted.
RUN_NAMES = frozenset(
    {
        SCHEMA_FILE,
        CONFIG_FILE,
        METRICS_FILE,
        CHECKPOINT_DIR,
        CHAMPION_DIR,
        LOCK_FILE,
        TESTS_FILE,
        TESTS_DIR,
    }
)


def _has_checkpoint(run: RunDir) -> bool:
    return run.checkpoints.is_dir() and any(
        e.name.startswith("gen-") and not is_temp_file(e.name) for e in run.checkpoints.iterdir()
    )


def check_new_run_dir(path: str | os.PathLike[str]) -> bool:
    """Checks, without changing anything, that a new run may be created in ``path``.

    Allowed are a missing or empty directory and one left by a run that committed
    nothing: an interrupted creation (no ``config.toml`` yet) or a run stopped before its
    first checkpoint, holding only the names a run writes (:data:`RUN_NAMES`).

    Returns:
        True when ``path`` holds such leftovers, which creation will clear.

    Raises:
        RunDirError: When ``path`` is a file, holds a run with a checkpoint or holds
            anything else.
    """
    run = RunDir(Path(path))
    if run.path.exists() and not run.path.is_dir():
        raise RunDirError(f"{run.path}: exists and is not a directory")
    if not run.path.exists():
        return False
    entries = sorted(e.name for e in run.path.iterdir())
    if run.config.is_file() and _has_checkpoint(run):  # a run, perhaps with its reports
        raise RunDirError(
            f"{run.path}: already holds an mtpg run; resume it (mtpg train --resume "
            f"{run.path}) or choose another directory"
        )
    foreign = [n for n in entries if n not in RUN_NAMES and not is_temp_file(n)]
    if foreign:
        shown = ", ".join(foreign[:5]) + (", ..." if len(foreign) > 5 else "")
        raise RunDirError(
            f"{run.path}: directory is not empty and is not an mtpg run directory "
            f"(contains {shown}); choose a new or empty directory"
        )
    if _has_checkpoint(run):
        raise RunDirError(
            f"{run.path}: already holds an mtpg run; resume it (mtpg train --resume "
            f"{run.path}) or choose another directory"
        )
    return bool(entries)


def _clear_leftovers(run: RunDir) -> None:
    """Removes what a run that committed nothing left behind (all but the lock file)."""
    for entry in run.path.iterdir():
        if entry.name == LOCK_FILE:
            continue
        if entry.is_dir() and not entry.is_symlink():
            shutil.rmtree(entry)
        else:
            entry.unlink()


def init_run_dir(
    path: str | os.PathLike[str], config_toml: str | None, resume: bool = False
) -> RunDir:
    """Creates a run directory, or opens an existing one to resume it.

    A new run needs a missing or empty directory, or one a run left without committing
    anything (see :func:`check_new_run_dir`; its leftovers are cleared). Creation writes
    ``checkpoints/``, ``champions/`` and ``format.json`` (the schema version) first and
    ``config.toml`` (atomically) last, so a directory is a run exactly when its creation
    completed. Resuming needs an existing run of a schema this mtpg reads (one without
    ``format.json`` gets it, see :mod:`mtpg.io.runschema`); its ``config.toml`` is
    replaced by ``config_toml`` when given (the caller checks that the change is
    compatible) and kept when ``config_toml`` is None.

    The caller holds the directory's lock (:mod:`mtpg.io.lock`) when other processes may
    use it.

    Args:
        path: The run directory.
        config_toml: The resolved configuration as TOML text (may be None on resume).
        resume: Continue the run already in ``path``.

    Returns:
        The run directory's paths.

    Raises:
        RunDirError: When ``path`` is a file, a non-empty directory that is not a run,
            already holds a run (and ``resume`` is False) or holds none (and ``resume``
            is True).
        RunSchemaError: On resume, when the run is of a schema this mtpg does not read.
    """
    run = RunDir(Path(path))
    if resume:
        check_resumable(run.path)
        check_schema(run.path)
    else:
        if config_toml is None:
            raise RunDirError(f"{run.path}: a new run needs its configuration")
        if check_new_run_dir(run.path):
            _clear_leftovers(run)
        run.path.mkdir(parents=True, exist_ok=True)
        point("create", 0)
    run.checkpoints.mkdir(exist_ok=True)
    run.champions.mkdir(exist_ok=True)
    if resume:
        stamp_schema(run.path)
    else:
        write_schema(run.path)
    if config_toml is not None:
        atomic_write_bytes(run.config, config_toml.encode("utf-8"))
    if not resume:
        point("created", 0)
    return run


def check_run(path: str | os.PathLike[str]) -> None:
    """Raises :class:`RunDirError` unless ``path`` holds an mtpg run, saying why.

    For commands that read a run (``report``, ``evaluate``, ...); ``mtpg train --resume``
    uses :func:`check_resumable`, whose messages speak of resuming.
    """
    run = RunDir(Path(path))
    if not run.path.exists():
        raise RunDirError(f"{run.path}: no such run directory")
    if not run.path.is_dir():
        raise RunDirError(f"{run.path}: exists and is not a directory")
    if is_run_dir(run.path):
        return
    names = [e.name for e in run.path.iterdir()]
    if names and not run.config.is_file():
        if all(n in RUN_NAMES or is_temp_file(n) for n in names):
            raise RunDirError(
                f"{run.path}: holds no mtpg run (its creation was interrupted before "
                f"{CONFIG_FILE} was written); start it again with mtpg train --out {run.path}"
            )
    missing = CONFIG_FILE if not run.config.is_file() else f"{CHECKPOINT_DIR}/"
    raise RunDirError(f"{run.path}: not an mtpg run directory (no {missing})")


def check_resumable(path: str | os.PathLike[str]) -> None:
    """Raises :class:`RunDirError` unless ``path`` holds a run to resume, saying why."""
    run = RunDir(Path(path))
    if run.path.exists() and not run.path.is_dir():
        raise RunDirError(f"{run.path}: exists and is not a directory")
    if is_run_dir(run.path):
        return
    if run.path.is_dir():
        names = [e.name for e in run.path.iterdir()]
        if names and all(n in RUN_NAMES or is_temp_file(n) for n in names):
            if run.config.is_file():
                return  # created, sub-directories missing: resuming completes it
            raise RunDirError(
                f"{run.path}: holds no mtpg run to resume (its creation was interrupted "
                f"before config.toml was written); start it again with mtpg train --out "
                f"{run.path}"
            )
    raise RunDirError(f"{run.path}: holds no mtpg run to resume")


def roll_back(path: str | os.PathLike[str], generation: int) -> list[Path]:
    """Removes what a run wrote after ``generation`` besides rows: test folders, temp files.

    Test folders ``tests/gen-NNNNNN`` of later generations go, and temporary files of
    interrupted atomic writes anywhere in the run. (Rows are truncated by
    :meth:`MetricsWriter.truncate_after`; champions are rewritten from the state.)

    Returns:
        The paths removed.
    """
    run = RunDir(Path(path))
    removed = []
    tests = run.path / TESTS_DIR
    folders = [run.path, run.checkpoints, run.champions, tests]
    if tests.is_dir():
        for entry in sorted(tests.iterdir()):
            if entry.is_dir() and entry.name.startswith("gen-"):
                try:
                    gen = int(entry.name[4:])
                except ValueError:
                    continue
                if gen > generation:
                    shutil.rmtree(entry)
                    removed.append(entry)
                else:
                    folders.append(entry)
    for folder in folders:
        if folder.is_dir():
            for entry in folder.iterdir():
                if is_temp_file(entry.name) and entry.is_file():
                    entry.unlink()
                    removed.append(entry)
    return removed


class MetricsWriter:
    """Appends rows to a CSV file with a fixed header, flushing each row.

    An existing file is reopened for appending when its header matches; a partial last
    line left by a crash is dropped. A missing or empty file is started with the header.

    Args:
        path: The CSV file.
        header: Column names, in order.
        generation_key: The column :meth:`truncate_after` reads.

    Raises:
        RunDirError: When an existing file has a different header.
    """

    def __init__(
        self,
        path: str | os.PathLike[str],
        header: Sequence[str],
        generation_key: str = "generation",
    ) -> None:
        self.path = Path(path)
        self.header = tuple(header)
        self.generation_key = generation_key
        if len(set(self.header)) != len(self.header) or not self.header:
            raise ValueError(f"header must be non-empty without repeats, got {self.header}")
        text = self.path.read_text(encoding="utf-8") if self.path.exists() else ""
        if text:
            found = next(csv.reader(io.StringIO(text)), [])
            if tuple(found) != self.header:
                raise RunDirError(
                    f"{self.path}: header {found} does not match the expected {list(self.header)}"
                )
            if not text.endswith("\n"):  # keep whole lines only (the header at least)
                whole = text[: text.rfind("\n") + 1]
                self._rewrite(whole or self._render([self.header]))
        else:
            self._rewrite(self._render([self.header]))
        self._fh = open(self.path, "a", encoding="utf-8", newline="")
        self._writer = csv.writer(self._fh, lineterminator="\n")

    @staticmethod
    def _render(rows: Iterable[Sequence[Any]]) -> str:
        buf = io.StringIO()
        csv.writer(buf, lineterminator="\n").writerows(rows)
        return buf.getvalue()

    def _rewrite(self, text: str) -> None:
        atomic_write_bytes(self.path, text.encode("utf-8"))

    def append(self, row: Mapping[str, Any]) -> None:
        """Writes one row and flushes it.

        Args:
            row: A value for every column of the header and no other key.

        Raises:
            ValueError: When keys are missing or unknown.
        """
        missing = [k for k in self.header if k not in row]
        extra = [k for k in row if k not in self.header]
        if missing or extra:
            raise ValueError(f"{self.path}: row is missing {missing} / has unknown {extra}")
        self._writer.writerow([row[k] for k in self.header])
        self._fh.flush()

    def rows(self) -> list[dict[str, str]]:
        """The rows written so far, as strings keyed by column."""
        self._fh.flush()
        with open(self.path, encoding="utf-8", newline="") as fh:
            return list(csv.DictReader(fh))

    def truncate_after(self, generation: int) -> int:
        """Drops the rows of generations after ``generation`` (and malformed rows).

        Used on resume from the checkpoint of ``generation``; the file is rewritten
        atomically.

        Args:
            generation: Last generation to keep.

        Returns:
            Number of rows dropped.

        Raises:
            RunDirError: When the header has no generation column.
        """
        if self.generation_key not in self.header:
            raise RunDirError(f"{self.path}: no {self.generation_key!r} column to truncate on")
        col = self.header.index(self.generation_key)
        self._fh.close()
        with open(self.path, encoding="utf-8", newline="") as fh:
            body = list(csv.reader(fh))[1:]
        kept = []
        for row in body:
            try:
                if len(row) == len(self.header) and int(row[col]) <= generation:
                    kept.append(row)
            except ValueError:
                pass
        self._rewrite(self._render([self.header, *kept]))
        self._fh = open(self.path, "a", encoding="utf-8", newline="")
        self._writer = csv.writer(self._fh, lineterminator="\n")
        return len(body) - len(kept)

    def close(self) -> None:
        """Closes the file."""
        self._fh.close()

    def __enter__(self) -> MetricsWriter:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def canonical_tasks(task_names: Iterable[str]) -> tuple[str, ...]:
    """Sorts task names into canonical (task id) order, checking them.

    Raises:
        ValueError: For an empty set, an unknown name or a repeat.
    """
    from mtpg.envs.taskset.variants import canonical, order_key

    names = tuple(task_names)
    unknown = []
    for t in names:
        try:
            known = canonical(t) == t
        except ValueError:
            known = False
        if not known:
            unknown.append(t)
    if not names or unknown or len(set(names)) != len(names):
        raise ValueError(
            f"task set {names} must be non-empty, without repeats, from {', '.join(TASK_NAMES)}"
            " or their variants"
        )
    return tuple(sorted(names, key=order_key))


#: Longest champion file name written (bytes): file systems allow 255, and the atomic
#: writer adds a leading dot and a temporary suffix.
MAX_FILENAME = 200


def split_subset(text: str) -> list[str]:
    """The task names of a subset written ``A+B+C``.

    A ``+`` inside a variant's brackets (``Pendulum[observe=cos(theta)+sin(theta)]``) does
    not split.
    """
    names, depth, start = [], 0, 0
    for i, c in enumerate(text):
        depth += (c == "[") - (c == "]")
        if c == "+" and depth == 0:
            names.append(text[start:i])
            start = i + 1
    names.append(text[start:])
    return names


def _digest(text: str, n: int) -> str:
    return hashlib.sha256(text.encode()).hexdigest()[:n]


def file_safe(task: str) -> str:
    """A task name as a file name may hold it.

    A ``gym:`` or compiled (``module:ATTR``) name's colons, slashes and quotes become ``_``
    (the file's ``tasks`` entry keeps the name itself).
    """
    if is_gym(task) or is_compiled_name(task):
        return re.sub(r"[^A-Za-z0-9._\-\[\]=;()+,]", "_", task)
    return task


def champion_filename(task_names: tuple[str, ...]) -> str:
    """File name of the champion of a task subset: tasks in canonical order joined by "+".

    Example: ``("Acrobot", "CartPole")`` gives ``"CartPole+Acrobot.json"``. A name longer
    than :data:`MAX_FILENAME` bytes (long variant names) writes each variant as its base
    and a hash of its name (``MountainCar[1f0c2e9a]``), and if that is still too long the
    subset as ``6-tasks-HASH.json``; the file's ``tasks`` entry names the subset in full
    (:func:`read_champions` reads it back).
    """
    tasks = tuple(file_safe(t) for t in canonical_tasks(task_names))
    full = "+".join(tasks) + ".json"
    if len(full.encode()) <= MAX_FILENAME:
        return full
    short = "+".join(t if "[" not in t else f"{t.split('[')[0]}[{_digest(t, 8)}]" for t in tasks)
    if len(short.encode()) + 5 <= MAX_FILENAME:
        return short + ".json"
    return f"{len(tasks)}-tasks-{_digest(full, 16)}.json"


def write_champions(
    run_dir: str | os.PathLike[str],
    champions: Mapping[tuple[str, ...], tuple[Population, int, dict[str, Any] | None]],
) -> list[Path]:
    """Writes one graph file per task subset into ``RUN_DIR/champions/``.

    Each file's meta gets ``"tasks"`` (the subset, canonical order) unless it has one.

    Args:
        run_dir: The run directory.
        champions: ``task subset -> (population, root team id, meta)``.

    Returns:
        The files written.
    """
    directory = RunDir(Path(run_dir)).champions
    directory.mkdir(parents=True, exist_ok=True)
    written = []
    bodies: dict = {}  # each distinct champion rendered once (one population per call)
    for tasks, (pop, root, meta) in champions.items():
        path = directory / champion_filename(tasks)
        meta = {"tasks": list(canonical_tasks(tasks)), **(meta or {})}
        save_graph(path, pop, root, meta, bodies.setdefault(id(pop), {}))
        written.append(path)
    return written


def read_champions(
    run_dir: str | os.PathLike[str],
) -> dict[tuple[str, ...], tuple[Population, int, dict[str, Any]]]:
    """Loads the champion graph files of a run, keyed by task subset (canonical order)."""
    directory = RunDir(Path(run_dir)).champions
    out: dict[tuple[str, ...], tuple[Population, int, dict[str, Any]]] = {}
    if not directory.is_dir():
        return out
    for path in sorted(directory.glob("*.json")):
        try:
            tasks = canonical_tasks(split_subset(path.stem))
        except ValueError:  # a shortened name (long variants), or not a champion file
            try:
                graph = load_graph(path)
                tasks = canonical_tasks(graph[2]["tasks"])
            except (ValueError, KeyError, TypeError):
                continue
            if champion_filename(tasks) == path.name:
                out[tasks] = graph
            continue
        out[tasks] = load_graph(path)
    return out
