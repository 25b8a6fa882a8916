"""Experiments pass stop signals on to their training processes.

Stand-in processes (a few lines of Python, instead of ``mtpg train``) record the signals
they receive; the stop request is a stand-in for :class:`GracefulStop` whose ``signum``
becomes set once the first process is ready to receive it.
"""

from __future__ import annotations

import os
import signal
import sys
import time
from pathlib import Path

import pytest

from mtpg.evolve import experiment
from mtpg.evolve.experiment import execute, plan
from mtpg.evolve.stopping import StopNow

CHILD = r"""
import os, signal, sys, time
from pathlib import Path
out, mode = Path(sys.argv[1]), sys.argv[2]
got = []
def handle(signum, frame):
    got.append(signum)
    (out / "signals").write_text(" ".join(map(str, got)))
    if mode == "stoppable" or len(got) == 2:
        sys.exit(128 + signum)
for s in (signal.SIGTERM, signal.SIGINT):
    signal.signal(s, handle)
(out / "ready").write_text(str(os.getsid(0)))
if mode == "exit130":
    sys.exit(130)
end = time.time() + 5
while time.time() < end:
    time.sleep(0.01)
"""


def stand_in(monkeypatch, modes: dict[str, str]) -> None:
    def command(self, train_args, generations, workers):
        self.path.mkdir(parents=True, exist_ok=True)
        return [sys.executable, "-c", CHILD, str(self.path), modes[self.path.name]]

    monkeypatch.setattr(experiment.PlannedRun, "command", command)


class FakeStop:
    """``signum`` is set once ``ready`` exists; optionally a second signal follows."""

    def __init__(self, ready: Path, signum: int, second: Path | None = None) -> None:
        self.ready, self.value, self.second, self.raised = ready, signum, second, False

    @property
    def signum(self) -> int | None:
        if not self.ready.exists():
            return None
        if self.second is not None and self.second.exists() and not self.raised:
            self.raised = True  # the first signal arrived: now the second one
            raise StopNow(self.value)
        return self.value


def wait_for(path: Path) -> None:
    end = time.monotonic() + 20
    while not path.exists():
        assert time.monotonic() < end, f"{path} never appeared"
        time.sleep(0.01)


def test_a_stop_is_passed_on_once_and_no_further_run_starts(tmp_path, monkeypatch) -> None:
    runs = plan(tmp_path / "exp", seeds=2, ablation_seeds=0)
    stand_in(monkeypatch, {r.path.name: "stoppable" for r in runs})
    stop = FakeStop(runs[0].path / "ready", signal.SIGTERM)
    lines: list[str] = []
    assert execute(runs, [], generations=2, log=lines.append, stop=stop) == []
    assert lines == ["TPG-seed0: new -> starting", "TPG-seed0: stopped"]
    assert (runs[0].path / "signals").read_text() == str(int(signal.SIGTERM))
    assert not runs[1].path.exists()  # never started
    # a session of its own: a Ctrl-C at the terminal reaches it only through us
    assert int((runs[0].path / "ready").read_text()) != os.getsid(0)


def test_exit_status_above_128_without_a_stop_is_a_failure(tmp_path, monkeypatch) -> None:
    runs = plan(tmp_path / "exp", seeds=1, ablation_seeds=0)
    stand_in(monkeypatch, {runs[0].path.name: "exit130"})
    never = FakeStop(tmp_path / "never", signal.SIGTERM)
    lines: list[str] = []
    assert execute(runs, [], generations=2, log=lines.append, stop=never) == runs
    assert lines == ["TPG-seed0: new -> starting", "TPG-seed0: failed (130)"]


def test_a_second_signal_is_passed_on_before_stopping(tmp_path, monkeypatch) -> None:
    runs = plan(tmp_path / "exp", seeds=1, ablation_seeds=0)
    stand_in(monkeypatch, {runs[0].path.name: "stubborn"})
    out = runs[0].path
    stop = FakeStop(out / "ready", signal.SIGINT, second=out / "signals")
    with pytest.raises(StopNow):
        execute(runs, [], generations=2, log=lambda _: None, stop=stop)
    sigint = str(int(signal.SIGINT))
    assert (out / "signals").read_text() == f"{sigint} {sigint}"  # and it was waited for


def test_stop_now_from_elsewhere_terminates_the_running_processes(tmp_path, monkeypatch) -> None:
    runs = plan(tmp_path / "exp", seeds=2, ablation_seeds=0)
    stand_in(monkeypatch, {r.path.name: "stoppable" for r in runs})

    def log(line: str) -> None:
        if line == "TPG-seed1: new -> starting":
            wait_for(runs[0].path / "ready")
            raise StopNow(signal.SIGINT)  # e.g. an outer handler, no stop passed in

    with pytest.raises(StopNow):
        execute(runs, [], generations=2, parallel=2, log=log)
    assert (runs[0].path / "signals").read_text() == str(int(signal.SIGTERM))
