"""Hierarchical complexity (paper Fig. 8): teams visited per decision by subset champions.

Fig. 8 plots the teams visited per decision by the champion of every task subset against
the number of tasks in the subset (:func:`subset_complexity`, in ``mtpg report``). Across a
run the same numbers exist at every test point (``tests.csv``), and ``metrics.csv`` adds
the whole population's teams per decision and the size of the all-task champion at every
generation (:func:`hierarchy_statistics`, drawn by :func:`run_complexity` in ``mtpg
analyze RUN_DIR``).
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from mtpg.analysis.plotting import finish, pyplot, save
from mtpg.analysis.runs.loading import RunGroup
from mtpg.analysis.runs.reported_numbers import RunNumbers, describe
from mtpg.io.rundir import METRICS_FILE, TESTS_FILE, split_subset


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
        "subset_size": np.array([len(split_subset(r["subset"])) for r in rows]),
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


def subset_complexity(group: RunGroup, numbers: dict[Path, RunNumbers], path: Path) -> Path:
    """Fig. 8: teams visited per decision by the champion of every task subset.

    One column per subset (ordered by size); points: minimum, median and maximum over runs
    at the final test point, as in the paper.
    """
    plt = pyplot()
    runs = group.runs
    tasks = runs[0].tasks
    subsets = sorted(
        {str(r["subset"]) for r in runs[0].tests},
        key=lambda s: (len(split_subset(s)), [tasks.index(t) for t in split_subset(s)]),
    )
    values = np.array(
        [
            [float(run.row(s, numbers[run.path].generation)["teams_per_decision"]) for s in subsets]
            for run in runs
        ]
    )
    xs = np.arange(len(subsets))
    # 63 subsets of six tasks fit 11 inches with vertical labels (1,210 px at the DPI)
    fig, ax = plt.subplots(figsize=(min(11.0, max(6.0, 0.16 * len(subsets) + 3)), 5))
    if len(runs) == 1:  # minimum, median and maximum coincide: one marker, named so
        ax.scatter(xs, values[0], marker="o", color="black", s=14, label=runs[0].name)
    else:
        ax.vlines(xs, values.min(axis=0), values.max(axis=0), color="0.75", lw=1)
        ax.scatter(xs, values.max(axis=0), marker="^", color="tab:red", s=14, label="max over runs")
        ax.scatter(
            xs, np.median(values, axis=0), marker="o", color="black", s=14, label="median over runs"
        )
        ax.scatter(
            xs, values.min(axis=0), marker="v", color="tab:blue", s=14, label="min over runs"
        )
    ax.set_xticks(xs)
    ax.set_xticklabels(
        ["+".join(str(tasks.index(t)) for t in split_subset(s)) for s in subsets],
        rotation=90 if len(subsets) > 12 else 0,
        fontsize=6 if len(subsets) > 31 else 7,
    )
    ax.set_xlim(-0.8, len(subsets) - 0.2)
    ax.set_xlabel("task subset (" + ", ".join(f"{k} = {t}" for k, t in enumerate(tasks)) + ")")
    ax.set_ylabel("teams visited per decision\n(mean over test steps)")
    ax.set_title(f"Hierarchical complexity of each subset's champion: {group.label}")
    ax.legend(fontsize=7)
    caption = (
        f"{describe([numbers[r.path] for r in runs]).replace('All-task c', 'Each subset c')} "
        f"Teams per decision counted over those test episodes of every task; {len(runs)} run(s)."
    )
    return finish(fig, path, caption)


def run_complexity(stats: dict, means: dict, path: Path, title: str) -> Path:
    """Fig. 8 across a run: teams per decision of every subset champion, by subset size."""
    plt = pyplot()
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4))
    last = stats["test_generation"] == stats["final_generation"]
    sizes = stats["subset_size"][last]
    jitter = (np.arange(len(sizes)) % 7 - 3) * 0.04
    a.scatter(sizes + jitter, stats["teams_per_decision"][last], s=16, color="0.3")
    a.set_xlabel("number of tasks in the subset")
    a.set_ylabel("teams visited per decision (test)")
    a.set_title(f"Subset champions at generation {int(stats['final_generation'])}", fontsize=10)
    a.set_xticks(np.unique(stats["subset_size"]))
    cmap = plt.get_cmap("viridis")
    n = len(means["sizes"])
    for i, size in enumerate(means["sizes"]):
        b.plot(
            means["generations"],
            means["mean"][i],
            color=cmap(i / max(n - 1, 1)),
            marker=".",
            label=f"{size} task{'s' if size > 1 else ''}",
        )
    if len(stats["generation"]):
        b.plot(
            stats["generation"],
            stats["population_teams_per_decision"],
            color="0.6",
            ls=":",
            label="whole population (training)",
        )
    b.set_xlabel("generation")
    b.set_ylabel("teams visited per decision\n(mean over subset champions)")
    b.set_title("Over the run, by subset size", fontsize=10)
    b.legend(fontsize=7, ncol=2)
    fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    return save(fig, path)
