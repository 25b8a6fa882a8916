"""Graphs and checks shared by the export tests.

Every check feeds exported code the engine's own full episodes (``engine_stream``) and
requires the very same ``(a_d, a_c)`` bits at every decision.
"""

import numpy as np

from mtpg.engine.compile import compile_population
from mtpg.engine.random_populations import layered_graphs, tangled_population
from mtpg.engine.trace import trace_sequence
from mtpg.envs.specs.contract import TASK_NAMES
from mtpg.export.harness import Stream, mismatches
from mtpg.model.graph import Population, atomic
from mtpg.model.instructions import OP_ADD, OP_MUL, RegisterLayout

ALL_TASKS = list(range(len(TASK_NAMES)))
#: One held-out-style seed per task: a full episode of every task per graph.
SEEDS = [1_000_003]
EXTREME = [0.0, 1.0, -1.0, 1e-300, -1e-300, 1e10, -1e10, 1e300, -1e300, 0.5]


def random_cases():
    """Random graphs: tangled (shared programs and banks, cycles) and layered."""
    cases = []
    for seed in (11, 12):
        rng = np.random.default_rng(seed)
        pop = tangled_population(rng, 8, 24, 16, 3, 0.6)
        cases.append((f"tangled-{seed}", pop, int(rng.choice(list(pop.teams)))))
    rng = np.random.default_rng(14)
    small = RegisterLayout(n_registers=3, n_memory=2)
    pop = tangled_population(rng, 6, 16, 12, 2, 0.5, layout=small)
    cases.append(("tangled-R3-M2", pop, int(rng.choice(list(pop.teams)))))
    pop, roots = layered_graphs(np.random.default_rng(4), 1, teams=4, programs=6, instructions=12)
    cases += [(f"layered-{r}", pop, r) for r in roots]
    return cases


def accumulator_graph():
    """One team sharing one bank: the sign of a running sum of s[0] picks the action.

    Program A (action 1) bids ``0.9 * m[0]``, read before program B (action 0, bid 0)
    adds ``s[0]`` to ``m[0]``: decisions and ``a_c`` depend on every earlier step.
    """
    pop = Population()
    lay = pop.layout
    m0, s0, c09 = lay.mem_start, lay.obs_start, lay.obs_start - 1
    bank = pop.new_bank()
    a = pop.add_program(np.array([[OP_MUL, 0, m0, c09]]), atomic(1), bank)
    b = pop.add_program(np.array([[OP_ADD, m0, m0, s0]]), atomic(0), bank)
    return pop, pop.add_team([a.id, b.id]).id


def random_observations(n, seed):
    """Observations in [-1, 1] with a quarter of extreme values (up to 1e300)."""
    rng = np.random.default_rng(seed)
    obs = rng.uniform(-1, 1, size=(n, 2))
    mask = rng.random((n, 2)) < 0.25
    obs[mask] = rng.choice(EXTREME, size=mask.sum())
    return obs


def sequence_stream(pop, root, n, seed, no_memory=False, obs=None):
    """A stream of observations (random and extreme by default) as one episode of the engine."""
    obs = random_observations(n, seed) if obs is None else obs
    n = len(obs)
    cp = compile_population(pop, fold_constants=False)
    tr = trace_sequence(cp, root, obs, no_memory=no_memory, snapshot=False)
    teams = [
        [int(cp.team_ids[x]) for x in tr.team_log[tr.team_log[:, 0] == t, 1]] for t in range(n)
    ]
    starts = np.zeros(n, dtype=bool)
    starts[0] = True
    return Stream(obs, starts, tr.actions, teams, [-1])


def assert_same(stream, got, teams=True):
    """Every decision's (a_d, a_c) bits (and visited teams) equal the engine's."""
    bad = mismatches(stream, [(a, c) for a, c, _ in got])
    assert not bad, f"{len(bad)} decisions differ; first: {bad[0]}"
    assert all(isinstance(a, int) and isinstance(c, float) for a, c, _ in got)
    if teams:
        assert [t for _, _, t in got] == stream.teams
