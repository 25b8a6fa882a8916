import contextlib
import io
from types import SimpleNamespace

from mtpg.cli.main import main
from mtpg.cli.progress import ExperimentProgress, Progress, fmt_duration, last_test
from tinyruns import tiny_args


def row(gen, **extra):
    base = {
        "generation": gen,
        "decisions_per_s": 2.5e6,
        "teams_per_decision": 1.25,
        "best_CartPole": 200.0,
        "best_MountainCar": -150.0,
        "t_total": 1.0,
        "t_test": 0.0,
    }
    return {**base, **extra}


def test_header_names_every_column_and_lines_show_test_and_eta(tmp_path):
    tests = tmp_path / "tests.csv"
    tests.write_text(
        "generation,subset,root,graph_teams,teams_per_decision,test_CartPole,test_MountainCar\n"
        "5,CartPole+MountainCar,7,3,1.5,70.25,-200.0\n"
    )
    out = io.StringIO()
    p = Progress(
        10,
        ("CartPole", "MountainCar"),
        out,
        live=False,
        tests_file=tests,
        train_episodes=3,
        test_episodes=20,
    )
    p.begin(0)
    p(row(1))
    assert "left ? " in out.getvalue()  # no estimate from the compiling generation alone
    p._durations = [8.0, 2.0, 2.0]  # compilation, then two 2-second generations
    assert p.eta(4) == 12.0  # 6 generations left x 2 s, compilation left out
    p(row(5, t_test=0.5))
    text = out.getvalue()
    header = text.split("gen 1/10")[0]
    for words in (
        "train best",
        "best training score of any root",
        "test@G",
        "20 held-out episodes",
        "left = estimated time left",
        "s/gen",
        "CP = CartPole",
        "MC = MountainCar",
        "mean of 3 training episodes",
    ):
        assert words in header, words
    assert "gen 1/10: compiling" in text  # before the first generation appears
    last = text.strip().splitlines()[-1]
    assert "test@5 CP 70.25 MC -200" in last and "train best CP 200 MC -150" in last
    assert "left " in last and "s/gen" in last


def test_train_prints_header_compiling_line_and_final_test(tmp_path, capsys):
    args = tiny_args(quiet=False, evaluation__test_interval=5, evaluation__test_episodes=3)
    assert main(["train", *args, "--generations", "7", "--out", str(tmp_path / "r")]) == 0
    err = capsys.readouterr().err
    assert err.index("columns:") < err.index("compiling") < err.index("gen 1/7 |")
    assert err.index("teams/dec = teams visited per decision") < err.index("compiling")
    assert "test@7 " in err.strip().splitlines()[-2]  # the last generation is a test point
    assert last_test(tmp_path / "r" / "tests.csv", "CartPole+CartCentering")[0] == 7
    assert main(["train", "--resume", str(tmp_path / "r")]) == 0  # finished: nothing to do
    err = capsys.readouterr().err
    assert "compiling" not in err and "gen 8/7" not in err
    assert err.strip().endswith(f"done: {tmp_path / 'r'}")


def test_experiment_progress_reads_each_runs_metrics(tmp_path):
    runs = []
    for name, gens in (("a", 3), ("b", 1), ("c", 0)):
        d = tmp_path / name
        d.mkdir()
        if gens:
            (d / "metrics.csv").write_text(
                "generation,roots\n" + "".join(f"{g},1\n" for g in range(1, gens + 1))
            )
        runs.append(SimpleNamespace(path=d))
    lines = []
    watch = ExperimentProgress(runs, 3, lines.append, interval=0.01)
    text = watch.status()
    assert text.startswith("progress 1/3 runs done")
    assert "b gen 1/3" in text and "c waiting" in text and "a gen" not in text
    watch.start()
    (tmp_path / "c" / "metrics.csv").write_text("generation,roots\n1,1\n")
    import time

    deadline = time.monotonic() + 5
    while not any("c gen 1/3" in line for line in lines) and time.monotonic() < deadline:
        time.sleep(0.02)
    watch.stop()
    assert any("c gen 1/3" in line for line in lines)


def test_durations():
    assert [fmt_duration(s) for s in (5, 187, 7500)] == ["5s", "3m07s", "2h05m"]


def test_a_live_line_fits_the_terminal_width(monkeypatch):
    """Wider than the terminal, a live line would wrap and leave fragments behind."""
    import io
    import os
    import shutil

    from mtpg.cli.progress import Progress

    tasks = (
        "CartPole",
        "Acrobot",
        "CartCentering",
        "Pendulum",
        "MountainCar",
        "MountainCarContinuous",
    )
    row = {"generation": 3, "t_total": 1.0, "decisions_per_s": 1.5e6, "teams_per_decision": 1.9}
    row.update({f"best_{t}": -123.456 for t in tasks})
    for columns in (80, 40):
        size = os.terminal_size((columns, 24))
        monkeypatch.setattr(shutil, "get_terminal_size", lambda *_a, s=size: s)
        live = io.StringIO()
        progress = Progress(10, tasks, stream=live, live=True)
        progress.begin(0)
        progress(row)
        written = live.getvalue().split("tasks: ", 1)[1].split("\n", 1)[1]  # after the header
        assert "\n" not in written  # one line, rewritten in place (tqdm's carriage returns)
        lines = [text.rstrip() for text in written.split("\r") if text.strip()]
        assert len(lines) == 2
        assert all(len(text) <= columns - 1 for text in written.split("\r"))  # padding too
        assert lines[0].startswith("gen 1/10: compiling")
        assert lines[-1].startswith("gen 3/10 |") and lines[-1].endswith("...")
        progress.close()
        assert live.getvalue().endswith("\n") and live.getvalue().count("\n") == 6
        progress.close()  # twice is harmless
    logged = io.StringIO()
    progress = Progress(10, tasks, stream=logged, live=False)
    progress(row)
    assert "teams/dec 1.90" in logged.getvalue()  # a log keeps the whole line
    assert "\r" not in logged.getvalue()  # and has no live line


def test_log_messages_go_above_a_live_line(monkeypatch):
    """A warning while the line is live gets a line of its own; the status line is redrawn."""
    import io
    import logging
    import sys

    from mtpg.cli.progress import Progress

    live = io.StringIO()
    monkeypatch.setattr(sys, "stderr", live)  # the CLI's handler writes to standard error
    handler = logging.StreamHandler(sys.stderr)
    logger = logging.getLogger("mtpg")
    logger.addHandler(handler)
    progress = Progress(10, ("CartPole",), stream=live, live=True)
    try:
        progress.begin(0)
        with progress.messages():
            logger.warning("something to say")
    finally:
        logger.removeHandler(handler)
        progress.close()
    after = live.getvalue().split("tasks: CP = CartPole\n", 1)[1]
    assert after.startswith("\rgen 1/10: compiling")
    # the line is cleared, the message written on a line of its own, the line redrawn
    assert "\rsomething to say\n\rgen 1/10: compiling" in after
    assert after.endswith("\n") and after.count("\n") == 2
    assert isinstance(Progress(1, ("CartPole",), live=False).messages(), contextlib.nullcontext)


def test_the_live_line_shows_on_a_terminal_that_reports_no_size(monkeypatch):
    """A bare pseudo-terminal reports 0 x 0: tqdm would hide the line below the screen."""
    import os
    import sys

    import pytest

    from mtpg.cli.progress import Progress

    pty = pytest.importorskip("pty")
    leader, follower = pty.openpty()
    with open(follower, "w", encoding="utf-8", closefd=True) as terminal:
        assert terminal.isatty()
        monkeypatch.setattr(sys, "stderr", terminal)  # tqdm reads the size of standard error
        monkeypatch.delenv("COLUMNS", raising=False)
        progress = Progress(10, ("CartPole",), stream=terminal)
        assert progress.live
        progress.begin(0)
        progress.close()
    written = b""
    os.set_blocking(leader, False)
    try:
        while chunk := os.read(leader, 65536):
            written += chunk
    except (BlockingIOError, OSError):
        pass
    os.close(leader)
    assert b"gen 1/10: compiling" in written
