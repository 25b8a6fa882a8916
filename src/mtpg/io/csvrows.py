"""A run's CSV files (``metrics.csv``, ``tests.csv``) as rows of numbers, for the Python API."""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Any


def read_rows(path: Path, text: tuple[str, ...] = ()) -> list[dict[str, Any]]:
    """Rows of a run's CSV file, numbers parsed (empty cells NaN); none if it is missing.

    Args:
        path: The CSV file.
        text: Columns kept as text.
    """
    if not path.is_file():
        return []
    with open(path, encoding="utf-8", newline="") as fh:
        return [
            {k: v if k in text else _number(v) for k, v in row.items()}
            for row in csv.DictReader(fh)
        ]


def _number(value: str) -> float | str:
    """A cell as a float (NaN when empty), or the text when it is not a number."""
    if value == "":
        return math.nan
    try:
        return float(value)
    except ValueError:
        return value
