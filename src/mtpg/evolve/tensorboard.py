"""A reporter that logs each generation to TensorBoard event files (optional extra).

``mtpg train --tensorboard DIR`` (or ``Session.run_all(reporters=[TensorBoardReporter(DIR,
...)])``) writes, once per completed generation with the generation as the step, the
columns of the ``metrics.csv`` row and, at a test point, the all-task champion's test
scores, so that ``tensorboard --logdir DIR`` shows a run in progress. The writer is
``tensorboardX``'s ``SummaryWriter`` (the ``tensorboard`` extra): it writes the event-file
format without TensorFlow or PyTorch, needing only ``protobuf``. Off by default; nothing
of it is stored with the run, so turning it on or off changes no result and no run
identity.

Tags: ``train/best/<task>``, ``train/median/<task>`` (training scores),
``test/all_tasks/<task>`` (test points), ``population/<column>`` (roots, teams, programs,
banks, banks_in_use, programs_per_bank, new_roots), ``decisions/<column>``
(teams_per_decision, instructions_per_decision, decisions_per_s) and ``seconds/<phase>``
(``t_variation`` ... ``t_total``).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from mtpg.evolve.trainer import Generation, Reporter, Trainer

#: What to install when the writer is missing (one line for the user).
MISSING = (
    'TensorBoard logging needs the tensorboard extra: pip install -e ".[tensorboard]" in '
    "the mtpg checkout (it installs tensorboardX)"
)
POPULATION = (
    "roots",
    "teams",
    "programs",
    "banks",
    "banks_in_use",
    "programs_per_bank",
    "new_roots",
)
DECISIONS = ("teams_per_decision", "instructions_per_decision", "decisions_per_s", "decisions")


def check_available() -> None:
    """Raises ``ValueError`` with :data:`MISSING` when tensorboardX cannot be imported."""
    try:
        import tensorboardX  # noqa: F401
    except ImportError:
        raise ValueError(MISSING) from None


def scalars(
    metrics: dict[str, float], tests: list[dict[str, Any]] | None, tasks: tuple[str, ...]
) -> dict[str, float]:
    """The tags and values one generation logs (see the module docstring)."""
    out: dict[str, float] = {}
    for key, value in metrics.items():
        if key == "generation":
            continue
        if key.startswith(("best_", "median_")):
            kind, _, task = key.partition("_")
            out[f"train/{kind}/{task}"] = float(value)
        elif key in POPULATION:
            out[f"population/{key}"] = float(value)
        elif key in DECISIONS:
            out[f"decisions/{key}"] = float(value)
        elif key.startswith("t_"):
            out[f"seconds/{key.removeprefix('t_')}"] = float(value)
        else:
            out[f"other/{key}"] = float(value)
    full = "+".join(tasks)
    for row in tests or []:
        if row["subset"] == full:
            for task in tasks:
                out[f"test/all_tasks/{task}"] = float(row[f"test_{task}"])
    return out


class TensorBoardReporter(Reporter):
    """Writes each completed generation's scalars to TensorBoard event files in ``logdir``.

    Args:
        logdir: Directory of the event files (created if missing); a resumed run adds a
            new event file beside the earlier ones (its name ends in the generation it
            starts from and the process id, so no file is overwritten), with the same
            tags and later steps.
        tasks: The run's task names (for the test tags).
    """

    def __init__(self, logdir: str | Path, tasks: tuple[str, ...]) -> None:
        check_available()
        self.logdir = Path(logdir)
        self.tasks = tuple(tasks)
        self.writer: Any = None

    def start(self, trainer: Trainer) -> None:
        """Opens a new event file for the generations this process runs."""
        import os

        from tensorboardX import SummaryWriter

        suffix = f".from-gen{trainer.state.generation:06d}.pid{os.getpid()}"
        self.writer = SummaryWriter(str(self.logdir), flush_secs=10, filename_suffix=suffix)

    def generation(self, gen: Generation, trainer: Trainer) -> None:
        """Logs the generation's scalars at step ``gen.number`` and flushes them."""
        for tag, value in scalars(gen.metrics, gen.tests, self.tasks).items():
            self.writer.add_scalar(tag, value, gen.number)
        self.writer.flush()  # a run in progress is seen at once

    def end(self, trainer: Trainer) -> None:
        """Closes the event file."""
        if self.writer is not None:
            self.writer.close()
