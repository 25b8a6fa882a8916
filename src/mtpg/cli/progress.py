"""Progress display of a training run: a live status line on a terminal, plain lines else."""

from __future__ import annotations

import sys
import time
from typing import TextIO

#: Short task labels for the status line.
SHORT = {
    "CartPole": "CP",
    "Acrobot": "AB",
    "CartCentering": "CC",
    "Pendulum": "PD",
    "MountainCar": "MC",
    "MountainCarContinuous": "MCC",
}


def _fmt_rate(x: float) -> str:
    return f"{x / 1e6:.2f}M" if x >= 1e6 else f"{x / 1e3:.0f}k"


class Progress:
    """Reports each generation.

    Args:
        total: The run's last generation.
        tasks: Active task names.
        stream: Where to write (standard error by default).
        live: Rewrite one status line in place; default: when ``stream`` is a terminal.
    """

    def __init__(
        self,
        total: int,
        tasks: tuple[str, ...],
        stream: TextIO | None = None,
        live: bool | None = None,
    ) -> None:
        self.total = total
        self.tasks = tasks
        self.stream = stream or sys.stderr
        self.live = self.stream.isatty() if live is None else live
        self.start = time.perf_counter()

    def line(self, row: dict[str, float]) -> str:
        """The status text of one metrics row."""
        elapsed = time.perf_counter() - self.start
        scores = " ".join(f"{SHORT[t]} {row[f'best_{t}']:.4g}" for t in self.tasks)
        return (
            f"gen {int(row['generation'])}/{self.total}  {elapsed:7.1f}s  "
            f"{_fmt_rate(row['decisions_per_s'])} dec/s  best: {scores}  "
            f"teams/decision {row['teams_per_decision']:.2f}  "
            f"champion teams {int(row['champion_teams'])}"
        )

    def __call__(self, row: dict[str, float], _trainer: object = None) -> None:
        """Shows one generation."""
        text = self.line(row)
        if self.live:
            self.stream.write("\r\x1b[2K" + text)
            if row["generation"] >= self.total:
                self.stream.write("\n")
        else:
            self.stream.write(text + "\n")
        self.stream.flush()

    def close(self) -> None:
        """Ends a live line so later output starts on a new line."""
        if self.live:
            self.stream.write("\n")
            self.stream.flush()
