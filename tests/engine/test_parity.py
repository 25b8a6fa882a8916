"""The compiled kernels must match the plain-Python reference interpreter bit for bit."""

import numpy as np
import pytest
from hypothesis import given, settings

from graph_strategies import tangled_cases
from mtpg.engine.batch import Episodes, evaluate_roots, run_jobs
from mtpg.engine.compile import compile_population
from mtpg.engine.oracle import ReferenceAgent, reference_episode
from mtpg.engine.random_populations import layered_graphs, tangled_population
from mtpg.engine.trace import trace_sequence
from mtpg.envs.specs.contract import TASK_NAMES
from mtpg.model.graph import check_invariants
from mtpg.model.instructions import BIG

EXTREME = [0.0, 1.0, -1.0, 1e-300, -1e-300, 1e10, -1e10, 1e300, -1e300, 0.5]


def observations(rng, n):
    obs = rng.uniform(-1, 1, size=(n, 2))
    mask = rng.random((n, 2)) < 0.2
    obs[mask] = rng.choice(EXTREME, size=mask.sum())
    return obs


def compare_sequence(pop, root, obs, no_memory=False):
    cp = compile_population(pop, fold_constants=False)
    trace = trace_sequence(cp, root, obs, no_memory=no_memory)
    full = trace_sequence(
        compile_population(pop, remove_introns=False), root, obs, no_memory=no_memory
    )
    agent = ReferenceAgent(pop, root, no_memory=no_memory)
    m = pop.layout.n_memory
    for t, o in enumerate(obs):
        d = agent.act(o)
        # actions
        assert trace.actions[t, 0] == d.action
        assert trace.actions[t, 1] == d.continuous
        # teams visited: never twice, ending where the decision ended
        teams = [int(cp.team_ids[x]) for x in trace.team_log[trace.team_log[:, 0] == t, 1]]
        assert teams == d.teams
        assert len(set(teams)) == len(teams)
        # bids of every program executed, in order
        rows = trace.prog_log[:, 0] == t
        bids = list(
            zip(
                (int(cp.program_ids[p]) for p in trace.prog_log[rows, 1]),
                trace.bids[rows].tolist(),
                strict=True,
            )
        )
        assert bids == d.bids
        # memory contents of every bank
        for dense, bank_id in enumerate(cp.bank_ids):
            want = agent.memory.get(int(bank_id), [0.0] * m)
            got = trace.memory[t, dense * m : (dense + 1) * m]
            assert got.tolist() == want, (t, bank_id)
        assert np.all(np.abs(trace.memory[t]) <= BIG)
        assert np.all(np.isfinite(trace.bids))
    # removing introns changes no output
    assert np.array_equal(full.actions, trace.actions)
    assert np.array_equal(full.memory, trace.memory)
    assert np.array_equal(full.bids, trace.bids)
    return trace


@settings(max_examples=60, deadline=None, derandomize=True)
@given(case=tangled_cases())
def test_random_tangled_graphs_match_reference(case):
    rng, pop, no_memory = case
    check_invariants(pop)
    root = int(rng.choice(list(pop.teams)))
    trace = compare_sequence(pop, root, observations(rng, 12), no_memory=no_memory)
    # a decision always ends at an atomic action
    assert set(np.unique(trace.actions[:, 0])) <= {0, 1, 2}


def test_layered_graphs_match_reference():
    rng = np.random.default_rng(7)
    pop, roots = layered_graphs(rng, 5, teams=3, programs=10, instructions=10)
    check_invariants(pop)
    for root in roots:
        compare_sequence(pop, root, observations(rng, 20))


@pytest.mark.parametrize("task", range(len(TASK_NAMES)))
def test_episode_returns_match_reference(task):
    rng = np.random.default_rng(100 + task)
    pop = tangled_population(rng, 6, 20, 12, 4, 0.5)
    roots = list(pop.teams)[:3]
    episodes = Episodes.grid([task], [0, 1])
    cp = compile_population(pop)
    returns, result = evaluate_roots(cp, roots, episodes)
    for i, root in enumerate(roots):
        for e in range(2):
            total, steps = reference_episode(
                ReferenceAgent(pop, root), task, episodes.starts[e], episodes.noise[e]
            )
            assert returns[i, e] == total
            assert result.steps[i * 2 + e] == steps


def test_serial_and_parallel_batches_are_bit_identical():
    rng = np.random.default_rng(3)
    pop, roots = layered_graphs(rng, 40, teams=3, programs=6, instructions=8)
    cp = compile_population(pop)
    episodes = Episodes.grid(list(range(len(TASK_NAMES))), [0, 1])
    serial, rs = evaluate_roots(cp, roots, episodes, threads=1)
    parallel, rp = evaluate_roots(cp, roots, episodes, threads=2)
    assert serial.tobytes() == parallel.tobytes()
    assert np.array_equal(rs.steps, rp.steps)
    assert np.array_equal(rs.instructions, rp.instructions)
    # job order does not matter either
    perm = rng.permutation(len(roots) * len(episodes.tasks))
    job_roots = np.repeat([cp.team_index(r) for r in roots], len(episodes.tasks))[perm]
    job_eps = np.tile(np.arange(len(episodes.tasks)), len(roots))[perm]
    shuffled = run_jobs(cp, job_roots, job_eps, episodes, threads=2)
    assert np.array_equal(shuffled.returns, serial.ravel()[perm])
    # nor how jobs are dealt out in blocks, serially or over threads
    for threads, block in [(1, 5), (2, 1), (2, 7), (2, 10_000)]:
        dealt = run_jobs(cp, job_roots, job_eps, episodes, threads=threads, block=block)
        assert dealt.returns.tobytes() == shuffled.returns.tobytes()
        assert np.array_equal(dealt.instructions, shuffled.instructions)


def test_bad_block_is_refused():
    rng = np.random.default_rng(4)
    pop, roots = layered_graphs(rng, 2, teams=1, programs=2, instructions=2)
    cp = compile_population(pop)
    episodes = Episodes.grid([0], [0])
    with pytest.raises(ValueError, match="block"):
        run_jobs(cp, np.array([cp.team_index(roots[0])]), np.array([0]), episodes, block=0)


def test_no_memory_mode_differs_only_by_memory():
    rng = np.random.default_rng(5)
    pop, roots = layered_graphs(rng, 30, teams=2, programs=6, instructions=10)
    cp = compile_population(pop)
    episodes = Episodes.grid([3], [0])  # Pendulum reads m[0] as its torque
    with_mem, _ = evaluate_roots(cp, roots, episodes)
    without, _ = evaluate_roots(cp, roots, episodes, no_memory=True)
    assert not np.array_equal(with_mem, without)
    # in both modes the production kernel equals the reference interpreter, which differs
    # between the modes only in zeroing the banks before every program execution
    for i, root in enumerate(roots[:8]):
        for returns, no_memory in ((with_mem, False), (without, True)):
            agent = ReferenceAgent(pop, root, no_memory=no_memory)
            total, _ = reference_episode(agent, 3, episodes.starts[0], episodes.noise[0])
            assert returns[i, 0] == total, (root, no_memory)


def test_the_compiled_graph_carries_the_no_memory_mode():
    """``compile_population(..., no_memory=True)`` plays as the deprecated argument does."""
    rng = np.random.default_rng(5)
    pop, roots = layered_graphs(rng, 30, teams=2, programs=6, instructions=10)
    plain, ablated = compile_population(pop), compile_population(pop, no_memory=True)
    assert not plain.no_memory and ablated.no_memory and ablated.graph.no_memory
    assert ablated.with_memory_mode(None) is ablated
    assert not ablated.with_memory_mode(False).no_memory
    assert plain.graph.no_memory is False  # the flag itself untouched by the override
    episodes = Episodes.grid([3], [0])  # Pendulum reads m[0] as its torque
    passed, a = evaluate_roots(plain, roots, episodes, no_memory=True)
    for lanes in (0, 4):
        carried, b = evaluate_roots(ablated, roots, episodes, lanes=lanes)
        assert carried.tobytes() == passed.tobytes()
        assert np.array_equal(a.instructions, b.instructions)
    on, _ = evaluate_roots(ablated, roots, episodes, no_memory=False)
    assert on.tobytes() == evaluate_roots(plain, roots, episodes)[0].tobytes()
