"""Runs with validation or resampled training episodes, stopped and resumed, repeat exactly.

The tiny run of ``stopruns`` (commits at 3, 6 and 7) with each option on: killed inside a
generation after the last commit, resumed with ``mtpg train --resume``, every file of the
run directory equals an uninterrupted run's (metrics timing aside).
"""

import pytest

from mtpg.cli.main import main
from stopruns import ARGS, EXPECTED_CODES, assert_same_run, resume_after_stop, stop_at

OPTIONS = {
    "validation": [
        "--set",
        "evaluation.validation_episodes=2",
        "--set",
        "evaluation.validation_top_k=3",
    ],
    # blocks change at generations 3, 5 and 7: the resumed generations 4 and 5 redraw
    "resampling": ["--set", "evaluation.resample_interval=2"],
    "lexicase": ["--set", "team.parent_selection=lexicase"],
    "resampling-mean": [
        "--set",
        "evaluation.resample_interval=2",
        "--set",
        "evaluation.resample_mean=true",
    ],
}


@pytest.mark.parametrize("option", sorted(OPTIONS))
def test_killed_mid_generation_and_resumed_equals_the_uninterrupted_run(tmp_path, option):
    args = [*ARGS, *OPTIONS[option]]
    ref = tmp_path / "ref"
    assert main(["train", *args, "--out", str(ref)]) == 0
    header = (ref / "metrics.csv").read_text().splitlines()[0]
    assert ("validation_decisions" in header) == (option == "validation")
    assert ("reevaluated_roots" in header) == option.startswith("resampling")
    assert ('parent_selection = "lexicase"' in (ref / "config.toml").read_text()) == (
        option == "lexicase"
    )
    run = tmp_path / "run"
    res = stop_at(run, "select:5:KILL", args)
    assert res.returncode == EXPECTED_CODES["KILL"], res.stderr
    done = resume_after_stop(run, args)
    assert done.returncode == 0, done.stderr
    assert_same_run(ref, run)
