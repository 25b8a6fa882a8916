"""The wait for a Dask scheduler is short by default and can be set (within a KillWait)."""

import logging
import socket
import time

import pytest

from mtpg.cli.main import main
from mtpg.engine import dask_backend
from tinyruns import tiny_args

pytest.importorskip("distributed")


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def test_default_wait_fits_inside_slurms_default_killwait(monkeypatch):
    monkeypatch.delenv(dask_backend.SCHEDULER_WAIT_ENV, raising=False)
    assert dask_backend.scheduler_wait() == dask_backend.CONNECT_TIMEOUT <= 15


@pytest.mark.parametrize("text", ["0", "-1", "nan", "soon", "7200"])
def test_a_bad_wait_is_refused_naming_the_variable(monkeypatch, text):
    monkeypatch.setenv(dask_backend.SCHEDULER_WAIT_ENV, text)
    with pytest.raises(ValueError, match="MTPG_SCHEDULER_WAIT"):
        dask_backend.scheduler_wait()


def test_scheduler_wait_option_bounds_the_wait_for_a_missing_scheduler(tmp_path, capsys):
    address = f"tcp://127.0.0.1:{free_port()}"  # nothing listens there
    args = ["train", *tiny_args(), "--generations", "1", "--backend", "dask"]
    levels = {name: logging.getLogger(name).level for name in ("distributed", "distributed.comm")}
    start = time.monotonic()
    code = main(
        [*args, "--address", address, "--scheduler-wait", "1", "--out", str(tmp_path / "r")]
    )
    took = time.monotonic() - start
    assert code == 2
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith(
        f"mtpg train: error: address: cannot reach the dask scheduler at {address}"
    )
    assert took < 9  # the default wait (10 s) was not used
    assert dask_backend.SCHEDULER_WAIT_ENV not in __import__("os").environ  # put back
    assert not (tmp_path / "r").exists()  # connected before the run directory was made
    assert {name: logging.getLogger(name).level for name in levels} == levels  # put back


def test_resuming_with_a_missing_scheduler_changes_nothing(tmp_path, capsys):
    run = tmp_path / "r"
    assert main(["train", *tiny_args(), "--generations", "1", "--out", str(run)]) == 0
    before = {p: p.read_bytes() for p in sorted(run.rglob("*")) if p.is_file()}
    address = f"tcp://127.0.0.1:{free_port()}"
    resume = ["train", "--resume", str(run), "--generations", "2", "--quiet"]
    code = main([*resume, "--backend", "dask", "--address", address, "--scheduler-wait", "1"])
    assert code == 2
    assert "cannot reach the dask scheduler" in capsys.readouterr().err
    assert {p: p.read_bytes() for p in sorted(run.rglob("*")) if p.is_file()} == before


def test_scheduler_wait_option_is_checked(tmp_path, capsys):
    code = main(["train", *tiny_args(), "--scheduler-wait", "0", "--out", str(tmp_path / "r")])
    assert code == 2
    assert "--scheduler-wait must be in (0, 3600]" in capsys.readouterr().err


def test_a_refused_evaluator_leaves_dasks_log_levels_as_they_were():
    levels = {name: logging.getLogger(name).level for name in ("distributed", "distributed.comm")}
    with pytest.raises(ValueError, match="dask workers must be >= 1, got 0"):
        dask_backend.DaskEvaluator(n_workers=0)
    address = f"tcp://127.0.0.1:{free_port()}"
    with pytest.raises(
        dask_backend.BackendError, match=f"cannot reach the dask scheduler at {address}"
    ):
        dask_backend.DaskEvaluator(address, timeout=0.5)
    assert {name: logging.getLogger(name).level for name in levels} == levels


def test_workers_without_mtpg_are_one_line_and_the_client_is_closed(monkeypatch):
    closed = []

    class Client:
        def run(self, fn):
            raise ImportError("No module named 'mtpg'")

        def close(self):
            closed.append(True)

    def connect(self, address, *args):
        self.client, self.address = Client(), address

    monkeypatch.setattr(dask_backend.DaskEvaluator, "_connect", connect)
    with pytest.raises(dask_backend.BackendError) as err:
        dask_backend.DaskEvaluator("tcp://10.0.0.1:8786", timeout=1)
    assert str(err.value) == (
        "address: the workers of tcp://10.0.0.1:8786 cannot import mtpg (No module named "
        "'mtpg'); install the same mtpg version on every worker"
    )
    assert closed == [True]
