"""The lane engine plays every job exactly as the scalar kernel (mtpg.engine.lanes).

Each job's return, steps, teams visited and instructions executed must be the scalar
kernel's bit for bit, whatever the lane-block size, the order of the jobs (roots mixed
within a lane block), the memory mode, folding, register layout or the threads.
"""

import numpy as np
import pytest
from hypothesis import given, settings

from graph_strategies import tangled_cases
from mtpg.engine.batch import Episodes, run_jobs
from mtpg.engine.compile import compile_population
from mtpg.engine.lane_graph import (
    P_ACT,
    P_GLOBAL,
    localise,
    new_local_graph,
    registers_to_zero,
    unlocalise,
)
from mtpg.engine.ops import OP_COPY
from mtpg.engine.random_populations import layered_graphs, tangled_population
from mtpg.envs.specs.contract import TASK_NAMES
from mtpg.model.instructions import RegisterLayout

FIELDS = ("returns", "steps", "teams", "instructions")
ALL_TASKS = list(range(len(TASK_NAMES)))


def _jobs(cp, roots, episodes, rng=None):
    n_ep = len(episodes.tasks)
    job_roots = np.repeat([cp.team_index(r) for r in roots], n_ep).astype(np.int64)
    job_eps = np.tile(np.arange(n_ep, dtype=np.int64), len(roots))
    if rng is not None:  # any order: lane blocks then mix roots and tasks
        order = rng.permutation(len(job_roots))
        job_roots, job_eps = job_roots[order], job_eps[order]
    return job_roots, job_eps


def _same(a, b):
    for f in FIELDS:
        assert getattr(a, f).tobytes() == getattr(b, f).tobytes(), f


@given(tangled_cases())
@settings(max_examples=40, deadline=None)
def test_lanes_equal_scalar_on_tangled_graphs(case):
    rng, pop, no_memory = case
    cp = compile_population(pop)
    episodes = Episodes.grid(ALL_TASKS, [int(rng.integers(1000)), int(rng.integers(1000))])
    roots = pop.roots() or list(pop.teams)[:1]
    job_roots, job_eps = _jobs(cp, roots, episodes, rng)
    block = int(rng.integers(1, 40))
    scalar = run_jobs(cp, job_roots, job_eps, episodes, no_memory=no_memory, block=block, lanes=0)
    for lanes in (1, int(rng.integers(2, 12)), 32):
        got = run_jobs(
            cp, job_roots, job_eps, episodes, no_memory=no_memory, block=block, lanes=lanes
        )
        _same(got, scalar)


@pytest.mark.parametrize("no_memory", [False, True])
@pytest.mark.parametrize("fold", [False, True])
def test_lanes_equal_scalar_on_layered_graphs_and_threads(no_memory, fold):
    rng = np.random.default_rng(5)
    pop, roots = layered_graphs(rng, 40, teams=3, programs=6, instructions=8)
    cp = compile_population(pop, fold_constants=fold)
    episodes = Episodes.grid(ALL_TASKS, [3, 4, 5])
    job_roots, job_eps = _jobs(cp, roots, episodes)
    n_ep = len(episodes.tasks)
    scalar = run_jobs(cp, job_roots, job_eps, episodes, no_memory=no_memory, block=n_ep, lanes=0)
    for threads, lanes in ((1, 7), (1, 64), (2, 32), (2, 1)):
        got = run_jobs(
            cp, job_roots, job_eps, episodes, threads, no_memory, block=n_ep, lanes=lanes
        )
        _same(got, scalar)


def test_lanes_equal_scalar_with_other_register_and_input_sizes():
    rng = np.random.default_rng(8)
    layouts = (
        RegisterLayout(n_registers=3, n_memory=2),
        RegisterLayout(n_registers=12),
        RegisterLayout(n_registers=70, n_memory=3),  # above 64: every register zeroed
        RegisterLayout(n_obs=4),  # inputs the built-in tasks lack read 0 in every lane
    )
    for layout in layouts:
        pop = tangled_population(rng, 5, 20, 25, 4, 0.5, layout)
        cp = compile_population(pop)
        episodes = Episodes.grid(ALL_TASKS, [0, 1])
        job_roots, job_eps = _jobs(cp, pop.roots(), episodes)
        _same(
            run_jobs(cp, job_roots, job_eps, episodes, lanes=5),
            run_jobs(cp, job_roots, job_eps, episodes, lanes=0),
        )


def test_negative_lanes_are_refused():
    rng = np.random.default_rng(1)
    pop, roots = layered_graphs(rng, 2, teams=1, programs=2, instructions=2)
    cp = compile_population(pop)
    episodes = Episodes.grid([0], [0])
    with pytest.raises(ValueError, match="lanes"):
        run_jobs(cp, *_jobs(cp, roots, episodes), episodes, lanes=-1)


def _prog(*rows):
    instrs = np.array(rows, dtype=np.uint32).reshape(-1, 4)
    return instrs, np.array([0, len(instrs)], dtype=np.int64)


@pytest.mark.parametrize(
    ("rows", "want"),
    [
        # r0 <- r1 + r2: reads r1 and r2 unwritten; writes the bid
        ([(0, 0, 1, 2)], 0b110),
        # r3 <- cos(r4); r0 <- r3 * r3: r4 read first; r3 written before its reads
        ([(5, 3, 0, 4), (2, 0, 3, 3)], 0b10000),
        # unary ops read only src2: r5 <- sqrt(r6) reads r6, not r7; bid never written
        ([(8, 5, 7, 6)], 0b1000001),
        # the conditionals read their target: IF r1 < r2 THEN r1 <- -r1
        ([(14, 1, 1, 2)], 0b111),
        # a copy reads only src2; registers 8 and up are not private
        ([(OP_COPY, 0, 3, 9)], 0),
    ],
)
def test_registers_to_zero(rows, want):
    instrs, offsets = _prog(*rows)
    assert int(registers_to_zero(instrs, offsets[0], offsets[1], 8)) == want


def test_a_block_graph_is_local_and_the_maps_are_left_clean():
    """localise numbers the reachable teams, programs and banks; unlocalise undoes it."""
    rng = np.random.default_rng(4)
    pop = tangled_population(rng, 6, 20, 10, 4, 0.6)
    g = compile_population(pop).graph
    lg = new_local_graph(g)
    maps, lteam, lteam_off, lprog = lg.maps, lg.teams, lg.team_offsets, lg.programs
    assert (maps == -1).all()
    roots = np.array([0], dtype=np.int64)
    localise(g, roots, 4, 10_000, lg)
    n_lt, n_lp = int(lg.counts[0]), int(lg.counts[1])
    assert lteam[0] == 0 and n_lt >= 1 and lteam_off[n_lt] == n_lp
    for lt in range(n_lt):  # every local team holds its global team's programs, in order
        t = lteam[lt]
        members = g.team_members[g.team_offsets[t] : g.team_offsets[t + 1]]
        assert list(lprog[lteam_off[lt] : lteam_off[lt + 1], P_GLOBAL]) == list(members)
        for row in lprog[lteam_off[lt] : lteam_off[lt + 1]]:  # pointers stay in the block
            assert row[P_ACT] < n_lt
    unlocalise(lg)
    assert (maps == -1).all()
