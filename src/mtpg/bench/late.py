"""The late-generation workload: a committed run's own graphs on all its tasks.

The CartPole workload of ``mtpg bench engine`` times random graphs of a fixed shape. A
paper run spends its time elsewhere: at generation 1,000 its roots are graphs of several
teams with long, tangled programs playing six tasks. This workload takes the population of
a run's last checkpoint, compiles it as training does, and plays every root on the run's
training episodes (each task with the first block's seeds), one root's episodes per
block, exactly the batch a generation evaluates. It times the lane engine (the engine's
default) against the scalar kernel, interleaved and each by process CPU time, and checks
that both give every job the same outcome.
"""

from __future__ import annotations

import statistics
import time
from pathlib import Path

import numpy as np

from mtpg.bench.workload import Workload, drive
from mtpg.engine.batch import Episodes
from mtpg.engine.compile import compile_population
from mtpg.engine.lanes import DEFAULT_LANES


def population_workload(pop, pool: Episodes, t0: float) -> Workload:
    """Every root of ``pop`` on every episode of ``pool``, one root's episodes per block.

    Args:
        pop: The population (compiled here, as training compiles it).
        pool: The episodes each root plays.
        t0: ``time.perf_counter()`` when building began (for ``build_seconds``).
    """
    cp = compile_population(pop)
    root_ids = list(pop.roots())
    n_ep = len(pool.tasks)
    roots = np.array([cp.team_index(r) for r in root_ids], dtype=np.int64)
    return Workload(
        pop=pop,
        root_ids=root_ids,
        cp=cp,
        pool=pool,
        job_roots=np.repeat(roots, n_ep),
        job_episodes=np.tile(np.arange(n_ep, dtype=np.int64), len(roots)),
        episodes=n_ep,
        teams=len(pop.teams),
        programs=len(pop.programs),
        instructions=int(cp.n_instructions.sum()),
        pointer_fraction=float(np.mean(cp.graph.prog_action >= 0)),
        build_seconds=time.perf_counter() - t0,
    )


def late_workload(run_dir: str | Path) -> tuple[Workload, int]:
    """Every root of a run's last checkpoint on the run's training episodes.

    Args:
        run_dir: A run directory with a checkpoint.

    Returns:
        The workload (one job per root and training episode) and the checkpoint's
        generation.

    Raises:
        ValueError: The directory holds no checkpoint.
    """
    from mtpg.envs.taskset.episode_seeds import resampled_training_seeds
    from mtpg.evolve.session import load_state, read_run_config

    t0 = time.perf_counter()
    config = read_run_config(run_dir)
    state = load_state(run_dir, config)
    if state is None:
        raise ValueError(f"{run_dir}: holds no checkpoint")
    ev = config.evaluation
    seeds = resampled_training_seeds(config.seed, 0, ev.train_episodes)
    table = ev.task_table()
    pool = Episodes.grid(list(table.ids), seeds, table)
    work = population_workload(state.population, pool, t0)
    return work, state.generation


def late_benchmark(
    run_dir: str | Path, repeats: int = 3, lanes: int = DEFAULT_LANES, log=None
) -> dict:
    """Times the lane engine against the scalar kernel on :func:`late_workload`.

    Each round plays the whole workload with the scalar kernel, then with the lane
    engine, one thread each, timed by process CPU time; the ratio of the two times is taken
    per round and its median reported.

    Args:
        run_dir: The run directory.
        repeats: Rounds (at least 1).
        lanes: Lane-block size.
        log: Called with progress lines (``None``: silent).

    Returns:
        The figures: decisions, decisions per CPU second of each engine (medians), the
        per-round ratios and their median, teams and instructions per decision.

    Raises:
        RuntimeError: The two engines disagree on any job.
    """
    say = log or (lambda _msg: None)
    if repeats < 1 or lanes < 1:
        raise ValueError("need repeats >= 1 and lanes >= 1")
    work, generation = late_workload(run_dir)
    say(f"{len(work.root_ids)} roots of generation {generation}, {work.episodes} episodes each")
    small = Workload(
        **{**work.__dict__, "job_roots": work.job_roots[:1], "job_episodes": work.job_episodes[:1]}
    )
    drive(small, 1, 0)  # compile (or load) both kernels outside the clock
    drive(small, 1, lanes)
    scalar, lane, ratios = [], [], []
    for r in range(repeats):
        a = drive(work, 1, 0)
        b = drive(work, 1, lanes)
        for f in ("returns", "steps", "teams", "instructions"):
            if getattr(a.result, f).tobytes() != getattr(b.result, f).tobytes():
                raise RuntimeError(f"the lane engine and the scalar kernel disagree ({f})")
        scalar.append(a.cpu_seconds)
        lane.append(b.cpu_seconds)
        ratios.append(a.cpu_seconds / b.cpu_seconds)
        say(f"  round {r + 1}/{repeats}: scalar {a.cpu_seconds:.2f} s, lanes {b.cpu_seconds:.2f} s")
    decisions = int(a.result.steps.sum())
    return {
        "run": str(run_dir),
        "generation": generation,
        "roots": len(work.root_ids),
        "episodes_per_root": work.episodes,
        "decisions": decisions,
        "teams_per_decision": int(a.result.teams.sum()) / decisions,
        "instructions_per_decision": int(a.result.instructions.sum()) / decisions,
        "lanes": lanes,
        "scalar_cpu_decisions_per_s": decisions / statistics.median(scalar),
        "lanes_cpu_decisions_per_s": decisions / statistics.median(lane),
        "lanes_vs_scalar": statistics.median(ratios),
        "lanes_vs_scalar_all": ratios,
        "repeats": repeats,
    }
