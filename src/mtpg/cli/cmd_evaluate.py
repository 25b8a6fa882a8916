"""``mtpg evaluate``: test a graph file (or a run's multi-task champion) on unseen episodes."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from mtpg.cli.common import resolve_graph
from mtpg.cli.memory_option import add_memory_option, resolve_no_memory


def register(subparsers: argparse._SubParsersAction) -> None:
    """Adds the ``evaluate`` command."""
    p = subparsers.add_parser(
        "evaluate",
        help="test a program graph on unseen episodes",
        description="Score a graph file, or the champion of all tasks of a run directory, on "
        "test episodes (seeds disjoint from training), raw and normalised against random "
        "play (0) and the reference best (1). A graph runs with memory as it was evolved "
        "(a TPG-NoMemory graph without memory) unless --memory says otherwise.",
    )
    p.add_argument("target", metavar="GRAPH_OR_RUN", help="a graph .json file or a run directory")
    p.add_argument("--tasks", help="comma-separated tasks (default: the graph's or run's tasks)")
    p.add_argument(
        "--episodes",
        type=int,
        help="episodes per task (default: a run's evaluation.test_episodes, so the numbers "
        "equal its report; 100 for a graph file)",
    )
    p.add_argument("--seed", type=int, default=0, help="test seed offset (default 0)")
    p.add_argument("--workers", type=int, default=1, help="threads (default 1)")
    p.add_argument("--json", action="store_true", help="print one JSON object instead")
    add_memory_option(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Runs the command."""
    from mtpg.analysis.runs.loading import normalise_scores
    from mtpg.cli.common import target_task_table, task_list
    from mtpg.cli.main import UsageError
    from mtpg.envs.specs.contract import TASK_NAMES
    from mtpg.envs.specs.param_table import MAX_STEPS
    from mtpg.envs.taskset.episode_seeds import N_TEST_EPISODES
    from mtpg.envs.taskset.variants import known
    from mtpg.evolve.heldout_test import evaluate_graph
    from mtpg.limits import check_evaluation_fits

    pop, root, meta, tasks = resolve_graph(Path(args.target))
    if args.episodes is None:  # a run's own protocol, so evaluate and report agree
        is_run = Path(args.target).is_dir()
        args.episodes = int(meta["test_episodes"]) if is_run else N_TEST_EPISODES
    check_options(args)
    if args.tasks is not None:
        tasks = task_list(args.tasks)
    unknown = [t for t in tasks if not known(t)]
    if unknown:
        raise UsageError(f"unknown task {unknown[0]!r}; choose from {', '.join(TASK_NAMES)}")
    table = target_task_table(Path(args.target), tasks)
    longest = max([int(MAX_STEPS.max()), *(s.max_steps for s in table.specs)])
    check_evaluation_fits(len(tasks) * args.episodes, longest)
    no_memory, memory = resolve_no_memory(args.memory, meta)
    scores = evaluate_graph(
        pop, root, tasks, args.episodes, args.seed, args.workers, no_memory, table.given
    )
    single = single_task_bests(Path(args.target), tasks)
    out = {t: {**s.as_dict(), "no_memory": no_memory, "memory": memory} for t, s in scores.items()}
    for t, best in single.items():
        out[t]["single_task_champion"] = best
        out[t]["normalised_single_task"] = normalise_scores({t: scores[t].mean}, {t: best}, table)[
            t
        ]
    if args.json:  # strict JSON: an undefined ratio (best = random) is null
        clean = {
            t: {k: (None if isinstance(v, float) and v != v else v) for k, v in row.items()}
            for t, row in out.items()
        }
        print(json.dumps(clean, allow_nan=False))
        return 0
    from mtpg.envs.taskset.episode_seeds import describe_held_out

    where = (
        f"all-task champion at generation {meta['generation']} (best root by training score)"
        if Path(args.target).is_dir() and "generation" in meta
        else "graph file"
    )
    n_teams = len(pop.reachable(root))
    print(
        f"{args.target}: {where}, root team {root}, {n_teams} team{'s' * (n_teams != 1)}; "
        f"{describe_held_out(args.episodes, args.seed)}; {memory}"
    )
    print(
        "normalised: 0 = random play, 1 = reference best"
        + ("; vs single: 1 = the run's own single-task champion, same generation" if single else "")
    )
    width = max(22, *(len(t) for t in scores))  # variant names can be long
    header = f"{'task':<{width}} {'mean':>10} {'std':>9} {'normalised':>10} {'teams/dec':>9}"
    print(header + (f" {'vs single':>9}" if single else ""))
    for t, s in scores.items():
        norm = f"{s.normalised:>10.3f}" if s.normalised == s.normalised else f"{'n/a':>10}"
        line = f"{t:<{width}} {s.mean:>10.3f} {s.std:>9.3f} {norm} {s.teams_per_decision:>9.2f}"
        if t in single:
            v = out[t]["normalised_single_task"]
            line += f" {v:>9.3f}" if v == v else f" {'n/a':>9}"  # n/a: champion = random
        print(line)
    raw = [t for t, s in scores.items() if s.normalised != s.normalised]
    if raw:  # a task without a reference best (a Gymnasium task with none given)
        print(
            f"raw scores (no reference best given) for {', '.join(raw)}: give one as "
            'evaluation.references = ["TASK: best=NUMBER, source=TEXT"]'
        )
    return 0


def check_options(args: argparse.Namespace) -> None:
    """Refuses episode counts, seeds and thread counts outside their limits."""
    from mtpg.cli.main import UsageError
    from mtpg.limits import LIMITS

    top = LIMITS["episodes"]
    if not 1 <= args.episodes <= top:
        raise UsageError(f"--episodes must be in 1..{top:,}, got {args.episodes}")
    if not 0 <= args.seed <= 2**62:  # test seeds are 1,000,000 + seed + k in int64
        raise UsageError(f"--seed must be in 0..{2**62}, got {args.seed}")
    if not 1 <= args.workers <= LIMITS["workers"]:
        raise UsageError(f"--workers must be in 1..{LIMITS['workers']}, got {args.workers}")


def single_task_bests(target: Path, tasks: list[str]) -> dict[str, float]:
    """The ``vs single`` denominators of a run (:func:`single_task_scores`), else empty."""
    from mtpg.analysis.runs.champions import single_task_scores, tested_run

    run = tested_run(target) if target.is_dir() else None
    return {} if run is None else single_task_scores(run, tasks)
