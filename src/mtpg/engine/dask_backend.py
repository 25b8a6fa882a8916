"""The ``dask`` evaluation backend: batches of roots on the workers of a Dask cluster.

Per evaluation the compiled population travels once to every worker as plain NumPy arrays
(``Client.scatter`` with ``broadcast=True``), and so does each episode table, once per run
(the training table is the same every generation); the roots are dealt round-robin into
about :data:`TASKS_PER_THREAD` batches per worker thread, each root with all its episodes
(so a worker plays one graph's episodes back to back, its code and memory banks in cache),
each batch one task that runs the serial compiled kernel of
:mod:`mtpg.engine.episode_kernels` (importable, ``cache=True``: each worker process compiles or
loads the kernels once, on its first task), and the outcomes are put back in job order.
Results are bit-identical to the local backend's.

Gymnasium tasks (:mod:`mtpg.envs.specs.gym_task`) step in Python: a table holding them
sends the compiled population itself and each batch runs
:func:`~mtpg.engine.batch.run_jobs` on its worker (:func:`play_mixed_batch`), which makes
the batch's environments there. So every worker must import what the task names: the
``gymnasium`` package, and for ``gym:module:Env-v0`` the user's module (on the workers'
``PYTHONPATH``, or installed); a worker that cannot is an error of one line naming the
module.

Faults. A worker that dies mid-evaluation costs time only: Dask recomputes its batches on
the other workers (evaluation is pure); should every copy of the inputs die with workers,
the evaluation is sent again (up to :data:`RESUBMITS` times). A lost scheduler (or a batch
that keeps killing workers) cannot be recovered from inside the cluster; the evaluation in
progress is then finished on this machine's threads, so the generation completes with the
very same result, and :meth:`DaskEvaluator.check` raises
:class:`~mtpg.engine.evaluator.BackendLost` before the next generation starts: the run
stops cleanly at a generation boundary and ``mtpg train --resume`` continues it.
"""

from __future__ import annotations

import logging
import os
import warnings

import numpy as np

from mtpg.engine.batch import BatchResult, Episodes, Jobs, evaluate_roots, run_jobs
from mtpg.engine.compile import CompiledPopulation, Graph
from mtpg.engine.evaluator import BackendError, BackendLost
from mtpg.engine.lanes import DEFAULT_LANES, run_lanes_queue

_LOG = logging.getLogger(__name__)

#: Batches per worker thread: enough to balance roots of uneven cost, few enough that the
#: scheduler's cost per task (about 1.5 ms) stays negligible. Measured on paper-sized
#: evaluations (1575 roots x 30 episodes, 2 workers): 8 per thread left the workers idle
#: for 0.2 s of a 5.8 s evaluation, 4 per thread for 0.5 s.
TASKS_PER_THREAD = 8
#: Fewest roots per batch (smaller evaluations use fewer batches).
MIN_ROOTS_PER_BATCH = 8
#: Times an evaluation is sent again when the cluster lost its inputs or results (while
#: the scheduler is still there) before it counts as lost.
RESUBMITS = 3
#: Episode tables kept on the cluster between evaluations (training and test tables).
TABLES_KEPT = 4
#: Seconds to wait for a scheduler (to connect, or to come back before it counts as lost)
#: unless ``MTPG_SCHEDULER_WAIT`` (``mtpg train --scheduler-wait``) says otherwise: short
#: enough that a run whose scheduler died with its job still finishes the generation on
#: this machine and commits it within SLURM's default ``KillWait`` of 30 s.
CONNECT_TIMEOUT = 10
#: The environment variable that overrides :data:`CONNECT_TIMEOUT` (seconds).
SCHEDULER_WAIT_ENV = "MTPG_SCHEDULER_WAIT"


def scheduler_wait() -> float:
    """Seconds to wait for the scheduler: ``MTPG_SCHEDULER_WAIT`` or :data:`CONNECT_TIMEOUT`.

    Raises:
        BackendError: The variable is not a number of seconds in (0, 3600].
    """
    text = os.environ.get(SCHEDULER_WAIT_ENV, "").strip()
    if not text:
        return float(CONNECT_TIMEOUT)
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not 0 < value <= 3600:
        raise BackendError(
            f"{SCHEDULER_WAIT_ENV} (--scheduler-wait) must be seconds in (0, 3600], got {text!r}"
        )
    return value


def graph_arrays(cp: CompiledPopulation) -> Graph:
    """The compiled graph as the kernels take it: arrays and three ints, no model objects."""
    return cp.graph


def play_batch(
    graph: Graph,
    job_roots: np.ndarray,
    job_eps: np.ndarray,
    table: Episodes,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Plays one batch of jobs serially (runs on a worker).

    Args:
        graph: :func:`graph_arrays` of the compiled population.
        job_roots: int64 dense team index of each job.
        job_eps: int64 episode row of each job.
        table: The episode table (the parameter table travels with the episodes,
            variants' rows included). The memory ablation is the graph's
            (``graph.no_memory``).

    Returns:
        ``returns, steps, teams, instructions`` of the batch's jobs, in order.
    """
    out = BatchResult.zeros(len(job_roots))
    queue = np.zeros(1, dtype=np.int64)
    jobs = Jobs(job_roots, job_eps)
    # one queue block: the batch's jobs in lane blocks of consecutive jobs (a root's episodes)
    run_lanes_queue(queue, max(len(job_roots), 1), DEFAULT_LANES, jobs, table, out, graph)
    return out


def play_mixed_batch(
    cp: CompiledPopulation, job_roots: np.ndarray, job_eps: np.ndarray, table: Episodes
) -> BatchResult:
    """Plays one batch of a table with Gymnasium tasks (runs on a worker).

    Its environments are made on the worker; :func:`~mtpg.engine.batch.run_jobs` plays
    them as on this machine, so results are the local backend's.

    Raises:
        GymTaskError: One line, saying it happened on a worker (and, for a module that
            does not import there, what the workers need).
    """
    from mtpg.envs.specs.gym_task import GymTaskError

    try:
        return run_jobs(cp, job_roots, job_eps, table, 1, block=max(len(table.tasks), 1))
    except GymTaskError as exc:
        hint = ""
        if "does not import" in str(exc):
            hint = "; every dask worker must import it (on its PYTHONPATH, or installed)"
        raise GymTaskError(f"on dask worker (pid {os.getpid()}): {exc}{hint}") from None


def warm_up() -> int:
    """Loads (or compiles) the kernels in a worker process; returns its pid."""
    from mtpg.engine.compile import compile_population
    from mtpg.engine.random_populations import layered_graphs

    pop, roots = layered_graphs(np.random.default_rng(0), 1, teams=2, programs=2, instructions=2)
    evaluate_roots(compile_population(pop), roots, Episodes.grid([0], [0]))
    return os.getpid()


def _set_dask_log_level(level: int) -> dict[str, int]:
    """Sets the level of Dask's loggers (some, like the client's, have their own).

    Returns:
        The levels they had, by logger name (to put back with :func:`_restore_log_levels`).
    """
    names = [n for n in logging.root.manager.loggerDict if n.split(".")[0] == "distributed"]
    old = {}
    for name in dict.fromkeys(["distributed", *names]):
        logger = logging.getLogger(name)
        old[name] = logger.level
        logger.setLevel(level)
    return old


def _restore_log_levels(levels: dict[str, int]) -> None:
    for name, level in levels.items():
        logging.getLogger(name).setLevel(level)


def plan_batches(n_roots: int, threads: int, min_roots: int) -> int:
    """Number of batches for ``n_roots`` roots on a cluster with ``threads`` worker threads.

    About :data:`TASKS_PER_THREAD` batches per thread, but each with at least
    ``min_roots`` roots (a batch holds whole roots), and at least one batch.
    """
    most = max(1, n_roots // max(1, min_roots))
    return max(1, min(TASKS_PER_THREAD * max(1, threads), most))


class DaskEvaluator:
    """Evaluates batches of roots on a Dask cluster.

    Dask's own log messages in this process (the client's and, for a local cluster, the
    scheduler's and nannies') are silenced until :meth:`close`: a lost scheduler would
    otherwise print Dask's tracebacks of every reconnection attempt, while the run reports
    what matters in one line of its own (errors are one line unless asked for). With the
    environment variable ``MTPG_DEBUG`` set (``mtpg --debug`` sets it) they are shown as
    Dask logs them.

    Args:
        address: Scheduler address (``tcp://HOST:PORT``) of a running cluster, or None to
            start a local cluster on the loopback interface.
        n_workers: Worker processes of the local cluster (one thread each); ignored with
            ``address``.
        fallback_threads: Threads used on this machine to finish an evaluation whose
            cluster was lost.
        min_roots: Fewest roots per batch.
        timeout: Seconds to wait for the scheduler (to connect, and to reconnect before it
            counts as lost); :func:`scheduler_wait` when None.

    Raises:
        BackendError: The scheduler at ``address`` cannot be reached within ``timeout``
            (Dask's log levels are then put back), or the workers cannot import mtpg.
    """

    def __init__(
        self,
        address: str | None = None,
        n_workers: int = 2,
        fallback_threads: int = 1,
        min_roots: int = MIN_ROOTS_PER_BATCH,
        timeout: float | None = None,
    ) -> None:
        timeout = scheduler_wait() if timeout is None else timeout
        if not address and n_workers < 1:
            raise ValueError(f"dask workers must be >= 1, got {n_workers}")
        log_level = logging.INFO if os.environ.get("MTPG_DEBUG") else logging.CRITICAL
        self._log_levels = _set_dask_log_level(log_level)
        self.address = address
        self.fallback_threads = fallback_threads
        self.min_roots = min_roots
        self.lost: str | None = None
        self.resubmits = 0
        self._tables: dict = {}
        self.client = self.cluster = None
        try:
            self._connect(address, n_workers, timeout, log_level)
            self.pids = self.client.run(warm_up)
        except BaseException as exc:
            self.close()  # a local cluster started, and Dask's log levels, are put back
            if isinstance(exc, ImportError):
                raise BackendError(
                    f"address: the workers of {self.address} cannot import mtpg ({exc}); "
                    "install the same mtpg version on every worker"
                ) from exc
            if address and self.client is None and isinstance(exc, OSError):
                raise BackendError(
                    f"address: cannot reach the dask scheduler at {address}: {exc}"
                ) from exc
            raise

    def _connect(self, address: str | None, n_workers: int, timeout: float, log_level: int) -> None:
        """Connects to the scheduler at ``address``, or starts a local cluster and its client."""
        from distributed import Client, LocalCluster

        if address:
            self.client = Client(address, timeout=timeout)
            return
        with warnings.catch_warnings():
            # with the dashboard off the scheduler still serves health checks over HTTP
            # on loopback, on port 8787 or, when that is taken, on any free port
            warnings.filterwarnings("ignore", message="Port .* is already in use")
            self.cluster = LocalCluster(
                n_workers=n_workers,
                threads_per_worker=1,
                processes=True,
                host="127.0.0.1",
                dashboard_address=None,
                silence_logs=max(log_level, logging.ERROR),
            )
        self.client = Client(self.cluster, timeout=timeout)
        self.address = self.cluster.scheduler_address

    @property
    def threads(self) -> int:
        """Worker threads in the cluster now."""
        return int(sum(self.client.nthreads().values()))

    def worker_pids(self) -> dict[str, int]:
        """Process id of every worker, by worker address."""
        return self.client.run(os.getpid)

    def evaluate(
        self,
        cp: CompiledPopulation,
        root_ids: list[int],
        episodes: Episodes,
        no_memory: bool | None = None,
    ) -> tuple[np.ndarray, BatchResult]:
        """See :meth:`mtpg.engine.evaluator.Evaluator.evaluate`."""
        cp = cp.with_memory_mode(no_memory)  # the deprecated override, if any
        if self.lost is not None:
            return evaluate_roots(cp, root_ids, episodes, self.fallback_threads)
        roots = np.array([cp.team_index(r) for r in root_ids], dtype=np.int64)
        n_ep = len(episodes.tasks)
        for attempt in range(RESUBMITS + 1):
            try:
                parts = self._map(cp, roots, episodes)
                break
            except Exception as exc:  # a cluster failure: retry, else local
                if not _is_cluster_failure(exc):
                    raise
                if attempt < RESUBMITS and self.client.status == "running":
                    self.resubmits += 1
                    continue  # e.g. every copy of the inputs died with workers: send again
                self.lost = f"{type(exc).__name__}: {exc}".strip().splitlines()[0]
                return evaluate_roots(cp, root_ids, episodes, self.fallback_threads)
        n = len(roots) * n_ep
        result = BatchResult(
            np.zeros(n), np.zeros(n, np.int64), np.zeros(n, np.int64), np.zeros(n, np.int64)
        )
        n_batches = len(parts)
        for b, part in enumerate(parts):  # batch b holds roots b, b + n_batches, ...
            for column, values in zip(
                (result.returns, result.steps, result.teams, result.instructions),
                part,
                strict=True,
            ):
                column.reshape(len(roots), n_ep)[b::n_batches] = values.reshape(-1, n_ep)
        return result.returns.reshape(len(roots), n_ep), result

    def _map(self, cp, roots, episodes) -> list:
        n_ep = len(episodes.tasks)
        n_batches = plan_batches(len(roots), self.threads, self.min_roots)
        # Gymnasium tasks step in Python on the workers: they take the population itself
        play, code = (play_mixed_batch, cp) if episodes.gym else (play_batch, graph_arrays(cp))
        [graph] = self.client.scatter([code], broadcast=True, hash=False)
        table = self._table(episodes)
        episode_rows = np.arange(n_ep, dtype=np.int64)
        futures = []
        for b in range(n_batches):
            batch = roots[b::n_batches]
            futures.append(
                self.client.submit(
                    play,
                    graph,
                    np.repeat(batch, n_ep),
                    np.tile(episode_rows, len(batch)),
                    table,
                    pure=False,
                )
            )
        try:
            return self.client.gather(futures)
        except Exception:
            self._tables.clear()  # its copies may have died with the workers: send again
            raise
        finally:
            for f in (*futures, graph):
                f.release()

    def _table(self, episodes: Episodes):
        """The cluster's copy of an episode table, sent once per run and table."""
        key = (episodes.tasks.tobytes(), episodes.seeds.tobytes())
        if key not in self._tables:
            if len(self._tables) >= TABLES_KEPT:
                self._tables.pop(next(iter(self._tables))).release()
            [self._tables[key]] = self.client.scatter([episodes], broadcast=True, hash=False)
        return self._tables[key]

    def check(self) -> None:
        """Raises :class:`BackendLost` once the cluster was lost (at a generation boundary)."""
        if self.lost is not None:
            raise BackendLost(
                f"lost the dask cluster at {self.address} ({self.lost}); the generation in "
                "progress was finished on this machine and the run stopped there"
            )

    def close(self) -> None:
        """Disconnects, and shuts down a local cluster started by this evaluator."""
        for thing in (self.client, self.cluster):
            if thing is not None:
                try:
                    thing.close()
                except Exception as exc:  # closing a dead cluster
                    _LOG.warning(f"closing the dask cluster: {exc}")
        self.cluster = None
        _restore_log_levels(self._log_levels)


def _is_cluster_failure(exc: BaseException) -> bool:
    """True for failures of the cluster itself (not of the evaluation code)."""
    from concurrent.futures import CancelledError

    from distributed import KilledWorker
    from distributed.comm.core import CommClosedError

    return isinstance(exc, OSError | TimeoutError | CancelledError | CommClosedError | KilledWorker)
