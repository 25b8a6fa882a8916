"""The dask backend gives the local backend's results, also when a worker dies."""

import os
import signal

import numpy as np
import pytest

pytest.importorskip("distributed")

from mtpg.config import build_config
from mtpg.engine.batch import Episodes, evaluate_roots
from mtpg.engine.compile import compile_population
from mtpg.engine.dask_backend import DaskEvaluator, plan_batches
from mtpg.engine.random_populations import tangled_population
from mtpg.envs.taskset.task_table import TaskTable
from mtpg.evolve.columns import TIMING_COLUMNS
from mtpg.evolve.trainer import Trainer

TINY = [
    "team.root_size=30",
    "team.n_elite=3",
    "team.init_team_size=3",
    "evaluation.train_episodes=2",
    'evaluation.tasks=["CartPole", "MountainCar"]',
    "evaluation.test_episodes=3",
    "team.p_atomic=0.7",
]


@pytest.fixture(scope="module")
def cluster():
    ev = DaskEvaluator(n_workers=2, min_roots=1)
    yield ev
    ev.close()


def tiny(*extra, generations=4):
    return build_config("paper", overrides=[*TINY, f"generations={generations}", *extra])


def run(config, evaluator=None):
    """Metrics (timing aside), test rows after every generation, and champions."""
    trainer = Trainer(config)
    if evaluator is not None:
        trainer.evaluator = evaluator
    rows, tests = [], []
    while not trainer.done:
        row = trainer.run_generation()
        rows.append({k: v for k, v in row.items() if k not in TIMING_COLUMNS})
        tests.append(trainer.held_out_scores())
    return rows, tests, trainer.state.champions


def test_plan_batches_about_eight_per_thread_with_enough_roots_each():
    assert plan_batches(200, threads=8, min_roots=10) == 20  # 200 roots: 20 of 10
    assert plan_batches(2000, threads=8, min_roots=10) == 64  # 8 per thread
    assert plan_batches(1, threads=8, min_roots=10) == 1
    assert plan_batches(5, threads=2, min_roots=1) == 5


@pytest.mark.parametrize("no_memory", [False, True])
def test_batches_equal_the_local_engine(cluster, no_memory):
    pop = tangled_population(np.random.default_rng(3), 60, 150, 12, 20)
    cp = compile_population(pop)
    roots = sorted(pop.teams)[::2]
    # a variant too: the workers never resolve its name, its row travels with the episodes
    table = TaskTable.from_names(["Pendulum[max_steps=30;observe=theta_dot]"])
    eps = Episodes.grid([0, 1, 2, 4, table.ids[0]], [0, 1, 2], table)
    want, w = evaluate_roots(cp, roots, eps, 1, no_memory)
    got, g = cluster.evaluate(cp, roots, eps, no_memory)
    assert np.array_equal(want, got)
    for a, b in zip(
        (w.steps, w.teams, w.instructions), (g.steps, g.teams, g.instructions), strict=True
    ):
        assert np.array_equal(a, b)


def test_training_on_dask_equals_local_threads(cluster):
    one = run(tiny("workers=1"))
    two = run(tiny("workers=2"))
    dask = run(tiny(), cluster)
    assert one == two == dask


def test_train_command_on_a_local_cluster_writes_the_local_run(tmp_path):
    import csv

    from mtpg.cli.main import main

    def train(out, *extra):
        args = ["train", "--preset", "paper", "--generations", "3", "--out", str(out)]
        args += [f"--set={o}" for o in TINY] + ["--set=evaluation.test_interval=2", "--quiet"]
        assert main([*args, *extra]) == 0
        with open(out / "metrics.csv") as fh:
            rows = [
                {k: v for k, v in r.items() if k not in TIMING_COLUMNS} for r in csv.DictReader(fh)
            ]
        return rows, (out / "tests.csv").read_text()

    local = train(tmp_path / "local", "--workers", "2")
    dask = train(tmp_path / "dask", "--backend", "dask", "--dask-workers", "1")
    assert local == dask and len(local[0]) == 3


def test_a_worker_killed_mid_generation_costs_time_not_the_run(cluster):
    want = run(tiny())
    client = cluster.client
    real_gather = client.gather
    killed = []

    def gather_after_killing(futures, *args, **kwargs):
        # the generation's batches are submitted: kill one worker process while they run
        if len(killed) < 2:
            pid = sorted(cluster.worker_pids().values())[0]
            os.kill(pid, signal.SIGKILL)
            killed.append(pid)
        return real_gather(futures, *args, **kwargs)

    client.gather = gather_after_killing
    try:
        got = run(tiny(), cluster)
    finally:
        del client.gather
    assert len(killed) == 2 and cluster.lost is None
    assert got == want
    client.wait_for_workers(2, timeout=60)
    assert not set(killed) & set(cluster.worker_pids().values())  # the nanny replaced them


def free_port():
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_for_port(port, seconds=60):
    import socket
    import time

    end = time.monotonic() + seconds
    while time.monotonic() < end:
        with socket.socket() as s:
            if s.connect_ex(("127.0.0.1", port)) == 0:
                return
        time.sleep(0.2)
    raise TimeoutError(f"nothing listens on port {port}")


class Cluster:
    """A scheduler and one worker as separate processes (``dask scheduler``/``dask worker``)."""

    def __init__(self, port):
        import subprocess
        import sys
        from pathlib import Path

        dask = str(Path(sys.executable).parent / "dask")
        self.address = f"tcp://127.0.0.1:{port}"
        quiet = {"stdout": subprocess.DEVNULL, "stderr": subprocess.DEVNULL}
        self.scheduler = subprocess.Popen(
            [dask, "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
            **quiet,
        )
        self.worker = subprocess.Popen(
            [dask, "worker", self.address, "--nworkers", "1", "--nthreads", "1"]
            + ["--no-dashboard", "--death-timeout", "5"],
            **quiet,
        )
        wait_for_port(port)

    def kill_scheduler(self):
        self.scheduler.kill()
        self.scheduler.wait()

    def stop(self):
        import subprocess

        self.worker.terminate()  # the nanny stops its worker process
        try:
            self.worker.wait(timeout=20)
        except subprocess.TimeoutExpired:
            self.worker.kill()
            self.worker.wait()
        self.kill_scheduler()


@pytest.mark.slow  # schedulers and workers as separate processes: about a minute
def test_a_lost_scheduler_stops_the_run_at_a_boundary_and_resume_continues_it(
    tmp_path, monkeypatch
):
    import csv

    import mtpg.engine.dask_backend as backend
    from mtpg.engine.evaluator import BackendLost
    from mtpg.evolve.session import Session
    from mtpg.io.checkpoint import checkpoint_path

    def metrics(run_dir):
        with open(run_dir / "metrics.csv") as fh:
            return [
                {k: v for k, v in r.items() if k not in TIMING_COLUMNS} for r in csv.DictReader(fh)
            ]

    def champions(run_dir):
        return {p.name: p.read_bytes() for p in sorted((run_dir / "champions").glob("*.json"))}

    extra = ["evaluation.test_interval=2", "checkpoint_interval=10"]
    Session(tmp_path / "local", tiny(*extra, generations=5)).run_all()
    monkeypatch.setattr(backend, "CONNECT_TIMEOUT", 5)  # the scheduler counts as lost after 5 s
    port = free_port()
    config = tiny(*extra, "backend=dask", f'address="tcp://127.0.0.1:{port}"', generations=5)
    first = Cluster(port)
    try:
        session = Session(tmp_path / "dask", config)
        session.trainer.evaluator.client.wait_for_workers(1, timeout=60)

        def kill_after_generation_1(row, trainer):
            if row["generation"] == 1:
                first.kill_scheduler()

        with pytest.raises(BackendLost, match="lost the dask cluster"):
            session.run_all(kill_after_generation_1)
        session.trainer.close()
    finally:
        first.stop()
    # generation 2 was finished on this machine and checkpointed; nothing of generation 3
    assert len(metrics(tmp_path / "dask")) == 2
    assert checkpoint_path(tmp_path / "dask", 2).exists()
    assert not checkpoint_path(tmp_path / "dask", 3).exists()
    second = Cluster(port)  # a new scheduler at the same address
    try:
        resumed = Session(tmp_path / "dask", config, resume=True)
        assert resumed.trainer.state.generation == 2
        resumed.run_all()
        resumed.trainer.close()
    finally:
        second.stop()
    assert metrics(tmp_path / "dask") == metrics(tmp_path / "local")
    assert champions(tmp_path / "dask") == champions(tmp_path / "local")


def test_dask_logs_are_silenced_while_open_and_restored_on_close(monkeypatch):
    import logging

    monkeypatch.delenv("MTPG_DEBUG", raising=False)
    client_log = logging.getLogger("distributed.client")
    before = client_log.level
    ev = DaskEvaluator(n_workers=1)
    try:
        assert client_log.level == logging.CRITICAL
        assert logging.getLogger("distributed").level == logging.CRITICAL
    finally:
        ev.close()
    assert client_log.level == before
