"""``mtpg bench``: benchmarks; ``mtpg bench engine`` times the compiled execution engine."""

from __future__ import annotations

import argparse
import json
import sys


def register(subparsers: argparse._SubParsersAction) -> None:
    """Adds the ``bench`` command and its ``engine`` subcommand.

    Args:
        subparsers: The top-level sub-parser collection.
    """
    bench = subparsers.add_parser("bench", help="benchmarks", description="Benchmarks.")
    sub = bench.add_subparsers(dest="bench_command", metavar="BENCH")
    eng = sub.add_parser(
        "engine",
        help="decisions per second of the compiled engine on random graphs driving CartPole",
        description=(
            "Times the compiled engine on a fixed, seeded workload: random graphs of "
            "TEAMS x PROGRAMS x INSTRUCTIONS (about 40% of programs pointing to a later "
            "team), each playing EPISODES CartPole episodes, run by the batch kernel "
            "training uses. The Python reference interpreter and, when installed, the "
            "pytpg package are timed on the first REFERENCE_GRAPHS graphs; with --c, the "
            "same work in hand-written C is checked bit for bit and timed against the "
            "engine. Prints a summary, then one JSON object as the last line."
        ),
    )
    eng.add_argument("--graphs", type=int, default=3000, help="number of graphs (3000)")
    eng.add_argument("--teams", type=int, default=3, help="teams per graph (3)")
    eng.add_argument("--programs", type=int, default=10, help="programs per team (10)")
    eng.add_argument("--instructions", type=int, default=10, help="instructions per program (10)")
    eng.add_argument("--episodes", type=int, default=16, help="CartPole episodes per graph (16)")
    eng.add_argument(
        "--threads",
        type=int,
        default=1,
        help="Numba threads (1); above 1, each run is paired with a one-thread run for the scaling",
    )
    eng.add_argument("--repeats", type=int, default=3, help="timed runs, median reported (3)")
    eng.add_argument("--seed", type=int, default=0, help="workload seed (0)")
    eng.add_argument(
        "--reference-graphs",
        type=int,
        default=20,
        help="graphs played by the reference interpreter and pytpg (20)",
    )
    eng.add_argument("--no-pytpg", action="store_true", help="do not time pytpg")
    eng.add_argument(
        "--c",
        action="store_true",
        help="also time the same work in hand-written C (needs a C compiler), interleaved"
        " with one-thread engine runs, process CPU time",
    )
    eng.add_argument(
        "--c-flags",
        default="-O3 -march=native",
        help="optimisation flags of the C build ('-O3 -march=native'; fast-math refused)",
    )
    eng.add_argument(
        "--c-beside",
        default="-O2 -march=native",
        help="flags of a second C build reported beside it ('-O2 -march=native'; '' for none)",
    )
    eng.add_argument(
        "--late",
        metavar="RUN_DIR",
        help="instead, the late-generation workload: every root of RUN_DIR's last checkpoint"
        " on its training episodes (all its tasks), lane engine against the scalar kernel,"
        " interleaved, one thread, process CPU time",
    )
    eng.add_argument(
        "--lanes",
        type=int,
        default=32,
        help="lane-block size of the engine (32, the default of training; 0: the scalar"
        " kernel, one job at a time, the like for like of the scalar C port)",
    )
    eng.set_defaults(func=run)
    tasks = sub.add_parser(
        "tasks",
        help="training speed: built-in CartPole, CartPole as a compiled user task, gym:CartPole-v1",
        description=(
            "Trains the same preset from the same seed on the built-in CartPole, on "
            "CartPole written as a compiled task of a user's module (mtpg.bench.user_cartpole; "
            "its run is identical to the built-in's) and on Gymnasium's CartPole-v1 (stepped "
            "in Python), each in a fresh process, the arms in turn; reports the median "
            "decisions per evaluation second (generation 1, which compiles, left out). "
            "Prints a summary, then one JSON object as the last line."
        ),
    )
    tasks.add_argument("--preset", default="demo", help="preset trained (demo)")
    tasks.add_argument("--generations", type=int, default=30, help="generations per run (30)")
    tasks.add_argument("--repeats", type=int, default=3, help="rounds, median reported (3)")
    tasks.add_argument("--seed", type=int, default=1, help="run seed (1)")
    tasks.set_defaults(func=_run_tasks)
    lanes = sub.add_parser(
        "lanes",
        help="the lane engine against the scalar kernel on every workload, with page faults",
        description=(
            "Plays each workload with the scalar kernel and with the lane engine, in "
            "interleaved rounds, and checks that every job has the same outcome in both: the "
            "random CartPole graphs of `mtpg bench engine`, a demo population at generation "
            "1 on all six tasks, and with --late RUN_DIR every root of that run's last "
            "checkpoint. One thread is timed by process CPU time, more by wall time; the "
            "process's minor page faults during each call are counted. Prints a table, "
            "then one JSON object as the last line (mtpg.bench.lanes_bench)."
        ),
    )
    lanes.add_argument("--late", metavar="RUN_DIR", help="a run for the late workload (none)")
    lanes.add_argument("--graphs", type=int, default=3000, help="graphs of the engine workload")
    lanes.add_argument("--threads", default="1,2", help="thread counts, comma-separated (1,2)")
    lanes.add_argument("--repeats", type=int, default=3, help="rounds, medians reported (3)")
    lanes.add_argument("--lanes", type=int, default=32, help="lane-block size (32)")
    lanes.set_defaults(func=_run_lanes)
    bench.set_defaults(func=lambda _args: _help(bench))


def _help(parser: argparse.ArgumentParser) -> int:
    parser.print_help()
    return 2


def _fmt(value: float | None, unit: str = "") -> str:
    return "n/a" if value is None else f"{value:,.0f}{unit}"


def _run_tasks(args: argparse.Namespace) -> int:
    """``mtpg bench tasks``: prints the summary and the JSON line."""
    from mtpg.bench.engine import machine_info
    from mtpg.bench.tasks import benchmark

    try:
        r = benchmark(args.preset, args.generations, args.repeats, args.seed)
    except RuntimeError as exc:
        raise SystemExit(f"mtpg bench tasks: {exc}") from None
    m = machine_info()
    r["machine"] = m
    print(f"\ntraining speed, {args.preset} preset, {args.generations} generations ({m['cpu']})")
    for label, arm in r["arms"].items():
        print(f"  {label:<20} {arm['decisions_per_s']:>12,.0f} decisions/s  ({arm['task']})")
    same = "identical runs" if r["compiled_run_identical_decisions"] else "runs differ"
    print(f"  compiled / built-in  {r['compiled_vs_built_in']:.2f}  ({same})")
    print(json.dumps(r))
    return 0


def _run_lanes(args: argparse.Namespace) -> int:
    """``mtpg bench lanes``: prints the table and the JSON line."""
    from mtpg.bench.engine import machine_info
    from mtpg.bench.lanes_bench import lanes_benchmark

    try:
        threads = [int(t) for t in args.threads.split(",")]
        r = lanes_benchmark(args.late, args.graphs, args.repeats, threads, args.lanes, None)
    except (OSError, ValueError, RuntimeError) as exc:  # bad input, or the engines disagree
        raise SystemExit(f"mtpg bench lanes: {exc}") from None
    m = machine_info()
    r["machine"] = m
    print(f"lane engine ({r['lanes']} lanes) against the scalar kernel ({m['cpu']})")
    print(
        "| workload | threads | clock | decisions | scalar decisions/s | lanes decisions/s"
        " | lanes / scalar | page faults scalar / lanes |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for row in r["rows"]:
        faults = f"{_fmt(row['scalar_page_faults'])} / {_fmt(row['lanes_page_faults'])}"
        print(
            f"| {row['workload']} | {row['threads']} | {row['clock']} | {row['decisions']:,} |"
            f" {_fmt(row['scalar_decisions_per_s'])} | {_fmt(row['lanes_decisions_per_s'])} |"
            f" {row['lanes_vs_scalar']:.2f} | {faults} |"
        )
    print(f"(median of {r['repeats']} interleaved rounds; every job identical in both)")
    print(json.dumps(r))
    return 0


def _run_late(args: argparse.Namespace, log) -> int:
    """``mtpg bench engine --late RUN_DIR``: prints the summary and the JSON line."""
    from mtpg.bench.engine import machine_info
    from mtpg.bench.late import late_benchmark

    try:
        r = late_benchmark(args.late, args.repeats, args.lanes, log)
    except (OSError, ValueError) as exc:  # config, run directory and checkpoint errors
        raise SystemExit(f"mtpg bench engine: {exc}") from None
    m = machine_info()
    r["machine"] = m
    print(
        f"\nmtpg engine, late-generation workload ({m['cpu']}, numba {m['numba']})\n"
        f"  workload      {r['roots']} roots of {r['run']} at generation {r['generation']},"
        f" {r['episodes_per_root']} training episodes each: {r['decisions']:,} decisions,"
        f" {r['teams_per_decision']:.2f} teams and {r['instructions_per_decision']:.1f}"
        " instructions per decision\n"
        f"  scalar        {_fmt(r['scalar_cpu_decisions_per_s'])} decisions per CPU second\n"
        f"  lanes ({r['lanes']})    {_fmt(r['lanes_cpu_decisions_per_s'])} decisions per CPU"
        f" second: {r['lanes_vs_scalar']:.2f}x the scalar kernel (median of {r['repeats']}"
        " interleaved rounds, every job checked identical)"
    )
    print(json.dumps(r))
    return 0


def run(args: argparse.Namespace) -> int:
    """Runs ``mtpg bench engine`` and prints the summary and the JSON line.

    Args:
        args: Parsed options.

    Returns:
        0.
    """
    from mtpg.bench.engine import benchmark

    def log(msg: str) -> None:
        print(msg, flush=True)

    if args.late:
        return _run_late(args, log)

    r = benchmark(
        graphs=args.graphs,
        teams=args.teams,
        programs=args.programs,
        instructions=args.instructions,
        episodes=args.episodes,
        threads=args.threads,
        repeats=args.repeats,
        seed=args.seed,
        reference_graphs=args.reference_graphs,
        pytpg=not args.no_pytpg,
        c=args.c,
        c_flags=tuple(args.c_flags.split()),
        c_beside=tuple(args.c_beside.split()),
        log=log,
        lanes=args.lanes,
    )
    m = r["machine"]
    speed_ref = r["speedup_vs_reference"]
    speed_pt = r["speedup_vs_pytpg"]
    lines = [
        "",
        f"mtpg engine benchmark ({m['cpu']}, {m['cores']} cores, numba {m['numba']})",
        f"  workload      {r['graphs']} graphs x {r['teams']} teams x {r['programs']} programs"
        f" x {r['instructions']} instructions, {r['pointer_fraction']:.1%} pointers,"
        f" {r['episodes']} CartPole episodes each; engine: "
        + (f"lane engine, {r['lanes']} lanes" if r["lanes"] else "scalar kernel"),
        f"  compiled      {_fmt(r['decisions_per_s'])} decisions/s on {r['threads']} thread(s)"
        f" (median of {r['repeats']}: {r['seconds']:.3f} s for {r['decisions']:,} decisions,"
        " environment included)",
        f"                {r['teams_per_decision']:.2f} teams and"
        f" {r['instructions_per_decision']:.1f} instructions per decision"
        f" ({r['effective_instruction_fraction']:.0%} of instructions left after intron"
        f" removal), {_fmt(r['instructions_per_s'])} instructions/s",
        f"  reference     {_fmt(r['reference_decisions_per_s'])} decisions/s"
        f" (Python interpreter, {r['reference_graphs']} graphs, same episodes and actions)"
        + (f"; compiled is {speed_ref:,.0f}x faster" if speed_ref else ""),
        f"  pytpg         {_fmt(r['pytpg_decisions_per_s'])} decisions/s"
        + (
            f" (same graph shapes and observations, own instruction set, no memory,"
            f" {r['pytpg_teams_per_decision']:.2f} teams per decision);"
            f" compiled is {speed_pt:,.0f}x faster"
            if speed_pt
            else " (not installed or not run)"
        ),
        f"  setup         {r['build_seconds']:.1f} s to draw and compile the graphs",
    ]
    if r["scaling"] is not None:
        lines.insert(
            4,
            f"  scaling       {r['scaling']:.2f}x one thread on {r['threads']} threads (one"
            f" thread {_fmt(r['one_thread_decisions_per_s'])} decisions/s; median of"
            f" {r['repeats']} interleaved pairs, wall time)",
        )
    if r["engine_vs_c"] is not None:
        lines.insert(
            -1,
            f"  C             {_fmt(r['c_decisions_per_s'])} decisions/s (same work, checked bit"
            f" for bit); engine {_fmt(r['engine_cpu_decisions_per_s'])} on 1 thread:"
            f" {r['engine_vs_c']:.3f} of C (median of {r['repeats']} interleaved pairs, CPU time;"
            f" C built with {r['c_flags']})",
        )
    if r.get("c_beside"):
        b = r["c_beside"]
        lines.insert(
            -1,
            f"                C built with {b['c_flags']}: {_fmt(b['c_decisions_per_s'])}"
            f" decisions/s; engine {b['engine_vs_c']:.3f} of it",
        )
    print("\n".join(lines))
    sys.stdout.flush()
    print(json.dumps(r))
    return 0
