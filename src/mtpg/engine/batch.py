"""Evaluation of many roots x tasks x episodes in one compiled call.

The episode table, the jobs and the outputs are named tuples of arrays, each passed to the
kernels as one argument (:mod:`mtpg.engine.episode_kernels`).
"""

from __future__ import annotations

from typing import NamedTuple

import numba
import numpy as np

from mtpg.engine.compile import CompiledPopulation
from mtpg.engine.episode_kernels import run_jobs_parallel, run_jobs_queue
from mtpg.engine.gym_play import play_gym
from mtpg.engine.lanes import DEFAULT_LANES, run_lanes_parallel, run_lanes_queue
from mtpg.engine.user_kernels import kernels as user_kernels
from mtpg.envs.specs.gym_task import TRAIN_RESET_OFFSET
from mtpg.envs.taskset.episodes import draw_episodes
from mtpg.envs.taskset.task_table import (
    BUILTIN_SHAPE,
    GYM_ID_BASE,
    REGISTERED,
    USER_ID_BASE,
    TaskTable,
)


class Episodes(NamedTuple):
    """A table of episodes: task, start state and noise row of each (a kernel argument).

    Attributes:
        tasks: int64 ``[n]`` task ids.
        seeds: int64 ``[n]`` episode seeds.
        starts: float64 ``[n, STATE_SIZE]``.
        noise: float64 ``[n, T + 1]``.
        obs_noise: float64 ``[n, T + 1, 2]``: the observation noise of variants with
            ``noise`` (:func:`mtpg.envs.taskset.episodes.draw_episodes`), or ``[n, 0, 2]``.
        params: float64 ``[ids, N_PARAMS]``: the parameter table the task ids index
            (the ``params`` of the task table the episodes were drawn from).

    A table of a task table with Gymnasium tasks is a :class:`GymEpisodes`, which also
    holds those tasks (:attr:`gym`); :func:`run_jobs` plays their rows from Python
    (:mod:`mtpg.engine.gym_play`; a row's seed is its ``reset`` seed) and hands the
    compiled kernels a plain :class:`Episodes` (:meth:`compiled`).
    """

    tasks: np.ndarray
    seeds: np.ndarray
    starts: np.ndarray
    noise: np.ndarray
    obs_noise: np.ndarray
    params: np.ndarray

    @classmethod
    def make(cls, tasks: np.ndarray, seeds: np.ndarray, table: TaskTable = REGISTERED) -> Episodes:
        """Draws the episodes with the given task ids of ``table`` and seeds (equal lengths)."""
        tasks = np.asarray(tasks, dtype=np.int64)
        seeds = np.asarray(seeds, dtype=np.int64)
        starts, noise, obs_noise = draw_episodes(tasks, seeds, table)
        fields = (tasks, seeds, starts, noise, obs_noise, table.params)
        return GymEpisodes.holding(fields, table.gym, table.user)

    @property
    def gym(self) -> tuple:
        """The Gymnasium tasks of the table (``()`` for compiled tasks alone).

        Task ``k`` (:class:`~mtpg.envs.specs.gym_task.GymTask`) has id ``GYM_ID_BASE + k``.
        """
        return getattr(self, "__dict__", {}).get("gym_tasks", ())

    @property
    def user(self) -> tuple:
        """The compiled tasks of users' modules of the table (``()`` for none).

        Task ``k`` (:class:`~mtpg.envs.specs.compiled_task.CompiledTask`) has id
        ``USER_ID_BASE + k``; :func:`run_jobs` plays the table with the engine's loop
        compiled for them (:mod:`mtpg.engine.user_kernels`).
        """
        return getattr(self, "__dict__", {}).get("user_tasks", ())

    @classmethod
    def single(
        cls,
        task: int,
        start: np.ndarray,
        noise: np.ndarray,
        obs_noise: np.ndarray | None = None,
        params: np.ndarray | None = None,
    ) -> Episodes:
        """A table of one given episode: ``task`` from ``start`` with the ``noise`` row.

        ``obs_noise``: the rows ``[T + 1, 2]`` of a variant with observation noise;
        ``params``: the parameter table ``task`` indexes (the registered tasks' by default).
        """
        eps = np.zeros((0, 2)) if obs_noise is None else obs_noise
        return cls(
            np.array([task], dtype=np.int64),
            np.zeros(1, dtype=np.int64),
            np.ascontiguousarray(start, dtype=np.float64).reshape(1, -1),
            np.ascontiguousarray(noise, dtype=np.float64).reshape(1, -1),
            np.ascontiguousarray(eps, dtype=np.float64).reshape(1, -1, 2),
            REGISTERED.params if params is None else params,
        )

    @classmethod
    def grid(
        cls,
        tasks: list[int],
        seeds: list[int] | np.ndarray,
        table: TaskTable = REGISTERED,
        training: bool = False,
    ) -> Episodes:
        """Every task with every seed, task-major: episode ``i * len(seeds) + k``.

        With ``training``, a Gymnasium task's seeds below ``TRAIN_RESET_OFFSET`` are
        offset by it (:mod:`mtpg.envs.specs.gym_task`), so no test seed below 10**9 replays a
        training episode; the compiled tasks' seeds are as given.
        """
        seeds = np.asarray(seeds, dtype=np.int64)
        task_col = np.repeat(np.asarray(tasks, dtype=np.int64), len(seeds))
        seed_col = np.tile(seeds, len(tasks))
        if training:
            shift = (task_col >= GYM_ID_BASE) & (seed_col < TRAIN_RESET_OFFSET)
            seed_col = np.where(shift, seed_col + TRAIN_RESET_OFFSET, seed_col)
        return cls.make(task_col, seed_col, table)

    def with_noise(self, noise: np.ndarray) -> Episodes:
        """The same table with another noise matrix (its Gymnasium tasks kept)."""
        fields = (*self[:3], noise, *self[4:])
        return GymEpisodes.holding(fields, self.gym, self.user)

    def compiled(self) -> Episodes:
        """The table without its Gymnasium tasks (its compiled tasks kept)."""
        return GymEpisodes.holding(tuple(self), (), self.user)

    def plain(self) -> Episodes:
        """The table as the compiled kernels take it (a plain :class:`Episodes`)."""
        return Episodes(*self) if type(self) is not Episodes else self


class GymEpisodes(Episodes):
    """An :class:`Episodes` table that also holds its task table's Gymnasium and compiled tasks.

    The tasks are attributes, not fields, so the compiled kernels' argument type stays
    the six arrays (they are given :meth:`Episodes.plain`).
    """

    @classmethod
    def holding(cls, fields: tuple, gym: tuple, user: tuple = ()) -> Episodes:
        """The table of ``fields`` holding the Gymnasium tasks ``gym`` and compiled ``user``.

        A plain :class:`Episodes` when both are empty.
        """
        if not gym and not user:
            return Episodes(*fields)
        table = cls(*fields)
        table.__dict__["gym_tasks"] = tuple(gym)
        table.__dict__["user_tasks"] = tuple(user)
        return table


class Jobs(NamedTuple):
    """The jobs of a batch (a kernel argument).

    Job ``j`` plays row ``episodes[j]`` of the episode table with dense root ``roots[j]``.

    Attributes:
        roots: int64 ``[n_jobs]`` dense team indices.
        episodes: int64 ``[n_jobs]`` rows of the episode table.
    """

    roots: np.ndarray
    episodes: np.ndarray


class BatchResult(NamedTuple):
    """Per-job outcomes of :func:`run_jobs` (the kernels' output argument).

    Attributes:
        returns: float64 ``[n_jobs]`` episode returns.
        steps: int64 ``[n_jobs]`` decisions (= environment steps) per episode.
        teams: int64 ``[n_jobs]`` teams visited, summed over the episode's decisions.
        instructions: int64 ``[n_jobs]`` instructions executed in the episode.
    """

    returns: np.ndarray
    steps: np.ndarray
    teams: np.ndarray
    instructions: np.ndarray

    @classmethod
    def zeros(cls, n: int) -> BatchResult:
        """Outputs for ``n`` jobs, zeroed."""
        return cls(np.zeros(n), np.zeros(n, np.int64), np.zeros(n, np.int64), np.zeros(n, np.int64))


def run_jobs(
    cp: CompiledPopulation,
    job_roots: np.ndarray,
    job_episodes: np.ndarray,
    episodes: Episodes,
    threads: int = 1,
    no_memory: bool | None = None,
    block: int = 1,
    lanes: int = DEFAULT_LANES,
) -> BatchResult:
    """Plays every job ``(root, episode)`` in one compiled call.

    Results do not depend on ``threads``: each job runs on its own with a fresh memory
    state, whichever thread takes it.

    Args:
        cp: The compiled population.
        job_roots: int64 dense team indices, one per job.
        job_episodes: int64 rows of ``episodes``, one per job.
        episodes: The episode table.
        threads: Numba threads to use (1: serial kernel, no thread pool).
        no_memory: Deprecated: the ablation is ``cp``'s (``no_memory`` of
            :func:`~mtpg.engine.compile.compile_population`). A bool overrides it for this
            call; ``None`` keeps it.
        block: Jobs taken together from the queue by one thread (see
            ``run_jobs_queue``); the number of jobs per root keeps each root's episodes on
            one thread, in order. Results do not depend on it.
        lanes: Jobs of a block played in lockstep by the lane engine
            (:mod:`mtpg.engine.lanes`); 0 plays one job at a time with the scalar
            kernel. Results do not depend on it.

    Returns:
        The per-job outcomes.
    """
    if threads < 1:
        raise ValueError(f"threads must be >= 1, got {threads}")
    if block < 1:
        raise ValueError(f"block must be >= 1, got {block}")
    if lanes < 0:
        raise ValueError(f"lanes must be >= 0, got {lanes}")
    if episodes.gym:
        return _run_mixed(cp, job_roots, job_episodes, episodes, threads, no_memory, block, lanes)
    check_fits_compiled_tasks(cp, episodes, job_episodes)
    out = BatchResult.zeros(len(job_roots))
    jobs = Jobs(
        np.ascontiguousarray(job_roots, dtype=np.int64),
        np.ascontiguousarray(job_episodes, dtype=np.int64),
    )
    queue = np.zeros(1, dtype=np.int64)
    g = cp.with_memory_mode(no_memory).graph
    queue_kernel, parallel_kernel = run_jobs_queue, run_jobs_parallel
    lanes_kernel, lanes_parallel = run_lanes_queue, run_lanes_parallel
    if episodes.user:  # the loops compiled for the table's compiled tasks
        queue_kernel, parallel_kernel, lanes_kernel, lanes_parallel = user_kernels(
            episodes.user, USER_ID_BASE, episodes.starts.shape[1]
        )
        episodes = episodes.plain()
    if threads == 1 and lanes == 0:
        queue_kernel(queue, block, jobs, episodes, out, g)
    elif threads == 1:
        lanes_kernel(queue, block, lanes, jobs, episodes, out, g)
    else:
        threads = min(threads, numba.config.NUMBA_NUM_THREADS)
        numba.set_num_threads(threads)
        if lanes == 0:
            parallel_kernel(threads, queue, block, jobs, episodes, out, g)
        else:
            lanes_parallel(threads, queue, block, lanes, jobs, episodes, out, g)
    return out


def check_fits_compiled_tasks(
    cp: CompiledPopulation, episodes: Episodes | None = None, rows: np.ndarray | None = None
) -> None:
    """Refuses a graph the compiled tasks cannot play.

    The registered tasks observe 2 inputs and take 3 actions; a compiled task of a user's
    module observes its ``n_obs`` inputs (a graph of fewer inputs cannot play it).

    Args:
        cp: The compiled population.
        episodes: The episode table (its compiled tasks checked too), or None.
        rows: The rows of ``episodes`` the jobs play (all when None).

    Raises:
        ValueError: One line naming the layout size at fault.
    """
    user = episodes.user if episodes is not None else ()
    if user:
        tasks = episodes.tasks if rows is None else episodes.tasks[np.asarray(rows)]
        present = set(np.unique(tasks).tolist())
        for k, task in enumerate(user):
            if USER_ID_BASE + k in present and cp.layout.n_obs < task.n_obs:
                raise ValueError(
                    f"layout.n_obs must be >= {task.n_obs} to play {task.name} "
                    f"(it observes {task.n_obs} inputs), got {cp.layout.n_obs}"
                )
        if all(t >= USER_ID_BASE for t in present):
            return
    n_obs, n_actions, _ = BUILTIN_SHAPE
    if cp.layout.n_obs < n_obs:
        raise ValueError(
            f"layout.n_obs must be >= {n_obs} to play the registered tasks "
            f"(they observe {n_obs} inputs), got {cp.layout.n_obs}"
        )
    if cp.layout.n_actions > n_actions:
        raise ValueError(
            f"layout.n_actions must be <= {n_actions} to play the registered tasks "
            f"(they take {n_actions} atomic actions), got {cp.layout.n_actions}"
        )


def _run_mixed(cp, job_roots, job_episodes, episodes, threads, no_memory, block, lanes):
    """:func:`run_jobs` for a table with Gymnasium tasks: their jobs step in Python."""
    job_roots = np.asarray(job_roots, dtype=np.int64)
    job_episodes = np.asarray(job_episodes, dtype=np.int64)
    out = BatchResult.zeros(len(job_roots))
    gym_job = episodes.tasks[job_episodes] >= GYM_ID_BASE
    table = episodes.compiled()
    if not gym_job.all():
        mine = ~gym_job
        done = run_jobs(
            cp, job_roots[mine], job_episodes[mine], table, threads, no_memory, block, lanes
        )
        for field, values in zip(out, done, strict=True):
            field[mine] = values
    cp = cp.with_memory_mode(no_memory)
    for k, task in enumerate(episodes.gym):
        mine = np.flatnonzero(gym_job & (episodes.tasks[job_episodes] == GYM_ID_BASE + k))
        if len(mine):
            seeds = episodes.seeds[job_episodes[mine]]
            done = play_gym(cp, job_roots[mine], task, seeds)
            for field, values in zip(out, done, strict=True):
                field[mine] = values
    return out


def evaluate_roots(
    cp: CompiledPopulation,
    root_ids: list[int],
    episodes: Episodes,
    threads: int = 1,
    no_memory: bool | None = None,
    lanes: int = DEFAULT_LANES,
) -> tuple[np.ndarray, BatchResult]:
    """Plays every episode of the table with every root.

    Args:
        cp: The compiled population.
        root_ids: Model ids of the teams to evaluate.
        episodes: The episode table.
        threads: Numba threads.
        no_memory: Deprecated pass-through, see :func:`run_jobs` (the ablation is a
            property of ``cp``).
        lanes: Lane-block size, see :func:`run_jobs` (0: the scalar kernel).

    Returns:
        ``returns`` float64 ``[n_roots, n_episodes]`` and the flat per-job result
        (root-major).
    """
    roots = np.array([cp.team_index(r) for r in root_ids], dtype=np.int64)
    n_ep = len(episodes.tasks)
    job_roots = np.repeat(roots, n_ep)
    job_eps = np.tile(np.arange(n_ep, dtype=np.int64), len(roots))
    result = run_jobs(
        cp, job_roots, job_eps, episodes, threads, no_memory, block=max(n_ep, 1), lanes=lanes
    )
    return result.returns.reshape(len(roots), n_ep), result
