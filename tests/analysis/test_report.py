import json
import re
import shutil
import subprocess
import warnings

import numpy as np
import pytest

from mtpg.analysis.runs import hierarchical_complexity
from mtpg.analysis.runs import score_figures as plots
from mtpg.analysis.runs import statistics_figures as plots_stats
from mtpg.analysis.runs.champions import champion_path
from mtpg.analysis.runs.loading import group_runs, load_run, normalise_scores, reference_best
from mtpg.analysis.runs.report import MixedRunsWarning, build_report
from mtpg.analysis.runs.reported_numbers import best_of, best_single_task, run_numbers
from mtpg.cli.main import main
from mtpg.envs.specs.contract import CARTCENTERING, TASK_NAMES
from mtpg.envs.taskset.reference_scores import (
    REFERENCE,
    measure_random,
    measure_time_optimal_cartcentering,
)
from mtpg.envs.taskset.task_table import TaskTable
from mtpg.io.serialize import load_graph
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


@pytest.fixture(scope="module")
def twelve(tmp_path_factory):
    """A 12-generation run tested every 5 generations."""
    out = tmp_path_factory.mktemp("long") / "g12"
    args = tiny_args(n_elite=3, evaluation__test_interval=5, evaluation__test_episodes=3)
    assert main(["train", *args, "--generations", "12", "--out", str(out)]) == 0
    return out


def test_a_test_point_at_the_last_generation(twelve):
    run = load_run(twelve)
    assert sorted({int(r["generation"]) for r in run.tests}) == [5, 10, 12]
    assert run_numbers(run).generation == 12
    assert champion_path(run).parent.name == "gen-000012"


EXPECTED = [
    "ablations.png",
    "aggregate.png",
    "hierarchy.png",
    "learning_curves.png",
    "normalised_vs_reference.png",
    "normalised_vs_single.png",
    "performance_profile.png",
    "probability_of_improvement.png",
    "training_curves.png",
]


@pytest.fixture(scope="module")
def report(runs, tmp_path_factory):
    """The report of the three runs (two seeds and an ablation), built once."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return build_report(runs, tmp_path_factory.mktemp("report") / "report")


def test_report_writes_every_figure_without_warnings(report):
    names = sorted(p.name for p in report.parent.glob("*.png"))
    assert names == EXPECTED
    page = report.read_text()
    assert page.count("<img ") == len(EXPECTED) and "data:image/png;base64," in page
    for png in names:
        assert (report.parent / png).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.fixture
def quick_png(monkeypatch):
    """Figures saved as stub files (rendering is tested once, by the ``report`` fixture)."""
    import matplotlib.figure

    monkeypatch.setattr(
        matplotlib.figure.Figure, "savefig", lambda self, path, **kw: path.write_bytes(b"png")
    )


def test_default_report_location(runs, capsys, quick_png):
    assert main(["report", str(runs[0])]) == 0
    assert (runs[0] / "report" / "index.html").is_file()
    assert not (runs[0] / "report" / "ablations.png").exists()  # one experiment only


def _cells(page: str, title: str) -> dict[str, list[str]]:
    """Rows of the HTML table under ``title``: run name -> cell texts."""
    table = page.split(f"<h2>{title}</h2>", 1)[1].split("</table>", 1)[0]
    rows = {}
    for tr in re.findall(r"<tr>(.*?)</tr>", table)[1:]:
        cells = re.findall(r"<td>(.*?)</td>", tr)
        rows[cells[1]] = cells[2:]
    return rows


def test_report_evaluate_and_html_agree_on_every_number(runs, report, capsys):
    page = report.read_text()
    test_rows = _cells(page, "Test return of each run&#x27;s all-task champion")
    norm_rows = _cells(page, "Normalised against the reference best")
    single_rows = _cells(page, "Normalised against the run&#x27;s own single-task champions")
    for path in runs:
        run = load_run(path)
        n = run_numbers(run)
        capsys.readouterr()
        assert main(["evaluate", str(path), "--json"]) == 0
        data = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
        for k, task in enumerate(run.tasks):
            row = data[task]
            assert row["episodes"] == n.episodes == 3  # the run's own test episodes
            assert row["mean"] == n.test[task]  # same graph, same episodes: bit for bit
            assert row["normalised"] == n.normalised[task]
            vs = row["normalised_single_task"]
            assert (vs is None and np.isnan(n.vs_single[task])) or vs == n.vs_single[task]
            assert row["single_task_champion"] == n.single[task]
            assert test_rows[run.name][k] == f"{n.test[task]:.3f}"
            assert norm_rows[run.name][k] == f"{n.normalised[task]:.3f}"
            expect = "n/a" if np.isnan(n.vs_single[task]) else f"{n.vs_single[task]:.3f}"
            assert single_rows[run.name][k] == expect
        assert f"final generation {n.generation}, 3 test episodes per task" in page


def test_numbers_use_training_selection_not_test_scores(runs):
    run = load_run(runs[0])
    n = run_numbers(run)
    final = run.final_generation
    # the single-task denominators are the single-task champions at the final generation,
    # whatever their earlier test scores
    for task in run.tasks:
        assert n.single[task] == float(run.row(task, final)[f"test_{task}"])
    # training scores are recomputed from the graph and equal what selection used
    _, _, meta = load_graph(runs[0] / "champions" / "CartPole+CartCentering.json")
    assert meta["generation"] == final
    assert n.train == pytest.approx(meta["train_scores"], abs=0)
    # the best run is the one with the highest minimum normalised training score
    all_n = [run_numbers(load_run(p)) for p in runs[:2]]
    assert best_of(all_n).selection_score == max(x.selection_score for x in all_n)
    # the shared single-task denominator (Fig. 7, results page) is the best run's per task
    best = best_single_task(all_n)
    for task in run.tasks:
        assert best[task] == max(x.single[task] for x in all_n)


def test_mixed_configurations_are_grouped_labelled_and_warned(
    runs, twelve, tmp_path, capsys, quick_png
):
    loaded = [load_run(p) for p in [*runs, twelve]]
    groups, warns = group_runs(loaded)
    labels = [g.label for g in groups]
    assert [len(g.runs) for g in groups] == [2, 1, 1]
    assert labels[0].startswith("TPG (") and "generations=4" in labels[0]
    assert "generations=12" in labels[1] and labels[2] == "TPG-NoMemory"
    assert any("generations" in w for w in warns) and any("test_interval" in w for w in warns)
    # seeds and an ablation alone are not a mixture
    assert group_runs(loaded[:3])[1] == []
    assert main(["report", *map(str, runs), str(twelve), "--out", str(tmp_path / "m2")]) == 0
    err = capsys.readouterr().err
    assert "warning: runs differ in generations" in err
    assert "Warning: runs differ" in (tmp_path / "m2" / "index.html").read_text()


FIGURES = [
    lambda g, n, p: plots.learning_curves(g[0], n, p),
    lambda g, n, p: plots.normalised_vs_single(g[0], n, p),
    lambda g, n, p: plots.normalised_vs_reference(g[0], n, p),
    lambda g, n, p: plots.ablations(g, n, p),
    lambda g, n, p: hierarchical_complexity.subset_complexity(g[0], n, p),
    lambda g, n, p: plots_stats.aggregate(
        g, n, {x.label: plots_stats.group_estimates(x, n) for x in g}, p
    ),
    lambda g, n, p: plots_stats.profile(g, n, p),
    lambda g, n, p: plots_stats.improvement(g, n, plots_stats.improvements(g, n), p),
]


@pytest.mark.parametrize("draw", FIGURES)
def test_every_figure_is_labelled_and_states_its_numbers(runs, tmp_path, monkeypatch, draw):
    figs = []
    import matplotlib.figure

    from mtpg.analysis import plotting

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", lambda *a, **k: None)  # fast
    monkeypatch.setattr(plotting._AggFigures, "close", lambda _self, fig: figs.append(fig))
    loaded = [load_run(p) for p in runs]
    groups, _ = group_runs(loaded)
    numbers = {r.path: run_numbers(r) for r in loaded}
    draw(groups, numbers, tmp_path / "x.png")
    fig = figs[0]
    used = [ax for ax in fig.axes if ax.axison]
    assert used
    for ax in used:
        assert ax.get_xlabel() and ax.get_ylabel() and (ax.get_title() or fig._suptitle)
        assert ax.get_legend() is not None or fig.legends
    caption = " ".join(t.get_text() for t in fig.texts).replace("\n", " ")
    assert "held-out episodes" in caption and "3 held-out" in caption  # how many episodes
    assert "training score" in caption  # the selection rule
    assert "generation" in caption  # at which generation


def test_normalisation_is_0_for_random_and_1_for_the_reference_controller():
    best, _, captured = measure_time_optimal_cartcentering()
    assert captured == 100
    task = TASK_NAMES[CARTCENTERING]
    table = TaskTable.from_names([task])
    ref = reference_best(table)
    assert normalise_scores({task: best}, ref, table)[task] == pytest.approx(1.0, abs=1e-12)
    stored = REFERENCE[CARTCENTERING].random
    assert normalise_scores({task: stored}, ref, table)[task] == 0.0
    # a fresh random agent, on other episodes, scores close to 0
    mean, std = measure_random(CARTCENTERING, n=2000, seed=7, seed_base=5_000_000)
    assert abs(normalise_scores({task: mean}, ref, table)[task]) < 0.05


def test_mixture_warning_is_a_python_warning(runs, twelve, monkeypatch, tmp_path):
    monkeypatch.setattr("mtpg.analysis.runs.report.run_numbers", lambda run: 1 / 0)
    with pytest.warns(MixedRunsWarning), pytest.raises(ZeroDivisionError):
        build_report([runs[0], twelve], tmp_path / "x")  # warned before any number is made


@pytest.mark.skipif(
    not (shutil.which("chromium") or shutil.which("chromium-browser")),
    reason="Chromium is not installed",
)
def test_report_page_opens_in_headless_chromium(report, tmp_path):
    index = report
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


def test_report_has_the_memorisation_probe_of_every_run(runs, report, capsys):
    page = report.read_text()
    title = "Memorisation probe: training episodes, fresh noise, held-out episodes"
    rows = _cells(page, title)
    assert sorted(rows) == sorted(p.name for p in runs)
    for path in runs:
        capsys.readouterr()
        assert main(["probe", str(path), "--json"]) == 0
        data = json.loads(capsys.readouterr().out)
        run = load_run(path)
        n = run_numbers(run)
        for k, task in enumerate(run.tasks):
            row = data["tasks"][task]
            sets = [row[s]["normalised"] for s in ("train", "fresh_noise", "test")]
            assert rows[path.name][k + 2] == " / ".join(f"{v:.2f}" for v in sets)
            assert row["test"]["normalised"] == n.normalised[task]  # the report's own test
        assert rows[path.name][:2] == [str(n.generation), "0..1"]  # (a): two training episodes


def test_training_scores_of_a_resampled_run_are_on_its_last_block(tmp_path):
    out = tmp_path / "robust"
    args = tiny_args(n_elite=3, evaluation__test_episodes=3, evaluation__resample_interval=1)
    assert main(["train", *args, "--generations", "3", "--seed", "2", "--out", str(out)]) == 0
    run = load_run(out)
    _, _, meta = load_graph(out / "champions" / "CartPole+CartCentering.json")
    assert meta["generation"] == run.final_generation == 3
    assert run_numbers(run).train == meta["train_scores"]  # block 2, not seeds 0..1
