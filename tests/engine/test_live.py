"""The live decider (one compiled call for many Python-stepped episodes) against the oracle.

Pairs of several roots play interleaved, each in its own episode with its own memory; every
decision's atomic action and continuous outputs must equal the reference agent's, bit for
bit, with observations of more inputs than the paper's two and with fewer (the rest 0).
"""

import numpy as np
import pytest

from mtpg.engine.compile import compile_population
from mtpg.engine.live import LiveDecider
from mtpg.engine.oracle import ReferenceAgent
from mtpg.engine.random_populations import layered_graphs
from mtpg.model.instructions import RegisterLayout


@pytest.mark.parametrize(
    ("n_obs", "given", "no_memory"), [(2, 2, False), (4, 4, False), (4, 3, True)]
)
def test_interleaved_pairs_decide_as_the_reference_agent(n_obs, given, no_memory):
    rng = np.random.default_rng(7)
    layout = RegisterLayout(n_obs=n_obs)
    pop, roots = layered_graphs(rng, 5, teams=3, programs=6, instructions=12, layout=layout)
    cp = compile_population(pop, no_memory=no_memory)
    pair_roots = [roots[i % len(roots)] for i in range(12)]  # roots shared by pairs
    live = LiveDecider(cp, np.array([cp.team_index(r) for r in pair_roots]), n_continuous=3)
    agents = [ReferenceAgent(pop, r, no_memory=no_memory) for r in pair_roots]
    for step in range(40):
        if step % 15 == 0:  # new episodes: fresh memory for some pairs only
            for i in range(0, 12, 1 + step // 15):
                live.reset(i)
                agents[i].reset()
        which = rng.permutation(12)[: rng.integers(1, 13)]
        obs = rng.uniform(-1, 1, (len(which), given))
        a_d, a_c = live.decide(which, obs)
        for k, i in enumerate(which):
            want = agents[i].act(list(obs[k]) + [0.0] * (n_obs - given))
            assert a_d[k] == want.action
            assert a_c[k, 0] == want.continuous  # bit for bit
            # continuous output j is m[j] of the final program's bank
            assert a_c[k].tolist() == agents[i].bank(want.bank)[:3]


def test_more_continuous_outputs_than_memory_registers_is_refused():
    rng = np.random.default_rng(1)
    pop, roots = layered_graphs(rng, 1, layout=RegisterLayout(n_memory=2))
    cp = compile_population(pop)
    with pytest.raises(ValueError, match="program.n_memory is 2"):
        LiveDecider(cp, np.array([cp.team_index(roots[0])]), n_continuous=3)


def test_a_layout_with_more_inputs_than_a_compiled_task_reads_zero_there():
    """A run over tasks of different sizes: the paper's tasks feed 2 of 3 inputs."""
    from mtpg.engine.batch import Episodes, evaluate_roots
    from mtpg.engine.oracle import reference_episode

    rng = np.random.default_rng(3)
    pop, roots = layered_graphs(rng, 2, programs=4, instructions=8, layout=RegisterLayout(n_obs=3))
    reads_third = sum(
        int((p.instructions[:, 3] == pop.layout.obs_start + 2).sum()) for p in pop.programs.values()
    )
    assert reads_third > 0  # the graphs do read the missing input
    cp = compile_population(pop)
    table = Episodes.grid([0, 3], [0])  # CartPole and Pendulum
    lanes, _ = evaluate_roots(cp, roots, table, lanes=32)
    scalar, _ = evaluate_roots(cp, roots, table, lanes=0)
    assert lanes.tolist() == scalar.tolist()
    for i, root in enumerate(roots):
        agent = ReferenceAgent(pop, root)
        for e in range(len(table.tasks)):
            want, _ = reference_episode(agent, int(table.tasks[e]), table.starts[e], table.noise[e])
            assert scalar[i, e] == want
