"""Evaluation throughput of the local and dask backends on paper-preset generations.

Runs the same generations (paper preset, same seed) once per backend and reports, for
generations 2..G, the median evaluation throughput (decisions per second of the
evaluation step: compilation, transfer and kernels) and the median generation time. The
runs must agree on every non-timing metric, which the script checks.

    python benchmarks/backend_throughput.py --generations 6 \\
        --backends local:1 local:2 dask:1 dask:2 dask:4

``local:N`` is the local backend on N threads; ``dask:N`` starts a local Dask cluster of
N one-thread worker processes on the loopback interface (dashboard off). Measure on an
otherwise idle machine (the CPU seconds, summed over the driver and the local worker
processes, show the backend's overhead even on a busy one); the last line is one JSON
object with every figure.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics

from mtpg.config import build_config
from mtpg.evolve.columns import TIMING_COLUMNS
from mtpg.evolve.trainer import Trainer


def tree_cpu() -> float:
    """CPU seconds used so far by this process and its children (the local workers)."""
    import psutil

    me = psutil.Process()
    total = sum(me.cpu_times()[:2])
    for child in me.children(recursive=True):
        try:
            total += sum(child.cpu_times()[:2])
        except psutil.Error:
            pass
    return total


def run(spec: str, generations: int, seed: int, extra: list[str]) -> tuple[list, list]:
    kind, n = spec.split(":")
    overrides = [f"generations={generations}", f"seed={seed}", *extra]
    if kind == "local":
        overrides.append(f"workers={n}")
    else:
        overrides += ["backend=dask", f"dask_workers={n}", "workers=2"]
    trainer = Trainer(build_config("paper", overrides=overrides))
    rows, cpu = [], []
    try:
        while not trainer.done:
            before = tree_cpu()
            rows.append(trainer.run_generation())
            cpu.append(tree_cpu() - before)
    finally:
        trainer.close()
    timing = [(r["decisions_per_s"], r["t_total"], c) for r, c in zip(rows, cpu, strict=True)]
    timing = timing[1:]
    same = [{k: v for k, v in r.items() if k not in TIMING_COLUMNS} for r in rows]
    return timing, same


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--generations", type=int, default=6)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--backends", nargs="+", default=["local:2", "dask:2"])
    ap.add_argument("--set", action="append", default=[], help="section.field=value")
    args = ap.parse_args()
    results, reference = {}, None
    for spec in args.backends:
        timing, same = run(spec, args.generations, args.seed, args.set)
        if reference is None:
            reference = same
        elif same != reference:
            raise SystemExit(f"{spec}: metrics differ from {args.backends[0]}'s")
        dps = statistics.median(t[0] for t in timing)
        gen = statistics.median(t[1] for t in timing)
        cpu = statistics.median(t[2] for t in timing)
        results[spec] = {"decisions_per_s": dps, "generation_s": gen, "generation_cpu_s": cpu}
        print(
            f"{spec:10s} {dps:14,.0f} decisions/s  {gen:7.2f} s per generation"
            f"  {cpu:7.2f} s CPU per generation (driver and local workers)",
            flush=True,
        )
    base = results.get("local:2")
    if base:
        for spec, r in results.items():
            r["vs_local_2_threads"] = r["decisions_per_s"] / base["decisions_per_s"]
            print(f"{spec:10s} {r['vs_local_2_threads']:.2f} of local:2")
    machine = {"cpu": platform.processor() or platform.machine(), "cores": os.cpu_count()}
    print(json.dumps({"generations": args.generations, "machine": machine, **results}))


if __name__ == "__main__":
    from mtpg._kernel_cache import refresh

    refresh()  # before the first kernel: a Numba cache older than the sources goes
    main()
