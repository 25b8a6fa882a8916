"""Memory banks as a coevolved population: deletion, top-up, pointer mutation, persistence."""

import csv
import json
from collections import Counter

import numpy as np
import pytest

from mtpg.config import build_config
from mtpg.evolve.persist import state_from_payload, state_to_payload
from mtpg.evolve.session import Session
from mtpg.evolve.trainer import Trainer
from mtpg.evolve.variation import Varier, init_population
from mtpg.io.serialize import (
    graph_from_dict,
    graph_to_dict,
    population_from_dict,
    population_to_dict,
)
from mtpg.model.graph import InvariantError, Population, atomic, check_invariants

MULTI = [
    "team.root_size=24",
    "team.n_elite=3",
    "team.init_team_size=3",
    "team.p_atomic=0.7",
    "team.p_memory=0.5",
    "evaluation.train_episodes=1",
    'evaluation.tasks=["CartPole", "MountainCar", "Pendulum"]',
]


def config(*extra, generations=8):
    return build_config("paper", overrides=[*MULTI, f"generations={generations}", *extra])


def two_team_population():
    pop = Population()
    code = np.zeros((1, 4), dtype=np.int32)
    for _ in range(2):
        a = pop.add_program(code, atomic(0), pop.new_bank()).id
        b = pop.add_program(code, atomic(1), pop.new_bank()).id
        pop.add_team([a, b])
    return pop


def test_prune_deletes_banks_no_program_points_to_and_top_up_adds_fresh_ones():
    pop = two_team_population()
    assert pop.banks() == [0, 1, 2, 3]
    del pop.teams[1]
    pop.prune()
    assert pop.banks() == [0, 1] and set(pop.programs) == {0, 1}
    assert pop.top_up_banks(5) == [4, 5, 6]  # fresh ids: never reused
    assert pop.banks() == [0, 1, 4, 5, 6] and pop.banks_in_use() == {0, 1}
    assert pop.top_up_banks(3) == []
    check_invariants(pop)  # banks without programs are legal
    pop.prune()
    assert pop.banks() == [0, 1]


def test_invariants_raise_a_named_error():
    pop = two_team_population()
    pop.memory_banks.discard(3)
    with pytest.raises(InvariantError, match="program 3 points to missing bank 3"):
        check_invariants(pop)
    pop = two_team_population()
    pop.teams[0].programs = [0]
    with pytest.raises(InvariantError, match="team 0 has 1 programs"):
        check_invariants(pop)


def test_every_generation_ends_with_at_least_one_bank_per_team():
    trainer = Trainer(config())
    shared = False
    while not trainer.done:
        row = trainer.run_generation()
        pop = trainer.state.population
        check_invariants(pop)
        assert len(pop.memory_banks) >= len(pop.teams)
        # top-up only: no more banks than needed beyond those in use
        assert len(pop.memory_banks) == max(len(pop.teams), len(pop.banks_in_use()))
        assert row["banks"] == len(pop.memory_banks)
        assert row["banks_in_use"] == len(pop.banks_in_use())
        assert row["programs_per_bank"] == len(pop.programs) / len(pop.banks_in_use())
        shared |= row["programs_per_bank"] > 1
    assert shared


def test_pointer_mutation_draws_from_all_other_banks_fresh_ones_included():
    cfg = build_config(
        "paper",
        overrides=["team.root_size=4", "team.init_team_size=2", "team.p_memory=1.0"],
    )
    rng = np.random.default_rng(0)
    pop = init_population(cfg, rng)
    fresh = set(pop.top_up_banks(20))  # 8 banks in use + 12 fresh ones
    varier = Varier(pop, cfg, rng, 2)
    draws = Counter()
    for _ in range(200):
        parent = pop.roots()[0]
        before = set(pop.programs)
        varier.child(parent, parent)
        draws.update(pop.programs[pid].bank for pid in set(pop.programs) - before)
    assert fresh & set(draws), "a pointer mutation never chose a fresh bank"
    # uniform over the 20 banks: each other bank is drawn
    assert len(draws) >= 18


def test_pointer_mutation_never_keeps_the_current_bank():
    cfg = build_config("paper", overrides=["team.root_size=2", "team.p_memory=1.0"])
    rng = np.random.default_rng(1)
    pop = init_population(cfg, rng)
    pop.top_up_banks(30)
    varier = Varier(pop, cfg, rng, 2)
    counts = Counter(varier._other_bank(3) for _ in range(3000))
    assert 3 not in counts and set(counts) == set(pop.banks()) - {3}
    assert max(counts.values()) < 2 * min(counts.values())  # roughly uniform


def test_checkpoint_payload_round_trips_the_bank_population():
    trainer = Trainer(config(generations=3))
    while not trainer.done:
        trainer.run_generation()
    pop = trainer.state.population
    pop.top_up_banks(len(pop.memory_banks) + 5)  # make sure fresh banks are present
    assert pop.memory_banks - pop.banks_in_use()
    payload = json.loads(json.dumps(state_to_payload(trainer.state)))
    state, _ = state_from_payload(payload)
    assert state.population.memory_banks == pop.memory_banks
    assert state.population.next_bank_id == pop.next_bank_id
    assert population_to_dict(state.population) == population_to_dict(pop)
    # and the restored run continues exactly as the original
    original = Trainer(config(generations=5), trainer.state)
    restored = Trainer(config(generations=5), state)
    for _ in range(2):
        a, b = original.run_generation(), restored.run_generation()
        assert (a["banks"], a["banks_in_use"]) == (b["banks"], b["banks_in_use"])
    assert population_to_dict(original.state.population) == population_to_dict(
        restored.state.population
    )


def test_version_1_populations_are_still_read():
    pop = two_team_population()
    pop.top_up_banks(6)
    d = population_to_dict(pop)
    assert d["version"] == 2 and d["banks"] == [0, 1, 2, 3, 4, 5]
    old = {k: v for k, v in d.items() if k != "banks"} | {"version": 1}
    back = population_from_dict(old)
    assert back.memory_banks == {0, 1, 2, 3}  # v1 knew only banks in use


def test_graph_files_round_trip_the_banks_of_the_graph():
    trainer = Trainer(config(generations=4))
    while not trainer.done:
        trainer.run_generation()
    pop = trainer.state.population
    for root in pop.roots():
        back, back_root = graph_from_dict(json.loads(json.dumps(graph_to_dict(pop, root))))
        used = {pop.programs[p].bank for t in pop.reachable(root) for p in pop.teams[t].programs}
        assert back.memory_banks == used
        assert {pid: p.bank for pid, p in back.programs.items()} == {
            pid: pop.programs[pid].bank for pid in back.programs
        }
        check_invariants(back)


def test_metrics_csv_has_bank_columns(tmp_path):
    Session(tmp_path / "run", config(generations=3)).run_all()
    with open(tmp_path / "run" / "metrics.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 3
    for row in rows:
        banks, in_use = int(row["banks"]), int(row["banks_in_use"])
        assert banks >= int(row["teams"]) and 1 <= in_use <= banks
        assert float(row["programs_per_bank"]) == pytest.approx(int(row["programs"]) / in_use)


def test_paper_preset_is_the_published_run():
    cfg = build_config("paper")
    assert cfg.team.root_size == 1000
    assert cfg.elites_per_subset == 25
    assert cfg.evaluation.n_subsets * cfg.elites_per_subset == 1575  # new roots per generation
    table3 = build_config("paper", overrides=["team.n_elite=50"])
    assert table3.evaluation.n_subsets * table3.elites_per_subset == 3150


@pytest.mark.parametrize(
    ("banks", "needle"),
    [
        ([0, 1, 2], "program 3 points to missing bank 3"),
        ([0, 1, 2, 3, 3], "population.banks repeats a bank"),
        ([0, 1, 2, 3, 99], "bank id 99 outside counter"),
        ([0, 1, "2", 3], "population.banks[2] must be an integer"),
    ],
)
def test_population_loader_checks_the_bank_list(banks, needle):
    from mtpg.io.serialize import FormatError

    d = population_to_dict(two_team_population())
    d["banks"] = banks
    with pytest.raises(FormatError, match=needle.replace("[", r"\[").replace("]", r"\]")):
        population_from_dict(d)
