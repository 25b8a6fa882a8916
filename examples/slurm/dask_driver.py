"""Runs one ``mtpg train`` against a Dask cluster started for it, and always closes it.

The driver starts a scheduler in this process and asks SLURM for worker jobs
(``dask_jobqueue.SLURMCluster``; ``--local N`` starts N worker processes on this machine
instead, for trying the recipe without SLURM), then runs ``mtpg train ... --backend dask
--address ...`` as a child process and waits for it. However the run ends, the cluster is
closed afterwards, which cancels the worker jobs:

* USR1 (sent by ``train-dask.sbatch`` when the time limit nears) and SIGTERM, SIGINT,
  SIGHUP are passed on to the run as SIGTERM: it commits the generation under way and
  stops (exit status 143). The run has a session of its own, so Ctrl-C reaches it only
  through the driver. Inside a SLURM job (``SLURM_JOB_ID`` set) SIGTERM is not passed
  on, because SLURM sends it to every process of the job, the run included: passing it on
  would make it a second signal, which stops the run at once.
* The cluster is closed only after the run has ended, so its last generation is
  evaluated by the workers, not by this machine.

TLS (default): the scheduler, the workers and the run talk over TLS with temporary
credentials made for this cluster (``distributed.security.Security.temporary``, needs the
``cryptography`` package), so only processes given the credentials can submit work.
Without it (``--no-tls``) anyone who can reach the scheduler's port can run code as you.

Usage::

    python dask_driver.py [options] -- [mtpg train options]
    python dask_driver.py --jobs 4 --cores 32 --memory 64GB -- --resume runs/paper-seed0

Exit status: the run's (0 finished, 143 stopped by a signal, 1 or 2 failed).
"""

from __future__ import annotations

import argparse
import os
import shlex
import signal
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

#: Signals passed on to the run as SIGTERM.
FORWARDED = (signal.SIGUSR1, signal.SIGTERM, signal.SIGINT, signal.SIGHUP)


def parse_args(argv: list[str]) -> argparse.Namespace:
    """The driver's options; everything after ``--`` goes to ``mtpg train``."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--local", type=int, metavar="N", help="N worker processes here, no SLURM")
    p.add_argument("--jobs", type=int, default=1, help="SLURM worker jobs (default 1)")
    p.add_argument("--cores", type=int, default=32, help="cores per worker job (default 32)")
    p.add_argument("--memory", default="64GB", help="memory per worker job (default 64GB)")
    p.add_argument("--walltime", default="24:00:00", help="worker job time limit")
    p.add_argument("--queue", help="SLURM partition of the worker jobs")
    p.add_argument("--account", help="SLURM account of the worker jobs")
    p.add_argument("--interface", help="network interface of the scheduler, e.g. ib0")
    p.add_argument(
        "--prologue",
        action="append",
        default=[],
        help="shell line run before each worker starts (repeatable); the driver's "
        "virtual environment, if any, is activated first",
    )
    p.add_argument("--no-tls", action="store_true", help="plain TCP: no authentication")
    p.add_argument(
        "--shared-dir",
        default=str(Path.home() / ".mtpg-dask"),
        help="private folder that every node reads, for the workers' TLS files "
        "(default ~/.mtpg-dask)",
    )
    p.add_argument("train", nargs=argparse.REMAINDER, help="-- then mtpg train options")
    args = p.parse_args(argv)
    if args.train and args.train[0] == "--":
        args.train = args.train[1:]
    return args


def security(args: argparse.Namespace) -> Any:
    """Temporary TLS credentials for this cluster, or None with ``--no-tls``."""
    if args.no_tls:
        return None
    from distributed.security import Security

    try:
        return Security.temporary()
    except ImportError:
        sys.exit("dask_driver: TLS needs the cryptography package (pip install cryptography)")


def venv_prologue() -> list[str]:
    """The line that activates this Python's virtual environment on a worker, if any."""
    if sys.prefix == sys.base_prefix:
        return []
    return [f"source {shlex.quote(str(Path(sys.prefix) / 'bin' / 'activate'))}"]


def slurm_cluster(args: argparse.Namespace, sec: Any) -> Any:
    """A ``SLURMCluster`` of one-thread worker processes, ``args.cores`` per job."""
    from dask_jobqueue import SLURMCluster

    scheduler_options: dict[str, Any] = {"dashboard_address": None}
    shared = Path(args.shared_dir)
    shared.mkdir(mode=0o700, parents=True, exist_ok=True)
    if args.interface:
        scheduler_options["interface"] = args.interface
    return SLURMCluster(
        queue=args.queue,
        account=args.account,
        cores=args.cores,
        processes=args.cores,  # one thread per worker process: the tested set-up
        memory=args.memory,
        walltime=args.walltime,
        job_script_prologue=[
            *venv_prologue(),
            *args.prologue,
            'export NUMBA_CACHE_DIR="/tmp/$USER-numba"',  # node-local kernel cache
        ],
        worker_extra_args=["--no-dashboard"],
        scheduler_options=scheduler_options,
        security=sec,
        protocol="tls://" if sec is not None else "tcp://",
        shared_temp_directory=str(shared),
    )


def local_cluster(n: int, sec: Any) -> Any:
    """N one-thread worker processes on the loopback interface."""
    from distributed import LocalCluster

    return LocalCluster(
        n_workers=n,
        threads_per_worker=1,
        host="127.0.0.1",
        dashboard_address=None,
        security=sec,
        protocol="tls://" if sec is not None else "tcp://",
    )


def client_env(sec: Any, folder: Path) -> dict[str, str]:
    """Environment that gives the run the cluster's client credentials (files, mode 600)."""
    env = dict(os.environ)
    if sec is None:
        return env
    names = {
        "CA_FILE": ("ca.pem", sec.tls_ca_file),
        "CLIENT__CERT": ("client-cert.pem", sec.tls_client_cert),
        "CLIENT__KEY": ("client-key.pem", sec.tls_client_key),
    }
    for key, (name, text) in names.items():
        path = folder / name
        path.touch(mode=0o600)
        path.write_text(text)
        env[f"DASK_DISTRIBUTED__COMM__TLS__{key}"] = str(path)
    env["DASK_DISTRIBUTED__COMM__REQUIRE_ENCRYPTION"] = "True"
    return env


class Stopper:
    """Passes stop signals on to the run as SIGTERM (once it runs; before, remembers them).

    Args:
        in_slurm: Inside a SLURM job, where SLURM sends SIGTERM to the run itself.
    """

    def __init__(self, in_slurm: bool) -> None:
        self.in_slurm = in_slurm
        self.child: subprocess.Popen | None = None
        self.requested = False

    def __call__(self, signum: int, _frame: object) -> None:
        """The signal handler."""
        if signum == signal.SIGTERM and self.in_slurm and self.child is not None:
            return  # SLURM signals every process of the job: the run has it already
        self.requested = True
        if self.child is not None:
            self.child.send_signal(signal.SIGTERM)

    def install(self) -> None:
        """Makes this the handler of every signal in :data:`FORWARDED`."""
        for sig in FORWARDED:
            signal.signal(sig, self)

    def run(self, command: list[str], env: dict[str, str]) -> int:
        """Runs the training in its own session (no terminal signals); returns its status."""
        if self.requested:
            return 128 + signal.SIGTERM  # stopped before the run began
        self.child = subprocess.Popen(command, env=env, start_new_session=True)
        return self.child.wait()


def main(argv: list[str] | None = None) -> int:
    """Starts the cluster, runs the training, closes the cluster; returns the run's status."""
    args = parse_args(sys.argv[1:] if argv is None else argv)
    stopper = Stopper(in_slurm=bool(os.environ.get("SLURM_JOB_ID")))
    stopper.install()  # from here on a stop signal cannot skip closing the cluster
    sec = security(args)
    cluster = local_cluster(args.local, sec) if args.local else slurm_cluster(args, sec)
    try:
        if not args.local:
            print(cluster.job_script(), file=sys.stderr)
            cluster.scale(jobs=args.jobs)
        mtpg = shlex.split(os.environ.get("MTPG", "mtpg"))
        command = [*mtpg, "train", *args.train, "--backend", "dask"]
        command += ["--address", cluster.scheduler_address]
        print(f"dask_driver: scheduler at {cluster.scheduler_address}", file=sys.stderr)
        with tempfile.TemporaryDirectory(prefix="mtpg-tls-") as folder:
            status = stopper.run(command, client_env(sec, Path(folder)))
    finally:
        cluster.close()
        print("dask_driver: cluster closed", file=sys.stderr)
    return status


if __name__ == "__main__":
    sys.exit(main())
