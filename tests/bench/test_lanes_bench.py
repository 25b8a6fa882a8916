"""``mtpg bench lanes``: both engines on one workload, the same outcomes, faults counted."""

import pytest

from mtpg.bench import lanes_bench
from mtpg.bench.workload import make_workload
from mtpg.cli.main import main


def test_compare_times_both_engines_on_identical_jobs():
    row = lanes_bench.compare(make_workload(12, episodes=4), threads=1, repeats=2, lanes=8)
    assert row["clock"] == "process CPU" and len(row["lanes_vs_scalar_all"]) == 2
    assert row["decisions"] > 0 and row["scalar_decisions_per_s"] > 0
    assert row["lanes_vs_scalar"] == pytest.approx(
        row["lanes_decisions_per_s"] / row["scalar_decisions_per_s"], rel=0.5
    )
    assert isinstance(row["scalar_page_faults"], int) and row["lanes_page_faults"] >= 0


def test_the_first_generation_workload_is_a_fresh_demo_population_on_six_tasks():
    work = lanes_bench.first_generation_workload("demo", seed=3)
    assert len(work.root_ids) == 300 and work.episodes == 6 * 3  # 6 tasks x 3 episodes
    assert work.pointer_fraction == 0.0  # generation 1: every program atomic


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--threads", "1,x"], "mtpg bench lanes: invalid literal"),
        (["--threads", "0"], "mtpg bench lanes: need repeats >= 1"),
        (
            ["--late", "/no/such/run", "--graphs", "2", "--repeats", "1", "--threads", "1"],
            "mtpg bench lanes: /no/such/run: no such run directory",
        ),
    ],
)
def test_bad_input_is_one_line(args, message, capsys):
    with pytest.raises(SystemExit) as stop:
        main(["bench", "lanes", *args])
    assert str(stop.value).startswith(message)
