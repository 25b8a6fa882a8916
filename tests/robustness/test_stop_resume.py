"""A run stopped at any moment, by any signal, resumes into exactly the uninterrupted run.

Moments are hit precisely with the fault-injection points (``mtpg._faults``): the
process signals itself there. The slow set covers 23 moments per signal plus timed kills.
"""

import random
import signal

import pytest

from mtpg.cli.main import main
from stopruns import (
    ARGS,
    EXPECTED_CODES,
    assert_same_run,
    resume_after_stop,
    stop_after,
    stop_at,
)

#: Every named moment of the tiny run (phase:generation), across all its parts.
MOMENTS = [
    "create:0",  # run directory made and locked, config.toml not yet written
    "created:0",
    "evaluate:1",
    "select:1",
    "metrics:1",
    "vary:2",
    "test:2",  # during a test point: rows written, graphs not yet
    "evaluate:3",
    "commit:3",  # champions written, checkpoint not yet
    "checkpoint:3",  # checkpoint in its temporary file
    "committed:3",
    "vary:4",  # mid-variation
    "metrics:4",
    "test:4",
    "select:5",
    "vary:6",
    "test:6",
    "commit:6",
    "checkpoint:6",
    "committed:6",
    "vary:7",
    "commit:7",
    "checkpoint:7",
]


def test_the_moments_pass_every_fault_injection_phase():
    from mtpg._faults import PHASES

    assert {m.split(":")[0] for m in MOMENTS} == set(PHASES)


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    ref = tmp_path_factory.mktemp("ref") / "run"
    assert main(["train", *ARGS, "--out", str(ref)]) == 0
    return ref


def check(reference, run, moments, signame):
    res = stop_at(run, ",".join(f"{m}:{signame}" for m in moments))
    last = all(m.endswith(":7") for m in moments)  # the run's last generation
    if signame != "KILL" and last:  # the generation under way completes the run
        assert res.returncode == 0 and "done:" in res.stderr, res.stderr
    else:
        assert res.returncode == EXPECTED_CODES[signame], res.stderr
    assert "Traceback" not in res.stderr
    done = resume_after_stop(run, ARGS)
    assert done.returncode == 0, done.stderr
    assert_same_run(reference, run)


@pytest.mark.parametrize(
    ("moment", "signame"),
    [("create:0", "KILL"), ("checkpoint:3", "KILL"), ("test:4", "TERM")],
)
def test_stop_and_resume_quick(reference, tmp_path, moment, signame):
    check(reference, tmp_path / "run", [moment], signame)


def test_second_signal_stops_at_once_and_resumes_exactly(reference, tmp_path):
    run = tmp_path / "run"
    res = stop_at(run, "vary:5:TERM,select:5:TERM")
    assert res.returncode == 143
    assert "stopped at once" in res.stderr and "continues from generation 3" in res.stderr
    assert not (run / "checkpoints" / "gen-000005.json.gz").exists()
    assert resume_after_stop(run, ARGS).returncode == 0
    assert_same_run(reference, run)


@pytest.mark.slow
@pytest.mark.parametrize("signame", ["KILL", "TERM"])
@pytest.mark.parametrize("moment", MOMENTS)
def test_stop_and_resume_everywhere(reference, tmp_path, moment, signame):
    check(reference, tmp_path / "run", [moment], signame)


@pytest.mark.slow
@pytest.mark.parametrize("signame", ["HUP", "INT"])
@pytest.mark.parametrize("moment", ["test:4", "vary:5"])
def test_other_stop_signals(reference, tmp_path, moment, signame):
    check(reference, tmp_path / "run", [moment], signame)


@pytest.mark.slow
def test_stopped_twice_then_resumed(reference, tmp_path):
    run = tmp_path / "run"
    assert stop_at(run, "test:2:TERM").returncode == 143
    from stopruns import mtpg

    res = mtpg(
        "train", "--resume", str(run), "--quiet", env={"MTPG_TEST_STOP_AT": "checkpoint:6:KILL"}
    )
    assert res.returncode == -signal.SIGKILL
    assert resume_after_stop(run, ARGS).returncode == 0
    assert_same_run(reference, run)


@pytest.mark.slow
@pytest.mark.parametrize("k", range(8))
def test_timed_random_stops(reference, tmp_path, k):
    rnd = random.Random(1000 + k)
    sig = [signal.SIGKILL, signal.SIGTERM][k % 2]
    run = tmp_path / "run"
    stop_after(run, rnd.uniform(0.5, 6.0), sig)
    done = resume_after_stop(run, ARGS)
    assert done.returncode == 0, done.stderr
    assert_same_run(reference, run)
