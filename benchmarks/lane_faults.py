"""Where the lane engine's page faults come from: per call, not per block.

Plays the first 1, 10, 100 and all roots of a run's last checkpoint on its training
episodes (one root's episodes per queue block, as training plays them), with the scalar
kernel and with the lane engine, and prints each call's minor page faults and CPU
seconds. If the lane engine allocated per block, its faults would grow with the blocks;
they stay at a few hundred per call, the first touches of the worker's buffers
(``lanes.lane_buffers`` and ``lane_graph.new_local_graph``, allocated once per call and
left unfilled), bounded by the pages the largest block's graph reaches.

    python benchmarks/lane_faults.py [results/runs/TPG-seed3]
"""

from __future__ import annotations

import resource
import sys
import time

from mtpg.bench.late import late_workload
from mtpg.engine.batch import run_jobs


def _faults() -> int:
    return resource.getrusage(resource.RUSAGE_SELF).ru_minflt


def main(argv: list[str] | None = None) -> int:
    """Prints one line per (roots, engine) call; returns the exit status."""
    argv = sys.argv[1:] if argv is None else argv
    work, _ = late_workload(argv[0] if argv else "results/runs/TPG-seed3")
    n_ep = work.episodes
    for lanes in (0, 32):  # compiled (or loaded from the cache) before anything is counted
        run_jobs(work.cp, work.job_roots[:n_ep], work.job_episodes[:n_ep], work.pool, lanes=lanes)
    for k in (1, 10, 100, len(work.root_ids)):
        rows = slice(0, k * n_ep)
        for lanes in (0, 32):
            f0, t0 = _faults(), time.process_time()
            run_jobs(
                work.cp,
                work.job_roots[rows],
                work.job_episodes[rows],
                work.pool,
                block=n_ep,
                lanes=lanes,
            )
            print(
                f"roots {k:5d}  {'lanes ' if lanes else 'scalar'}  faults {_faults() - f0:5d}"
                f"  CPU {time.process_time() - t0:6.2f} s",
                flush=True,
            )
    g = work.cp.graph
    n_banks = int(g.prog_bank.max()) + 1
    print(f"{len(g.instrs)} instructions, {len(g.team_offsets) - 1} teams, {n_banks} banks")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
