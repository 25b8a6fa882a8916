"""The engine benchmark's workload and its compiled driver (see :mod:`mtpg.bench.engine`).

A fixed, seeded workload: ``graphs`` independent random graphs (``teams`` x ``programs``
x ``instructions``, about 40% of programs pointing to a later team, one memory bank per
program) each drive CartPole for ``steps`` decisions, starting a new episode (and so
resetting memory) whenever one terminates or is truncated. Episode start states come
from a fixed pool drawn by :func:`mtpg.envs.make_episodes`.

Three interpreters are timed on it:

* the compiled engine (:func:`mtpg.engine.kernels.decide`) on the whole workload, environment
  steps included, serially or over Numba threads;
* the plain-Python reference interpreter (:class:`~mtpg.engine.reference.ReferenceAgent`) on
  the first few graphs, timing its decisions only; its actions are checked against the
  compiled run, so both play the very same episodes;
* optionally the ``pytpg`` package, on graphs of the same shape (same team and pointer
  structure, programs of the same length in its own instruction set, no memory) fed the
  observation sequences recorded by the reference run, timing its decisions only.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numba
import numpy as np
from numba import njit, prange

from mtpg.engine.compile import CompiledPopulation, compile_population
from mtpg.engine.kernels import decide, thread_buffers
from mtpg.engine.workload import layered_graphs
from mtpg.envs import CARTPOLE, TASK_PARAMS, env_observe, env_reset, env_step, make_episodes
from mtpg.model.graph import Population
from mtpg.model.instructions import N_CONSTANTS

#: Share of programs that point to another team.
POINTER_FRACTION = 0.4
#: Size of the episode pool (a prime, so graphs walk it along different paths).
EPISODE_POOL = 1021
#: Chunks per thread in parallel runs (graphs are dealt out round-robin).
CHUNKS_PER_THREAD = 8


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


def episode_row(graph: int, k: int, n_graphs: int, n_pool: int) -> int:
    """Pool row of the ``k``-th episode of graph ``graph`` (same rule as the kernel)."""
    return (graph + k * n_graphs) % n_pool


@dataclass(frozen=True)
class Workload:
    """The benchmark's graphs and episodes.

    Attributes:
        pop: The population holding every graph.
        root_ids: Model id of each graph's root team.
        cp: The compiled population.
        roots: int64 dense root team index of each graph.
        starts: float64 ``[EPISODE_POOL, STATE_SIZE]`` episode start states.
        noise: float64 ``[EPISODE_POOL, T + 1]`` episode noise rows.
        steps: Decisions per graph.
        teams: Teams per graph.
        programs: Programs per team.
        instructions: Instructions per program (before intron removal).
        pointer_fraction: Measured share of programs pointing to a team.
        build_seconds: Time taken to draw and compile the graphs.
    """

    pop: Population
    root_ids: list[int]
    cp: CompiledPopulation
    roots: np.ndarray
    starts: np.ndarray
    noise: np.ndarray
    steps: int
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
    steps: int = 300,
    seed: int = 0,
) -> Workload:
    """Draws the benchmark workload.

    Args:
        graphs: Number of graphs.
        teams: Teams per graph.
        programs: Programs per team (>= 2).
        instructions: Instructions per program.
        steps: Decisions per graph.
        seed: Seed of the graphs and of the episode pool.

    Returns:
        The workload.
    """
    if graphs < 1 or teams < 1 or programs < 2 or instructions < 1 or steps < 1:
        raise ValueError(
            "need graphs >= 1, teams >= 1, programs >= 2, instructions >= 1, steps >= 1"
        )
    t0 = time.perf_counter()
    rng = np.random.default_rng([seed, 0x7E9])
    p = pointer_probability(teams, programs)
    pop, root_ids = layered_graphs(rng, graphs, teams, programs, instructions, p_pointer=p)
    cp = compile_population(pop)
    build = time.perf_counter() - t0
    seeds = np.arange(EPISODE_POOL, dtype=np.int64) + np.int64(seed) * EPISODE_POOL
    starts, noise = make_episodes(np.full(EPISODE_POOL, CARTPOLE, dtype=np.int64), seeds)
    return Workload(
        pop=pop,
        root_ids=root_ids,
        cp=cp,
        roots=np.array([cp.team_index(r) for r in root_ids], dtype=np.int64),
        starts=np.ascontiguousarray(starts),
        noise=np.ascontiguousarray(noise),
        steps=steps,
        teams=teams,
        programs=programs,
        instructions=instructions,
        pointer_fraction=float(np.mean(cp.prog_action >= 0)),
        build_seconds=build,
    )


@njit(cache=True, error_model="numpy")
def drive_strided(
    chunk,
    n_chunks,
    roots,
    steps,
    ep_start,
    ep_noise,
    params,
    out_teams,
    out_instr,
    out_episodes,
    out_actions,
    team_offsets,
    team_members,
    prog_offsets,
    instrs,
    prog_action,
    prog_bank,
    R,
    M,
    base,
):  # noqa: N803
    """Drives graphs ``chunk, chunk + n_chunks, ...`` on CartPole with one workspace.

    Graph ``g`` makes ``steps`` decisions from root ``roots[g]``; its ``k``-th episode
    starts from pool row ``(g + k * n_graphs) % n_pool``. It writes the teams visited,
    instructions executed and episodes started to ``out_*[g]``, and its discrete actions
    to ``out_actions[g]`` when ``g < out_actions.shape[0]``.
    """
    n_graphs = len(roots)
    n_pool = ep_start.shape[0]
    W, team_stamp, bank_stamp, state, counts = thread_buffers(team_offsets, prog_bank, R, M, base)  # noqa: N806
    obs = W[R + N_CONSTANTS : R + N_CONSTANTS + 2]
    stamp = 0
    episode = 0
    record = out_actions.shape[0]
    for g in range(chunk, n_graphs, n_chunks):
        root = roots[g]
        k = 0
        e = g % n_pool
        env_reset(CARTPOLE, params, ep_start[e], state)
        env_observe(CARTPOLE, params, state, ep_noise[e, 0], obs)
        counts[0] = 0
        counts[1] = 0
        t = 0
        for s in range(steps):
            a_d, a_c = decide(
                root,
                W,
                team_stamp,
                stamp,
                bank_stamp,
                episode,
                False,
                counts,
                team_offsets,
                team_members,
                prog_offsets,
                instrs,
                prog_action,
                prog_bank,
                R,
                M,
                base,
            )
            stamp += 1
            if g < record:
                out_actions[g, s] = a_d
            reward, terminated, truncated = env_step(CARTPOLE, params, state, a_d, a_c)
            t += 1
            if terminated or truncated:
                k += 1
                episode += 1
                e = (g + k * n_graphs) % n_pool
                env_reset(CARTPOLE, params, ep_start[e], state)
                t = 0
            env_observe(CARTPOLE, params, state, ep_noise[e, t], obs)
        episode += 1
        out_teams[g] = counts[0]
        out_instr[g] = counts[1]
        out_episodes[g] = k + 1


@njit(cache=True, error_model="numpy", parallel=True)
def drive_parallel(
    n_chunks,
    roots,
    steps,
    ep_start,
    ep_noise,
    params,
    out_teams,
    out_instr,
    out_episodes,
    out_actions,
    team_offsets,
    team_members,
    prog_offsets,
    instrs,
    prog_action,
    prog_bank,
    R,
    M,
    base,
):  # noqa: N803
    """Runs :func:`drive_strided` for ``n_chunks`` strided chunks over the Numba threads."""
    for c in prange(n_chunks):
        drive_strided(
            c,
            n_chunks,
            roots,
            steps,
            ep_start,
            ep_noise,
            params,
            out_teams,
            out_instr,
            out_episodes,
            out_actions,
            team_offsets,
            team_members,
            prog_offsets,
            instrs,
            prog_action,
            prog_bank,
            R,
            M,
            base,
        )


@dataclass(frozen=True)
class DriveResult:
    """Per-graph counters of one compiled run.

    Attributes:
        teams: int64 ``[graphs]`` teams visited.
        instructions: int64 ``[graphs]`` instructions executed.
        episodes: int64 ``[graphs]`` episodes started.
        actions: int8 ``[record, steps]`` discrete actions of the first ``record`` graphs.
        seconds: Wall time of the kernel call.
    """

    teams: np.ndarray
    instructions: np.ndarray
    episodes: np.ndarray
    actions: np.ndarray
    seconds: float


def drive(work: Workload, threads: int = 1, record: int = 0) -> DriveResult:
    """Runs the whole workload once with the compiled engine.

    Args:
        work: The workload.
        threads: Numba threads (1: the serial kernel, no thread pool).
        record: Number of leading graphs whose actions are kept.

    Returns:
        The counters and the wall time.
    """
    if threads < 1:
        raise ValueError(f"threads must be >= 1, got {threads}")
    n = work.n_graphs
    out_teams = np.zeros(n, np.int64)
    out_instr = np.zeros(n, np.int64)
    out_episodes = np.zeros(n, np.int64)
    out_actions = np.zeros((min(record, n), work.steps), np.int8)
    args = (
        work.roots,
        work.steps,
        work.starts,
        work.noise,
        TASK_PARAMS,
        out_teams,
        out_instr,
        out_episodes,
        out_actions,
        *work.cp.kernel_args(),
    )
    if threads == 1:
        t0 = time.perf_counter()
        drive_strided(0, 1, *args)
        seconds = time.perf_counter() - t0
    else:
        numba.set_num_threads(threads)
        t0 = time.perf_counter()
        drive_parallel(threads * CHUNKS_PER_THREAD, *args)
        seconds = time.perf_counter() - t0
    return DriveResult(out_teams, out_instr, out_episodes, out_actions, seconds)


def warm_up(threads: int) -> None:
    """Compiles (or loads from cache) the kernels on a tiny workload."""
    tiny = make_workload(2, 2, 2, 2, steps=3)
    drive(tiny, 1)
    if threads > 1:
        drive(tiny, threads)
