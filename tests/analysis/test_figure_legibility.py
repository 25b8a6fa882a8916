"""Figures say what they show: sizes, markers, value labels and panel titles."""

import numpy as np
import pytest

from mtpg.analysis.graph import figures
from mtpg.analysis.plotting import DPI
from mtpg.analysis.runs import hierarchical_complexity
from mtpg.analysis.runs import score_figures as plots
from mtpg.analysis.runs.loading import group_runs, load_run
from mtpg.analysis.runs.reported_numbers import run_numbers
from mtpg.cli.main import main
from tinyruns import tiny_args

SIX = "CartPole,Acrobot,CartCentering,Pendulum,MountainCar,MountainCarContinuous"


@pytest.fixture(scope="module")
def six_task_runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("six")
    args = tiny_args(SIX, root_size=12, n_elite=1, evaluation__test_episodes=2)
    dirs = []
    for seed in (0, 1):
        out = root / f"s{seed}"
        argv = ["train", *args, "--generations", "1", "--seed", str(seed), "--out", str(out)]
        assert main(argv) == 0
        dirs.append(out)
    return dirs


@pytest.fixture
def drawn(monkeypatch):
    """The figures drawn, kept open instead of written."""
    import matplotlib.figure

    from mtpg.analysis import plotting

    figs = []
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", lambda *a, **k: None)
    monkeypatch.setattr(plotting._AggFigures, "close", lambda _self, fig: figs.append(fig))
    return figs


def _numbers(paths):
    loaded = [load_run(p) for p in paths]
    groups, _ = group_runs(loaded)
    return groups, {r.path: run_numbers(r) for r in loaded}


def test_hierarchy_of_one_run_is_one_marker_per_subset_and_fits_a_page(
    six_task_runs, drawn, tmp_path
):
    groups, numbers = _numbers(six_task_runs[:1])
    hierarchical_complexity.subset_complexity(groups[0], numbers, tmp_path / "h.png")
    fig = drawn[0]
    assert fig.get_figwidth() * DPI <= 1300
    ax = fig.axes[0]
    assert len(ax.get_xticks()) == 63
    assert len(ax.collections) == 1  # min, median and max of one run are one point
    assert [t.get_text() for t in ax.get_legend().get_texts()] == ["s0"]


def test_hierarchy_of_several_runs_shows_their_range(six_task_runs, drawn, tmp_path):
    groups, numbers = _numbers(six_task_runs)
    hierarchical_complexity.subset_complexity(groups[0], numbers, tmp_path / "h.png")
    labels = [t.get_text() for t in drawn[0].axes[0].get_legend().get_texts()]
    assert labels == ["max over runs", "median over runs", "min over runs"]


def test_value_labels_stand_clear_of_their_markers(six_task_runs, drawn, tmp_path):
    groups, numbers = _numbers(six_task_runs)
    plots.normalised_vs_single(groups[0], numbers, tmp_path / "s.png")
    fig = drawn[0]
    ax = fig.axes[0]
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    labels = [t for t in ax.texts if t.get_text()]
    assert len(labels) == 6
    radius = 6 / 72 * fig.dpi / 2 + 1  # the markers are 6 points wide
    for text in labels:
        box = text.get_window_extent(renderer)
        x, y = ax.transData.transform(text.xy)
        assert not (box.x0 - radius < x < box.x1 + radius and box.y0 - radius < y < box.y1 + radius)


def _series(n):
    steps = np.arange(n)
    return {
        "step": steps,
        "teams": np.ones(n),
        "instructions": np.full(n, 10.0),
        "oldest": np.full(n, np.nan),
        "newest": np.full(n, np.nan),
    }


@pytest.mark.parametrize(("r", "named"), [(0.06, False), (-0.45, True), (0.9, True)])
def test_the_velocity_panel_is_called_a_prediction_only_when_a_register_tracks_it(
    drawn, tmp_path, r, named
):
    n = 400
    prediction = {
        "velocity": np.sin(np.arange(n) / 9),
        "register": np.cos(np.arange(n) / 9),
        "r": r,
        "label": "b1.m0",
        "variable": "theta dot",
    }
    figures.time_series("Pendulum", _series(n), prediction, tmp_path / "t.png", "title")
    axes = drawn[0].axes
    assert ("velocity prediction" in axes[3].get_ylabel()) is named
    notes = [t.get_text() for t in axes[3].texts]
    assert any("no register tracks the velocity" in t for t in notes) is not named
    # the running mean of a long episode says its unit
    legend = [t.get_text() for t in axes[0].get_legend().get_texts()]
    assert legend == ["running mean over 10 steps"]
