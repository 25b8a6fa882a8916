"""Population and graph files: every validation rule broken once, with its exact message.

A valid population dict and a valid graph dict (a root team pointing to an inner team)
are changed in one place per case; the refusal must name the part that is wrong (the
key, the list index or the program/team id) and the problem.
"""

from __future__ import annotations

import copy
import json

import numpy as np
import pytest

from mtpg.io.serialize import (
    FormatError,
    graph_from_dict,
    graph_to_dict,
    population_from_dict,
    population_to_dict,
)
from mtpg.model.graph import Population, atomic


def small() -> tuple[Population, int]:
    """Programs 0 and 1 (atomic) in team 0; root team 1 holds program 2 (-> team 0) and 0."""
    pop = Population()
    code = np.array([[0, 0, 1, 2], [1, 8, 2, 3]], dtype=np.int32)
    a = pop.add_program(code, atomic(0), pop.new_bank()).id
    b = pop.add_program(code[:1], atomic(1), pop.new_bank()).id
    inner = pop.add_team([a, b], birth=0).id
    c = pop.add_program(code, inner, pop.new_bank()).id
    root = pop.add_team([c, a], birth=1).id
    return pop, root


def changed(data: dict, path: list, value=None, delete: bool = False) -> dict:
    out = copy.deepcopy(data)
    node = out
    for part in path[:-1]:
        node = node[part]
    if delete:
        del node[path[-1]]
    else:
        node[path[-1]] = value
    return out


POP, ROOT = small()
P = json.loads(json.dumps(population_to_dict(POP)))
G = json.loads(json.dumps(graph_to_dict(POP, ROOT, {"x": 1})))


@pytest.mark.parametrize(
    ("path", "value", "message"),
    [
        (["format"], "x", "population: format is 'x', expected 'mtpg-population'"),
        (["layout"], None, "population is missing key 'layout'"),
        (["next_program_id"], None, "population is missing key 'next_program_id'"),
        (["next_team_id"], -1, "population.next_team_id must be >= 0, got -1"),
        (["next_bank_id"], -1, "population.next_bank_id must be >= 0, got -1"),
        (["programs"], None, "population is missing key 'programs'"),
        (["programs"], {}, "population.programs must be a list, got dict"),
        (["programs", 0], 3, "population.programs[0] must be a JSON object, got int"),
        (["programs", 0, "id"], None, "population.programs[0] is missing key 'id'"),
        (["programs", 1, "id"], -1, "population.programs[1].id must be >= 0, got -1"),
        (["programs", 1, "id"], 0, "program 0 appears twice"),
        (["programs", 0, "instructions"], None, "program 0 is missing key 'instructions'"),
        (["programs", 0, "action"], None, "program 0 is missing key 'action'"),
        (["programs", 0, "action"], -4, "program 0 action must be >= -3, got -4"),
        (["programs", 0, "bank"], None, "program 0 is missing key 'bank'"),
        (["programs", 0, "bank"], -1, "program 0 bank must be >= 0, got -1"),
        (["teams"], None, "population is missing key 'teams'"),
        (["teams"], 1, "population.teams must be a list, got int"),
        (["teams", 0], "x", "population.teams[0] must be a JSON object, got str"),
        (["teams", 0, "id"], None, "population.teams[0] is missing key 'id'"),
        (["teams", 1, "id"], -2, "population.teams[1].id must be >= 0, got -2"),
        (["teams", 1, "id"], 0, "team 0 appears twice"),
        (["teams", 0, "programs"], None, "team 0 is missing key 'programs'"),
        (["teams", 0, "programs"], ["a"], "team 0 programs[0] must be an integer, got 'a'"),
        (["teams", 0, "birth"], None, "team 0 is missing key 'birth'"),
        (["teams", 0, "birth"], 1.5, "team 0 birth must be an integer, got 1.5"),
        (["banks"], None, "population is missing key 'banks'"),
        (["banks"], [0, 0, 1, 2], "population.banks repeats a bank"),
    ],
)
def test_population_file_errors_name_the_part(path, value, message) -> None:
    with pytest.raises(FormatError) as err:
        population_from_dict(changed(P, path, value, delete=value is None))
    assert str(err.value) == message


def test_population_must_be_an_object() -> None:
    with pytest.raises(FormatError) as err:
        population_from_dict([])
    assert str(err.value) == "population must be a JSON object, got list"


def test_population_round_trip_keeps_ids_counters_and_banks() -> None:
    pop = population_from_dict(P)
    assert list(pop.programs) == list(POP.programs) and list(pop.teams) == list(POP.teams)
    assert (pop.next_program_id, pop.next_team_id, pop.next_bank_id) == (3, 2, 3)
    assert pop.memory_banks == {0, 1, 2}
    assert [pop.teams[t].birth for t in pop.teams] == [0, 1]


@pytest.mark.parametrize(
    ("path", "value", "message"),
    [
        (["format"], "x", "graph: format is 'x', expected 'mtpg-graph'"),
        (["root"], None, "graph is missing key 'root'"),
        (["layout"], None, "graph is missing key 'layout'"),
        (["meta"], None, "graph is missing key 'meta'"),
        (["teams"], None, "graph is missing key 'teams'"),
        (["programs"], None, "graph is missing key 'programs'"),
        (["meta"], [], "graph meta must be a JSON object, got list"),
        (["programs"], 1, "graph programs must be a list, got int"),
        (["teams"], 1, "graph teams must be a list, got int"),
        (["programs", 0], 1, "graph programs[0] must be a JSON object, got int"),
        (["programs", 0, "id"], None, "graph programs[0] is missing key 'id'"),
        (["programs", 0, "id"], -1, "graph programs[0].id must be >= 0, got -1"),
        (["programs", 1, "id"], 2, "program 2 appears twice"),
        (["programs", 0, "instructions"], None, "program 2 is missing key 'instructions'"),
        (["programs", 0, "action"], None, "program 2 is missing key 'action'"),
        (["programs", 0, "bank"], None, "program 2 is missing key 'bank'"),
        (["programs", 0, "bank"], -1, "program 2 bank must be >= 0, got -1"),
        (["teams", 0], 1, "graph teams[0] must be a JSON object, got int"),
        (["teams", 0, "id"], None, "graph teams[0] is missing key 'id'"),
        (["teams", 0, "id"], -1, "graph teams[0].id must be >= 0, got -1"),
        (["teams", 1, "id"], 1, "team 1 appears twice"),
        (["teams", 0, "programs"], None, "team 1 is missing key 'programs'"),
        (["teams", 0, "programs"], [99], "team 1 holds program 99, which the file does not define"),
        (["teams", 0, "programs"], ["a"], "team 1 programs[0] must be an integer, got 'a'"),
        (["teams", 0, "birth"], None, "team 1 is missing key 'birth'"),
        (["teams", 0, "birth"], "1", "team 1 birth must be an integer, got '1'"),
        (["teams", 1, "id"], 77, "program 2 points to team 0, which is missing"),
        (["root"], -1, "graph root must be >= 0, got -1"),
        (["root"], 55, "graph root 55 is not one of its teams"),
    ],
)
def test_graph_file_errors_name_the_part(path, value, message) -> None:
    with pytest.raises(FormatError) as err:
        graph_from_dict(changed(G, path, value, delete=value is None))
    assert str(err.value) == message


def test_graph_must_be_an_object_and_rebuilds_counters_from_its_ids() -> None:
    with pytest.raises(FormatError) as err:
        graph_from_dict("x")
    assert str(err.value) == "graph must be a JSON object, got str"
    pop, root = graph_from_dict(G)
    assert root == ROOT == 1
    assert (pop.next_team_id, pop.next_program_id, pop.next_bank_id) == (2, 3, 3)
    assert pop.memory_banks == {0, 1, 2}
    assert pop.teams[1].programs == [2, 0] and pop.programs[2].action == 0


@pytest.mark.parametrize(
    ("path", "value", "message"),
    [
        (["layout"], [], "layout must be a JSON object, got list"),
        (["layout", "n_memory"], None, "layout is missing key 'n_memory'"),
        (["layout", "n_registers"], 0, "layout.n_registers must be >= 1, got 0"),
        (["layout", "x"], 1, "layout has unknown keys ['x']"),
        (["layout", "n_obs"], 70000, "layout.n_obs must be <= 65536, got 70000"),
        (["layout", "n_actions"], 0, "layout.n_actions must be >= 1, got 0"),
        (["layout", "n_memory"], 257, "layout.n_memory must be <= 256, got 257"),
        (["programs", 0, "instructions"], 5, "program 0 instructions must be a list, got int"),
        (["programs", 0, "instructions"], [], "program 0 has no instructions"),
        (
            ["programs", 0, "instructions"],
            [[1, 2], [1, 2, 3]],
            "program 0 instructions are not [op, dst, src1, src2] rows",
        ),
        (
            ["programs", 0, "instructions"],
            [[1, 2, 3]],
            "program 0 instructions must be [op, dst, src1, src2] rows",
        ),
        (
            ["programs", 0, "instructions"],
            [[1.5, 2, 3, 4]],
            "program 0 instructions must hold integers, got float64 values",
        ),
        (["programs", 0, "instructions"], [[99, 0, 1, 2]], "program 0: op out of range [0, 16)"),
        (
            ["next_team_id"],
            2**63,
            "population.next_team_id must fit a 64-bit integer, got 9223372036854775808",
        ),
        (
            ["teams", 0, "birth"],
            -(2**63) - 1,
            "team 0 birth must fit a 64-bit integer, got -9223372036854775809",
        ),
        (["version"], 9, "population: unsupported version 9 (this mtpg reads 1 or 2)"),
        (["version"], None, "population is missing key 'version'"),
        (["format"], None, "population is missing key 'format'"),
    ],
)
def test_layout_instruction_and_integer_errors(path, value, message) -> None:
    with pytest.raises(FormatError) as err:
        population_from_dict(changed(P, path, value, delete=value is None))
    assert str(err.value) == message


@pytest.mark.parametrize(
    ("path", "value"),
    [
        (["layout", "n_memory"], 256),  # the largest bank
        (["next_team_id"], 2**63 - 1),
        (["teams", 0, "birth"], -(2**63)),
    ],
)
def test_values_at_the_limits_are_accepted(path, value) -> None:
    data = changed(P, path, value)
    if path[0] == "layout":  # instructions must still fit: shift the memory target
        data["programs"][0]["instructions"] = [[0, 0, 1, 2]]
        data["programs"][1]["instructions"] = [[0, 0, 1, 2]]
        data["programs"][2]["instructions"] = [[0, 0, 1, 2]]
    population_from_dict(data)


@pytest.mark.parametrize(
    ("action", "message"),
    [
        (3, "program 2 action must be a JSON object, got int"),
        ({"x": 1}, 'program 2 action must be {"atomic": a} or {"team": id}, got {\'x\': 1}'),
        ({"atomic": -1}, "program 2 atomic action must be >= 0, got -1"),
        ({"atomic": 3}, "program 2 atomic action must be < 3, got 3"),
        ({"team": -1}, "program 2 team pointer must be >= 0, got -1"),
        ({"team": 0}, None),  # team 0 is in the file
    ],
)
def test_graph_action_pointers(action, message) -> None:
    data = changed(G, ["programs", 0, "action"], action)
    if message is None:
        pop, _ = graph_from_dict(data)
        assert pop.programs[2].action == 0
        return
    with pytest.raises(FormatError) as err:
        graph_from_dict(data)
    assert str(err.value) == message


def test_graph_version() -> None:
    with pytest.raises(FormatError) as err:
        graph_from_dict(changed(G, ["version"], 2))
    assert str(err.value) == "graph: unsupported version 2 (this mtpg reads 1)"


@pytest.mark.parametrize(
    ("path", "value", "message"),
    [
        (["teams", 0, "programs"], 5, "team 0 programs must be a list, got int"),
        (["banks"], 5, "population.banks must be a list, got int"),
        (["teams", 0, "programs"], [0, 7], "population: team 0 holds missing program 7"),
    ],
)
def test_id_lists_and_population_invariants(path, value, message) -> None:
    with pytest.raises(FormatError) as err:
        population_from_dict(changed(P, path, value))
    assert str(err.value) == message


def test_version_1_population_takes_its_banks_from_its_programs() -> None:
    old = changed(P, ["version"], 1)
    del old["banks"]
    assert population_from_dict(old).memory_banks == {0, 1, 2}


def test_graph_instructions_and_graph_to_dict_arguments() -> None:
    with pytest.raises(FormatError) as err:
        graph_from_dict(changed(G, ["programs", 0, "instructions"], 5))
    assert str(err.value) == "program 2 instructions must be a list, got int"
    with pytest.raises(ValueError) as err:
        graph_to_dict(POP, ROOT, [1])
    assert str(err.value) == "meta must be a dict, got list"
    with pytest.raises(ValueError) as err:
        graph_to_dict(POP, 99)
    assert str(err.value) == "root team 99 is not in the population"
