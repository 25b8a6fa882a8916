"""Hierarchy statistics across a run (paper Fig. 8), as arrays read from its CSV files.

Fig. 8 plots the teams visited per decision by the champion of every task subset against
the number of tasks in the subset. Across a run the same numbers exist at every test
point (``tests.csv``), and ``metrics.csv`` adds the whole population's teams per decision
and the size of the all-task champion at every generation.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from mtpg.io.rundir import METRICS_FILE, TESTS_FILE


def _read(path: Path) -> list[dict[str, str]]:
    with open(path, encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def hierarchy_statistics(run_dir: str | Path) -> dict[str, np.ndarray]:
    """Reads the hierarchy statistics of a run directory.

    Args:
        run_dir: The run directory.

    Returns:
        From ``tests.csv``: ``test_generation``, ``subset_size``, ``teams_per_decision``,
        ``graph_teams`` (one entry per subset champion and test point), ``final_generation``.
        From ``metrics.csv`` (empty arrays when absent): ``generation``,
        ``population_teams_per_decision``, ``champion_teams``.

    Raises:
        FileNotFoundError: When the run has no ``tests.csv``.
        ValueError: When it has no test rows yet.
    """
    run_dir = Path(run_dir)
    tests = run_dir / TESTS_FILE
    if not tests.is_file():
        raise FileNotFoundError(f"{tests}: no test results (was test_interval 0?)")
    rows = _read(tests)
    if not rows:
        raise ValueError(f"{tests}: no test results yet")
    out = {
        "test_generation": np.array([float(r["generation"]) for r in rows]),
        "subset_size": np.array([len(r["subset"].split("+")) for r in rows]),
        "teams_per_decision": np.array([float(r["teams_per_decision"]) for r in rows]),
        "graph_teams": np.array([float(r["graph_teams"]) for r in rows]),
    }
    out["final_generation"] = np.array(out["test_generation"].max())
    metrics = run_dir / METRICS_FILE
    mrows = _read(metrics) if metrics.is_file() else []
    out["generation"] = np.array([float(r["generation"]) for r in mrows])
    out["population_teams_per_decision"] = np.array([float(r["teams_per_decision"]) for r in mrows])
    out["champion_teams"] = np.array([float(r["champion_teams"]) for r in mrows])
    return out


def mean_by_size(stats: dict[str, np.ndarray], key: str = "teams_per_decision") -> dict:
    """Mean of ``key`` over the subset champions of each size at each test point.

    Returns:
        ``sizes`` (S,), ``generations`` (G,), ``mean`` (S, G).
    """
    sizes = np.unique(stats["subset_size"])
    gens = np.unique(stats["test_generation"])
    med = np.full((len(sizes), len(gens)), np.nan)
    for i, s in enumerate(sizes):
        for j, g in enumerate(gens):
            sel = (stats["subset_size"] == s) & (stats["test_generation"] == g)
            if sel.any():
                med[i, j] = np.mean(stats[key][sel])
    return {"sizes": sizes, "generations": gens, "mean": med}
