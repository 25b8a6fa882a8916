"""The engine benchmark behind ``mtpg bench engine``: baselines and the summary.

The workload and its compiled run (the engine's own batch kernel) live in
:mod:`mtpg.bench.workload`. Besides the compiled engine, three baselines can be timed:
the plain-Python reference interpreter on the first graphs (it plays the very same jobs,
and every return and episode length is checked against the compiled run), the ``pytpg``
package when installed (graphs of the same shape fed the recorded observations), and with
``c=True`` the same work in hand-written C (:mod:`mtpg.bench.c_port`), checked job by job
and timed interleaved with one-thread engine runs.
"""

from __future__ import annotations

import os
import platform
import statistics
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numba
import numpy as np

from mtpg.bench.workload import Workload, drive, make_workload, warm_up
from mtpg.engine.batch import BatchResult
from mtpg.engine.lanes import DEFAULT_LANES
from mtpg.engine.oracle import ReferenceAgent, reference_episode
from mtpg.envs import CARTPOLE
from mtpg.model.graph import Population
from mtpg.model.instructions import CONSTANTS, N_CONSTANTS


@dataclass(frozen=True)
class ReferenceRun:
    """The reference interpreter on the first graphs of the workload.

    Attributes:
        decisions: Decisions made.
        seconds: Time spent inside ``ReferenceAgent.act``.
        result: Per-job outcomes of the played jobs (teams and instructions are 0: the
            reference interpreter does not count them).
        observations: Per graph, float64 ``[decisions, 2]`` the observation of every decision.
    """

    decisions: int
    seconds: float
    result: BatchResult
    observations: list[np.ndarray]


class _TimedAgent:
    """A reference agent that times its decisions and keeps the observation of each."""

    def __init__(self, agent: ReferenceAgent) -> None:
        self.agent = agent
        self.seconds = 0.0
        self.seen: list[np.ndarray] = []

    def reset(self) -> None:
        self.agent.reset()

    def act(self, obs: np.ndarray):
        self.seen.append(np.array(obs, dtype=np.float64))
        t0 = time.perf_counter()
        decision = self.agent.act(obs)
        self.seconds += time.perf_counter() - t0
        return decision


def run_reference(work: Workload, graphs: int) -> ReferenceRun:
    """Plays the jobs of the first ``graphs`` graphs with the reference interpreter.

    The episodes are those of the same jobs in the workload, played by
    :func:`~mtpg.engine.oracle.reference_episode`; only the calls to ``act`` are timed.

    Args:
        work: The workload.
        graphs: Number of leading graphs to play.

    Returns:
        Decisions, time, per-job outcomes and observations.
    """
    graphs = min(graphs, work.n_graphs)
    n_jobs = graphs * work.episodes
    returns, steps = np.zeros(n_jobs), np.zeros(n_jobs, np.int64)
    observations = []
    seconds = 0.0
    for g in range(graphs):
        agent = _TimedAgent(ReferenceAgent(work.pop, work.root_ids[g]))
        for j in range(g * work.episodes, (g + 1) * work.episodes):
            e = int(work.job_episodes[j])
            returns[j], steps[j] = reference_episode(
                agent, CARTPOLE, work.pool.starts[e], work.pool.noise[e]
            )
        seconds += agent.seconds
        observations.append(np.array(agent.seen).reshape(-1, 2))
    zeros = np.zeros(n_jobs, np.int64)
    result = BatchResult(returns, steps, zeros, zeros.copy())
    return ReferenceRun(int(steps.sum()), seconds, result, observations)


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
    for g, seen in enumerate(reference.observations):
        graph = _pytpg_graph(pytpg_core, rng, work.pop, work.root_ids[g], layout)
        seq = [tuple(float(x) for x in o) for o in seen]
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


def _same_result(a: BatchResult, b: BatchResult) -> bool:
    """Whether two runs of the workload gave the same outcome for every job."""
    return all(
        np.array_equal(x, y)
        for x, y in zip(
            (a.returns, a.steps, a.teams, a.instructions),
            (b.returns, b.steps, b.teams, b.instructions),
            strict=True,
        )
    )


def _c_runs(
    work: Workload, engine: BatchResult, repeats: int, say, engine_run, builds, lanes: int = 0
):
    """Times each C build interleaved with the engine: C, engine, C', engine, C, ...

    Every C run is paired with the one-thread engine run just after it, so each build's
    ratio is a median of per-pair ratios, free of the drift of a shared machine.

    Args:
        work: The workload.
        engine: The engine's outcomes, which every C build must equal.
        repeats: Pairs per build.
        say: Progress callback.
        engine_run: Runs the engine once on one thread (a ``DriveResult``).
        builds: Optimisation flag tuples, one C build each.
        lanes: The C program's lane-block size (0: one job at a time), the engine's.

    Returns:
        ``{flags: (c_cpu_seconds, engine_cpu_seconds)}`` per repeat, or None without a
        compiler.
    """
    from mtpg.bench import c_port

    if c_port.find_compiler() is None:
        say("no C compiler: the C port is not timed")
        return None
    with tempfile.TemporaryDirectory(prefix="mtpg-bench-") as tmp:
        data = Path(tmp) / "workload.bin"
        c_port.write_input(work, data)
        exes = {}
        for k, flags in enumerate(builds):
            folder = Path(tmp) / f"build{k}"
            folder.mkdir()
            exes[flags] = c_port.build(folder, flags=flags)
            first = c_port.run_port(exes[flags], data, len(work.job_roots), lanes)
            c_port.check(engine, first.result)
            say(
                f"C port ({' '.join(flags)}): every job's return, steps, teams and instructions"
                " equal the engine's"
            )
        pairs: dict[tuple[str, ...], tuple[list[float], list[float]]] = {
            flags: ([], []) for flags in builds
        }
        for r in range(repeats):
            for flags, exe in exes.items():
                c_cpu, e_cpu = pairs[flags]
                c_cpu.append(c_port.run_port(exe, data, len(work.job_roots), lanes).cpu_seconds)
                e_cpu.append(engine_run().cpu_seconds)
                say(
                    f"  pair {r + 1}/{repeats} ({' '.join(flags)}): C {c_cpu[-1]:.3f} s,"
                    f" engine {e_cpu[-1]:.3f} s CPU"
                )
    return pairs


def _time_engine(
    work: Workload, threads: int, repeats: int, say, lanes: int = DEFAULT_LANES
) -> tuple[list, list]:
    """The timed compiled runs, and above one thread the one-thread run paired with each.

    Raises:
        RuntimeError: Two runs disagree on any job (between repeats or thread counts).
    """
    runs, singles = [], []
    for r in range(repeats):
        if threads > 1:  # the scaling: one-thread runs interleaved with the N-thread runs
            singles.append(drive(work, 1, lanes))
        res = drive(work, threads, lanes)
        runs.append(res)
        say(
            f"  run {r + 1}/{repeats}: {res.decisions / res.seconds:,.0f} decisions/s"
            + (f" (1 thread: {res.decisions / singles[-1].seconds:,.0f})" if singles else "")
        )
    for res in runs[1:] + singles:
        if not _same_result(res.result, runs[0].result):
            raise RuntimeError("compiled runs disagree between repeats or thread counts")
    return runs, singles


def _checked_reference(work: Workload, engine: BatchResult, graphs: int, say):
    """The reference interpreter on the first ``graphs`` graphs, checked against the engine.

    Raises:
        RuntimeError: A played job's return or length differs from the engine's.
    """
    say(f"reference interpreter on {graphs} graphs ...")
    ref = run_reference(work, graphs)
    played = slice(0, graphs * work.episodes)
    if not (
        np.array_equal(ref.result.steps, engine.steps[played])
        and np.array_equal(ref.result.returns, engine.returns[played])
    ):
        raise RuntimeError("reference interpreter and compiled engine disagree")
    return ref


def _time_c(
    work: Workload, engine: BatchResult, repeats: int, say, c_flags, c_beside, lanes=DEFAULT_LANES
):
    """The C builds asked for (:func:`_c_runs`): the main flags, then those beside."""
    say("the same work in C (interleaved with one-thread engine runs) ...")
    from mtpg.bench.c_port import C_FLAGS, C_FLAGS_BESIDE

    c_flags = tuple(c_flags) if c_flags else C_FLAGS
    c_beside = C_FLAGS_BESIDE if c_beside is None else tuple(c_beside)
    builds = [c_flags] + ([c_beside] if c_beside and c_beside != c_flags else [])
    return _c_runs(work, engine, repeats, say, lambda: drive(work, 1, lanes), builds, lanes)


def _summary(work: Workload, runs: list, threads: int, ref: ReferenceRun | None, pt) -> dict:
    """The figures of the compiled runs and the Python baselines (see ``mtpg bench engine``)."""
    first = runs[0].result
    seconds = statistics.median(r.seconds for r in runs)
    decisions = runs[0].decisions
    rate = decisions / seconds
    ref_rate = ref.decisions / ref.seconds if ref is not None and ref.seconds > 0 else None
    pt_rate = pt["decisions"] / pt["seconds"] if pt and pt["seconds"] > 0 else None
    executed = int(first.instructions.sum())
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
        "one_thread_decisions_per_s": None,
        "scaling": None,
        "c_decisions_per_s": None,
        "engine_cpu_decisions_per_s": None,
        "engine_vs_c": None,
        "graphs": work.n_graphs,
        "teams": work.teams,
        "programs": work.programs,
        "instructions": work.instructions,
        "episodes": work.episodes,
        "decisions": decisions,
        "pointer_fraction": work.pointer_fraction,
        "effective_instruction_fraction": len(work.cp.graph.instrs)
        / int(work.cp.n_instructions.sum()),
        "repeats": len(runs),
        "seconds": seconds,
        "seconds_all": [r.seconds for r in runs],
        "build_seconds": work.build_seconds,
    }


def _scaling(runs: list, singles: list) -> dict:
    """The one-thread rate and the median over pairs of one-thread over N-thread time."""
    scaling = [a.seconds / b.seconds for a, b in zip(singles, runs, strict=True)]
    return {
        "one_thread_decisions_per_s": runs[0].decisions
        / statistics.median(a.seconds for a in singles),
        "scaling": statistics.median(scaling),
        "scaling_all": scaling,
    }


def _c_figures(c_pairs: dict, decisions: int) -> dict:
    """The C builds' figures: the first build's at the top level, the next as ``c_beside``."""
    out = {}
    for k, (flags, (c_cpu, e_cpu)) in enumerate(c_pairs.items()):
        ratios = [cc / ee for cc, ee in zip(c_cpu, e_cpu, strict=True)]
        figures = {
            "c_decisions_per_s": decisions / statistics.median(c_cpu),
            "engine_cpu_decisions_per_s": decisions / statistics.median(e_cpu),
            "engine_vs_c": statistics.median(ratios),
            "engine_vs_c_all": ratios,
            "c_flags": " ".join(flags),
        }
        if k == 0:
            out.update(figures)
        else:
            out["c_beside"] = figures
    return out


def benchmark(
    graphs: int = 3000,
    teams: int = 3,
    programs: int = 10,
    instructions: int = 10,
    episodes: int = 16,
    threads: int = 1,
    repeats: int = 3,
    seed: int = 0,
    reference_graphs: int = 20,
    pytpg: bool = True,
    c: bool = False,
    c_flags: tuple[str, ...] | None = None,
    c_beside: tuple[str, ...] | None = None,
    log=None,
    lanes: int = DEFAULT_LANES,
) -> dict:
    """Runs the whole benchmark.

    Args:
        graphs: Number of graphs.
        teams: Teams per graph.
        programs: Programs per team.
        instructions: Instructions per program.
        episodes: CartPole episodes per graph.
        threads: Numba threads of the compiled runs. Above 1, every timed run is paired
            with a one-thread run just before it, and the scaling reported is the median
            over pairs of the one-thread time over the N-thread time (interleaving cancels
            the drift of a shared machine's speed).
        repeats: Timed compiled runs (pairs above 1 thread); the median is reported.
        seed: Workload seed.
        reference_graphs: Graphs played by the reference interpreter and by pytpg.
        pytpg: Time pytpg too (when installed).
        c: Also time the same work in hand-written C (:mod:`mtpg.bench.c_port`), checked
            bit for bit against the engine and run interleaved with one-thread engine runs
            (process CPU time of both).
        c_flags: Optimisation flags of the C build (default ``c_port.C_FLAGS``).
        c_beside: Flags of a second C build reported beside it (default
            ``c_port.C_FLAGS_BESIDE``; an empty tuple for none).
        log: Called with progress lines (``None``: silent).
        lanes: Lane-block size of the engine's runs (0: the scalar kernel, the like for
            like of the scalar C port).

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
    work = make_workload(graphs, teams, programs, instructions, episodes, seed)
    runs, singles = _time_engine(work, threads, repeats, say, lanes)
    first = runs[0].result
    record = min(reference_graphs, graphs)
    ref = _checked_reference(work, first, record, say) if record else None
    pt = None
    if pytpg and ref is not None:
        say(f"pytpg on {record} graphs ...")
        pt = run_pytpg(work, ref, seed)
    c_pairs = _time_c(work, first, repeats, say, c_flags, c_beside, lanes) if c else None
    out = _summary(work, runs, threads, ref, pt)
    out.update(reference_graphs=record, seed=seed, machine=machine_info(), lanes=lanes)
    if singles:
        out.update(_scaling(runs, singles))
    if c_pairs is not None:
        out.update(_c_figures(c_pairs, runs[0].decisions))
    return out
