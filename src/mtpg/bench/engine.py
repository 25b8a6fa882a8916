"""The engine benchmark behind ``mtpg bench engine``: baselines and the summary.

The workload and the compiled driver live in :mod:`mtpg.bench.workload`. Besides
the compiled engine, two baselines are timed on the first graphs of the workload: the
plain-Python reference interpreter (its actions are checked against the compiled run, so
both play the very same episodes) and, when installed, the ``pytpg`` package on graphs of
the same shape fed the recorded observations.
"""

from __future__ import annotations

import os
import platform
import statistics
import time
from dataclasses import dataclass

import numba
import numpy as np

from mtpg.bench.workload import Workload, drive, episode_row, make_workload, warm_up
from mtpg.engine.reference import ReferenceAgent
from mtpg.envs import CARTPOLE, TASK_PARAMS, env_observe, env_reset, env_step
from mtpg.envs.core import STATE_SIZE
from mtpg.model.graph import Population
from mtpg.model.instructions import CONSTANTS, N_CONSTANTS


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
