"""Exported C equals the engine bit for bit over full episodes of every task."""

import re

import numpy as np
import pytest
from export_cases import (
    ALL_TASKS,
    SEEDS,
    accumulator_graph,
    assert_same,
    random_cases,
    random_observations,
    sequence_stream,
)

from mtpg.engine.random_populations import tangled_population
from mtpg.export.c import header_text, source_text, write_c
from mtpg.export.common import prepare
from mtpg.export.harness import Stream, engine_stream

RANDOM = random_cases()


def check_both_builds(c_runner, pop, root, stream, no_memory):
    """The shipped build (-O2) and the tracing build both match the engine."""
    assert_same(stream, c_runner(pop, root, stream, no_memory), teams=False)
    assert_same(stream, c_runner(pop, root, stream, no_memory, trace=True))


@pytest.mark.parametrize("no_memory", [False, True], ids=["memory", "no-memory"])
@pytest.mark.parametrize("case", RANDOM, ids=[c[0] for c in RANDOM])
def test_random_graphs_play_every_task_like_the_engine(c_runner, case, no_memory):
    _, pop, root = case
    stream = engine_stream(pop, root, ALL_TASKS, SEEDS, no_memory)
    assert stream.tasks == ALL_TASKS and stream.episodes == len(ALL_TASKS)
    check_both_builds(c_runner, pop, root, stream, no_memory)


@pytest.mark.parametrize("no_memory", [False, True], ids=["memory", "no-memory"])
def test_evolved_graphs_play_every_task_like_the_engine(c_runner, evolved, no_memory):
    _, cases = evolved
    for _, pop, root, _ in cases:
        stream = engine_stream(pop, root, ALL_TASKS, SEEDS, no_memory)
        check_both_builds(c_runner, pop, root, stream, no_memory)


def test_evolved_cases_cover_hierarchy_and_shared_banks(evolved):
    _, cases = evolved
    graphs = [prepare(pop, root, no_memory=False) for _, pop, root, _ in cases]
    assert any(len(g.teams) > 1 for g in graphs), "no multi-team champion"
    assert any(not p.is_atomic for g in graphs for p in g.programs), "no team pointer"
    assert any(len(g.bank_ids) < len(g.programs) for g in graphs), "no shared memory bank"


@pytest.mark.parametrize("no_memory", [False, True], ids=["memory", "no-memory"])
def test_extreme_observations_match_the_engine(c_runner, no_memory):
    for k, (_, pop, root) in enumerate(RANDOM[:3]):
        stream = sequence_stream(pop, root, 400, seed=k, no_memory=no_memory)
        assert_same(stream, c_runner(pop, root, stream, no_memory, opt="-O0"), teams=False)
        assert_same(stream, c_runner(pop, root, stream, no_memory, trace=True))


def test_memory_persists_across_calls_until_reset(c_runner):
    pop, root = accumulator_graph()
    obs = random_observations(40, seed=9)
    two_episodes = sequence_stream(pop, root, 0, 0, obs=obs)
    two_episodes = Stream(
        np.concatenate([obs, obs]),
        np.r_[two_episodes.starts, two_episodes.starts],
        np.concatenate([two_episodes.actions, two_episodes.actions]),
        two_episodes.teams * 2,
        [-1, -1],
    )
    one_episode = sequence_stream(pop, root, 0, 0, obs=np.concatenate([obs, obs]))
    # the graph's second pass differs when memory carries over: the case tests something
    assert not np.array_equal(one_episode.actions, two_episodes.actions)
    assert_same(two_episodes, c_runner(pop, root, two_episodes), teams=False)
    assert_same(one_episode, c_runner(pop, root, one_episode), teams=False)


def test_generated_code_depends_on_math_h_only_and_drops_introns_and_unreachable_teams(tmp_path):
    rng = np.random.default_rng(2)
    pop = tangled_population(rng, 10, 30, 20, 4, 0.3)
    root = next(t for t in pop.teams if len(pop.reachable(t)) < len(pop.teams))
    graph = prepare(pop, root, no_memory=False, source="g.json", meta={"generation": 7})
    header, source = write_c(graph, tmp_path, "champ")
    c, h = source.read_text(), header.read_text()
    again = write_c(graph, tmp_path / "again", "champ")
    assert [p.read_text() for p in again] == [h, c]  # deterministic output
    assert re.findall(r"#include\s*(\S+)", c) == ["<math.h>", '"champ.h"']
    assert "#include" not in h
    reachable = pop.reachable(root)
    assert f"#define MTPG_N_TEAMS {len(reachable)}" in h
    ids = re.search(r"mtpg_team_ids\[MTPG_N_TEAMS\] = \{(.*)\}", c).group(1)
    assert [int(x) for x in ids.split(",")] == reachable
    # introns are gone; of the effective instructions, those evaluated at export time are
    # gone too unless they write memory (then they are stores of literals)
    statements = re.findall(r"^    [rm]\[\d+\] = ", c, flags=re.M)
    assert len(statements) == graph.n_statements
    stores = re.findall(r"^    m\[\d+\] = [-(\d]", c, flags=re.M)
    assert graph.n_statements == graph.n_instructions - graph.n_folded + len(stores)
    assert graph.n_introns > 0 and graph.n_folded > 0
    total = sum(len(pop.programs[p.id].instructions) for p in graph.programs)
    assert graph.n_instructions + graph.n_introns == total


def test_header_states_api_provenance_and_bit_identity_conditions():
    _, pop, root = RANDOM[0]
    meta = {"generation": 42, "seed": 5, "no_memory": True, "tasks": ["CartPole"]}
    graph = prepare(pop, root, no_memory=True, source="runs/x/champ.json", meta=meta)
    h = header_text(graph, "champ")
    for needle in (
        "void mtpg_reset(void);",
        "void mtpg_act(const double obs[2], int *a_d, double *a_c);",
        "-ffp-contract=off",
        "runs/x/champ.json",
        f"root team:  {root}",
        "generation: 42",
        "without memory",
        "banks zeroed before every program",
    ):
        assert needle in h, needle
    assert "mtpg_zero_bank(m); /* memory off" in source_text(graph, "champ")
    on = source_text(prepare(pop, root, no_memory=False), "champ")
    assert "mtpg_zero_bank(m)" not in on


@pytest.mark.slow
@pytest.mark.parametrize("seed", range(20))
def test_many_random_graphs_match_the_engine(c_runner, py_runner, seed):
    rng = np.random.default_rng(1000 + seed)
    pop = tangled_population(rng, 10, 40, 30, 5, [0.3, 0.6, 0.9][seed % 3])
    root = int(rng.choice(list(pop.teams)))
    for no_memory in (False, True):
        stream = engine_stream(pop, root, ALL_TASKS, SEEDS, no_memory)
        assert_same(stream, c_runner(pop, root, stream, no_memory, trace=True))
        assert_same(stream, py_runner(pop, root, stream, no_memory))
        extreme = sequence_stream(pop, root, 300, seed, no_memory)
        assert_same(extreme, c_runner(pop, root, extreme, no_memory), teams=False)
