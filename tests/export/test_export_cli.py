"""``mtpg export``: run directories, files written, the memory rule and the benchmark."""

import json

import pytest

from mtpg.cli.main import main
from mtpg.envs.specs.contract import TASK_NAMES
from mtpg.io.rundir import champion_filename
from mtpg.io.serialize import load_graph, save_graph


def test_exports_a_runs_champion_to_c_and_python(evolved, tmp_path, capsys):
    run, _ = evolved
    assert main(["export", str(run), "--lang", "c", "--out", str(tmp_path / "c")]) == 0
    out = capsys.readouterr().out
    assert "memory on (as evolved)" in out
    champion = run / "champions" / champion_filename(TASK_NAMES)
    _, root, meta = load_graph(champion)
    header = (tmp_path / "c" / "mtpg_graph.h").read_text()
    assert str(champion) in header
    assert f"generation: {meta['generation']}" in header
    assert (tmp_path / "c" / "mtpg_graph.c").is_file()
    py = tmp_path / "py" / "champ.py"
    assert main(["export", str(run), "--lang", "python", "--out", str(py)]) == 0
    assert str(champion) in py.read_text() and str(root) in py.read_text()


def test_a_graph_evolved_without_memory_needs_an_explicit_choice(evolved, tmp_path, capsys):
    _, cases = evolved
    _, pop, root, meta = cases[0]
    graph = tmp_path / "nomem.json"
    save_graph(graph, pop, root, {**meta, "no_memory": True})
    out = tmp_path / "c"
    assert main(["export", str(graph), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "nomem.json" in err and "--memory off" in err and "--memory on" in err
    assert not out.exists()
    assert main(["export", str(graph), "--out", str(out), "--memory", "off"]) == 0
    assert "memory off (as evolved)" in capsys.readouterr().out
    source = (out / "mtpg_graph.c").read_text()
    assert "mtpg_zero_bank(m); /* memory off" in source
    assert "without memory (TPG-NoMemory)" in (out / "mtpg_graph.h").read_text()
    assert main(["export", str(graph), "--out", str(out), "--memory", "on"]) == 0
    assert "overriding the evolved setting" in capsys.readouterr().out
    assert "mtpg_zero_bank(m); /* memory off" not in (out / "mtpg_graph.c").read_text()


def test_usage_errors_are_one_line(evolved, tmp_path, capsys):
    run, _ = evolved
    assert main(["export", str(run)]) == 2
    assert "--out" in capsys.readouterr().err
    assert main(["export", str(run), "--lang", "python", "--out", str(tmp_path / "x.c")]) == 2
    assert ".py" in capsys.readouterr().err
    assert main(["export", str(tmp_path / "missing.json"), "--out", str(tmp_path)]) == 2
    assert "missing.json" in capsys.readouterr().err


def test_bench_checks_and_times_the_exported_c(cc, evolved, capsys):
    run, _ = evolved
    args = ["export", str(run), "--bench", "--bench-episodes", "1", "--bench-runs", "1"]
    assert main([*args, "--tasks", "Pendulum,CartPole", "--json"]) == 0
    data = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert data["episodes"] == 2 and data["decisions"] >= 2
    for key in ("c_us_per_decision", "engine_us_per_decision", "python_us_per_decision"):
        assert data[key] > 0
    assert "-ffp-contract=off" in data["compiler"]


@pytest.mark.parametrize("bad", ["Pong", ""])
def test_bench_rejects_unknown_tasks(evolved, capsys, bad):
    run, _ = evolved
    code = main(["export", str(run), "--bench", "--tasks", bad or "CartPole,Pong"])
    assert code == 2 and "Pong" in capsys.readouterr().err
