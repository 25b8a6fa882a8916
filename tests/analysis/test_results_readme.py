"""``mtpg.analysis.results.readme``: the results page and its figures, from run directories."""

import re
import shutil
from pathlib import Path

import pytest

from mtpg.analysis.results import readme as results_readme
from stopruns import mtpg
from tinyruns import tiny_args
from toolmodules import load_tool


def _tiny_run(out, preset, seed, generations, *flags):
    """Trains a tiny run of ``preset`` (two tasks, test point every 2) into ``out``."""
    settings = tiny_args(
        "CartPole,MountainCar", root_size=16, n_elite=2, evaluation__test_interval=2
    )
    done = mtpg(
        "train", "--preset", preset, "--seed", str(seed), *flags, *settings,
        "--set", "evaluation.test_episodes=5", "--generations", str(generations),
        "--out", str(out),
    )  # fmt: skip
    assert done.returncode == 0, done.stderr


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    folder = tmp_path_factory.mktemp("results")
    for name, seed, flags in (
        ("TPG-seed1", 1, []),
        ("TPG-seed2", 2, []),
        ("TPG-NoMemory-seed1", 1, ["--no-memory"]),
    ):
        _tiny_run(folder / "runs" / name, "paper", seed, 4, *flags)
    return folder


def test_the_page_links_every_figure_it_draws_and_names_every_run(results):
    readme = results_readme.build(results, analyze=True)
    text = readme.read_text()
    links = re.findall(r"!\[[^]]*\]\(([^)]+)\)", text)
    assert any(link.startswith("figures/") for link in links)
    assert any(link.startswith("analysis/") for link in links)
    for link in links:
        assert (results / link).is_file(), link
    drawn = {f"{p.parent.name}/{p.name}" for p in results.glob("*/*.png")}
    assert drawn <= set(links), drawn - set(links)  # every figure drawn is on the page
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
    _tiny_run(folder / "runs" / "TPG-seed3", "paper", 3, 4)
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
    check_resume = load_tool("check_resume")

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
    from mtpg.analysis.results.tables import ablation_verdict

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


def test_tpg_robust_has_its_own_section_beside_the_paper_s_experiment(results, tmp_path):
    folder = tmp_path / "results"
    shutil.copytree(results / "runs", folder / "runs")
    _tiny_run(folder / "runs" / "TPG-robust-seed1", "robust", 1, 2)
    text = results_readme.build(folder, analyze=False, probe=True).read_text()
    section = text[text.index("## TPG-robust") : text.index("## Cost")]
    assert "**In progress**: 1 of 5 TPG-robust runs begun" in section
    assert "compared at generation 2" in section
    seeds = [ln.split(" | ")[0] for ln in section.splitlines() if ln.startswith("| TPG-")]
    # seed by seed: TPG then TPG-robust of seed 1 (both tables: scores, then the probe)
    assert seeds[:3] == ["| TPG-seed1", "| TPG-robust-seed1", "| TPG-seed2"]
    assert "| TPG-robust (1 run) |" in section and "P(TPG-robust > TPG) = " in section
    assert "| paper (10 runs) | 5 of 10 | 1 of 10 |" in section
    assert "| TPG-robust-seed1 | 2 | " in section  # the probe of its latest champion
    # the paper's experiment is of the other runs; TPG-robust is listed with them
    assert "| TPG-robust-seed1 | TPG-robust | 1 | 2 of 1000 (growing) |" in text
    assert "IQM over TPG seeds and all tasks" in text
    assert "**Does it reproduce" not in text  # answered once all five runs are there
    assert "TPG (evaluation." not in text  # no group label naming a differing setting


def test_robust_section_helpers():
    from mtpg.analysis.results import robust_section as rs

    assert rs.seed_of("TPG-robust-seed12") == 12 and rs.is_robust(Path("x/TPG-robust-seed1"))
    assert not rs.is_robust(Path("TPG-seed1"))
    with pytest.raises(ValueError, match="seedN"):
        rs.seed_of("TPG-robust")
    vs = [{"a": 0.6, "b": 0.95}, {"a": 0.59, "b": 1.0}, {"a": 0.9, "b": 0.9}]
    assert (rs.reaching(vs, 0.6), rs.reaching(vs, 0.9)) == (2, 1)
    rows = rs.seed_rows(
        [("TPG-robust-seed2", 5, {"a": 0.5, "b": 0.1}), ("TPG-seed2", 5, {"a": 1.0, "b": 0.0})],
        ("a", "b"),
    )
    assert rows == [
        ["TPG-seed2", "5", "1.00", "0.00", "0.00", "0.50"],
        ["TPG-robust-seed2", "5", "0.50", "0.10", "0.10", "0.30"],
    ]


def test_robust_runs_that_reached_the_target_are_compared_there():
    from types import SimpleNamespace as Run

    from mtpg.analysis.results import robust_section as rs

    done, mid, young = (
        Run(final_generation=1000),
        Run(final_generation=640),
        Run(final_generation=90),
    )
    # the finished runs at the target; the growing ones wait (they would pull it back)
    assert rs.compared_runs([done, young, done], 1000) == ([done, done], 1000)
    # none there yet: every run, at the latest test point all have reached
    assert rs.compared_runs([mid, young], 1000) == ([mid, young], 90)


def _comparison(tpg_scores, robust_scores, vs_scale=1.0):
    """A comparison of hand-made scores (``vs``: the scores times ``vs_scale``)."""
    from types import SimpleNamespace as Run

    import numpy as np

    from mtpg.analysis.results import robust_section as rs

    tasks = ["A", "B", "C"]
    groups = {
        label: [Run(name=f"{prefix}{i + 1}") for i in range(len(scores))]
        for label, prefix, scores in (
            ("TPG", "TPG-seed", tpg_scores),
            ("TPG-robust", "TPG-robust-seed", robust_scores),
        )
    }
    norm = {
        run.name: dict(zip(tasks, row, strict=True))
        for label, scores in (("TPG", tpg_scores), ("TPG-robust", robust_scores))
        for run, row in zip(groups[label], scores, strict=True)
    }
    vs = {name: {t: v * vs_scale for t, v in n.items()} for name, n in norm.items()}
    matrices = {
        label: np.array([[norm[r.name][t] for t in tasks] for r in runs])
        for label, runs in groups.items()
    }
    return rs.Comparison(tasks, groups, 1000, [], 0, norm, vs, matrices)


def test_the_answer_says_not_yet_until_the_paper_s_counts_are_met():
    from mtpg.analysis.results import robust_section as rs

    tpg = [[0.5, 0.4, 0.2]] * 4
    robust = [[0.95, 0.4, 0.7], [0.92, 0.3, 0.8], [0.99, 0.95, 0.65], [0.9, 0.5, 0.1]]
    [text] = rs.answer(_comparison(tpg, robust))
    assert text.startswith("**Does it reproduce the paper? Not yet.**")
    assert "0 of 4 TPG runs have an all-task champion" in text
    assert "better in A and C and level in B" in text
    # the best run by its worst task: seed 3, under 0.9 only in C
    assert "best run (TPG-robust-seed3) scores 0.9 or more of the reference best in 2 of 3" in text
    assert "and 0.65 in C (the paper's best run: at least 0.9 in 4 of 6" in text
    assert "only 1 of 4 TPG-robust runs reaches 0.6 in all six tasks and none reaches 0.9" in text
    assert text.endswith("B (IQM 0.45) and C (IQM 0.68) stay behind.")
    assert "(the intervals apart)" in text  # TPG's runs are alike: its interval is a point
    [same] = rs.answer(_comparison(robust, robust))
    assert "(the intervals overlap), level in 3 tasks," in same
    # half the runs at 0.6 and one in ten at 0.9 in every task: the paper's counts
    [text] = rs.answer(_comparison(tpg, [[0.95, 0.95, 0.95], [0.7, 0.8, 0.9]]))
    assert text.startswith("**Does it reproduce the paper? Yes.**")
    assert "And 2 of 2 TPG-robust runs reach 0.6 in all six tasks and 1 reaches 0.9" in text


def test_the_cost_is_cpu_time_per_generation_and_names_a_change_of_engine(tmp_path):
    import subprocess

    from mtpg.analysis.results import tables as rt

    def commit(repo, message):
        git = ["git", "-C", str(repo), "-c", "user.name=t", "-c", "user.email=t@t"]
        subprocess.run([*git, "commit", "-q", "--allow-empty", "-m", message], check=True)
        return subprocess.run(
            [*git, "rev-parse", "HEAD"], check=True, capture_output=True, text=True
        ).stdout.strip()

    repo = tmp_path / "repo"
    subprocess.run(["git", "init", "-q", str(repo)], check=True)
    old, lanes, new = commit(repo, "old"), commit(repo, "lanes"), commit(repo, "new")
    head = "from_generation,to_generation,mtpg_commit,started_utc,wall_s,cpu_s,workers\n"
    runs = {}
    for name, rows in (
        ("a", [f"0,10,{old},t,5,30,1", f"10,20,{old},t,5,,1"]),  # no CPU time: left out
        ("b", [f"0,30,{lanes},t,5,60,2"]),
        ("c", [f"0,10,{new},t,5,20,1"]),
    ):
        runs[name] = tmp_path / name
        runs[name].mkdir()
        (runs[name] / "provenance.csv").write_text(head + "\n".join(rows) + "\n")
    assert rt.cpu_seconds_per_generation([runs["a"], runs["b"]]) == 90 / 40
    rt_lane = rt.LANE_ENGINE
    try:
        rt.LANE_ENGINE = lanes
        note = rt.engine_note({"X": [runs["a"]], "Y": [runs["b"], runs["c"]]}, repo)
        assert "X grew with engines before the lane engine; Y grew with the lane engine" in note
        assert rt.engine_note({"X": [runs["b"]], "Y": [runs["c"]]}, repo) == ""  # the same
        assert rt.engine_note({"X": [runs["a"]]}, tmp_path) == ""  # no git here: unsaid
    finally:
        rt.LANE_ENGINE = rt_lane


def test_tpg_authors_joins_tpg_and_tpg_robust_in_a_three_group_section(results, tmp_path):
    folder = tmp_path / "results"
    shutil.copytree(results / "runs", folder / "runs")
    _tiny_run(folder / "runs" / "TPG-robust-seed1", "robust", 1, 2)
    settings = tiny_args(
        "CartPole,MountainCar[noise_high=pi;noise_low=-pi;obs_high=1;obs_low=0]",
        root_size=16, n_elite=2, evaluation__test_interval=2,
    )  # fmt: skip
    done = mtpg(
        "train", "--preset", "paper", "--seed", "1", *settings, "--set",
        "evaluation.test_episodes=5", "--generations", "2",
        "--out", str(folder / "runs" / "TPG-authors-seed1"),
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    text = results_readme.build(folder, analyze=False, probe=True).read_text()
    section = text[text.index("## The three groups") : text.index("## Cost")]
    assert "**In progress**: 1 of 5 TPG-authors runs begun, 1 at generation 2" in section
    # the variant's columns by its base name, normalised on one scale with the others
    assert "| run | generation | CartPole | MountainCar | worst task | mean |" in section
    assert "| TPG-authors (1 run) |" in section and "| TPG-robust (1 run) |" in section
    assert "P(TPG-authors > TPG) = " in section and "P(TPG-authors > TPG-robust) = " in section
    assert "| claim (paper) | TPG: its text |" in section
    assert "| TPG-authors-seed1 | 2 | " in section  # re-scores and the probe
    assert "](figures/three_groups.png)" in section  # the section's table, drawn
    assert (folder / "figures" / "three_groups.png").stat().st_size > 10_000
    assert "| TPG-authors-seed1 | TPG-authors | 1 | 2 of 1000 (growing) |" in text
    # the paper's experiment's re-score table keeps to the runs of its tasks
    assert "TPG-authors-seed1 | 2 | " not in text[: text.index("## The three groups")]


def test_the_authors_sentence_and_the_verdict_on_the_paper_s_claims():
    from types import SimpleNamespace as Run

    import numpy as np

    from mtpg.analysis.results import authors_section as au

    runs = [Run(name=f"TPG-authors-seed{i}") for i in (1, 2)]
    norm = {"TPG-authors-seed1": {"A": 0.9, "B": 0.7}, "TPG-authors-seed2": {"A": 1.0, "B": 0.5}}
    a = au.Authors(runs, runs, 1000, norm, norm, np.array([[0.9, 0.7], [1.0, 0.5]]))
    assert not a.complete and a.count(0.6) == 1 and a.count(0.9) == 0
    assert a.best.name == "TPG-authors-seed1"  # the higher worst task
    text = au.answer_sentence(a)
    assert "(TPG-authors, 2 of 5 runs at generation 1,000 so far)" in text
    assert "1 of 2 runs reaches 0.6 and 0 reach 0.9 of the group's own" in text
    rows = [
        ["x (5 of 10)", "0 of 5: does not hold", "3 of 5: holds", "1 of 2: holds"],
        ["y (1 of 10)", "0 of 5: does not hold", "0 of 5: does not hold", "1 of 2: holds"],
        ["z", "0 of 6: does not hold", "0 of 6: does not hold", "0 of 6: does not hold"],
    ]
    assert au.verdict(rows) == (
        "X: hold with the paper's text (TPG or TPG-robust). Y: hold only with its code's "
        "interface (TPG-authors). Z: hold with neither."
    )
    assert au.base("Pendulum[max_steps=300]") == "Pendulum"


def test_the_complete_answer_is_a_headline_and_three_sentences_one_per_kind_of_claim():
    from types import SimpleNamespace as Run

    import numpy as np

    from mtpg.analysis.results import answer as an
    from mtpg.analysis.results import authors_section as au

    tpg = [[0.5, 0.4, 0.2]] * 4
    robust = [[0.95, 0.4, 0.7], [0.92, 0.3, 0.8], [0.99, 0.95, 0.65], [0.9, 0.5, 0.1]]
    c = _comparison(tpg, robust)
    scores = [[0.9, 0.7, 0.6], [1.0, 0.65, 0.8], [0.95, 0.62, 0.7], [0.8, 0.5, 0.9], [1, 1, 0.3]]
    runs = [Run(name=f"TPG-authors-seed{i + 1}") for i in range(5)]
    norm = {r.name: dict(zip("ABC", row, strict=True)) for r, row in zip(runs, scores, strict=True)}
    a = au.Authors(runs, runs, 1000, norm, norm, np.array(scores))
    [text] = an.three_groups(c, a)
    assert text.startswith("**Does it reproduce the paper? In part.** With the paper's text,")
    body = text.split("**", 2)[2]
    assert body.count(". ") == 2 and body.endswith(".")  # three sentences
    assert "0 of 4 TPG runs and 1 of 4 TPG-robust runs" in text
    assert "in 2 of 3 tasks (the paper's best run: 4 of 6)" in text
    assert "(TPG-authors), 3 of 5 runs reach 0.6 in all six tasks and the IQM is" in text
    assert "P(TPG-authors > TPG-robust) = " in text
    assert "0 of the 13 runs reach 0.9 of their group's best single-task champion" in text
    assert text.endswith("and B and C are among the two weakest tasks of every group.")
    # a task among the two weakest of only some groups is not named
    assert an.weakest(c.estimates, ["A", "B", "C"]) == ["B", "C"]
    per_task = c.estimates["TPG-robust"][0]  # B and C its lowest; reversed: A and B
    both = {"x": (per_task, None), "y": (per_task[::-1], None)}
    assert an.weakest(both, ["A", "B", "C"]) == ["B"]
    # the headline follows the claims' verdict
    assert an.headline({"text": ["x"], "code": [], "neither": []}) == "Yes"
    assert an.headline({"text": ["x"], "code": ["y"], "neither": []}) == (
        "Only with its code's interface"
    )
    assert an.headline({"text": [], "code": [], "neither": ["z"]}) == "No"
