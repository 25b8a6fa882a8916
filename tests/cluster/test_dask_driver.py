"""The dask-jobqueue recipe of examples/slurm/: its worker job script, and its driver.

The driver (``dask_driver.py``) runs here with ``--local 2`` (worker processes on this
machine instead of SLURM jobs) under ``train-dask.sbatch`` with SLURM's signals simulated
as in ``test_slurm_requeue.py``.
"""

import importlib.util
import re
import socket
import sys

import pytest
from test_slurm_requeue import EXAMPLES, job, requeues, rows, slurm_env

from stopruns import run_files

pytest.importorskip("distributed")


def load_driver():
    spec = importlib.util.spec_from_file_location("dask_driver", EXAMPLES / "dask_driver.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_worker_job_script(tmp_path):
    pytest.importorskip("dask_jobqueue")
    pytest.importorskip("cryptography")
    driver = load_driver()
    args = driver.parse_args(
        ["--queue", "compute", "--account", "proj", "--cores", "16", "--memory", "32GB"]
        + ["--shared-dir", str(tmp_path / "shared"), "--prologue", "source venv/bin/activate"]
        + ["--", "--resume", "runs/paper-seed0"]
    )
    assert args.train == ["--resume", "runs/paper-seed0"]
    cluster = driver.slurm_cluster(args, driver.security(args))
    try:
        script = cluster.job_script()
        assert cluster.scheduler_address.startswith("tls://")
    finally:
        cluster.close()
    lines = script.splitlines()
    for line in ("#SBATCH -p compute", "#SBATCH -A proj", "#SBATCH --cpus-per-task=16"):
        assert line in lines
    assert lines.index("source venv/bin/activate") < lines.index(
        'export NUMBA_CACHE_DIR="/tmp/$USER-numba"'
    )
    worker = next(line for line in lines if "dask_worker" in line)
    for option in ("--nthreads 1", "--nworkers 16", "--no-dashboard", "--protocol tls://"):
        assert option in worker
    assert re.search(r"--death-timeout \d+", worker)  # orphaned workers end by themselves
    assert str(tmp_path / "shared") in worker  # the TLS files, on the shared folder


def test_no_tls_is_plain_tcp(tmp_path):
    pytest.importorskip("dask_jobqueue")
    driver = load_driver()
    args = driver.parse_args(["--no-tls", "--shared-dir", str(tmp_path)])
    assert driver.security(args) is None


def scheduler_port(out):
    return int(re.search(r"scheduler at \w+://127\.0\.0\.1:(\d+)", out).group(1))


def listening(port):
    with socket.socket() as s:
        return s.connect_ex(("127.0.0.1", port)) == 0


@pytest.mark.slow
def test_usr1_stops_the_run_closes_the_cluster_and_the_requeued_job_resumes(tmp_path):
    pytest.importorskip("cryptography")
    ref = tmp_path / "ref"
    code, out = job(EXAMPLES / "train.sbatch", slurm_env(tmp_path / "x", ref), tmp_path)
    assert code == 0, out
    run = tmp_path / "run"
    env = slurm_env(tmp_path, run, DRIVER_ARGS="--local 2", PYTHON=sys.executable)
    script = EXAMPLES / "train-dask.sbatch"
    code, out = job(script, env, tmp_path, signal_after=3)
    assert code == 143, out
    assert "(committed)" in out and "dask_driver: cluster closed" in out
    assert not listening(scheduler_port(out))
    assert requeues(tmp_path) == ["requeue 4242"]
    first = rows(run)
    code, out = job(script, env, tmp_path)  # the requeued job
    assert code == 0, out
    assert f"generation {first} of" in out and "dask_driver: cluster closed" in out
    a, b = run_files(ref), run_files(run)
    for name in a:  # config.toml and checkpoints name the backend; results do not depend on it
        if name.startswith(("champions/", "tests/")) or name in ("metrics.csv", "tests.csv"):
            assert a[name] == b[name], name


class FakeChild:
    def __init__(self):
        self.signals = []

    def send_signal(self, sig):
        self.signals.append(sig)


@pytest.mark.parametrize("in_slurm", [True, False])
def test_stop_signals_reach_the_run_once(in_slurm):
    import signal

    driver = load_driver()
    stopper = driver.Stopper(in_slurm=in_slurm)
    stopper.child = child = FakeChild()
    stopper(signal.SIGTERM, None)  # in SLURM, the run got this SIGTERM itself
    assert child.signals == ([] if in_slurm else [signal.SIGTERM])
    child.signals.clear()
    for sig in (signal.SIGUSR1, signal.SIGINT, signal.SIGHUP):
        stopper(sig, None)
    assert child.signals == [signal.SIGTERM] * 3


def test_a_signal_before_the_run_starts_means_the_run_is_not_started():
    import signal

    driver = load_driver()
    stopper = driver.Stopper(in_slurm=True)
    stopper(signal.SIGTERM, None)  # no run yet: remembered
    assert stopper.requested
    assert stopper.run(["false"], {}) == 128 + signal.SIGTERM and stopper.child is None
