"""Population dicts and graph files: exact round trips, identical decisions, clear errors."""

import copy
import json

import numpy as np
import pytest

from mtpg.engine.oracle import ReferenceAgent
from mtpg.engine.random_populations import layered_graphs, tangled_population
from mtpg.io import (
    FormatError,
    graph_from_dict,
    graph_to_dict,
    load_graph,
    population_from_dict,
    population_to_dict,
    save_graph,
)
from mtpg.io._readable import dumps_readable
from mtpg.model import RegisterLayout
from mtpg.model.graph import check_invariants


def assert_same_population(a, b):
    assert a.layout == b.layout
    assert (a.next_program_id, a.next_team_id, a.next_bank_id) == (
        b.next_program_id,
        b.next_team_id,
        b.next_bank_id,
    )
    assert list(a.programs) == list(b.programs)
    assert list(a.teams) == list(b.teams)
    for pid, p in a.programs.items():
        q = b.programs[pid]
        assert (p.id, p.action, p.bank) == (q.id, q.action, q.bank)
        assert q.instructions.dtype == np.int32
        np.testing.assert_array_equal(p.instructions, q.instructions)
    for tid, t in a.teams.items():
        u = b.teams[tid]
        assert (t.id, t.programs, t.birth) == (u.id, u.programs, u.birth)


def tangled(seed, **kw):
    rng = np.random.default_rng(seed)
    pop = tangled_population(rng, n_teams=12, n_programs=30, max_len=8, n_banks=5, **kw)
    for k, team in enumerate(pop.teams.values()):
        team.birth = k * 3
    return pop


@pytest.mark.parametrize("seed", range(5))
def test_population_round_trip_tangled(seed):
    pop = tangled(seed, layout=RegisterLayout(4, 3, 2) if seed == 4 else None)
    d = population_to_dict(pop)
    # survives JSON text exactly
    back = population_from_dict(json.loads(json.dumps(d)))
    assert_same_population(pop, back)
    assert population_to_dict(back) == d


def test_population_round_trip_keeps_dict_order():
    pop, _ = layered_graphs(np.random.default_rng(1), n_graphs=4)
    # shuffle insertion order: ids no longer ascending
    for attr in ("teams", "programs"):
        items = list(getattr(pop, attr).items())
        np.random.default_rng(2).shuffle(items)
        setattr(pop, attr, dict(items))
    pop.next_bank_id += 7  # counters are kept as they are, not recomputed
    back = population_from_dict(json.loads(json.dumps(population_to_dict(pop))))
    assert_same_population(pop, back)


def corrupt(d, edit):
    d = copy.deepcopy(d)
    edit(d)
    return d


POP_ERRORS = [
    (lambda d: d.update(format="mtpg-graph"), "format"),
    (lambda d: d.update(version=3), "unsupported version 3"),
    (lambda d: d.pop("next_team_id"), "missing key 'next_team_id'"),
    (lambda d: d["layout"].update(n_memory=0), "layout.n_memory"),
    (lambda d: d["programs"][0].update(id="3"), "must be an integer"),
    (lambda d: d["programs"][0].update(instructions=[]), "no instructions"),
    (lambda d: d["programs"][0].update(instructions=[[0, 1, 2]]), "[op, dst, src1, src2]"),
    (lambda d: d["programs"][0].update(instructions=[[0, 1, 2, 3.5]]), "integers"),
    (lambda d: d["programs"][0]["instructions"][0].__setitem__(0, 16), "op out of range"),
    (lambda d: d["programs"][0]["instructions"][0].__setitem__(1, 40), "dst out of range"),
    (lambda d: d["programs"][0].update(action=-4), "action must be >= -3"),
    (lambda d: d["programs"][0].update(bank=10**6), "bank"),
    (lambda d: d["programs"].append(d["programs"][0]), "appears twice"),
    (lambda d: d["teams"][0].update(programs=[10**6, 0]), "missing program"),
    (lambda d: d["teams"][0].update(birth=None), "birth must be an integer"),
    (lambda d: d.update(next_program_id=0), "outside counter"),
]


@pytest.mark.parametrize(("edit", "needle"), POP_ERRORS)
def test_population_from_dict_rejects(edit, needle):
    d = population_to_dict(tangled(0))
    with pytest.raises(FormatError) as info:
        population_from_dict(corrupt(d, edit))
    assert needle in str(info.value)


def decisions(pop, root, obs):
    agent = ReferenceAgent(pop, root)
    out = []
    for o in obs:
        dec = agent.act(o)
        out.append((dec.action, dec.continuous, dec.teams, dec.bids))
    return out


@pytest.mark.parametrize("seed", range(3))
def test_graph_file_gives_identical_decisions(tmp_path, seed):
    rng = np.random.default_rng(seed)
    pop, roots = layered_graphs(rng, n_graphs=3, teams=3, programs=6, instructions=12)
    tangled_pop = tangled(seed)
    obs = rng.uniform(-1, 1, size=(25, 2))
    cases = [(pop, roots[1]), *((tangled_pop, r) for r in tangled_pop.roots()[:2])]
    for k, (source, root) in enumerate(cases):
        path = tmp_path / f"g{k}.json"
        save_graph(path, source, root, meta={"score": 1.5, "tasks": ["CartPole"]})
        back, back_root, meta = load_graph(path)
        check_invariants(back)
        assert back_root == root
        assert meta == {"score": 1.5, "tasks": ["CartPole"]}
        assert set(back.teams) == set(source.reachable(root))
        assert decisions(back, back_root, obs) == decisions(source, root, obs)
        # the graph dict survives a second round trip unchanged
        assert graph_to_dict(back, back_root, meta) == graph_to_dict(source, root, meta)


def test_graph_dict_is_readable():
    pop, roots = layered_graphs(np.random.default_rng(0), n_graphs=2, teams=2, programs=3)
    d = graph_to_dict(pop, roots[1])
    assert d["format"] == "mtpg-graph" and d["version"] == 1 and d["root"] == roots[1]
    assert [t["id"] for t in d["teams"]] == pop.reachable(roots[1])
    prog = d["programs"][0]
    assert prog["action"] in ({"atomic": 0}, {"atomic": 1}, {"atomic": 2})
    assert len(prog["code"]) == len(prog["instructions"]) and "<-" in prog["code"][0]
    text = dumps_readable(d)
    assert json.loads(text) == d
    assert "[0, " in text or any(f"\n        [{op}, " in text for op in range(16))
    # the rebuilt population's counters lie past its ids
    back, root = graph_from_dict(d)
    assert back.next_team_id == max(back.teams) + 1
    assert back.next_program_id == max(back.programs) + 1
    assert back.next_bank_id == max(p.bank for p in back.programs.values()) + 1


def test_graph_to_dict_rejects_unknown_root():
    pop, _ = layered_graphs(np.random.default_rng(0), n_graphs=1)
    with pytest.raises(ValueError, match="root team 99"):
        graph_to_dict(pop, 99)


def graph_with_pointer():
    pop, roots = layered_graphs(np.random.default_rng(3), n_graphs=1, teams=3, p_pointer=1.0)
    return graph_to_dict(pop, roots[0])


def first_pointer(d):
    return next(p for p in d["programs"] if "team" in p["action"])


GRAPH_ERRORS = [
    (lambda d: d.update(format="mtpg-checkpoint"), "format is 'mtpg-checkpoint'"),
    (lambda d: d.update(version=7), "unsupported version 7"),
    (lambda d: d.pop("programs"), "missing key 'programs'"),
    (lambda d: d.update(meta=[]), "meta must be a JSON object"),
    (lambda d: d.update(root=12345), "root 12345"),
    (lambda d: first_pointer(d).update(action={"team": 777}), "team 777, which is missing"),
    (lambda d: first_pointer(d).update(action={"atomic": 3}), "atomic action must be < 3"),
    (lambda d: first_pointer(d).update(action={"jump": 1}), '{"atomic": a}'),
    (lambda d: d["teams"][0]["programs"].append(999), "program 999"),
    (lambda d: d["programs"][0]["instructions"][0].__setitem__(3, -1), "src2 out of range"),
    (lambda d: d["programs"][0].update(instructions="x"), "must be a list"),
    (lambda d: d["teams"][0].update(programs=d["teams"][0]["programs"][:1]), "has 1 programs"),
]


@pytest.mark.parametrize(("edit", "needle"), GRAPH_ERRORS)
def test_graph_from_dict_rejects(edit, needle):
    with pytest.raises(FormatError) as info:
        graph_from_dict(corrupt(graph_with_pointer(), edit))
    assert needle in str(info.value)


def test_load_graph_errors_name_the_file(tmp_path):
    missing = tmp_path / "nope.json"
    with pytest.raises(FormatError, match="nope.json"):
        load_graph(missing)
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(FormatError, match=r"bad\.json: not valid JSON"):
        load_graph(bad)
    wrong = tmp_path / "wrong.json"
    wrong.write_text(json.dumps({**graph_with_pointer(), "version": 9}))
    with pytest.raises(FormatError, match=r"wrong\.json: graph: unsupported version 9"):
        load_graph(wrong)


def test_save_graph_rejects_non_json_meta_and_leaves_no_temp(tmp_path):
    pop, roots = layered_graphs(np.random.default_rng(0), n_graphs=1)
    with pytest.raises(FormatError, match="g.json"):
        save_graph(tmp_path / "g.json", pop, roots[0], meta={"x": np.zeros(2)})
    with pytest.raises(FormatError, match="g.json"):
        save_graph(tmp_path / "g.json", pop, roots[0], meta={"x": float("nan")})
    assert list(tmp_path.iterdir()) == []
    save_graph(tmp_path / "g.json", pop, roots[0])
    assert [p.name for p in tmp_path.iterdir()] == ["g.json"]
