"""Variation on hand-made programs and teams: each trial of Table 3, one at a time.

Every test switches on one variation operator (all other probabilities 0) and checks
what it must do against values worked out by hand: the instruction stream of the pool,
the redraw of a mutated field, uniform insertion and swap positions, the decaying
deletion and addition trials, the team-size bound, reordering, memory and action
pointers. Frequencies are checked over a few hundred draws from fixed seeds with wide
margins (more than five standard deviations).
"""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest

from mtpg.config import ProgramConfig, build_config
from mtpg.evolve import variation as variation_module
from mtpg.evolve.variation import POOL_BLOCK, InstructionPool, Varier, mutate_code
from mtpg.model.graph import Population, atomic
from mtpg.model.instructions import RegisterLayout, random_instructions

L = RegisterLayout()
OFF = {
    "team.p_crossover": 0.0,
    "team.p_delete": 0.0,
    "team.p_add": 0.0,
    "team.p_reorder": 0.0,
    "team.p_new": 0.0,
    "team.p_action": 0.0,
    "team.p_memory": 0.0,
}


def team_config(**changes):
    """The paper's configuration with every team-level trial off except ``changes``."""
    settings = dict(OFF)
    settings.update({k.replace("__", "."): v for k, v in changes.items()})
    return build_config("paper", overrides=[f"{k}={v}" for k, v in settings.items()])


def program_config(**changes) -> ProgramConfig:
    base = {"p_delete": 0.0, "p_add": 0.0, "p_mutate": 0.0, "p_swap": 0.0}
    return ProgramConfig(**{**base, **changes})


def rows(n: int, start: int = 90) -> np.ndarray:
    """``n`` distinct marker instructions (values no pool row repeats in all columns)."""
    return np.array([[start + i] * 4 for i in range(n)], dtype=np.int32)


# --- the instruction pool -------------------------------------------------------------------


def test_pool_hands_out_one_stream_in_order_drawing_blocks_only_when_needed() -> None:
    pool, twin = InstructionPool(np.random.default_rng(5), L), np.random.default_rng(5)
    first = random_instructions(twin, L, POOL_BLOCK)
    x = pool.take(1000)
    assert x.dtype == np.int32 and x.shape == (1000, 4)
    assert np.array_equal(x, first[:1000])
    assert np.array_equal(pool.take(24), first[1000:])  # exactly the rest: no new block
    assert pool.rng.random() == twin.random()
    second = random_instructions(twin, L, POOL_BLOCK)
    assert np.array_equal(pool.take(10), second[:10])
    third = random_instructions(twin, L, 3000 - (POOL_BLOCK - 10))  # only what is missing
    big = pool.take(3000)
    assert np.array_equal(big, np.concatenate([second[10:], third]))
    assert pool.rng.random() == twin.random()


# --- mutate_code: one operator at a time ----------------------------------------------------


def known_pool(block: np.ndarray, seed: int = 0) -> InstructionPool:
    pool = InstructionPool(np.random.default_rng(seed), L)
    pool.block, pool.at = block.astype(np.int32), 0
    return pool


def test_a_mutated_field_takes_the_first_pool_value_that_differs() -> None:
    code = np.array([[3, 1, 2, 4]], dtype=np.int32)
    for seed in range(8):
        twin = np.random.default_rng(seed)
        twin.random(), twin.random(), twin.random()  # delete, add, mutate trials
        assert int(twin.integers(0, 1)) == 0  # the instruction
        column = int(twin.integers(0, 4))
        block = np.repeat(code, 5, axis=0)
        block[2, column] += 1  # the third draw is the first that differs
        pool = known_pool(block)
        out = mutate_code(code, program_config(p_mutate=1.0), L, np.random.default_rng(seed), pool)
        want = code.copy()
        want[0, column] += 1
        assert np.array_equal(out, want) and pool.at == 3, seed
        assert np.array_equal(code, [[3, 1, 2, 4]])  # the input is never changed


def test_a_field_that_never_differs_is_left_after_sixteen_draws() -> None:
    code = np.array([[3, 1, 2, 4]], dtype=np.int32)
    pool = known_pool(np.repeat(code, 40, axis=0))
    out = mutate_code(code, program_config(p_mutate=1.0), L, np.random.default_rng(0), pool)
    assert np.array_equal(out, code) and pool.at == 16


def test_every_column_is_mutated_about_equally_often() -> None:
    rng = np.random.default_rng(1)
    code = random_instructions(rng, L, 6)
    counts = Counter()
    for _ in range(800):
        out = mutate_code(code, program_config(p_mutate=1.0), L, rng)
        changed = np.argwhere(out != code)
        assert len(changed) == 1  # one field of one instruction
        counts[int(changed[0, 1])] += 1
    assert sorted(counts) == [0, 1, 2, 3]
    assert all(0.17 < c / 800 < 0.33 for c in counts.values()), counts


def test_an_instruction_is_inserted_at_a_uniform_position() -> None:
    rng = np.random.default_rng(2)
    code = rows(2)
    where = Counter()
    for _ in range(900):
        out = mutate_code(code, program_config(p_add=1.0), L, rng)
        assert len(out) == 3
        rest = [k for k in range(3) if out[k, 0] < 90]
        assert len(rest) == 1
        k = rest[0]
        assert np.array_equal(np.delete(out, k, axis=0), code)
        where[k] += 1
    assert all(0.25 < where[k] / 900 < 0.42 for k in range(3)), where


def test_a_swap_exchanges_two_distinct_instructions_chosen_uniformly() -> None:
    rng = np.random.default_rng(3)
    two = rows(2)
    for _ in range(20):
        assert np.array_equal(mutate_code(two, program_config(p_swap=1.0), L, rng), two[::-1])
    code = rows(4)
    pairs = Counter()
    for _ in range(1200):
        out = mutate_code(code, program_config(p_swap=1.0), L, rng)
        moved = tuple(np.flatnonzero(out[:, 0] != code[:, 0]).tolist())
        assert len(moved) == 2
        i, j = moved
        assert out[i, 0] == code[j, 0] and out[j, 0] == code[i, 0]
        pairs[moved] += 1
    assert len(pairs) == 6
    assert all(0.11 < c / 1200 < 0.23 for c in pairs.values()), pairs


# --- Varier: team-level trials ---------------------------------------------------------------


def population(n_programs: int, parent: list[int], pointers: dict[int, int] | None = None):
    """Programs 0..n-1 (atomic unless in ``pointers``: program -> team) and teams.

    Team 0 (born in generation 0) holds programs 0 and 1; the parent (born in generation
    1) holds ``parent``.
    """
    pop = Population(layout=L)
    code = np.array([[0, 0, 1, 2]], dtype=np.int32)
    for pid in range(n_programs):
        prog = pop.add_program(code, atomic(pid % 3), pop.new_bank())
        assert prog.id == pid
    older = pop.add_team([0, 1], birth=0).id
    root = pop.add_team(parent, birth=1).id
    for pid, team in (pointers or {}).items():
        pop.programs[pid].action = team
    return pop, older, root


def kids(pop, root, cfg, n, seed=0):
    varier = Varier(pop, cfg, np.random.default_rng(seed), 2)
    return [pop.teams[varier.child(root, root)].programs for _ in range(n)]


def test_reordering_moves_one_program_to_any_position() -> None:
    pop, _, root = population(8, [5, 6, 7])
    seen = {tuple(k) for k in kids(pop, root, team_config(team__p_reorder=1.0), 200)}
    assert {(7, 5, 6), (6, 7, 5), (5, 7, 6), (6, 5, 7)} <= seen
    pop, _, root = population(8, [5, 6])
    seen = {tuple(k) for k in kids(pop, root, team_config(team__p_reorder=1.0), 60)}
    assert (6, 5) in seen


def test_a_child_equal_to_its_parent_gets_a_uniformly_chosen_program_mutated() -> None:
    parent = [3, 4, 5, 6, 7]
    pop, _, root = population(8, parent)
    where = Counter()
    for kid in kids(pop, root, team_config(), 500):
        changed = [k for k in range(5) if kid[k] != parent[k]]
        assert len(changed) == 1
        where[changed[0]] += 1
    assert all(0.12 < where[k] / 500 < 0.28 for k in range(5)), where


def test_deletion_goes_down_to_two_programs_and_keeps_an_atomic_one() -> None:
    pop, _, root = population(8, [2, 3, 4])
    for kid in kids(pop, root, team_config(team__p_delete=1.0), 50):
        assert len(kid) == 2
    # two atomic programs and one pointer: any of the three may go
    pop, older, root = population(8, [2, 3, 4], pointers={4: 0})
    left = Counter()
    for kid in kids(pop, root, team_config(team__p_delete=1.0), 600):
        assert len(kid) == 2 and any(pop.programs[p].action < 0 for p in kid)
        left[4 in kid] += 1
    assert 0.55 < left[True] / 600 < 0.78, left


def test_deletion_trials_decay_geometrically() -> None:
    parent = list(range(2, 14))
    pop, _, root = population(14, parent)
    deleted = [12 - len(k) for k in kids(pop, root, team_config(team__p_delete=0.5), 800)]
    # P(>=1) = 1/2, P(>=2) = 1/2 * 1/4, P(>=3) = 1/8 * 1/8, ...: mean about 0.64
    assert 0.54 < np.mean(deleted) < 0.74, np.mean(deleted)


def test_additions_respect_the_team_size_bound_and_land_anywhere() -> None:
    pop, _, root = population(10, [5, 6])
    cfg = team_config(team__p_add=1.0, team__max_team_size=3, team__init_team_size=2)
    where, added = Counter(), Counter()
    for kid in kids(pop, root, cfg, 900):
        assert len(kid) == 3
        (new,) = set(kid) - {5, 6}
        where[kid.index(new)] += 1
        added[new] += 1
    assert all(0.25 < where[k] / 900 < 0.42 for k in range(3)), where
    assert set(added) == {0, 1, 2, 3, 4, 7, 8, 9}  # drawn from the whole program population


def test_memory_pointers_change_only_when_drawn_and_to_another_bank() -> None:
    parent = [2, 3, 4]
    pop, _, root = population(5, parent)
    for kid in kids(pop, root, team_config(team__p_new=1.0), 30):
        assert [pop.programs[p].bank for p in kid] == [2, 3, 4]
    # two banks in the population: a change always moves to the other one
    pop, _, root = population(5, parent)
    for pid in pop.programs:
        pop.programs[pid].bank = pid % 2
    pop.memory_banks = {0, 1}
    for kid in kids(pop, root, team_config(team__p_new=1.0, team__p_memory=1.0), 30):
        assert [pop.programs[p].bank for p in kid] == [1, 0, 1]
    # a single bank: nothing to change to
    pop, _, root = population(5, parent)
    for pid in pop.programs:
        pop.programs[pid].bank = 0
    pop.memory_banks = {0}
    for kid in kids(pop, root, team_config(team__p_new=1.0, team__p_memory=1.0), 10):
        assert [pop.programs[p].bank for p in kid] == [0, 0, 0]


def test_a_pointer_to_team_zero_is_not_taken_for_the_last_atomic_program() -> None:
    # the parent holds one atomic program and one pointing to team 0 (action 0)
    pop, older, root = population(5, [2, 3], pointers={3: 0})
    assert older == 0
    cfg = team_config(team__p_new=1.0, team__p_action=1.0, team__p_atomic=0.0)
    targets = Counter()
    for first, second in kids(pop, root, cfg, 200):
        assert pop.programs[first].action < 0  # the last atomic one stays atomic
        target = pop.programs[second].action
        assert target >= 0  # p_atomic = 0: a team
        targets["team 0" if target == 0 else pop.teams[target].birth] += 1
    # the older teams are team 0 and the parent (a root: pointed to through a clone)
    assert targets["team 0"] > 50 and targets[2] > 50, targets


def test_other_bank_is_uniform_over_the_rest_of_the_bank_population() -> None:
    pop, _, _ = population(5, [2, 3])
    varier = Varier(pop, team_config(), np.random.default_rng(7), 2)
    assert varier.banks == [0, 1, 2, 3, 4]
    got = Counter(varier._other_bank(2) for _ in range(1000))
    assert sorted(got) == [0, 1, 3, 4] and all(180 < c < 320 for c in got.values()), got
    for absent in (-1, 99):  # not a bank of the population: any bank
        got = Counter(varier._other_bank(absent) for _ in range(1000))
        assert sorted(got) == [0, 1, 2, 3, 4] and all(130 < c < 270 for c in got.values())


def test_variation_draws_new_instructions_in_blocks(monkeypatch) -> None:
    calls = []
    real = variation_module.random_instructions

    def counting(rng, layout, n):
        calls.append(n)
        return real(rng, layout, n)

    monkeypatch.setattr(variation_module, "random_instructions", counting)
    pop, _, root = population(8, [2, 3, 4, 5])
    kids(pop, root, team_config(team__p_new=1.0), 40)  # 160 mutated copies
    assert calls == [POOL_BLOCK]


@pytest.mark.parametrize("seed", [0, 1])
def test_metrics_row_from_a_hand_made_result(seed: int) -> None:
    from types import SimpleNamespace

    from mtpg.evolve.columns import metrics_row
    from mtpg.evolve.trainer import Trainer

    cfg = build_config(
        "paper",
        overrides=[
            "team.root_size=6",
            "team.n_elite=2",
            "team.init_team_size=2",
            "evaluation.train_episodes=1",
            'evaluation.tasks=["CartPole", "MountainCar"]',
            f"seed={seed}",
        ],
    )
    trainer = Trainer(cfg)
    trainer.run_generation()
    pop = trainer.state.population
    for prog in pop.programs.values():
        prog.bank = min(pop.memory_banks)  # a single bank in use
    scores = np.array([trainer.state.scores[r] for r in sorted(trainer.state.scores)])
    result = SimpleNamespace(steps=np.array([1]), teams=np.array([3]), instructions=np.array([7]))
    st = trainer.state

    def metrics(new_roots, result, times):
        names = trainer.tasks.names
        return metrics_row(
            st.generation, pop, st.scores, st.champions[-1], names, new_roots, result, {}, times
        )

    row = metrics([1, 2], result, (10.0, 11.0, 11.5, 12.0))
    assert row["programs_per_bank"] == len(pop.programs)
    assert row["decisions"] == 1 and row["new_roots"] == 2
    assert row["teams_per_decision"] == 3.0 and row["instructions_per_decision"] == 7.0
    assert row["decisions_per_s"] == 1 / 0.5
    assert (row["t_variation"], row["t_evaluation"], row["t_selection"]) == (1.0, 0.5, 0.5)
    assert row["t_total"] == 2.0 and row["t_test"] == 0.0
    for k, task in enumerate(("CartPole", "MountainCar")):
        assert row[f"best_{task}"] == scores[:, k].max()
        assert row[f"median_{task}"] == float(np.median(scores[:, k]))
    four = SimpleNamespace(
        steps=np.array([2, 2]), teams=np.array([6, 6]), instructions=np.array([14, 14])
    )
    row = metrics([1, 2], four, (10.0, 11.0, 13.0, 14.0))
    assert row["decisions"] == 4 and row["decisions_per_s"] == 2.0
    assert row["teams_per_decision"] == 3.0 and row["instructions_per_decision"] == 7.0
    none = SimpleNamespace(steps=np.array([0]), teams=np.array([0]), instructions=np.array([0]))
    row = metrics([], none, (0.0, 1.0, 1.0, 1.0))
    assert row["teams_per_decision"] == 0.0 and row["decisions_per_s"] == 0.0
