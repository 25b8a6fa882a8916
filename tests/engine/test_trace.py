import numpy as np

from mtpg.engine.compile import compile_population
from mtpg.engine.trace import trace_episode, trace_sequence
from mtpg.envs import make_episodes
from mtpg.model.graph import Population, atomic
from mtpg.model.instructions import RegisterLayout

L = RegisterLayout()
M1, S0 = L.mem_start + 1, L.obs_start


def one_team(codes, actions=(0, 1)):
    pop = Population(layout=L)
    bank = pop.new_bank()
    pids = [
        pop.add_program(np.array(c, dtype=np.int32), atomic(a), bank).id
        for c, a in zip(codes, actions, strict=True)
    ]
    pop.add_team(pids)
    return pop


def test_memory_log_records_the_step_of_the_last_write():
    # program 0: r0 <- m[1] + s[0] (reads m[1]); m[1] <- |s[0]| (writes it)
    pop = one_team([[[0, 0, M1, S0], [12, M1, 0, S0]], [[0, 0, S0, S0]]])
    trace = trace_sequence(compile_population(pop, fold_constants=False), 0, np.full((4, 2), 0.5))
    reads = trace.mem_log[trace.mem_log[:, 3] == 0]
    writes = trace.mem_log[trace.mem_log[:, 3] == 1]
    assert reads[:, 0].tolist() == [0, 1, 2, 3]
    assert reads[:, 4].tolist() == [-1, 0, 1, 2]  # value read was written one step earlier
    assert writes[:, 4].tolist() == [-1, 0, 1, 2]  # and overwrites that value
    assert (reads[:, 2] == 1).all() and (writes[:, 2] == 1).all()
    # every decision visited the one team and ran both programs
    assert trace.teams_per_decision().tolist() == [1, 1, 1, 1]
    assert np.bincount(trace.prog_log[:, 0]).tolist() == [2, 2, 2, 2]
    assert np.bincount(trace.instr_log[:, 0]).tolist() == [3, 3, 3, 3]


def test_no_memory_mode_resets_last_write():
    pop = one_team([[[0, 0, M1, S0], [12, M1, 0, S0]], [[0, 0, S0, S0]]])
    trace = trace_sequence(
        compile_population(pop, fold_constants=False), 0, np.full((3, 2), 0.5), no_memory=True
    )
    reads = trace.mem_log[trace.mem_log[:, 3] == 0]
    assert reads[:, 4].tolist() == [-1, -1, -1]


def test_traced_episode_matches_batch_kernel():
    from mtpg.engine.batch import Episodes, evaluate_roots
    from mtpg.engine.random_populations import layered_graphs

    pop, roots = layered_graphs(np.random.default_rng(4), 6, teams=3, programs=5, instructions=6)
    cp = compile_population(pop, fold_constants=False)
    for task in range(6):
        eps = Episodes.grid([task], [3])
        returns, result = evaluate_roots(compile_population(pop), roots, eps)  # folded
        starts, noise = make_episodes(np.array([task]), np.array([3]))
        for i, root in enumerate(roots):
            trace = trace_episode(cp, root, task, starts[0], noise[0])
            assert sum(trace.rewards.tolist(), 0.0) == returns[i, 0]  # same summation order
            assert len(trace.actions) == result.steps[i]
            assert trace.teams_per_decision().sum() == result.teams[i]
            assert len(trace.instr_log) == result.instructions[i]


def test_a_run_whose_logs_overflow_is_played_again_with_room_for_all(monkeypatch):
    """Logs that outgrow the first buffers are counted, and the run is played again."""
    from mtpg.engine import record
    from mtpg.engine.random_populations import layered_graphs

    pop, roots = layered_graphs(np.random.default_rng(5), 2, teams=3, programs=5, instructions=6)
    cp = compile_population(pop, fold_constants=False)
    starts, noise = make_episodes(np.array([0]), np.array([1]))
    roomy = trace_episode(cp, roots[0], 0, starts[0], noise[0], snapshot=True)
    monkeypatch.setattr(record, "FIRST_ROWS", 3)
    played = []
    real = record.new_recorder

    def counting(*args):
        played.append(1)
        return real(*args)

    monkeypatch.setattr(record, "new_recorder", counting)
    tight = trace_episode(cp, roots[0], 0, starts[0], noise[0], snapshot=True)
    assert len(played) == 2
    for field in roomy.__dataclass_fields__:
        assert np.array_equal(getattr(roomy, field), getattr(tight, field)), field


def test_a_traced_episode_ends_where_its_noise_row_ends():
    from mtpg.engine.random_populations import layered_graphs
    from mtpg.envs.specs.contract import ACROBOT

    pop, roots = layered_graphs(np.random.default_rng(4), 1, teams=2, programs=4, instructions=4)
    cp = compile_population(pop, fold_constants=False)
    starts, noise = make_episodes(np.array([ACROBOT]), np.array([0]))  # up to 500 steps
    trace = trace_episode(cp, roots[0], ACROBOT, starts[0], noise[0, :8])
    assert len(trace.actions) == 7 and len(trace.states) == 8
