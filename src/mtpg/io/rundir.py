"""The run directory: configuration, metrics, checkpoints and champion graphs.

Layout::

    RUN_DIR/config.toml        the resolved configuration of the run
    RUN_DIR/metrics.csv        one row per generation (fixed header)
    RUN_DIR/checkpoints/       gen-NNNNNN.json.gz (see mtpg.io.checkpoint)
    RUN_DIR/champions/         one graph file per task subset, e.g. CartPole+Acrobot.json

A directory is an mtpg run directory when it holds ``config.toml`` and ``checkpoints/``.
"""

from __future__ import annotations

import csv
import io
import os
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from mtpg.envs.core import TASK_NAMES
from mtpg.io._atomic import atomic_write_bytes
from mtpg.io.checkpoint import CHECKPOINT_DIR
from mtpg.io.serialize import load_graph, save_graph
from mtpg.model.graph import Population

CONFIG_FILE = "config.toml"
METRICS_FILE = "metrics.csv"
CHAMPION_DIR = "champions"


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


def init_run_dir(
    path: str | os.PathLike[str], config_toml: str | None, resume: bool = False
) -> RunDir:
    """Creates a run directory, or opens an existing one to resume it.

    A new run needs a missing or empty directory. Resuming needs an existing run; its
    ``config.toml`` is replaced by ``config_toml`` when given (the caller checks that the
    change is compatible) and kept when ``config_toml`` is None.

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
    """
    run = RunDir(Path(path))
    if run.path.exists() and not run.path.is_dir():
        raise RunDirError(f"{run.path}: exists and is not a directory")
    if is_run_dir(run.path):
        if not resume:
            raise RunDirError(
                f"{run.path}: already holds an mtpg run; resume it or choose another directory"
            )
    elif resume:
        raise RunDirError(f"{run.path}: holds no mtpg run to resume")
    else:
        entries = sorted(e.name for e in run.path.iterdir()) if run.path.exists() else []
        if entries:
            shown = ", ".join(entries[:5]) + (", ..." if len(entries) > 5 else "")
            raise RunDirError(
                f"{run.path}: directory is not empty and is not an mtpg run directory "
                f"(contains {shown}); choose a new or empty directory"
            )
        if config_toml is None:
            raise RunDirError(f"{run.path}: a new run needs its configuration")
    run.path.mkdir(parents=True, exist_ok=True)
    run.checkpoints.mkdir(exist_ok=True)
    run.champions.mkdir(exist_ok=True)
    if config_toml is not None:
        atomic_write_bytes(run.config, config_toml.encode("utf-8"))
    return run


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
    names = tuple(task_names)
    unknown = [t for t in names if t not in TASK_NAMES]
    if not names or unknown or len(set(names)) != len(names):
        raise ValueError(
            f"task set {names} must be non-empty, without repeats, from {', '.join(TASK_NAMES)}"
        )
    return tuple(sorted(names, key=TASK_NAMES.index))


def champion_filename(task_names: tuple[str, ...]) -> str:
    """File name of the champion of a task subset: tasks in canonical order joined by "+".

    Example: ``("Acrobot", "CartPole")`` gives ``"CartPole+Acrobot.json"``.
    """
    return "+".join(canonical_tasks(task_names)) + ".json"


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
    for tasks, (pop, root, meta) in champions.items():
        path = directory / champion_filename(tasks)
        save_graph(path, pop, root, {"tasks": list(canonical_tasks(tasks)), **(meta or {})})
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
            tasks = canonical_tasks(path.stem.split("+"))
        except ValueError:
            continue  # not a champion file
        out[tasks] = load_graph(path)
    return out
