"""One paper generation's evaluation with and without constant folding, alternated.

Loads a committed run's last checkpoint, compiles its population twice (folded, the
default, and ``fold_constants=False``), and plays every root on the training episodes of
every task with each in turn, ``--rounds`` times, timing process CPU time on one thread;
both must give identical returns. Run with nothing else running for absolute figures;
the ratio holds up under load better than either time::

    python benchmarks/fold_generation.py results/runs/TPG-seed1 --rounds 4
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

from mtpg.engine.batch import Episodes, evaluate_roots
from mtpg.engine.compile import compile_population
from mtpg.evolve.session import load_state, read_run_config


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path, help="run directory")
    parser.add_argument("--rounds", type=int, default=4, help="alternated rounds (4)")
    args = parser.parse_args(argv)
    config = read_run_config(args.run)
    state = load_state(args.run, config)
    if state is None:
        raise SystemExit(f"{args.run}: no checkpoint")
    pop, ev = state.population, config.evaluation
    roots = sorted(pop.roots())
    episodes = Episodes.grid(list(ev.task_ids), list(range(ev.train_episodes)))
    plain = compile_population(pop, fold_constants=False)
    folded = compile_population(pop)
    for cp in (plain, folded):  # compile the kernels (or load them) before timing
        evaluate_roots(cp, roots[:2], episodes)
    ratios = []
    for _ in range(args.rounds):
        c0 = time.process_time()
        want, _ = evaluate_roots(plain, roots, episodes)
        c1 = time.process_time()
        got, _ = evaluate_roots(folded, roots, episodes)
        c2 = time.process_time()
        if got.tobytes() != want.tobytes():
            raise SystemExit("folded and unfolded code disagree")
        ratios.append((c1 - c0) / (c2 - c1))
        print(
            f"{len(roots)} roots: unfolded {c1 - c0:.1f} s, folded {c2 - c1:.1f} s, "
            f"speed ratio {ratios[-1]:.3f}",
            flush=True,
        )
    print(f"median speed ratio {statistics.median(ratios):.3f} over {args.rounds} rounds")
    return 0


if __name__ == "__main__":
    from mtpg._kernel_cache import refresh

    refresh()  # before the first kernel: a Numba cache older than the sources goes
    sys.exit(main())
