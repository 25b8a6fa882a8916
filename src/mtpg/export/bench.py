"""Microseconds per decision: exported C, the engine and the exported Python, same stream.

The workload is a fixed observation stream (:class:`~mtpg.export.harness.Stream`): full
test episodes of each task as the engine plays them with the graph, so every decision
visits the teams a real episode visits. Memory is reset at every episode start, as in
play. The environment is not stepped while timing: the figures are the cost of the
decisions alone.

* **C**: the exported code compiled with ``-O2 -ffp-contract=off`` into the driver of
  :mod:`mtpg.export.harness`, playing the stream ``repeats`` times per run; CPU time by
  ``clock()``. Before timing, the driver's actions are checked bitwise against the engine's.
* **engine**: :func:`mtpg.engine.episode_kernels.decide` (the kernel training runs) called from
  one compiled loop over the same stream, one thread; wall time around that call.
* **Python**: the exported module's ``reset``/``act`` over the stream once per run.

Each figure is the fastest of ``runs`` runs (the least disturbed by other load).
"""

from __future__ import annotations

import importlib.util
import math
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numba import njit

from mtpg.engine.compile import compile_population
from mtpg.engine.episode_kernels import decide, thread_buffers
from mtpg.export.c import write_c
from mtpg.export.common import ExportGraph
from mtpg.export.harness import (
    STRICT_FLAGS,
    Stream,
    build_driver,
    find_compiler,
    mismatches,
    run_check,
)
from mtpg.export.python import write_python
from mtpg.model.graph import Population

#: Seconds one timed run of the C driver or the engine should last at least.
MIN_RUN_SECONDS = 0.3


@njit(cache=True, error_model="numpy")
def _engine_loop(g, root, obs, starts, repeats):
    """Plays the stream ``repeats`` times with the engine's decision kernel; a checksum."""
    buf = thread_buffers(g)
    stamp = 0
    episode = -1
    checksum = 0.0
    for _ in range(repeats):
        for t in range(obs.shape[0]):
            if starts[t]:
                episode += 1
            buf.obs[0] = obs[t, 0]
            buf.obs[1] = obs[t, 1]
            a_d, a_c = decide(g, buf, root, stamp, episode, None)
            stamp += 1
            checksum += a_d + a_c
    return checksum


@dataclass(frozen=True)
class BenchResult:
    """Microseconds per decision of each implementation (fastest run).

    Attributes:
        decisions: Decisions in the stream.
        episodes: Episodes in the stream.
        c_us: Exported C.
        engine_us: The engine's decision kernel.
        python_us: Exported Python module (None when not timed).
        c_repeats: Stream passes per timed C run.
        engine_repeats: Stream passes per timed engine run.
        compiler: The C compile command's compiler and flags.
    """

    decisions: int
    episodes: int
    c_us: float
    engine_us: float
    python_us: float | None
    c_repeats: int
    engine_repeats: int
    compiler: str


def _repeats(seconds_once: float) -> int:
    return max(1, math.ceil(MIN_RUN_SECONDS / max(seconds_once, 1e-9)))


def time_c(exe: Path, stream: Stream, runs: int) -> tuple[float, int]:
    """Fastest C run in microseconds per decision, and the stream passes per run."""
    import subprocess

    text = stream.text()

    def once(repeats: int) -> float:
        done = subprocess.run(
            [str(exe), "bench", str(repeats)],
            input=text,
            capture_output=True,
            text=True,
            check=True,
        )
        seconds, decisions, _ = done.stdout.split()
        return float(seconds) / int(decisions)

    repeats = _repeats(once(1) * len(stream.obs))
    return min(once(repeats) for _ in range(runs)) * 1e6, repeats


def time_engine(pop: Population, root: int, stream: Stream, no_memory: bool, runs: int):
    """Fastest engine run in microseconds per decision, and the stream passes per run."""
    cp = compile_population(pop, no_memory=no_memory)
    args = (
        cp.graph,
        cp.team_index(root),
        np.ascontiguousarray(stream.obs),
        np.ascontiguousarray(stream.starts),
    )
    _engine_loop(*args, 1)  # compile / load from cache

    def once(repeats: int) -> float:
        t0 = time.perf_counter()
        _engine_loop(*args, repeats)
        return (time.perf_counter() - t0) / (repeats * len(stream.obs))

    repeats = _repeats(once(1) * len(stream.obs))
    return min(once(repeats) for _ in range(runs)) * 1e6, repeats


def time_python(module_path: Path, stream: Stream, runs: int) -> float:
    """Fastest pass of the exported Python module in microseconds per decision."""
    spec = importlib.util.spec_from_file_location("mtpg_exported_bench", module_path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    rows = [tuple(r) for r in stream.obs.tolist()]
    starts = stream.starts.tolist()
    best = math.inf
    for _ in range(runs):
        t0 = time.perf_counter()
        for t, o in enumerate(rows):
            if starts[t]:
                mod.reset()
            mod.act(o)
        best = min(best, time.perf_counter() - t0)
    return best / len(rows) * 1e6


def benchmark(
    graph: ExportGraph,
    pop: Population,
    root: int,
    stream: Stream,
    *,
    runs: int = 5,
    python: bool = True,
    workdir: Path | None = None,
) -> BenchResult:
    """Exports, checks bit-identity on the stream, then times C, the engine and Python.

    Args:
        graph: The prepared graph (its ``no_memory`` mode is the one timed everywhere).
        pop: The population holding the graph (for the engine).
        root: Root team id.
        stream: The engine's stream for this graph and memory mode.
        runs: Timed runs per implementation; the fastest counts.
        python: Also time the exported Python module.
        workdir: Where to build (a temporary directory when None).

    Returns:
        The figures.

    Raises:
        RuntimeError: When compiling fails or the C actions differ from the engine's.
    """
    with tempfile.TemporaryDirectory(prefix="mtpg-export-bench-") as tmp:
        work = Path(workdir or tmp)
        write_c(graph, work, "mtpg_bench_graph")
        exe = build_driver(work, "mtpg_bench_graph", work / "mtpg_bench")
        bad = mismatches(stream, [(a, c) for a, c, _ in run_check(exe, stream)])
        if bad:
            raise RuntimeError(f"exported C differs from the engine: {bad[0]}")
        c_us, c_rep = time_c(exe, stream, runs)
        engine_us, e_rep = time_engine(pop, root, stream, graph.no_memory, runs)
        py_us = None
        if python:
            py_us = time_python(write_python(graph, work / "mtpg_bench_graph.py"), stream, runs)
    return BenchResult(
        decisions=len(stream.obs),
        episodes=stream.episodes,
        c_us=c_us,
        engine_us=engine_us,
        python_us=py_us,
        c_repeats=c_rep,
        engine_repeats=e_rep,
        compiler=" ".join([str(find_compiler()), *STRICT_FLAGS, "-O2"]),
    )
