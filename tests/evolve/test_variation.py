import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from mtpg.config import build_config
from mtpg.evolve.variation import Varier, init_population, mutate_code
from mtpg.model.graph import check_invariants
from mtpg.model.instructions import valid_instructions


def small_config(**team):
    overrides = [f"team.{k}={v}" for k, v in team.items()]
    return build_config(
        "paper", overrides=["team.root_size=12", "team.init_team_size=4", *overrides]
    )


def frozen_copy(pop):
    return (
        {pid: (p.instructions.copy(), p.action, p.bank) for pid, p in pop.programs.items()},
        {tid: list(t.programs) for tid, t in pop.teams.items()},
    )


@settings(max_examples=40, deadline=None, derandomize=True)
@given(
    seed=st.integers(0, 2**32 - 1),
    p_atomic=st.sampled_from([0.0, 0.5, 0.95, 1.0]),
    p_x=st.sampled_from([0.0, 0.5, 1.0]),
)
def test_invariants_hold_after_every_child(seed, p_atomic, p_x):
    config = small_config(p_atomic=p_atomic, p_crossover=p_x, p_action=0.8, p_memory=0.5, p_new=0.5)
    rng = np.random.default_rng(seed)
    pop = init_population(config, rng)
    check_invariants(pop)
    for gen in range(2, 5):
        roots = pop.roots()
        before_programs, before_teams = frozen_copy(pop)
        varier = Varier(pop, config, rng, gen)
        for _ in range(10):
            child = varier.child(int(rng.choice(roots)), int(rng.choice(roots)))
            check_invariants(pop)
            assert pop.teams[child].birth == gen
            assert pop.teams[child].programs != [] and child in pop.roots()
        # existing programs and teams are never changed in place
        for pid, (code, action, bank) in before_programs.items():
            prog = pop.programs[pid]
            assert np.array_equal(prog.instructions, code)
            assert (prog.action, prog.bank) == (action, bank)
        for tid, members in before_teams.items():
            assert pop.teams[tid].programs == members
        # every pre-existing root is still a root: roots are cloned, never subsumed
        assert set(roots) <= set(pop.roots())


def test_no_hierarchy_creates_no_team_pointers():
    config = small_config(p_atomic=1.0, p_action=1.0, p_new=1.0)
    rng = np.random.default_rng(0)
    pop = init_population(config, rng)
    varier = Varier(pop, config, rng, 2)
    for _ in range(50):
        varier.child(int(rng.choice(pop.roots())), int(rng.choice(pop.roots())))
    assert all(p.is_atomic for p in pop.programs.values())


def test_pointer_mutation_clones_subsumed_roots():
    config = small_config(p_atomic=0.0, p_action=1.0, p_new=1.0)
    rng = np.random.default_rng(1)
    pop = init_population(config, rng)
    roots = set(pop.roots())
    varier = Varier(pop, config, rng, 2)
    child = varier.child(min(roots), min(roots))
    targets = {
        pop.programs[p].action for p in pop.teams[child].programs if not pop.programs[p].is_atomic
    }
    assert targets, "with p_atomic = 0 the child points to other teams"
    for t in targets:
        assert t not in roots  # a clone, not the root itself
        assert pop.teams[t].birth == 2
        assert any(pop.teams[t].programs == pop.teams[r].programs for r in roots)


def test_crossover_keeps_parent_order():
    config = small_config(p_crossover=1.0, p_delete=0.0, p_add=0.0, p_reorder=0.0, p_new=0.0)
    rng = np.random.default_rng(2)
    pop = init_population(config, rng)
    a, b = pop.roots()[:2]
    varier = Varier(pop, config, rng, 2)
    for _ in range(20):
        child = pop.teams[varier.child(a, b)].programs
        for parent in (pop.teams[a].programs, pop.teams[b].programs):
            from_parent = [p for p in child if p in parent]
            assert from_parent == [p for p in parent if p in from_parent]


def test_mutate_code_is_a_valid_copy():
    config = small_config()
    rng = np.random.default_rng(3)
    pop = init_population(config, rng)
    for prog in list(pop.programs.values())[:40]:
        original = prog.instructions.copy()
        new = mutate_code(prog.instructions, config.program, pop.layout, rng)
        assert valid_instructions(new, pop.layout) is None
        assert np.array_equal(prog.instructions, original)
