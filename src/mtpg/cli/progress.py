"""Progress displays: a training run's generations, and the runs of an experiment.

A training run prints a header naming every column, a line while the first generation
compiles, then one status line per generation (rewritten in place on a terminal):

    gen 12/250 | 0.74 s/gen | left 2m51s | 6.86M dec/s | train best CP 50 AB -200 |
    test@10 CP 38.2 AB -500 | teams/dec 1.01

``train best`` is the best training score of any root on each task (a different root may be
best on each, and training uses only a few episodes): it is not what the run has learnt.
``test@G`` is the all-task champion's mean return on the held-out episodes at the last test
point G: the number the report shows.

On a terminal the status line is a `tqdm <https://tqdm.github.io>`_ line (a text-only
``bar_format``): tqdm rewrites it in place, and :meth:`Progress.messages` routes the
``mtpg`` logger's messages through ``tqdm.write`` so that a warning does not break it.
Elsewhere (a log file, a pipe) there is no live line: each generation is one whole line.
"""

from __future__ import annotations

import contextlib
import csv
import logging
import shutil
import sys
import threading
import time
from pathlib import Path
from typing import TextIO

from tqdm import tqdm
from tqdm.contrib.logging import logging_redirect_tqdm

from mtpg.envs.specs.compiled_task import is_compiled_name
from mtpg.envs.specs.gym_task import is_gym
from mtpg.envs.specs.gym_task import short as gym_short
from mtpg.envs.specs.registry import TASKS
from mtpg.evolve.trainer import Generation, Reporter

#: Short task labels for the status line (the header spells them out): each spec's
#: ``short``.
SHORT = {t.name: t.short for t in TASKS}


def _short(task: str) -> str:
    """A task's short label: the registry's, a variant its base's, a ``gym:`` task its own."""
    if is_gym(task):
        return gym_short(task)
    if is_compiled_name(task):  # module:ATTR: the attribute
        return task.rsplit(":", 1)[1][:4]
    return SHORT[task.split("[", 1)[0]]


def short_names(tasks: tuple[str, ...] | list[str]) -> dict[str, str]:
    """The status line's label of each task.

    A task's short name, a variant its base's; labels that repeat in the run are numbered
    in run order (``CP1``, ``CP2``).
    """
    base = {t: _short(t) for t in tasks}
    labels = list(base.values())
    out, seen = {}, dict.fromkeys(labels, 0)
    for t in tasks:
        if labels.count(base[t]) > 1:
            seen[base[t]] += 1
            out[t] = f"{base[t]}{seen[base[t]]}"
        else:
            out[t] = base[t]
    return out


class StatusLine(tqdm):
    """A tqdm line that shows only its description: the status text, rewritten in place.

    Updated by hand once per generation, so tqdm's monitor thread (which tunes the
    refresh rate of fast loops) is not started.
    """

    monitor_interval = 0


def _fmt_rate(x: float) -> str:
    return f"{x / 1e6:.2f}M" if x >= 1e6 else f"{x / 1e3:.0f}k"


def fmt_duration(seconds: float) -> str:
    """``"42s"``, ``"3m07s"`` or ``"2h05m"``."""
    s = int(round(max(seconds, 0.0)))
    if s < 60:
        return f"{s}s"
    if s < 3600:
        return f"{s // 60}m{s % 60:02d}s"
    return f"{s // 3600}h{s % 3600 // 60:02d}m"


def last_test(tests_file: Path | None, subset: str) -> tuple[int, dict[str, float]] | None:
    """The last test row of ``subset`` in a ``tests.csv``: ``(generation, task -> score)``."""
    if tests_file is None or not tests_file.is_file():
        return None
    found = None
    with open(tests_file, encoding="utf-8") as fh:
        for row in csv.DictReader(fh):
            if row.get("subset") == subset:
                found = row
    if found is None:
        return None
    scores = {k[5:]: float(v) for k, v in found.items() if k.startswith("test_")}
    return int(float(found["generation"])), scores


def champion_test(rows: list[dict], subset: str) -> tuple[int, dict[str, float]] | None:
    """The test point's row of ``subset`` among a generation's rows: as :func:`last_test`."""
    for row in rows:
        if row.get("subset") == subset:
            scores = {k[5:]: float(v) for k, v in row.items() if k.startswith("test_")}
            return int(float(row["generation"])), scores
    return None


class Progress(Reporter):
    """Reports each generation of a training run.

    A :class:`~mtpg.evolve.trainer.Reporter`: given to the run with its other reporters,
    it reads each test point's scores from the generation itself. Called as a function
    with a metrics row (the older form), it reads them back from ``tests_file``.

    Args:
        total: The run's last generation.
        tasks: Active task names.
        stream: Where to write (standard error by default).
        live: Rewrite one status line in place; default: when ``stream`` is a terminal.
        tests_file: The run's ``tests.csv``, for the champion's last test score.
        train_episodes: Training episodes per task (named in the header).
        test_episodes: Held-out episodes per task at a test point (named in the header).
    """

    def __init__(
        self,
        total: int,
        tasks: tuple[str, ...],
        stream: TextIO | None = None,
        live: bool | None = None,
        tests_file: Path | None = None,
        train_episodes: int | None = None,
        test_episodes: int | None = None,
    ) -> None:
        self.total = total
        self.tasks = tasks
        self.short = short_names(tasks)
        self.stream = stream or sys.stderr
        self.live = self.stream.isatty() if live is None else live
        self._started = time.perf_counter()
        self.tests_file = tests_file
        self.train_episodes = train_episodes
        self.test_episodes = test_episodes
        self.test: tuple[int, dict[str, float]] | None = None
        self._last = self._started
        self._durations: list[float] = []
        self._header_done = False
        self._line: StatusLine | None = None

    @classmethod
    def for_session(cls, session, **kwargs) -> Progress:
        """A display for a :class:`mtpg.evolve.session.Session`, announced on the stream.

        Prints the header and the "compiling" line at once (the first generation compiles
        the engine's kernels, which takes seconds before anything else appears).
        """
        from mtpg.io.rundir import TESTS_FILE

        ev = session.config.evaluation
        progress = cls(
            session.config.generations,
            ev.tasks,
            tests_file=Path(session.run.path) / TESTS_FILE,
            train_episodes=ev.train_episodes,
            test_episodes=ev.test_episodes,
            **kwargs,
        )
        progress.test = last_test(progress.tests_file, "+".join(ev.tasks))
        progress.begin(session.trainer.state.generation)
        return progress

    def header(self) -> str:
        """The lines that name every column of the status line."""
        names = ", ".join(f"{self.short[t]} = {t}" for t in self.tasks)
        train = f"mean of {self.train_episodes} training episodes" if self.train_episodes else ""
        test = f"{self.test_episodes} held-out episodes" if self.test_episodes else "held-out"
        return (
            "columns: gen = generations done/total | s/gen = seconds of the last generation | "
            "left = estimated time left | dec/s = graph decisions per second\n"
            f"  train best = best training score of any root on each task ({train}; the best "
            "root may differ per task, so this is not the champion's score)\n"
            f"  test@G = the all-task champion's mean return on {test} per task at the last "
            "test point G (what `mtpg report` and `mtpg evaluate` show)\n"
            "  teams/dec = teams visited per decision, mean over the generation's new roots in "
            "training (1: no team passes the decision on)\n"
            f"  tasks: {names}"
        )

    def _write_header(self) -> None:
        if not self._header_done:
            self.stream.write(self.header() + "\n")
            self._header_done = True

    def begin(self, generation: int = 0) -> None:
        """Prints the header and a line saying the next generation compiles first.

        A run that has no generation left (a finished run resumed) gets the header only.
        """
        self._write_header()
        if generation >= self.total:
            return
        text = (
            f"gen {generation + 1}/{self.total}: compiling the engine's kernels (cached after "
            "the first run), then evaluating..."
        )
        self._write(text)
        self._last = time.perf_counter()

    def _write(self, text: str) -> None:
        """Shows ``text``: the live line on a terminal, a whole line elsewhere."""
        if not self.live:
            self.stream.write(text + "\n")
            self.stream.flush()
            return
        # The terminal's width is read at each write (it may change). A line longer than
        # the terminal would wrap, and each rewrite would leave its first rows behind.
        width = shutil.get_terminal_size((80, 24)).columns - 1  # no wrap at the last column
        if len(text) > width:
            text = text[: max(width - 3, 0)] + "..."
        if self._line is None:
            self._line = StatusLine(
                desc=text,
                file=self.stream,
                bar_format="{desc}",
                ncols=width,
                mininterval=0,
                position=0,  # the one line: never below lines of other tqdm bars
                # tqdm hides lines below the screen's height, which it reads from the
                # terminal unless given: a terminal that reports no size (a bare pty)
                # would hide this one, at the top, too
                nrows=2,
            )
        else:
            self._line.ncols = width
            self._line.set_description_str(text, refresh=True)

    def messages(self) -> contextlib.AbstractContextManager[object]:
        """A context in which the ``mtpg`` logger's messages leave the live line intact.

        On a terminal they are written above the line (``tqdm.write``); elsewhere
        nothing changes.
        """
        if not self.live:
            return contextlib.nullcontext()
        return logging_redirect_tqdm([logging.getLogger("mtpg")], tqdm_class=StatusLine)

    def eta(self, generation: int) -> float:
        """Seconds left: mean duration of the recent generations times those remaining.

        The first generation of a process (it compiles the kernels) is left out, so there
        is no estimate (NaN, shown as "?") until a second generation has run.
        """
        recent = self._durations[1:]
        if not recent:
            return float("nan")
        recent = recent[-20:]
        return sum(recent) / len(recent) * max(self.total - generation, 0)

    def line(self, row: dict[str, float]) -> str:
        """The status text of one metrics row."""
        gen = int(row["generation"])
        took = self._durations[-1] if self._durations else float(row.get("t_total", 0.0))
        left = self.eta(gen)
        train = " ".join(f"{self.short[t]} {row[f'best_{t}']:.4g}" for t in self.tasks)
        if self.test is not None:
            g, scores = self.test
            test = f"test@{g} " + " ".join(f"{self.short[t]} {scores[t]:.4g}" for t in self.tasks)
        else:
            test = "test: none yet"
        return (
            f"gen {gen}/{self.total} | {took:.2f} s/gen | "
            f"left {fmt_duration(left) if left == left else '?'} | "
            f"{_fmt_rate(row['decisions_per_s'])} dec/s | train best {train} | {test} | "
            f"teams/dec {row['teams_per_decision']:.2f}"
        )

    def generation(self, gen: Generation, trainer: object = None) -> None:
        """Shows one generation (the reporter form): its test scores come with it."""
        if gen.tests:
            self.test = champion_test(gen.tests, "+".join(self.tasks)) or self.test
        self.show(gen.metrics)

    def __call__(self, row: dict[str, float], _trainer: object = None) -> None:
        """Shows one generation from its metrics row, reading a test point's scores back."""
        if row.get("t_test", 0.0) > 0 or int(row["generation"]) >= self.total:
            self.test = last_test(self.tests_file, "+".join(self.tasks)) or self.test
        self.show(row)

    def show(self, row: dict[str, float]) -> None:
        """Writes the status line of one metrics row."""
        now = time.perf_counter()
        self._durations.append(now - self._last)
        self._last = now
        self._write_header()
        self._write(self.line(row))
        if row["generation"] >= self.total:
            self.close()

    def close(self) -> None:
        """Ends a live line so later output starts on a new line (twice is harmless)."""
        if self._line is not None:
            self._line.close()
            self._line = None


def run_generation(run_dir: Path) -> int:
    """Generations recorded in a run's ``metrics.csv`` (0 when it has none yet)."""
    from mtpg.io.rundir import RunDir

    path = RunDir(Path(run_dir)).metrics
    try:
        lines = path.read_text(encoding="utf-8").strip().splitlines()
    except OSError:
        return 0
    if len(lines) < 2:
        return 0
    try:
        return int(float(lines[-1].split(",", 1)[0]))
    except ValueError:
        return 0


class ExperimentProgress:
    """Reports the generation of every run of an experiment while it runs.

    A background thread reads each run's ``metrics.csv`` every ``interval`` seconds and
    logs one line when anything moved, e.g.
    ``progress 3/8 done | TPG-seed1 gen 12/62 (left ~1m40s) | TPG-seed2 waiting``.

    Args:
        runs: Objects with a ``path`` (run directory), e.g. planned runs.
        generations: Generations per run.
        log: Called with each line.
        interval: Seconds between checks.
    """

    def __init__(self, runs, generations: int, log, interval: float = 15.0) -> None:
        self.runs = list(runs)
        self.generations = generations
        self.log = log
        self.interval = interval
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._seen: dict[Path, tuple[float, int]] = {}
        self._last_text = ""

    def status(self) -> str:
        """One line with every unfinished run's generation and estimated time left."""
        now = time.monotonic()
        parts, done = [], 0
        for run in self.runs:
            gen = run_generation(run.path)
            if gen >= self.generations:
                done += 1
                continue
            if gen == 0:
                parts.append(f"{run.path.name} waiting")
                continue
            first = self._seen.setdefault(run.path, (now, gen))
            rate = (gen - first[1]) / (now - first[0]) if now > first[0] else 0.0
            left = f" (left ~{fmt_duration((self.generations - gen) / rate)})" if rate > 0 else ""
            parts.append(f"{run.path.name} gen {gen}/{self.generations}{left}")
        return " | ".join([f"progress {done}/{len(self.runs)} runs done", *parts])

    def _loop(self) -> None:
        while not self._stop.wait(self.interval):
            text = self.status()
            if text != self._last_text:
                self.log(text)
                self._last_text = text

    def start(self) -> ExperimentProgress:
        """Starts reporting in a daemon thread."""
        self.status()  # note where every run starts, for the time estimates
        self._thread = threading.Thread(target=self._loop, daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        """Stops reporting."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join()
