"""The lane engine against the scalar kernel on every workload ``mtpg bench`` has.

``mtpg bench lanes`` plays each workload with both and checks that every job has the same
outcome in both (return, steps, teams visited, instructions executed):

- ``engine``: the random CartPole graphs of ``mtpg bench engine`` (short episodes, one
  task; :func:`mtpg.bench.workload.make_workload`);
- ``demo-gen1``: a ``demo`` population as generation 1 evaluates it (every root new, one
  team of atomic programs; :func:`mtpg.evolve.variation.init_population` from the seed's
  generator) on the preset's training episodes of all six tasks;
- ``late``: every root of a committed run's last checkpoint on its training episodes
  (:func:`mtpg.bench.late.late_workload`; ``--late RUN_DIR``), the batch a late paper
  generation evaluates.

Each workload is played at every thread count asked for, in rounds: the scalar kernel,
then the lane engine, so that both see the same machine state. A round is timed by
process CPU time on one thread and by wall time on more (CPU time then counts every
thread), and the minor page faults of the process during the call are counted
(``resource.getrusage``: a fault is a page touched for the first time, so a kernel that
allocates per block of jobs shows them and one that reuses its buffers does not). The
medians over the rounds are reported, with the per-round ratio of lanes to scalar.

The ``resource`` module is POSIX only; on Windows the faults are reported as ``None``.
"""

from __future__ import annotations

import statistics
import time
from collections.abc import Callable, Sequence
from pathlib import Path

import numpy as np

from mtpg.bench.late import late_workload, population_workload
from mtpg.bench.workload import Workload, drive, make_workload
from mtpg.engine.batch import Episodes
from mtpg.engine.lanes import DEFAULT_LANES

try:
    import resource
except ImportError:  # Windows
    resource = None

__all__ = ["compare", "first_generation_workload", "lanes_benchmark"]


def _faults() -> int | None:
    """Minor page faults of this process so far (None where the OS does not say)."""
    return None if resource is None else resource.getrusage(resource.RUSAGE_SELF).ru_minflt


def first_generation_workload(preset: str = "demo", seed: int = 0) -> Workload:
    """A preset's generation-1 population on the preset's training episodes, all tasks.

    Args:
        preset: The preset (``demo``: 300 roots).
        seed: Seeds the generator the population is drawn with.
    """
    from mtpg.api_config import preset as make_config
    from mtpg.envs.taskset.episode_seeds import resampled_training_seeds
    from mtpg.evolve.variation import init_population

    config = make_config(preset, seed=seed)
    pop = init_population(config, np.random.default_rng(np.random.SeedSequence(seed)))
    ev = config.evaluation
    table = ev.task_table()
    pool = Episodes.grid(
        list(table.ids), resampled_training_seeds(seed, 0, ev.train_episodes), table
    )
    return population_workload(pop, pool, time.perf_counter())


def _timed(work: Workload, threads: int, lanes: int):
    """One play of the workload: its outcome, seconds (CPU on one thread) and faults."""
    before = _faults()
    res = drive(work, threads, lanes)
    after = _faults()
    seconds = res.cpu_seconds if threads == 1 else res.seconds
    return res, seconds, None if before is None else after - before


def compare(work: Workload, threads: int, repeats: int, lanes: int = DEFAULT_LANES) -> dict:
    """Scalar kernel and lane engine on one workload, interleaved rounds.

    Raises:
        RuntimeError: The two disagree on any job.
    """
    small = Workload(
        **{**work.__dict__, "job_roots": work.job_roots[:2], "job_episodes": work.job_episodes[:2]}
    )
    for kind in (0, lanes):  # compile (or load) both, on this thread count, outside the clock
        drive(small, threads, kind)
    s_sec, l_sec, s_flt, l_flt, ratios = [], [], [], [], []
    for _ in range(repeats):
        a, sa, fa = _timed(work, threads, 0)
        b, sb, fb = _timed(work, threads, lanes)
        for f in ("returns", "steps", "teams", "instructions"):
            if getattr(a.result, f).tobytes() != getattr(b.result, f).tobytes():
                raise RuntimeError(f"the lane engine and the scalar kernel disagree ({f})")
        s_sec.append(sa)
        l_sec.append(sb)
        s_flt.append(fa)
        l_flt.append(fb)
        ratios.append(sa / sb)
    decisions = a.decisions

    def faults(xs: list) -> int | None:
        return None if xs[0] is None else int(statistics.median(xs))

    return {
        "threads": threads,
        "clock": "process CPU" if threads == 1 else "wall",
        "decisions": decisions,
        "scalar_decisions_per_s": decisions / statistics.median(s_sec),
        "lanes_decisions_per_s": decisions / statistics.median(l_sec),
        "lanes_vs_scalar": statistics.median(ratios),
        "lanes_vs_scalar_all": ratios,
        "scalar_page_faults": faults(s_flt),
        "lanes_page_faults": faults(l_flt),
        "teams_per_decision": int(a.result.teams.sum()) / decisions,
        "instructions_per_decision": int(a.result.instructions.sum()) / decisions,
    }


def lanes_benchmark(
    late_run: str | Path | None = None,
    graphs: int = 3000,
    repeats: int = 3,
    threads: Sequence[int] = (1, 2),
    lanes: int = DEFAULT_LANES,
    log: Callable[[str], None] | None = None,
) -> dict:
    """Every workload at every thread count: scalar kernel against lane engine.

    Args:
        late_run: A run directory for the ``late`` workload (None: left out).
        graphs: Graphs of the ``engine`` workload.
        repeats: Rounds per workload and thread count (at least 1).
        threads: Thread counts.
        lanes: The lane engine's block size.
        log: Called with progress lines (None: silent).

    Returns:
        ``{"lanes": lanes, "repeats": repeats, "rows": [...]}``, a row per workload and
        thread count (:func:`compare`'s figures and the workload's name).
    """
    say = log or (lambda _msg: None)
    if repeats < 1 or lanes < 1 or not threads or min(threads) < 1:
        raise ValueError("need repeats >= 1, lanes >= 1 and thread counts >= 1")
    if late_run is not None and not Path(late_run).is_dir():  # before any workload is built
        raise ValueError(f"{late_run}: no such run directory")
    makers: list[tuple[str, Callable[[], Workload]]] = [
        ("engine", lambda: make_workload(graphs)),
        ("demo-gen1", first_generation_workload),
    ]
    if late_run is not None:
        makers.append(("late", lambda: late_workload(late_run)[0]))
    rows = []
    for name, make in makers:
        work = make()
        for n in threads:
            row = {"workload": name, **compare(work, n, repeats, lanes)}
            rows.append(row)
            say(
                f"{name}, {n} thread(s): scalar {row['scalar_decisions_per_s']:,.0f}, lanes "
                f"{row['lanes_decisions_per_s']:,.0f} decisions/s ({row['lanes_vs_scalar']:.2f}x)"
            )
    return {"lanes": lanes, "repeats": repeats, "rows": rows}
