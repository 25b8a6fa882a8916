"""The exported Python module equals the engine bit for bit and needs only ``math``."""

import ast
import importlib.util
import json
import subprocess
import sys

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

from mtpg.envs.specs.contract import TASK_NAMES
from mtpg.export.common import prepare
from mtpg.export.harness import Stream, engine_stream
from mtpg.export.python import module_text, write_python

RANDOM = random_cases()


@pytest.mark.parametrize("no_memory", [False, True], ids=["memory", "no-memory"])
@pytest.mark.parametrize("case", RANDOM, ids=[c[0] for c in RANDOM])
def test_random_graphs_play_every_task_like_the_engine(py_runner, case, no_memory):
    _, pop, root = case
    stream = engine_stream(pop, root, ALL_TASKS, SEEDS, no_memory)
    assert_same(stream, py_runner(pop, root, stream, no_memory))


@pytest.mark.parametrize("no_memory", [False, True], ids=["memory", "no-memory"])
def test_evolved_graphs_play_every_task_like_the_engine(py_runner, evolved, no_memory):
    _, cases = evolved
    for _, pop, root, _ in cases:
        stream = engine_stream(pop, root, ALL_TASKS, SEEDS, no_memory)
        assert_same(stream, py_runner(pop, root, stream, no_memory))


@pytest.mark.parametrize("no_memory", [False, True], ids=["memory", "no-memory"])
def test_extreme_observations_match_the_engine(py_runner, no_memory):
    for k, (_, pop, root) in enumerate(RANDOM[:3]):
        stream = sequence_stream(pop, root, 400, seed=k, no_memory=no_memory)
        assert_same(stream, py_runner(pop, root, stream, no_memory))


def test_module_imports_math_only_and_runs_without_site_packages(tmp_path):
    _, pop, root = RANDOM[0]
    stream = sequence_stream(pop, root, 50, seed=1)
    graph = prepare(pop, root, no_memory=False, source="g.json", meta={"generation": 3})
    path = write_python(graph, tmp_path / "champ.py")
    tree = ast.parse(path.read_text())
    imported = {a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names}
    assert imported == {"math"}
    assert not any(isinstance(n, ast.ImportFrom) for n in ast.walk(tree))
    script = (
        "import json, sys, importlib.util as u; s = u.spec_from_file_location('champ', "
        "sys.argv[1]); champ = u.module_from_spec(s); s.loader.exec_module(champ); "
        "champ.reset(); "
        "print(json.dumps([(a, c.hex()) for a, c in map(champ.act, json.loads(sys.argv[2]))]))"
    )
    done = subprocess.run(
        [sys.executable, "-I", "-S", "-c", script, str(path), json.dumps(stream.obs.tolist())],
        capture_output=True,
        text=True,
        check=True,
    )
    got = [(a, float.fromhex(c), []) for a, c in json.loads(done.stdout)]
    assert_same(stream, got, teams=False)


def test_module_docstring_records_provenance():
    _, pop, root = RANDOM[1]
    meta = {"generation": 12, "seed": 4, "no_memory": True}
    text = module_text(prepare(pop, root, no_memory=False, source="a/b.json", meta=meta))
    doc = ast.get_docstring(ast.parse(text))
    for needle in ("a/b.json", f"root team:  {root}", "generation: 12", "without memory"):
        assert needle in doc, needle
    assert "memory on" in doc


def test_memory_persists_across_calls_until_reset(py_runner):
    pop, root = accumulator_graph()
    obs = random_observations(40, seed=9)
    one = sequence_stream(pop, root, 0, 0, obs=np.concatenate([obs, obs]))
    got = py_runner(pop, root, one)
    assert_same(one, got)
    restarted = Stream(one.obs, np.r_[one.starts[:40], one.starts[:40]], one.actions, [], [])
    again = py_runner(pop, root, restarted)
    assert [x[:2] for x in again[40:]] == [x[:2] for x in got[:40]]
    assert [x[:2] for x in again[40:]] != [x[:2] for x in got[40:]]


def test_module_plays_a_gymnasium_episode_with_the_engines_return(evolved, tmp_path):
    import gymnasium as gym

    from mtpg.engine.batch import Episodes, evaluate_roots
    from mtpg.engine.compile import compile_population

    _, cases = evolved
    _, pop, root, _ = max(cases, key=lambda c: len(c[1].reachable(c[2])))
    path = write_python(prepare(pop, root, no_memory=False), tmp_path / "gym_champ.py")
    spec = importlib.util.spec_from_file_location("gym_champ", path)
    agent = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(agent)
    for task in ("Pendulum", "CartPole"):
        env = gym.make(f"mtpg/{task}-v0")
        obs, _ = env.reset(seed=SEEDS[0])
        agent.reset()
        total, done = 0.0, False
        while not done:
            obs, reward, terminated, truncated, _ = env.step(agent.act(obs))
            total += reward
            done = terminated or truncated
        table = Episodes.grid([TASK_NAMES.index(task)], SEEDS)
        returns, _ = evaluate_roots(compile_population(pop), [root], table)
        assert total == returns[0, 0]
