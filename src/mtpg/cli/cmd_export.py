"""``mtpg export``: a program graph as standalone C or plain Python, memory included."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from mtpg.cli.memory_option import add_memory_option


def register(subparsers: argparse._SubParsersAction) -> None:
    """Adds the ``export`` command."""
    p = subparsers.add_parser(
        "export",
        help="write a program graph as standalone C or Python code",
        description="Write a graph file, or the champion of all tasks of a run directory, as "
        "standalone code with persistent shared memory: C99 (one .c and one .h, needing only "
        "<math.h>; API mtpg_reset() and mtpg_act(obs, &a_d, &a_c)) or one Python module "
        "(standard library only; reset() and act(obs) -> (a_d, a_c)). Introns and teams "
        "unreachable from the root are removed; results equal the engine's bit for bit "
        "(C: compiled without floating-point contraction, -ffp-contract=off). --bench "
        "compiles the C with the system compiler and reports microseconds per decision next "
        "to the engine's for the same graph.",
    )
    p.add_argument("target", metavar="GRAPH_OR_RUN", help="a graph .json file or a run directory")
    p.add_argument("--lang", choices=("c", "python"), default="c", help="output language (c)")
    p.add_argument(
        "--out",
        help="output directory (--lang c) or .py file (--lang python); optional with --bench",
    )
    p.add_argument("--name", default="mtpg_graph", help="base name of the .c/.h files (mtpg_graph)")
    add_memory_option(p)
    p.add_argument(
        "--bench",
        action="store_true",
        help="compile the exported C with the system compiler and time it against the engine",
    )
    p.add_argument(
        "--bench-episodes",
        type=int,
        default=5,
        help="test episodes per task in the benchmark's observation stream (5)",
    )
    p.add_argument("--bench-runs", type=int, default=5, help="timed runs; fastest counts (5)")
    p.add_argument("--tasks", help="comma-separated benchmark tasks (default: the graph's)")
    p.add_argument(
        "--json", action="store_true", help="print the benchmark as one JSON object (last line)"
    )
    p.set_defaults(func=run)


def resolve_path(target: Path) -> tuple[Path, list[str] | None]:
    """The graph file a target names (a run directory gives its all-task champion).

    Returns:
        ``(graph file, the run's task names or None for a plain graph file)``.
    """
    if not target.is_dir():
        if not target.is_file():
            raise FileNotFoundError(f"{target}: no such graph file or run directory")
        return target, None
    from mtpg.io.runconfig import read_run_config
    from mtpg.io.rundir import RunDir, champion_filename

    tasks = list(read_run_config(target).evaluation.tasks)
    path = RunDir(target).champions / champion_filename(tuple(tasks))
    if not path.is_file():
        raise FileNotFoundError(f"{path}: the run has no champion yet")
    return path, tasks


def choose_memory(choice: str, meta: dict, path: Path) -> tuple[bool, str]:
    """The memory mode of the export; a no-memory graph needs an explicit choice.

    Raises:
        UsageError: ``as-evolved`` for a graph evolved without memory.
    """
    from mtpg.cli.main import UsageError
    from mtpg.cli.memory_option import evolved_without_memory, resolve_no_memory

    if choice == "as-evolved" and evolved_without_memory(meta):
        raise UsageError(
            f"{path}: this graph was evolved without memory (TPG-NoMemory); say how the "
            "exported code runs it: --memory off (zero each bank before every program, as "
            "evolved) or --memory on (persistent memory)"
        )
    return resolve_no_memory(choice, meta)


def run(args: argparse.Namespace) -> int:
    """Runs the command."""
    from mtpg.cli.common import task_list
    from mtpg.cli.main import UsageError
    from mtpg.envs.specs.contract import TASK_NAMES
    from mtpg.envs.specs.registry import PAPER_TASKS
    from mtpg.envs.taskset.task_table import TaskTable
    from mtpg.envs.taskset.variants import known
    from mtpg.export.common import prepare
    from mtpg.io.serialize import load_graph

    if args.out is None and not args.bench:
        raise UsageError("--out is required (or use --bench)")
    if args.bench_episodes < 1 or args.bench_runs < 1:
        raise UsageError("--bench-episodes and --bench-runs must be >= 1")
    path, run_tasks = resolve_path(Path(args.target))
    pop, root, meta = load_graph(path)
    no_memory, description = choose_memory(args.memory, meta, path)
    graph = prepare(
        pop, root, no_memory=no_memory, source=str(path), meta=meta, memory_description=description
    )
    print(f"{path}: root team {root}; {description}; {graph.summary()}")
    if args.out is not None:
        if args.lang == "c":
            from mtpg.export.c import write_c

            header, source = write_c(graph, Path(args.out), args.name)
            print(f"wrote {header} and {source}")
        else:
            from mtpg.export.python import write_python

            try:
                print(f"wrote {write_python(graph, Path(args.out))}")
            except ValueError as exc:
                raise UsageError(str(exc)) from exc
    if not args.bench:
        return 0
    tasks = run_tasks or list(meta.get("tasks", PAPER_TASKS))
    if args.tasks:
        tasks = task_list(args.tasks)
    unknown = [t for t in tasks if not known(t)]
    if unknown:
        raise UsageError(f"unknown task {unknown[0]!r}; choose from {', '.join(TASK_NAMES)}")
    return _bench(args, graph, pop, root, TaskTable.from_names(tasks))


def _bench(args, graph, pop, root, table) -> int:
    from mtpg.cli.main import UsageError
    from mtpg.envs.taskset.episode_seeds import held_out_seeds
    from mtpg.export.bench import benchmark
    from mtpg.export.harness import engine_stream, find_compiler

    if find_compiler() is None:
        raise FileNotFoundError("no C compiler found for --bench (set CC or install cc/gcc)")
    seeds = held_out_seeds(args.bench_episodes)
    stream = engine_stream(pop, root, list(table.ids), seeds, graph.no_memory, table)
    try:
        res = benchmark(graph, pop, root, stream, runs=args.bench_runs)
    except RuntimeError as exc:
        raise UsageError(str(exc).splitlines()[0]) from exc
    out = {
        "decisions": res.decisions,
        "episodes": res.episodes,
        "c_us_per_decision": res.c_us,
        "engine_us_per_decision": res.engine_us,
        "python_us_per_decision": res.python_us,
        "engine_over_c": res.engine_us / res.c_us if res.c_us > 0 else None,
        "compiler": res.compiler,
    }
    if args.json:
        print(json.dumps(out))
        return 0
    print(
        f"stream: {res.episodes} test episodes ({args.bench_episodes} per task), "
        f"{res.decisions} decisions; actions of the exported C equal the engine's at every one"
    )
    print(f"compiled with: {res.compiler}; fastest of {args.bench_runs} runs")
    print(f"{'exported C':<16} {res.c_us:>10.3f} us/decision")
    print(f"{'engine (Numba)':<16} {res.engine_us:>10.3f} us/decision")
    if res.python_us is not None:
        print(f"{'exported Python':<16} {res.python_us:>10.3f} us/decision")
    return 0
