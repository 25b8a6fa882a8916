"""Counts the episodes two result-preserving savings would skip in a committed run.

Two ways to play fewer decisions without changing any result were considered to bring a
paper-preset run under an hour (docs/reproducing-the-paper.md, "Where a paper
generation's time goes"); this script measures how much each would save:

1. **Children equal to a scored root.** Every root plays the same training episodes, so
   a child whose reachable graph equals an already-scored root's, or an earlier child's,
   in everything that decides its behaviour would score the same without playing. Two
   roots are counted equal when their graphs have the same canonical form: teams numbered
   in order of first visit (depth first, program order), and per program its effective
   instructions (introns removed, :func:`mtpg.engine.compile.effective_code`), its atomic
   action or the number of the team it points to, and its memory bank numbered in order
   of first use (so bank sharing counts, bank ids do not).
2. **Champions tested before.** Teams and programs never change once made, so a champion
   already tested at an earlier test point would score the same again. Counted from the
   run's ``tests.csv`` (the ``root`` of every subset at every test point).

Usage (``--generations`` continues the run from its last checkpoint in memory, writing
nothing; each generation costs what a training generation costs)::

    python benchmarks/decision_savings.py results/runs/TPG-seed1 --generations 2
"""

from __future__ import annotations

import argparse
import csv
import sys
from pathlib import Path

from mtpg.engine.compile import effective_code
from mtpg.evolve.session import load_state, read_run_config
from mtpg.evolve.trainer import Trainer
from mtpg.model.graph import Population


def canonical_form(pop: Population, root: int) -> tuple:
    """The behaviour-deciding structure of the graph reachable from ``root``."""
    team_number: dict[int, int] = {root: 0}
    bank_number: dict[int, int] = {}
    order = [root]
    teams = []
    i = 0
    while i < len(order):  # breadth over the numbering; each team's body is in order
        body = []
        for pid in pop.teams[order[i]].programs:
            prog = pop.programs[pid]
            if prog.is_atomic:
                action = ("a", prog.atomic_action)
            else:
                if prog.action not in team_number:
                    team_number[prog.action] = len(order)
                    order.append(prog.action)
                action = ("t", team_number[prog.action])
            bank = bank_number.setdefault(prog.bank, len(bank_number))
            code = effective_code(prog, pop.layout)
            body.append((code.tobytes(), code.shape[0], action, bank))
        teams.append(tuple(body))
        i += 1
    return tuple(teams)


class CountingTrainer(Trainer):
    """A trainer that, after breeding each generation, counts children equal to a scored root."""

    rows: list[tuple[int, int, int]]

    def _vary(self, gen: int) -> None:
        super()._vary(gen)
        pop, scored = self.state.population, self.state.scores
        seen = {canonical_form(pop, r) for r in scored}
        children = [r for r in pop.roots() if r not in scored]
        copies = 0
        for child in children:
            form = canonical_form(pop, child)
            if form in seen:
                copies += 1
            seen.add(form)
        self.rows.append((gen, len(children), copies))


def duplicate_children(run_dir: Path, generations: int) -> list[tuple[int, int, int]]:
    """``(generation, children, copies)`` of the next generations of the run, in memory."""
    config = read_run_config(run_dir)
    state = load_state(run_dir, config)
    if state is None:
        raise SystemExit(f"{run_dir}: no checkpoint")
    trainer = CountingTrainer(config, state)
    trainer.rows = []
    try:
        for _ in range(generations):
            trainer.run_generation()
    finally:
        trainer.close()
    return trainer.rows


def retested_champions(run_dir: Path) -> tuple[int, int, int]:
    """``(test points, distinct champions summed over test points, tested before)``."""
    by_point: dict[int, set[int]] = {}
    with open(run_dir / "tests.csv", encoding="utf-8") as fh:
        for row in csv.DictReader(fh):
            by_point.setdefault(int(row["generation"]), set()).add(int(row["root"]))
    tested: set[int] = set()
    total = again = 0
    for gen in sorted(by_point):
        roots = by_point[gen]
        total += len(roots)
        again += len(roots & tested)
        tested |= roots
    return len(by_point), total, again


def main(argv: list[str] | None = None) -> int:
    """Command-line entry point."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path, help="run directory")
    parser.add_argument(
        "--generations", type=int, default=2, help="generations to breed and count (2; 0: none)"
    )
    args = parser.parse_args(argv)
    points, total, again = retested_champions(args.run)
    print(
        f"champions tested before: {again} of {total} distinct champions over {points} "
        f"test points ({100 * again / max(total, 1):.1f}%)"
    )
    for gen, children, copies in duplicate_children(args.run, args.generations):
        print(
            f"generation {gen}: {copies} of {children} children equal a scored root "
            f"or an earlier child ({100 * copies / max(children, 1):.1f}%)"
        )
    return 0


if __name__ == "__main__":
    from mtpg._kernel_cache import refresh

    refresh()  # before the first kernel: a Numba cache older than the sources goes
    sys.exit(main())
