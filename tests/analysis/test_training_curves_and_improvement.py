"""Training curves from metrics.csv, and the probability of improvement with its interval."""

import csv
import itertools

import numpy as np
import pytest

from mtpg.analysis.runs import statistics_figures
from mtpg.analysis.runs.loading import group_runs, load_run
from mtpg.analysis.runs.report import build_report
from mtpg.analysis.runs.statistics import _improvement, probability_of_improvement
from mtpg.analysis.runs.training_curves import read_metrics, training_curves
from mtpg.cli.main import main
from tinyruns import tiny_args


def brute_force(x, y):
    """P(X > Y) by the definition: every pair of runs on every task."""
    tasks = []
    for t in range(x.shape[1]):
        wins = [1.0 if a > b else 0.5 if a == b else 0.0 for a in x[:, t] for b in y[:, t]]
        tasks.append(sum(wins) / len(wins))
    return sum(tasks) / len(tasks)


@pytest.mark.parametrize("seed", range(5))
def test_probability_of_improvement_is_the_pairwise_definition(seed):
    rng = np.random.default_rng(seed)
    x = rng.integers(0, 4, size=(4, 3)) / 4  # few values: ties happen
    y = rng.integers(0, 4, size=(3, 3)) / 4
    forward = probability_of_improvement(x, y, n_resamples=200)
    backward = probability_of_improvement(y, x, n_resamples=200)
    assert forward.value == pytest.approx(brute_force(x, y))
    assert forward.value + backward.value == pytest.approx(1.0)
    assert forward.low <= forward.value <= forward.high


def exact_bootstrap(x, y):
    """Every resample of the stratified bootstrap, each as likely as the others."""
    n, m, tasks = x.shape[0], y.shape[0], x.shape[1]
    draws_x = list(itertools.product(range(n), repeat=n))
    draws_y = list(itertools.product(range(m), repeat=m))
    values = []
    for per_task in itertools.product(itertools.product(draws_x, draws_y), repeat=tasks):
        bx = np.stack([x[list(dx), t] for t, (dx, _) in enumerate(per_task)], axis=-1)
        by = np.stack([y[list(dy), t] for t, (_, dy) in enumerate(per_task)], axis=-1)
        values.append(float(_improvement(bx, by)))
    return np.array(values)


def test_the_interval_agrees_with_the_enumerated_bootstrap_distribution():
    x = np.array([[0.2, 0.9], [0.5, 0.1], [0.7, 0.4]])
    y = np.array([[0.3, 0.2], [0.5, 0.6]])
    exact = exact_bootstrap(x, y)
    assert len(exact) == (27 * 4) ** 2
    est = probability_of_improvement(x, y)
    lo_band = np.percentile(exact, [2.0, 3.0])
    hi_band = np.percentile(exact, [97.0, 98.0])
    assert lo_band[0] <= est.low <= lo_band[1]
    assert hi_band[0] <= est.high <= hi_band[1]
    # and the two ends match the enumerated percentiles to the support's resolution (1/12)
    assert est.low == pytest.approx(np.percentile(exact, 2.5), abs=1 / 12)
    assert est.high == pytest.approx(np.percentile(exact, 97.5), abs=1 / 12)


def test_one_run_against_one_run_has_no_interval_and_a_group_of_one_is_kept_as_is():
    one = np.array([[0.4, 0.6]])
    assert np.isnan(probability_of_improvement(one, one).low)
    many = np.array([[0.1, 0.9], [0.8, 0.2], [0.5, 0.5]])
    est = probability_of_improvement(many, one)
    assert 0 <= est.low < est.high <= 1 and est.runs == 3


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("curves")
    args = [*tiny_args(n_elite=3, evaluation__test_interval=2), "--generations", "4"]
    dirs = []
    for name, extra in (("s0", []), ("s1", ["--seed", "1"]), ("nomem", ["--no-memory"])):
        assert main(["train", *args, *extra, "--out", str(root / name)]) == 0
        dirs.append(root / name)
    return dirs


def test_training_curves_draw_the_columns_of_metrics_csv(runs, tmp_path, monkeypatch):
    import matplotlib.figure

    from mtpg.analysis import plotting

    figs = []
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", lambda *a, **k: None)
    monkeypatch.setattr(plotting._AggFigures, "close", lambda _self, fig: figs.append(fig))
    loaded = [load_run(p) for p in runs]
    groups, _ = group_runs(loaded)
    training_curves(groups, tmp_path / "t.png")
    axes = figs[0].axes
    with open(runs[0] / "metrics.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    first = [float(r["best_CartPole"]) for r in rows]
    median = [float(r["median_CartPole"]) for r in rows]
    drawn = [list(line.get_ydata()) for line in axes[0].get_lines()]
    assert first in drawn and median in drawn
    assert axes[0].get_title() == "CartPole" and axes[2].get_title().startswith("population")
    sizes = [list(line.get_ydata()) for line in axes[3].get_lines()]
    assert [float(r["banks_in_use"]) for r in rows] in sizes
    assert read_metrics(loaded[0])["generation"].tolist() == [1, 2, 3, 4]


def test_the_report_adds_training_curves_and_the_probability_of_improvement(runs, tmp_path):
    index = build_report(runs, tmp_path / "r")
    page = index.read_text()
    assert (tmp_path / "r" / "training_curves.png").stat().st_size > 10_000
    assert (tmp_path / "r" / "probability_of_improvement.png").stat().st_size > 10_000
    assert "Probability of improvement [95% CI]" in page and "P(TPG &gt; TPG-NoMemory)" in page
    loaded = [load_run(p) for p in runs]
    groups, _ = group_runs(loaded)
    from mtpg.analysis.runs.reported_numbers import run_numbers

    numbers = {r.path: run_numbers(r) for r in loaded}
    [(pair, est)] = statistics_figures.improvements(groups, numbers).items()
    assert pair == ("TPG", "TPG-NoMemory") and est.text(3) in page
