from __future__ import annotations

import math

import numpy as np
import pytest

from mtpg.envs import CARTCENTERING, TASK_NAMES
from mtpg.envs.taskset.reference_scores import (
    REFERENCE,
    make_test_seeds,
    measure_random,
    measure_time_optimal_cartcentering,
    normalise,
)


def test_table_shape_and_spec_figures() -> None:
    assert len(REFERENCE) == len(TASK_NAMES)
    bests = [r.best for r in REFERENCE]
    assert bests[0] == 195.0 and bests[1] == -100.0 and bests[3] == -123.11
    assert bests[4] == -110.0 and bests[5] == 90.0
    expected_random = [19.3, -500.0, -0.98, -1241.0, -200.0, -33.0]
    for ref, exp in zip(REFERENCE, expected_random, strict=True):
        assert ref.random == pytest.approx(exp, rel=0.03)
        assert ref.best > ref.random


def test_test_seeds_convention() -> None:
    np.testing.assert_array_equal(make_test_seeds()[[0, -1]], [1_000_000, 1_000_099])


def test_cartcentering_best_matches_remeasurement() -> None:
    score, steps, captured = measure_time_optimal_cartcentering()
    assert captured == 100
    assert score == pytest.approx(REFERENCE[CARTCENTERING].best, rel=1e-9)


def test_normalise() -> None:
    for task, ref in enumerate(REFERENCE):
        assert normalise(task, ref.random) == 0.0
        assert normalise(task, ref.best) == pytest.approx(1.0)
        assert normalise(task, ref.random + 2.0, best=ref.random + 4.0) == pytest.approx(0.5)
    arr = normalise(4, np.array([-200.0, -155.0, -110.0]))
    np.testing.assert_allclose(arr, [0.0, 0.5, 1.0])
    with pytest.raises(ValueError):
        normalise(1, 0.0, best=-500.0)
    assert math.isnan(REFERENCE[CARTCENTERING].solved)


# Guards the stored random-agent figures that every normalised score depends on. It takes
# a few seconds on an idle machine, so it runs in the default suite.
@pytest.mark.parametrize("task", range(len(TASK_NAMES)))
def test_random_figures_match_remeasurement(task: int) -> None:
    mean, std = measure_random(task)
    assert mean == pytest.approx(REFERENCE[task].random, rel=1e-6, abs=1e-9)
    assert std == pytest.approx(REFERENCE[task].random_std, rel=1e-6, abs=1e-9)
