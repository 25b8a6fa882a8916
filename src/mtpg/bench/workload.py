"""The engine benchmark's workload, played by the engine's own batch kernel.

A fixed, seeded workload: ``graphs`` independent random graphs (``teams`` x ``programs``
x ``instructions``, about 40% of programs pointing to a later team, one memory bank per
program) each play ``episodes`` CartPole episodes. Episode start states come from a fixed
pool drawn by :func:`mtpg.envs.make_episodes`; graph ``g``'s ``k``-th episode is pool row
``(g + k * graphs) % EPISODE_POOL``.

The workload is a batch of jobs (graph x episode) exactly as training builds one, and it
is played by :func:`mtpg.engine.batch.run_jobs`, the call training makes: the benchmark
has no episode loop of its own, so it times the very code that training runs (memory
reset per episode, environment steps and bookkeeping included).

The baselines (the reference interpreter, pytpg and the same work in C) are in
:mod:`mtpg.bench.engine` and :mod:`mtpg.bench.c_port`.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from mtpg.engine.batch import BatchResult, Episodes, run_jobs
from mtpg.engine.compile import CompiledPopulation, compile_population
from mtpg.engine.lanes import DEFAULT_LANES
from mtpg.engine.random_populations import layered_graphs
from mtpg.envs import CARTPOLE
from mtpg.model.graph import Population

#: Share of programs that point to another team.
POINTER_FRACTION = 0.4
#: Size of the episode pool (a prime, so graphs walk it along different paths).
EPISODE_POOL = 1021


def pointer_probability(teams: int, programs: int, fraction: float = POINTER_FRACTION) -> float:
    """The ``p_pointer`` of :func:`layered_graphs` giving ``fraction`` pointers overall.

    Only programs ``1..programs-1`` of the first ``teams - 1`` teams may point, so the
    expected fraction is ``p * (teams - 1) * (programs - 1) / (teams * programs)``.

    Args:
        teams: Teams per graph.
        programs: Programs per team.
        fraction: Wanted share of pointer programs.

    Returns:
        The probability, clipped to ``[0, 1]``.
    """
    eligible = (teams - 1) * (programs - 1)
    if eligible <= 0:
        return 0.0
    return min(1.0, fraction * teams * programs / eligible)


@dataclass(frozen=True)
class Workload:
    """The benchmark's graphs and episodes, as one batch of jobs.

    Attributes:
        pop: The population holding every graph.
        root_ids: Model id of each graph's root team.
        cp: The compiled population.
        pool: The ``EPISODE_POOL`` CartPole episodes (start states and noise).
        job_roots: int64 ``[graphs * episodes]`` dense root of each job (graph-major).
        job_episodes: int64 ``[graphs * episodes]`` pool row of each job.
        episodes: Episodes per graph.
        teams: Teams per graph.
        programs: Programs per team.
        instructions: Instructions per program (before intron removal).
        pointer_fraction: Measured share of programs pointing to a team.
        build_seconds: Time taken to draw and compile the graphs.
    """

    pop: Population
    root_ids: list[int]
    cp: CompiledPopulation
    pool: Episodes
    job_roots: np.ndarray
    job_episodes: np.ndarray
    episodes: int
    teams: int
    programs: int
    instructions: int
    pointer_fraction: float
    build_seconds: float

    @property
    def n_graphs(self) -> int:
        """Number of graphs."""
        return len(self.root_ids)


def make_workload(
    graphs: int,
    teams: int = 3,
    programs: int = 10,
    instructions: int = 10,
    episodes: int = 16,
    seed: int = 0,
) -> Workload:
    """Draws the benchmark workload.

    Args:
        graphs: Number of graphs.
        teams: Teams per graph.
        programs: Programs per team (>= 2).
        instructions: Instructions per program.
        episodes: CartPole episodes per graph.
        seed: Seed of the graphs and of the episode pool.

    Returns:
        The workload.
    """
    if graphs < 1 or teams < 1 or programs < 2 or instructions < 1 or episodes < 1:
        raise ValueError(
            "need graphs >= 1, teams >= 1, programs >= 2, instructions >= 1, episodes >= 1"
        )
    t0 = time.perf_counter()
    rng = np.random.default_rng([seed, 0x7E9])
    p = pointer_probability(teams, programs)
    pop, root_ids = layered_graphs(rng, graphs, teams, programs, instructions, p_pointer=p)
    cp = compile_population(pop)
    build = time.perf_counter() - t0
    seeds = np.arange(EPISODE_POOL, dtype=np.int64) + np.int64(seed) * EPISODE_POOL
    pool = Episodes.make(np.full(EPISODE_POOL, CARTPOLE, dtype=np.int64), seeds)
    roots = np.array([cp.team_index(r) for r in root_ids], dtype=np.int64)
    g = np.repeat(np.arange(graphs, dtype=np.int64), episodes)
    k = np.tile(np.arange(episodes, dtype=np.int64), graphs)
    return Workload(
        pop=pop,
        root_ids=root_ids,
        cp=cp,
        pool=pool,
        job_roots=roots[g],
        job_episodes=(g + k * graphs) % EPISODE_POOL,
        episodes=episodes,
        teams=teams,
        programs=programs,
        instructions=instructions,
        pointer_fraction=float(np.mean(cp.graph.prog_action >= 0)),
        build_seconds=build,
    )


@dataclass(frozen=True)
class DriveResult:
    """Per-job outcomes of one compiled run and its timing.

    Attributes:
        result: Returns, steps, teams and instructions of every job.
        seconds: Wall time of the kernel call.
        cpu_seconds: Process CPU time of the kernel call.
    """

    result: BatchResult
    seconds: float
    cpu_seconds: float

    @property
    def decisions(self) -> int:
        """Decisions made (environment steps over all episodes)."""
        return int(self.result.steps.sum())


def drive(work: Workload, threads: int = 1, lanes: int = DEFAULT_LANES) -> DriveResult:
    """Plays the whole workload once with the engine's batch kernel.

    Args:
        work: The workload.
        threads: Numba threads (1: the serial kernel, no thread pool).
        lanes: Lane-block size of :func:`~mtpg.engine.batch.run_jobs` (0: the scalar
            kernel, one job at a time).

    Returns:
        The per-job outcomes, the wall time and the process CPU time.
    """
    c0, t0 = time.process_time(), time.perf_counter()
    result = run_jobs(
        work.cp,
        work.job_roots,
        work.job_episodes,
        work.pool,
        threads,
        block=work.episodes,
        lanes=lanes,
    )
    seconds, cpu = time.perf_counter() - t0, time.process_time() - c0
    return DriveResult(result, seconds, cpu)


def warm_up(threads: int) -> None:
    """Compiles (or loads from cache) the kernels on a tiny workload."""
    tiny = make_workload(2, 2, 2, 2, episodes=2)
    drive(tiny, 1)
    if threads > 1:
        drive(tiny, threads)
