import json

from inside_graphs import writer_every_k
from mtpg.cli.main import main
from mtpg.io.serialize import save_graph
from tinyruns import tiny_args


def test_analyze_graph_writes_figures_and_a_self_contained_page(tmp_path, capsys):
    pop, root = writer_every_k()
    path = tmp_path / "g.json"
    save_graph(path, pop, root, {"tasks": ["CartCentering"]})
    out = tmp_path / "an"
    args = ["analyze", str(path), "--episodes", "2", "--out", str(out)]
    assert main(args + ["--decompose-task", "Pendulum"]) == 2  # checked before any work
    assert "Pendulum" in capsys.readouterr().err
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "memory on (as evolved)" in text
    names = {p.name for p in out.iterdir()}
    assert {
        "team_graph.png",
        "register_access.png",
        "timeseries_CartCentering.png",
        "decomposition_CartCentering.png",
        "graph.dot",
        "analysis.json",
        "index.html",
    } <= names
    page = (out / "index.html").read_text()
    assert page.count("data:image/png;base64,") == 4 and "team 2" in page
    summary = json.loads((out / "analysis.json").read_text())
    assert set(summary["tasks"]) == {"CartCentering"}
    assert summary["tasks"]["CartCentering"]["visit_rate"]["team 1"] == 1.0


def test_analyze_and_show_a_run_directory(tmp_path, capsys):
    run = tmp_path / "run"
    train = ["train", *tiny_args(), "--generations", "2", "--out", str(run)]
    assert main(train + ["--set", "evaluation.test_interval=1"]) == 0
    capsys.readouterr()
    assert main(["show", str(run)]) == 0
    assert "team 1 (id" in capsys.readouterr().out
    args = ["analyze", str(run), "--episodes", "1", "--memory", "off", "--tasks", "CartPole"]
    assert main(args) == 0
    text = capsys.readouterr().out
    assert "memory off (overriding the evolved setting)" in text
    assert (run / "analysis" / "run_hierarchy.png").is_file()
    assert "Hierarchy across the run" in (run / "analysis" / "index.html").read_text()
