"""The benchmark workload in hand-written C (``engine_port.c``): the engine's yardstick.

:func:`build` compiles ``engine_port.c`` (shipped with the package) with the system C
compiler; :func:`run_port` writes a workload's arrays to a binary file, runs the program
on it and reads back every job's return, steps, teams and instructions, plus the process
CPU seconds of its timed pass over the jobs (the last of :data:`PASSES`, so warm).
:func:`check` requires those outcomes to equal the engine's bit for bit, so both sides
provably do the same work.

Input file layout (native byte order): int64 header ``[n_teams, n_members, n_programs,
n_instrs, R, M, base, n_banks, n_jobs, n_pool, noise_width, n_constants, n_folded]``;
float64 ``[BIG, DIV_EPS, LOG_BIG, LOG_TINY]``; then ``team_offsets, team_members,
prog_offsets`` (int64), ``instrs`` (uint32, 4 per instruction), ``prog_action, prog_bank,
prog_count, job_roots, job_episodes`` (int64), the pool's ``starts`` and ``noise``
(float64, row-major), the CartPole parameter row (9 float64), the constants and the
folded constants (float64). Both sides run the same compiled, constant-folded code
(:mod:`mtpg.engine.fold`).
"""

from __future__ import annotations

import subprocess
from dataclasses import dataclass
from importlib.resources import files
from pathlib import Path

import numpy as np

from mtpg.bench.workload import Workload
from mtpg.engine.batch import BatchResult
from mtpg.envs import CARTPOLE, TASK_PARAMS
from mtpg.export.harness import STRICT_FLAGS, find_compiler
from mtpg.model.instructions import BIG, CONSTANTS, DIV_EPS, LOG_BIG, LOG_TINY

#: Default optimisation flags of the C yardstick (never fast-math; no contraction, so the
#: results are IEEE double arithmetic like the engine's).
C_FLAGS = ("-O3", "-march=native")
#: The build reported beside the default one.
C_FLAGS_BESIDE = ("-O2", "-march=native")
#: Passes of the job loop per run of the C program; only the last is timed (warm).
PASSES = 2


def limit_defines() -> list[str]:
    """``-D`` flags making the protection limits compile-time constants (exact hex literals)."""
    values = {"BIG": BIG, "DIV_EPS": DIV_EPS, "LOG_BIG": LOG_BIG, "LOG_TINY": LOG_TINY}
    return [f"-DMTPG_{name}={float(v).hex()}" for name, v in values.items()]


@dataclass(frozen=True)
class PortRun:
    """One run of the C program.

    Attributes:
        result: Per-job returns, steps, teams and instructions.
        cpu_seconds: Process CPU time of the job loop.
    """

    result: BatchResult
    cpu_seconds: float


def source() -> str:
    """The text of ``engine_port.c``."""
    return files("mtpg.bench").joinpath("engine_port.c").read_text(encoding="utf-8")


def build(directory: Path, compiler: str | None = None, flags: tuple[str, ...] = C_FLAGS) -> Path:
    """Compiles the C program into ``directory``.

    Args:
        directory: Where the source and executable are written.
        compiler: The compiler (default: ``$CC``, ``cc``, ``gcc`` or ``clang``).
        flags: Optimisation flags, added to ``STRICT_FLAGS`` (which forbid contraction).

    Returns:
        The executable.

    Raises:
        RuntimeError: When no compiler exists or compilation fails.
    """
    cc = compiler or find_compiler()
    if cc is None:
        raise RuntimeError("no C compiler found (set CC or install cc/gcc/clang)")
    directory = Path(directory)
    src = directory / "engine_port.c"
    src.write_text(source(), encoding="utf-8")
    exe = directory / "engine_port"
    if any("fast-math" in f or f == "-Ofast" for f in flags):
        raise ValueError("the C yardstick must not use fast-math: results would differ")
    cmd = [cc, *STRICT_FLAGS, *flags, *limit_defines(), str(src), "-o", str(exe), "-lm"]
    done = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{done.stdout}{done.stderr}")
    return exe


def write_input(work: Workload, path: Path) -> None:
    """Writes the workload in the program's input layout (see the module docstring)."""
    cp = work.cp
    starts, noise = work.pool.starts, work.pool.noise
    header = [
        len(cp.graph.team_offsets) - 1,
        len(cp.graph.team_members),
        len(cp.graph.prog_action),
        len(cp.graph.instrs),
        cp.layout.n_registers,
        cp.layout.n_memory,
        cp.mem_base,
        len(cp.bank_ids),
        len(work.job_roots),
        starts.shape[0],
        noise.shape[1],
        len(CONSTANTS),
        len(cp.graph.folded),
    ]
    parts = [
        np.asarray(header, np.int64),
        np.asarray([BIG, DIV_EPS, LOG_BIG, LOG_TINY], np.float64),
        cp.graph.team_offsets.astype(np.int64),
        cp.graph.team_members.astype(np.int64),
        cp.graph.prog_offsets.astype(np.int64),
        cp.graph.instrs.astype(np.uint32),
        cp.graph.prog_action.astype(np.int64),
        cp.graph.prog_bank.astype(np.int64),
        cp.graph.prog_count.astype(np.int64),
        work.job_roots.astype(np.int64),
        work.job_episodes.astype(np.int64),
        starts.astype(np.float64),
        noise.astype(np.float64),
        TASK_PARAMS[CARTPOLE, :9].astype(np.float64),
        np.asarray(CONSTANTS, np.float64),
        cp.graph.folded.astype(np.float64),
    ]
    with open(path, "wb") as f:
        for a in parts:
            f.write(np.ascontiguousarray(a).tobytes())


def run_port(exe: Path, input_path: Path, n_jobs: int, lanes: int = 0) -> PortRun:
    """Runs the C program on a written input and reads its outcomes.

    ``lanes`` > 0 plays up to that many consecutive jobs of one root in lockstep (the
    program's lane mode, the yardstick of the lane engine); 0 one job at a time.
    """
    out_path = Path(input_path).with_suffix(".out")
    done = subprocess.run(
        [str(exe), str(input_path), str(out_path), str(PASSES), str(lanes)],
        capture_output=True,
        text=True,
        check=False,
    )
    if done.returncode != 0:
        raise RuntimeError(f"the C port failed ({done.returncode}): {done.stderr.strip()}")
    raw = out_path.read_bytes()
    returns = np.frombuffer(raw[: 8 * n_jobs], np.float64).copy()
    rest = np.frombuffer(raw[8 * n_jobs :], np.int64).reshape(n_jobs, 3)
    result = BatchResult(returns, rest[:, 0].copy(), rest[:, 1].copy(), rest[:, 2].copy())
    return PortRun(result, float(done.stdout.split()[0]))


def check(engine: BatchResult, port: BatchResult) -> None:
    """Requires the C program's per-job outcomes to equal the engine's bit for bit.

    Raises:
        RuntimeError: Naming the first job that differs.
    """
    for name in ("returns", "steps", "teams", "instructions"):
        a, b = getattr(engine, name), getattr(port, name)
        bad = np.flatnonzero(a.view(np.int64) != b.view(np.int64))
        if len(bad):
            j = int(bad[0])
            raise RuntimeError(
                f"the C port and the engine disagree on job {j}'s {name}: {b[j]!r} vs {a[j]!r}"
            )
