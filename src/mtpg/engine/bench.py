"""The engine benchmark behind ``mtpg bench engine``.

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

import os
import platform
import statistics
import time
from dataclasses import dataclass

import numba
import numpy as np
from numba import njit, prange

from mtpg.engine.compile import CompiledPopulation, compile_population
from mtpg.engine.kernels import decide, new_workspace
from mtpg.engine.reference import ReferenceAgent
from mtpg.engine.workload import layered_graphs
from mtpg.envs import CARTPOLE, TASK_PARAMS, env_observe, env_reset, env_step, make_episodes
from mtpg.envs.core import STATE_SIZE
from mtpg.model.graph import Population
from mtpg.model.instructions import CONSTANTS, N_CONSTANTS

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
    n_teams = len(team_offsets) - 1
    n_banks = (prog_bank.max() + 1) if len(prog_bank) else 0
    W = new_workspace(base + n_banks * M, R)  # noqa: N806
    team_stamp = np.full(n_teams, -1, dtype=np.int64)
    bank_stamp = np.full(n_banks, -1, dtype=np.int64)
    state = np.zeros(STATE_SIZE)
    counts = np.zeros(2, dtype=np.int64)
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


@dataclass(frozen=True)
class ReferenceRun:
    """The reference interpreter on the first graphs of the workload.

    Attributes:
        decisions: Decisions made.
        seconds: Time spent inside ``ReferenceAgent.act``.
        actions: int8 ``[graphs, steps]`` discrete actions.
        observations: float64 ``[graphs, steps, 2]`` the observation of every decision.
    """

    decisions: int
    seconds: float
    actions: np.ndarray
    observations: np.ndarray


def run_reference(work: Workload, graphs: int) -> ReferenceRun:
    """Plays the first ``graphs`` graphs with the reference interpreter.

    Episodes follow the same pool rows as :func:`drive_strided`; only the calls to
    ``act`` are timed.

    Args:
        work: The workload.
        graphs: Number of leading graphs to play.

    Returns:
        Decisions, time, actions and observations.
    """
    graphs = min(graphs, work.n_graphs)
    steps = work.steps
    actions = np.zeros((graphs, steps), np.int8)
    observations = np.zeros((graphs, steps, 2))
    state = np.zeros(STATE_SIZE)
    obs = np.zeros(2)
    n_pool = len(work.starts)
    seconds = 0.0
    clock = time.perf_counter
    for g in range(graphs):
        agent = ReferenceAgent(work.pop, work.root_ids[g])
        agent.reset()
        k = 0
        e = episode_row(g, k, work.n_graphs, n_pool)
        env_reset(CARTPOLE, TASK_PARAMS, work.starts[e], state)
        env_observe(CARTPOLE, TASK_PARAMS, state, work.noise[e, 0], obs)
        t = 0
        for s in range(steps):
            observations[g, s] = obs
            t0 = clock()
            d = agent.act(obs)
            seconds += clock() - t0
            actions[g, s] = d.action
            _, terminated, truncated = env_step(
                CARTPOLE, TASK_PARAMS, state, d.action, d.continuous
            )
            t += 1
            if terminated or truncated:
                k += 1
                e = episode_row(g, k, work.n_graphs, n_pool)
                agent.reset()
                env_reset(CARTPOLE, TASK_PARAMS, work.starts[e], state)
                t = 0
            env_observe(CARTPOLE, TASK_PARAMS, state, work.noise[e, t], obs)
    return ReferenceRun(graphs * steps, seconds, actions, observations)


def _pytpg_graph(pytpg_core, rng: np.random.Generator, pop: Population, root_id: int, layout):
    """Builds a pytpg graph with the shape and pointer structure of one of ours.

    Teams keep their programs' order, atomic actions and pointers (to the matching
    team); each program becomes a pytpg program of the same length, drawn at random from
    pytpg's default operators (destinations among the private registers; operands an
    input, a register or one of our constants, one third each).
    """
    c = pytpg_core
    from pytpg.runtime import default_operator_registry

    registry = default_operator_registry()
    operators = [registry.resolve(name) for name in registry.names]
    team_ids = pop.reachable(root_id)
    local = {tid: i for i, tid in enumerate(team_ids)}
    teams = []
    next_id = 0
    for tid in team_ids:
        learners = []
        for pid in pop.teams[tid].programs:
            prog = pop.programs[pid]
            code = []
            for _ in range(len(prog.instructions)):
                op = operators[int(rng.integers(len(operators)))]
                operands = []
                for _ in range(op.arity):
                    kind = int(rng.integers(3))
                    if kind == 0:
                        operands.append(
                            c.InputOperand(c.InputIndex(int(rng.integers(layout.n_obs))))
                        )
                    elif kind == 1:
                        operands.append(
                            c.RegisterOperand(
                                c.RegisterIndex(int(rng.integers(layout.n_registers)))
                            )
                        )
                    else:
                        operands.append(
                            c.ConstantOperand(float(CONSTANTS[int(rng.integers(N_CONSTANTS))]))
                        )
                code.append(
                    c.Instruction(
                        operator=c.OperatorName(op.name),
                        destination=c.RegisterIndex(int(rng.integers(layout.n_registers))),
                        operands=tuple(operands),
                    )
                )
            if prog.is_atomic:
                action = c.AtomicAction(c.ActionID(prog.atomic_action))
            else:
                action = c.TeamReference(c.TeamID(local[prog.action]))
            program = c.Program(c.ProgramID(next_id), tuple(code))
            learners.append(c.Learner(c.LearnerID(next_id), program, action))
            next_id += 1
        teams.append(c.Team(c.TeamID(local[tid]), tuple(learners)))
    return c.TPGGraph(tuple(teams), (c.TeamID(0),))


def run_pytpg(work: Workload, reference: ReferenceRun, seed: int = 0) -> dict | None:
    """Times pytpg's decisions on graphs shaped like the workload's first graphs.

    Each graph sees the observation sequence the reference run recorded for the graph
    it copies. Graph validation before each decision is switched off; pytpg still checks
    every program as it runs it, which is part of its design.

    Args:
        work: The workload.
        reference: The reference run (its observations are replayed).
        seed: Seed of the program draws.

    Returns:
        ``{"decisions", "seconds", "teams"}`` or None when pytpg is not installed.
    """
    try:
        import pytpg.core as pytpg_core
        from pytpg.runtime import GraphRuntime, RuntimeConfig
    except ImportError:
        return None
    layout = work.pop.layout
    rng = np.random.default_rng([seed, 0x9F7])
    runtime = GraphRuntime(
        RuntimeConfig(input_size=layout.n_obs, register_count=layout.n_registers),
        validate_before_execution=False,
    )
    decisions, teams, seconds = 0, 0, 0.0
    clock = time.perf_counter
    for g in range(reference.observations.shape[0]):
        graph = _pytpg_graph(pytpg_core, rng, work.pop, work.root_ids[g], layout)
        seq = [tuple(float(x) for x in o) for o in reference.observations[g]]
        t0 = clock()
        for o in seq:
            teams += len(runtime.traverse(graph, o).steps)
        seconds += clock() - t0
        decisions += len(seq)
    return {"decisions": decisions, "seconds": seconds, "teams": teams}


def machine_info() -> dict:
    """CPU model, cores, OS and interpreter versions of this machine."""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return {
        "cpu": cpu,
        "cores": os.cpu_count(),
        "os": platform.platform(),
        "python": platform.python_version(),
        "numpy": np.__version__,
        "numba": numba.__version__,
    }


def benchmark(
    graphs: int = 3000,
    teams: int = 3,
    programs: int = 10,
    instructions: int = 10,
    steps: int = 300,
    threads: int = 1,
    repeats: int = 3,
    seed: int = 0,
    reference_graphs: int = 20,
    pytpg: bool = True,
    log=None,
) -> dict:
    """Runs the whole benchmark.

    Args:
        graphs: Number of graphs.
        teams: Teams per graph.
        programs: Programs per team.
        instructions: Instructions per program.
        steps: Decisions per graph.
        threads: Numba threads of the compiled runs.
        repeats: Timed compiled runs; the median is reported.
        seed: Workload seed.
        reference_graphs: Graphs played by the reference interpreter and by pytpg.
        pytpg: Time pytpg too (when installed).
        log: Called with progress lines (``None``: silent).

    Returns:
        The figures (see ``mtpg bench engine``).
    """
    say = log or (lambda _msg: None)
    if threads < 1 or repeats < 1 or reference_graphs < 0:
        raise ValueError("need threads >= 1, repeats >= 1, reference-graphs >= 0")
    if threads > numba.config.NUMBA_NUM_THREADS:
        raise ValueError(f"threads must be <= {numba.config.NUMBA_NUM_THREADS} (NUMBA_NUM_THREADS)")
    say("compiling kernels ...")
    warm_up(threads)
    say(f"building {graphs} graphs ...")
    work = make_workload(graphs, teams, programs, instructions, steps, seed)
    record = min(reference_graphs, graphs)
    runs = []
    for r in range(repeats):
        res = drive(work, threads, record)
        runs.append(res)
        say(f"  run {r + 1}/{repeats}: {graphs * steps / res.seconds:,.0f} decisions/s")
    first = runs[0]
    for res in runs[1:]:
        if not np.array_equal(res.instructions, first.instructions):
            raise RuntimeError("compiled runs disagree between repeats")
    seconds = statistics.median(r.seconds for r in runs)
    decisions = graphs * steps
    ref = None
    if record:
        say(f"reference interpreter on {record} graphs ...")
        ref = run_reference(work, record)
        if not np.array_equal(ref.actions, first.actions):
            raise RuntimeError("reference interpreter and compiled engine disagree")
    pt = None
    if pytpg and ref is not None:
        say(f"pytpg on {record} graphs ...")
        pt = run_pytpg(work, ref, seed)
    rate = decisions / seconds
    ref_rate = ref.decisions / ref.seconds if ref is not None and ref.seconds > 0 else None
    pt_rate = pt["decisions"] / pt["seconds"] if pt and pt["seconds"] > 0 else None
    executed = int(first.instructions.sum())
    total_instr = int(work.cp.n_instructions.sum())
    return {
        "decisions_per_s": rate,
        "instructions_per_decision": executed / decisions,
        "teams_per_decision": int(first.teams.sum()) / decisions,
        "instructions_per_s": executed / seconds,
        "threads": threads,
        "reference_decisions_per_s": ref_rate,
        "pytpg_decisions_per_s": pt_rate,
        "speedup_vs_reference": rate / ref_rate if ref_rate else None,
        "speedup_vs_pytpg": rate / pt_rate if pt_rate else None,
        "pytpg_teams_per_decision": pt["teams"] / pt["decisions"] if pt else None,
        "graphs": graphs,
        "teams": teams,
        "programs": programs,
        "instructions": instructions,
        "steps": steps,
        "decisions": decisions,
        "episodes": int(first.episodes.sum()),
        "pointer_fraction": work.pointer_fraction,
        "effective_instruction_fraction": len(work.cp.instrs) / total_instr,
        "repeats": repeats,
        "seconds": seconds,
        "seconds_all": [r.seconds for r in runs],
        "build_seconds": work.build_seconds,
        "reference_graphs": record,
        "seed": seed,
        "machine": machine_info(),
    }
