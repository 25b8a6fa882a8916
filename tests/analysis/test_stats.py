import itertools

import numpy as np
import pytest

from mtpg.analysis.runs.statistics import aggregate_iqm, iqm, per_task_iqm, performance_profile


def test_iqm_is_the_mean_of_the_middle_half():
    # 8 values: the two lowest and two highest are dropped, (3 + 4 + 5 + 6) / 4
    assert iqm(np.array([[8.0, 1.0], [3.0, 100.0], [5.0, 4.0], [-50.0, 6.0]])) == 4.5
    # 4 values: one dropped at each end
    assert iqm(np.array([[0.0], [1.0], [2.0], [10.0]])) == 1.5


def exact_percentiles(scores, statistic):
    """Every stratified resample of a small matrix, equally likely: the exact distribution."""
    n, m = scores.shape
    per_task = [list(itertools.product(range(n), repeat=n)) for _ in range(m)]
    values = []
    for choice in itertools.product(*per_task):
        sample = np.stack([scores[list(rows), k] for k, rows in enumerate(choice)], axis=1)
        values.append(statistic(sample))
    return np.percentile(values, [2.5, 97.5])


def test_stratified_bootstrap_interval_matches_exhaustive_enumeration():
    # 3 runs x 2 tasks: 27 x 27 = 729 equally likely stratified resamples
    scores = np.array([[0.0, 0.2], [0.5, 0.9], [1.0, 0.4]])
    lo, hi = exact_percentiles(scores, lambda s: iqm(s))
    est = aggregate_iqm(scores, n_resamples=20_000)
    assert est.value == pytest.approx(iqm(scores))
    assert est.low == pytest.approx(lo, abs=0.03) and est.high == pytest.approx(hi, abs=0.03)
    # runs are resampled within each task, never across: a matrix whose tasks differ
    # wildly keeps one value of each task in every resample
    wide = np.array([[0.0, 10.0], [0.0, 10.0]])
    assert aggregate_iqm(wide).low == aggregate_iqm(wide).high == 5.0


def test_one_run_has_no_interval():
    est = aggregate_iqm(np.array([[0.3, 0.5]]))
    assert est.value == pytest.approx(0.4) and np.isnan(est.low) and "n/a" in est.text()


def test_per_task_iqm_and_profile():
    scores = np.array([[0.0, 1.0], [0.2, 1.0], [0.4, 1.0], [0.6, 1.0]])
    tasks = per_task_iqm(scores, n_resamples=2000)
    assert [t.value for t in tasks] == pytest.approx([0.3, 1.0])
    assert tasks[1].low == tasks[1].high == 1.0
    frac, lo, hi = performance_profile(scores, np.array([-0.1, 0.1, 0.5, 1.0]), n_resamples=500)
    assert frac.tolist() == [1.0, 7 / 8, 5 / 8, 0.0]
    assert np.all(lo <= frac + 1e-12) and np.all(frac <= hi + 1e-12)
