"""Training runs stopped at chosen moments, resumed, and compared with an uninterrupted run."""

import csv
import io
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

from mtpg.evolve.columns import TIMING_COLUMNS
from tinyruns import tiny_args

#: Settings of a tiny run with a test point every 2 generations and a commit every 3.
SETTINGS = tiny_args(
    "CartPole,MountainCar",
    root_size=20,
    n_elite=3,
    evaluation__test_interval=2,
    evaluation__test_episodes=3,
    checkpoint_interval=3,
)
#: That run for 7 generations: test points 2, 4, 6 and commits 3, 6 and the end, 7.
ARGS = [*SETTINGS, "--generations", "7"]


def mtpg(*args, env=None, **kw):
    """``python -m mtpg ARGS`` as a subprocess (stdout/stderr captured as text)."""
    full = dict(os.environ)
    full.pop("MTPG_TEST_STOP_AT", None)
    full.update(env or {})
    return subprocess.run(
        [sys.executable, "-m", "mtpg", *args], env=full, capture_output=True, text=True, **kw
    )


def start(*args, env=None):
    """``python -m mtpg ARGS`` started in the background."""
    full = dict(os.environ)
    full.pop("MTPG_TEST_STOP_AT", None)
    full.update(env or {})
    return subprocess.Popen(
        [sys.executable, "-m", "mtpg", *args],
        env=full,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )


def without_timing(text):
    rows = list(csv.reader(io.StringIO(text)))
    keep = [i for i, c in enumerate(rows[0]) if c not in TIMING_COLUMNS]
    return [[r[i] for i in keep] for r in rows]


def run_files(run):
    """Every file of a run directory but the lock, metrics.csv without its timing columns."""
    run = Path(run)
    out = {}
    for p in sorted(run.rglob("*")):
        if p.is_file() and p.name != ".lock":
            rel = str(p.relative_to(run))
            data = p.read_bytes()
            out[rel] = without_timing(data.decode()) if rel == "metrics.csv" else data
    return out


def assert_same_run(ref, run):
    """metrics.csv (timing aside), tests.csv, tests/, champions/, checkpoints/ identical."""
    a, b = run_files(ref), run_files(run)
    assert sorted(a) == sorted(b)
    for name in a:
        assert a[name] == b[name], name


def resume_after_stop(run, out_args):
    """Continues a stopped run as a user would; returns the CompletedProcess."""
    run = Path(run)
    if (run / "config.toml").is_file():
        return mtpg("train", "--resume", str(run), "--quiet")
    return mtpg("train", *out_args, "--out", str(run))  # creation never completed


def stop_at(run, moments, args=ARGS):
    """Runs ``mtpg train`` that signals itself at ``moments`` (MTPG_TEST_STOP_AT)."""
    res = mtpg("train", *args, "--out", str(run), env={"MTPG_TEST_STOP_AT": moments})
    return res


def stop_after(run, seconds, sig, args=ARGS):
    """Runs ``mtpg train`` and sends ``sig`` after ``seconds`` (when still running)."""
    proc = start("train", *args, "--out", str(run))
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.01)
    if proc.poll() is None:
        proc.send_signal(sig)
    proc.communicate(timeout=300)
    return proc.returncode


EXPECTED_CODES = {
    "KILL": -signal.SIGKILL,
    "TERM": 128 + signal.SIGTERM,
    "INT": 128 + signal.SIGINT,
    "HUP": 128 + signal.SIGHUP,
}
