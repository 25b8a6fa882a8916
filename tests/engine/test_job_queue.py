"""The batch kernel's job queue: every block taken exactly once, by any number of workers.

Workers take blocks of jobs from a shared int64 counter with an atomic fetch-and-add
(:func:`mtpg.engine.episode_kernels.run_jobs_queue`). Duplicated work would not show in the
outputs (a job played twice writes the same values twice), so these tests read the
counter itself: with an atomic add it ends at exactly ``blocks + workers``; a lost update
between racing workers would leave it lower.
"""

import threading

import numba
import numpy as np

from mtpg.engine.batch import BatchResult, Episodes, Jobs, run_jobs
from mtpg.engine.compile import compile_population
from mtpg.engine.episode_kernels import _fetch_add, run_jobs_parallel, run_jobs_queue
from mtpg.engine.random_populations import layered_graphs
from mtpg.envs import TASK_PARAMS
from mtpg.envs.specs.contract import TASK_NAMES


def _setup(n_graphs=60, seeds=(0, 1, 2)):
    rng = np.random.default_rng(11)
    pop, roots = layered_graphs(rng, n_graphs, teams=2, programs=4, instructions=6)
    cp = compile_population(pop)
    episodes = Episodes.grid(list(range(len(TASK_NAMES))), list(seeds))
    n_ep = len(episodes.tasks)
    job_roots = np.repeat([cp.team_index(r) for r in roots], n_ep).astype(np.int64)
    job_eps = np.tile(np.arange(n_ep, dtype=np.int64), len(roots))
    return cp, job_roots, job_eps, episodes


def _args(cp, job_roots, job_eps, episodes):
    out = BatchResult.zeros(len(job_roots))
    table = episodes._replace(params=TASK_PARAMS)
    return out, (Jobs(job_roots, job_eps), table, out, cp.graph)


def test_serial_worker_takes_every_block_once():
    cp, job_roots, job_eps, episodes = _setup(10)
    out, args = _args(cp, job_roots, job_eps, episodes)
    queue = np.zeros(1, dtype=np.int64)
    run_jobs_queue(queue, 7, *args)
    n_blocks = -(-len(job_roots) // 7)
    assert queue[0] == n_blocks + 1
    expected = run_jobs(cp, job_roots, job_eps, episodes)
    assert out[0].tobytes() == expected.returns.tobytes()
    assert np.array_equal(out[3], expected.instructions)


def test_a_worker_starts_where_the_queue_stands():
    """A counter already at k leaves the first k blocks to others: their outputs stay 0."""
    cp, job_roots, job_eps, episodes = _setup(10)
    out, args = _args(cp, job_roots, job_eps, episodes)
    queue = np.array([3], dtype=np.int64)
    run_jobs_queue(queue, 5, *args)
    assert not out[1][:15].any()
    assert out[1][15:].min() >= 1


def test_parallel_workers_share_one_counter():
    cp, job_roots, job_eps, episodes = _setup()
    workers = min(2, numba.config.NUMBA_NUM_THREADS)
    numba.set_num_threads(workers)
    out, args = _args(cp, job_roots, job_eps, episodes)
    queue = np.zeros(1, dtype=np.int64)
    run_jobs_parallel(workers, queue, 1, *args)
    assert queue[0] == len(job_roots) + workers
    expected = run_jobs(cp, job_roots, job_eps, episodes)
    assert out[0].tobytes() == expected.returns.tobytes()


def test_python_threads_racing_on_one_counter_lose_no_update():
    """Four Python threads (the kernel releases the GIL) race for single-job blocks."""
    cp, job_roots, job_eps, episodes = _setup(200, seeds=(0,))
    out, args = _args(cp, job_roots, job_eps, episodes)
    queue = np.zeros(1, dtype=np.int64)
    threads = [threading.Thread(target=run_jobs_queue, args=(queue, 1, *args)) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert queue[0] == len(job_roots) + 4
    expected = run_jobs(cp, job_roots, job_eps, episodes)
    assert out[0].tobytes() == expected.returns.tobytes()
    assert np.array_equal(out[2], expected.teams)


@numba.njit(parallel=True)
def _hammer(counter, n, sink):
    for i in numba.prange(n):
        # the store may alias the counter, so every take reloads it (no hoisting)
        sink[i & 1023] = _fetch_add(counter)


def test_fetch_add_is_atomic_under_contention():
    """Two threads taking in a tight loop: a plain load-add-store would lose updates.

    (Lost updates need the two threads to run at the same moment; on a machine busy with
    other work they rarely do, so the count is large.)
    """
    numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
    counter = np.zeros(1, dtype=np.int64)
    n = 20_000_000
    sink = np.zeros(1024, dtype=np.int64)
    _hammer(counter, n, sink)
    assert counter[0] == n
    assert sink.max() < n
