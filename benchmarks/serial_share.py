"""Share of a training generation spent outside the compiled evaluation.

Runs the paper preset (or another) on the local backend and times, per generation,
variation, compilation of the population, the kernel evaluation of the new roots, and
selection (with the metrics row). The serial share is (variation + compilation +
selection) / total; shares, unlike seconds, stay meaningful on a busy machine.

    python benchmarks/serial_share.py --generations 100 --workers 2          # the figure
    python benchmarks/serial_share.py --generations 5 --profile              # hot spots

Prints one line per generation and a summary; ``--json FILE`` writes every row.
"""

from __future__ import annotations

import argparse
import cProfile
import json
import pstats
import time

import mtpg.evolve.trainer as trainer_module
from mtpg.config import build_config
from mtpg.evolve.trainer import Trainer


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--preset", default="paper")
    ap.add_argument("--generations", type=int, default=100)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--set", action="append", default=[], help="section.field=value")
    ap.add_argument("--profile", action="store_true", help="cProfile the serial parts")
    ap.add_argument("--json", help="write the per-generation rows here")
    args = ap.parse_args()
    config = build_config(
        args.preset,
        overrides=[f"generations={args.generations}", f"workers={args.workers}", *args.set],
    )
    compile_seconds = [0.0]
    real_compile = trainer_module.compile_population

    def timed_compile(*a, **k):
        t = time.perf_counter()
        out = real_compile(*a, **k)
        compile_seconds[0] += time.perf_counter() - t
        return out

    trainer_module.compile_population = timed_compile
    profiler = cProfile.Profile() if args.profile else None
    trainer = Trainer(config)
    rows = []
    print("gen  variation  compile  evaluate  selection  total   serial share")
    while not trainer.done:
        compile_seconds[0] = 0.0
        if profiler:
            profiler.enable()
        t = time.perf_counter()
        m = trainer.run_generation()
        total = time.perf_counter() - t
        if profiler:
            profiler.disable()
        comp = compile_seconds[0]
        row = {
            "generation": int(m["generation"]),
            "variation": m["t_variation"],
            "compile": comp,
            "evaluate": m["t_evaluation"] - comp,
            "selection": total - m["t_variation"] - m["t_evaluation"],
            "total": total,
            "teams": int(m["teams"]),
            "programs": int(m["programs"]),
        }
        row["serial_share"] = (row["variation"] + comp + row["selection"]) / total
        rows.append(row)
        print(
            f"{row['generation']:4d}  {row['variation']:8.3f}  {comp:7.3f}  "
            f"{row['evaluate']:8.3f}  {row['selection']:9.3f}  {total:6.2f}  "
            f"{row['serial_share']:6.1%}",
            flush=True,
        )
    parts = ("variation", "compile", "evaluate", "selection")
    sums = {p: sum(r[p] for r in rows) for p in parts}
    total = sum(r["total"] for r in rows)
    print(
        f"generations 1-{len(rows)}: "
        + ", ".join(f"{p} {sums[p] / total:.1%}" for p in parts)
        + f"; serial share {(total - sums['evaluate']) / total:.1%} of {total:.1f} s"
    )
    if args.json:
        with open(args.json, "w") as fh:
            json.dump(rows, fh)
    if profiler:
        pstats.Stats(profiler).sort_stats("cumulative").print_stats(30)


if __name__ == "__main__":
    from mtpg._kernel_cache import refresh

    refresh()  # before the first kernel: a Numba cache older than the sources goes
    main()
