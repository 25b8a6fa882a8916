import shutil
import subprocess
import warnings

import numpy as np
import pytest

from mtpg.analysis import plots
from mtpg.analysis.report import build_report
from mtpg.analysis.runs import load_run, normalise_scores, reference_best, vs_single_task
from mtpg.cli.main import main
from mtpg.envs.core import CARTCENTERING, TASK_NAMES
from mtpg.envs.reference import REFERENCE, measure_random, measure_time_optimal_cartcentering
from tinyruns import tiny_args

TINY = [
    *tiny_args(n_elite=3, evaluation__test_interval=2, evaluation__test_episodes=3),
    "--generations",
    "4",
]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("runs")
    dirs = []
    for name, extra in (("s0", []), ("s1", ["--seed", "1"]), ("nomem", ["--no-memory"])):
        assert main(["train", *TINY, *extra, "--out", str(root / name)]) == 0
        dirs.append(root / name)
    return dirs


def test_report_writes_every_figure_without_warnings(runs, tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        index = build_report(runs, tmp_path / "report")
    names = sorted(p.name for p in (tmp_path / "report").glob("*.png"))
    assert names == [
        "ablations.png",
        "hierarchy.png",
        "learning_curves.png",
        "normalised_vs_reference.png",
        "normalised_vs_single.png",
    ]
    page = index.read_text()
    assert page.count("<img ") == 5 and "data:image/png;base64," in page
    for png in names:
        assert (tmp_path / "report" / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_default_report_location(runs, capsys):
    assert main(["report", str(runs[0])]) == 0
    assert (runs[0] / "report" / "index.html").is_file()
    assert not (runs[0] / "report" / "ablations.png").exists()  # one experiment only


@pytest.mark.parametrize(
    "draw",
    [
        plots.learning_curves,
        plots.normalised_vs_single,
        plots.normalised_vs_reference,
        plots.ablations,
        plots.hierarchy,
    ],
)
def test_every_figure_has_labelled_axes_and_a_legend(runs, tmp_path, monkeypatch, draw):
    figs = []
    import matplotlib.pyplot as plt

    monkeypatch.setattr(plots, "_save", lambda fig, path: figs.append(fig) or path)
    monkeypatch.setattr(plt, "close", lambda fig=None: figs.append(fig) if fig else None)
    draw([load_run(p) for p in runs], tmp_path / "x.png")
    fig = figs[0]
    used = [ax for ax in fig.axes if ax.axison]
    assert used
    for ax in used:
        assert ax.get_xlabel() and ax.get_ylabel() and ax.get_title()
        assert ax.get_legend() is not None or fig.legends


def test_normalisation_is_0_for_random_and_1_for_the_reference_controller():
    best, _, captured = measure_time_optimal_cartcentering()
    assert captured == 100
    task = TASK_NAMES[CARTCENTERING]
    ref = reference_best((task,))
    assert normalise_scores({task: best}, ref)[task] == pytest.approx(1.0, abs=1e-12)
    stored = REFERENCE[CARTCENTERING].random
    assert normalise_scores({task: stored}, ref)[task] == 0.0
    # a fresh random agent, on other episodes, scores close to 0
    mean, std = measure_random(CARTCENTERING, n=2000, seed=7, seed_base=5_000_000)
    assert abs(normalise_scores({task: mean}, ref)[task]) < 0.05


def test_multitask_normalised_by_single_task_champions(runs):
    run = load_run(runs[0])
    norm = vs_single_task(run)
    for task in run.tasks:
        if np.isfinite(norm[task]) and run.best_single(task) == run.multitask_scores()[task]:
            assert norm[task] == pytest.approx(1.0)


@pytest.mark.skipif(
    not (shutil.which("chromium") or shutil.which("chromium-browser")),
    reason="Chromium is not installed",
)
def test_report_page_opens_in_headless_chromium(runs, tmp_path):
    index = build_report(runs, tmp_path / "report")
    browser = shutil.which("chromium") or shutil.which("chromium-browser")
    shot = tmp_path / "page.png"
    res = subprocess.run(
        [
            browser,
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--disable-quic",
            "--no-first-run",
            "--disable-background-networking",
            "--disable-component-update",
            "--disable-sync",
            f"--user-data-dir={tmp_path / 'profile'}",
            f"--screenshot={shot}",
            "--window-size=1200,3000",
            index.as_uri(),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert res.returncode == 0, res.stderr
    assert shot.is_file() and shot.stat().st_size > 10_000


def test_evaluate_run_reports_both_normalisations(runs, capsys):
    import json

    assert main(["evaluate", str(runs[0]), "--episodes", "3", "--json"]) == 0
    data = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    run = load_run(runs[0])
    for task, row in data.items():
        assert row["best_single_task"] == run.best_single(task)
        assert "normalised_single_task" in row and "normalised" in row
