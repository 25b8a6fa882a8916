"""``tools/results_readme.py``: the results page and its figures, from run directories alone."""

import re
import shutil
import sys
from pathlib import Path

import pytest

from stopruns import mtpg
from tinyruns import tiny_args

sys.path.insert(0, str(Path(__file__).parents[2] / "tools"))
import results_readme


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    folder = tmp_path_factory.mktemp("results")
    settings = tiny_args(
        "CartPole,MountainCar", root_size=16, n_elite=2, evaluation__test_interval=2
    )
    for name, seed, flag in (
        ("TPG-seed1", 1, []),
        ("TPG-seed2", 2, []),
        ("TPG-NoMemory-seed1", 1, ["--no-memory"]),
    ):
        done = mtpg(
            "train",
            "--preset",
            "paper",
            "--seed",
            str(seed),
            *flag,
            *settings,
            "--set",
            "evaluation.test_episodes=5",
            "--generations",
            "4",
            "--out",
            str(folder / "runs" / name),
        )
        assert done.returncode == 0, done.stderr
    return folder


def test_the_page_links_every_figure_it_draws_and_names_every_run(results):
    readme = results_readme.build(results, analyze=True)
    text = readme.read_text()
    links = re.findall(r"!\[[^]]*\]\(([^)]+)\)", text)
    assert any(link.startswith("figures/") for link in links)
    assert any(link.startswith("analysis/") for link in links)
    for link in links:
        assert (results / link).is_file(), link
    for name in ("TPG-seed1", "TPG-seed2", "TPG-NoMemory-seed1"):
        assert f"| {name} |" in text
    assert "**In progress**" in text  # 4 of 1,000 generations
    assert not (results / "figures" / "index.html").exists()


def test_the_page_quotes_the_numbers_of_the_report(results):
    from mtpg.analysis.runs.loading import load_run
    from mtpg.analysis.runs.reported_numbers import run_numbers

    text = results_readme.build(results, analyze=False).read_text()
    for name in ("TPG-seed1", "TPG-NoMemory-seed1"):
        n = run_numbers(load_run(results / "runs" / name))
        cells = [f"{n.normalised[t]:.2f}" for t in n.run.tasks]
        assert f"| {name} | {n.generation} | " + " | ".join(cells) + " |" in text


def test_the_page_gives_each_champion_test_return_with_its_interval(results):
    from mtpg.analysis.runs.loading import load_run
    from mtpg.analysis.runs.reported_numbers import run_numbers

    text = results_readme.build(results, analyze=False).read_text()
    n = run_numbers(load_run(results / "runs" / "TPG-seed2"))
    row = next(
        line for line in text.splitlines() if line.startswith("| TPG-seed2 |") and "±" in line
    )
    means = [float(cell.split("±")[0]) for cell in row.split("|")[3:-1]]
    assert means == [float(f"{n.test[t]:.4g}") for t in n.run.tasks]
    # the count of re-scores within sqrt(2) half-widths is of every (run, task) cell
    found = re.search(r"that close in (\d+) of (\d+) cells", text)
    assert found and int(found[1]) <= int(found[2]) == 3 * len(n.run.tasks)


def test_summaries_leave_out_runs_still_growing_once_some_are_finished(
    results, tmp_path, monkeypatch
):
    import shutil

    folder = tmp_path / "results"
    shutil.copytree(results / "runs", folder / "runs")
    settings = tiny_args(
        "CartPole,MountainCar", root_size=16, n_elite=2, evaluation__test_interval=2
    )
    done = mtpg(
        "train", "--preset", "paper", "--seed", "3", *settings,
        "--set", "evaluation.test_episodes=5", "--generations", "4",
        "--out", str(folder / "runs" / "TPG-seed3"),
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    tests = folder / "runs" / "TPG-seed3" / "tests.csv"  # as if still growing: test point 2
    head, *rows = tests.read_text().splitlines()
    column = head.split(",").index("generation")
    tests.write_text("\n".join([head, *(r for r in rows if int(r.split(",")[column]) <= 2)]) + "\n")
    monkeypatch.setattr(results_readme, "TARGET", 4)  # seeds 1 and 2 are finished
    text = results_readme.build(folder, analyze=False).read_text()
    assert "are of the 2 TPG runs at generation 4 (TPG-seed1, TPG-seed2)" in text
    assert "| TPG-seed3 | 2 | " in text  # still listed, at its latest test point
    assert "IQM over TPG seeds at generation 4 |" in text
    assert "Best TPG run: **TPG-seed" in text and "Best TPG run: **TPG-seed3**" not in text


def test_the_page_shows_the_recorded_resume_check(results, tmp_path):
    import check_resume

    page = tmp_path / "results"
    shutil.copytree(results / "runs", page / "runs")
    row = dict.fromkeys(check_resume.RECORD_COLUMNS, "")
    row |= {"run": "TPG-seed1", "resumed_from_commit": "a" * 40, "from_generation": "2"}
    row |= {"to_generation": "4", "metrics_rows": "2", "test_rows": "9", "result": "equal"}
    row |= {"mtpg_commit": "b" * 40, "checked_utc": "2026-12-03T18:00:00Z"}
    check_resume.record(page / check_resume.RECORD, [row])
    text = results_readme.build(page, analyze=False).read_text()
    assert "tools/check_resume.py --record" in text
    assert "| TPG-seed1 | aaaaaaaaaa | 2 -> 4 | 2 metrics, 9 tests | equal | bbbbbbbbbb |" in text


def test_the_paper_s_ablation_claims_are_read_as_stated_rules():
    from results_text import ablation_verdict

    tasks = ("CartPole", "Pendulum", "MountainCarContinuous")

    def vs(*values):
        return dict(zip(tasks, values, strict=True))

    assert ablation_verdict("TPG", vs(0.9, 0.86, 1.1)) == "as the paper"
    assert ablation_verdict("TPG", vs(0.9, 0.84, 1.1)) == "below 0.85 in Pendulum"
    assert ablation_verdict("TPG-NoXover", vs(0.8, 0.95, 1.0)) == "as the paper"
    assert ablation_verdict("TPG-NoXover", vs(0.79, 0.95, float("nan"))) == (
        "below 0.80 in CartPole, MountainCarContinuous"
    )
    assert ablation_verdict("TPG-NoMemory", vs(0.1, 0.49, 0.0)) == "as the paper"
    assert ablation_verdict("TPG-NoMemory", vs(0.1, 0.5, 0.7)) == (
        "0.5 or more in Pendulum, MountainCarContinuous"
    )
    assert ablation_verdict("TPG-NoHierarchy", vs(0.1, 0.79, 0.8)) == "as the paper"
    assert ablation_verdict("TPG-NoHierarchy", vs(0.9, 0.2, 0.5)) == "0.8 or more in CartPole"
    assert ablation_verdict("TPG-NoHierarchy", vs(0.1, 0.2, 0.5)) == "0.8 or more in no task"
