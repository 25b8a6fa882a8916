"""Running exported C against the engine: observation streams, a C driver, the comparison.

A *stream* is what the engine did on full episodes: the observation of every decision, a
flag marking each episode's first decision, and the engine's ``(a_d, a_c)`` and visited
teams at every decision (from :func:`mtpg.engine.trace.trace_episode`). Feeding the
stream to exported code and finding the same actions at every step shows that the code
would have played the very same episodes: the observations depend only on the start
state, the noise and the earlier actions.

The C driver (:data:`DRIVER_SOURCE`) reads the stream on standard input as text: ``R``
starts an episode (``mtpg_reset``), otherwise two observations as C99 hexadecimal floats
(exact). ``driver check`` prints ``a_d a_c`` per decision (``a_c`` in ``%a`` format,
exact; with ``-DMTPG_TRACE`` followed by the visited team ids); ``driver bench N`` plays
the whole stream N times and prints CPU seconds (``clock()``), decisions and a checksum.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from mtpg.engine.compile import compile_population
from mtpg.engine.trace import trace_episode
from mtpg.envs import env_observe
from mtpg.envs.taskset.task_table import REGISTERED, TaskTable
from mtpg.model.graph import Population

#: Flags of every compilation: C99, warnings as errors, no floating-point contraction.
STRICT_FLAGS = ("-std=c99", "-Wall", "-Wextra", "-Werror", "-ffp-contract=off")

DRIVER_SOURCE = r"""/* Driver of an exported mtpg graph: see mtpg.export.harness. */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

/* The API of the exported code (declared here so that one driver object serves every
 * exported graph; the exported .c checks its own header). */
void mtpg_reset(void);
void mtpg_act(const double obs[2], int *a_d, double *a_c);
#ifdef MTPG_TRACE
extern int mtpg_trace_n;
extern int mtpg_trace_teams[];
#endif

int main(int argc, char **argv)
{
    size_t cap = 1024, n = 0, t;
    double *obs = malloc(2 * cap * sizeof *obs);
    unsigned char *start = malloc(cap);
    char tok[128];
    int episode = 0, a_d = 0;
    double a_c = 0.0;
    if (argc < 2 || !obs || !start) {
        fprintf(stderr, "usage: %s check|bench REPEATS < stream\n", argv[0]);
        return 2;
    }
    while (scanf("%127s", tok) == 1) {
        if (tok[0] == 'R') {
            episode = 1;
            continue;
        }
        if (n == cap) {
            cap *= 2;
            obs = realloc(obs, 2 * cap * sizeof *obs);
            start = realloc(start, cap);
            if (!obs || !start)
                return 3;
        }
        obs[2 * n] = strtod(tok, NULL);
        if (scanf("%127s", tok) != 1)
            return 4;
        obs[2 * n + 1] = strtod(tok, NULL);
        start[n++] = (unsigned char)episode;
        episode = 0;
    }
    if (argv[1][0] == 'c') {
        for (t = 0; t < n; t++) {
            if (start[t])
                mtpg_reset();
            mtpg_act(obs + 2 * t, &a_d, &a_c);
            printf("%d %a", a_d, a_c);
#ifdef MTPG_TRACE
            {
                int k;
                for (k = 0; k < mtpg_trace_n; k++)
                    printf(" %d", mtpg_trace_teams[k]);
            }
#endif
            printf("\n");
        }
    } else {
        long repeats = argc > 2 ? atol(argv[2]) : 1, rep;
        double checksum = 0.0;
        clock_t t0 = clock(), t1;
        for (rep = 0; rep < repeats; rep++) {
            for (t = 0; t < n; t++) {
                if (start[t])
                    mtpg_reset();
                mtpg_act(obs + 2 * t, &a_d, &a_c);
                checksum += a_d + a_c;
            }
        }
        t1 = clock();
        printf("%.9g %lu %.17g\n", (double)(t1 - t0) / CLOCKS_PER_SEC,
               (unsigned long)(n * (size_t)repeats), checksum);
    }
    free(obs);
    free(start);
    return 0;
}
"""


@dataclass(frozen=True)
class Stream:
    """Full episodes as the engine played them.

    Attributes:
        obs: float64 ``(n, 2)``: the observation of every decision.
        starts: bool ``(n)``: True at the first decision of each episode.
        actions: float64 ``(n, 2)``: the engine's ``a_d, a_c``.
        teams: Team ids the engine visited at each decision.
        tasks: Task id of each episode.
    """

    obs: np.ndarray
    starts: np.ndarray
    actions: np.ndarray
    teams: list[list[int]]
    tasks: list[int]

    @property
    def episodes(self) -> int:
        """Number of episodes."""
        return int(self.starts.sum())

    def text(self) -> str:
        """The driver's input: ``R`` before each episode, observations as hex floats."""
        lines = []
        for t, (x, y) in enumerate(self.obs.tolist()):
            if self.starts[t]:
                lines.append("R")
            lines.append(f"{x.hex()} {y.hex()}")
        return "\n".join(lines) + "\n"


def engine_stream(
    pop: Population,
    root: int,
    tasks: list[int],
    seeds: list[int] | np.ndarray,
    no_memory: bool = False,
    table: TaskTable = REGISTERED,
) -> Stream:
    """Plays every task with every seed in the engine's tracing kernel.

    Args:
        pop: The population holding the graph.
        root: Root team id.
        tasks: Task ids of ``table``.
        seeds: Episode seeds (the same for every task).
        no_memory: Run in no-memory mode.
        table: The task table of the ids (the registered tasks by default).

    Returns:
        The stream, task-major.
    """
    from mtpg.engine.batch import Episodes

    # the tracer logs programs as stated (unfolded); the ablation is the compiled graph's
    cp = compile_population(pop, fold_constants=False, no_memory=no_memory)
    table = Episodes.grid(list(tasks), list(seeds), table)
    obs_rows, starts, actions, teams = [], [], [], []
    o = np.zeros(2)
    for e, task in enumerate(table.tasks.tolist()):
        eps = table.obs_noise[e] if table.obs_noise.shape[1] else None
        tr = trace_episode(
            cp,
            root,
            task,
            table.starts[e],
            table.noise[e],
            obs_noise=eps,
            params=table.params,
        )
        n = len(tr.actions)
        for t in range(n):
            e_t = None if eps is None else eps[t]
            env_observe(task, table.params, tr.states[t], table.noise[e, t], o, e_t)
            obs_rows.append(o.copy())
        starts.extend([True] + [False] * (n - 1))
        actions.append(tr.actions)
        log = tr.team_log
        for t in range(n):
            teams.append([int(cp.team_ids[x]) for x in log[log[:, 0] == t, 1]])
    return Stream(
        np.array(obs_rows).reshape(-1, 2),
        np.array(starts, dtype=bool),
        np.concatenate(actions),
        teams,
        [int(x) for x in table.tasks],
    )


def find_compiler() -> str | None:
    """The system C compiler: ``$CC``, else ``cc``, ``gcc`` or ``clang`` on the PATH."""
    for name in (os.environ.get("CC"), "cc", "gcc", "clang"):
        if name and shutil.which(name):
            return shutil.which(name)
    return None


def _compiler(compiler: str | None) -> str:
    cc = compiler or find_compiler()
    if cc is None:
        raise RuntimeError("no C compiler found (set CC or install cc/gcc/clang)")
    return cc


def _compile(cmd: list[str]) -> None:
    done = subprocess.run(cmd, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{done.stdout}{done.stderr}")


def compile_driver(
    out: Path, *, trace: bool = False, opt: str = "-O2", compiler: str | None = None
) -> Path:
    """Compiles the driver alone into the object file ``out`` (reusable for every graph)."""
    source = Path(out).with_suffix(".c")
    source.write_text(DRIVER_SOURCE, encoding="utf-8")
    flags = [*STRICT_FLAGS, opt, *(["-DMTPG_TRACE"] if trace else [])]
    _compile([_compiler(compiler), *flags, "-c", str(source), "-o", str(out)])
    return Path(out)


def build_driver(
    source_dir: Path,
    name: str,
    exe: Path,
    *,
    trace: bool = False,
    opt: str = "-O2",
    compiler: str | None = None,
    driver_object: Path | None = None,
) -> Path:
    """Compiles ``name.c`` of ``source_dir`` with the driver into ``exe``.

    Args:
        source_dir: Directory holding the exported ``name.c`` and ``name.h``.
        name: Base name of the exported files.
        exe: The executable to write.
        trace: Compile with ``-DMTPG_TRACE``.
        opt: Optimisation flag.
        compiler: Compiler path (default :func:`find_compiler`).
        driver_object: A driver compiled by :func:`compile_driver` with the same
            ``trace``; compiled along when None.

    Returns:
        ``exe``.

    Raises:
        RuntimeError: When no compiler exists or compilation fails (with its output).
    """
    source_dir = Path(source_dir)
    if driver_object is None:
        driver_object = compile_driver(
            source_dir / f"{name}_driver.o", trace=trace, opt=opt, compiler=compiler
        )
    flags = [*STRICT_FLAGS, opt, *(["-DMTPG_TRACE"] if trace else [])]
    source = str(source_dir / f"{name}.c")
    _compile([_compiler(compiler), *flags, source, str(driver_object), "-o", str(exe), "-lm"])
    return Path(exe)


def run_check(exe: Path, stream: Stream) -> list[tuple[int, float, list[int]]]:
    """Feeds the stream to a driver in ``check`` mode.

    Returns:
        ``(a_d, a_c, visited team ids)`` per decision (teams empty without tracing).
    """
    done = subprocess.run(
        [str(exe), "check"], input=stream.text(), capture_output=True, text=True, check=True
    )
    out = []
    for line in done.stdout.splitlines():
        fields = line.split()
        out.append((int(fields[0]), float.fromhex(fields[1]), [int(x) for x in fields[2:]]))
    return out


def mismatches(stream: Stream, got: list[tuple[int, float]]) -> list[str]:
    """Describes every decision whose ``(a_d, a_c)`` differs from the engine's (bitwise)."""
    if len(got) != len(stream.actions):
        return [f"{len(got)} decisions, the engine made {len(stream.actions)}"]
    bad = []
    for t, (row, mine) in enumerate(zip(stream.actions.tolist(), got, strict=True)):
        a_d, a_c = mine[0], float(mine[1])
        if a_d != int(row[0]) or a_c.hex() != float(row[1]).hex():
            bad.append(f"decision {t}: engine ({int(row[0])}, {row[1]!r}), export ({a_d}, {a_c!r})")
    return bad
