"""Run directories: creation and resume rules, metrics CSV, champion files."""

import csv

import numpy as np
import pytest

from mtpg.engine.oracle import ReferenceAgent
from mtpg.engine.random_populations import layered_graphs
from mtpg.io import (
    MetricsWriter,
    RunDirError,
    champion_filename,
    init_run_dir,
    is_run_dir,
    read_champions,
    write_champions,
)

TOML = 'seed = 3\n\n[evaluation]\ntasks = ["CartPole"]\n'
HEADER = ("generation", "best", "roots")


def test_init_new_run(tmp_path):
    run = init_run_dir(tmp_path / "a" / "run", TOML)
    assert run.config.read_text() == TOML
    assert run.checkpoints.is_dir() and run.champions.is_dir()
    assert is_run_dir(run.path)
    names = sorted(p.name for p in run.path.iterdir())
    assert names == ["champions", "checkpoints", "config.toml", "format.json"]
    # an empty existing directory is fine too
    (tmp_path / "empty").mkdir()
    assert is_run_dir(init_run_dir(tmp_path / "empty", TOML).path)


def test_init_refuses_existing_run_unless_resuming(tmp_path):
    run = init_run_dir(tmp_path / "run", TOML)
    # a run that committed nothing may be started again (its creation is redone)
    (run.path / "metrics.csv").write_text("generation\n")
    init_run_dir(run.path, TOML)
    names = sorted(p.name for p in run.path.iterdir())
    assert names == ["champions", "checkpoints", "config.toml", "format.json"]
    (run.checkpoints / "gen-000001.json.gz").write_bytes(b"")
    with pytest.raises(RunDirError, match="already holds an mtpg run"):
        init_run_dir(run.path, TOML)
    assert init_run_dir(run.path, None, resume=True).config.read_text() == TOML
    init_run_dir(run.path, TOML + "generations = 5\n", resume=True)
    assert run.config.read_text().endswith("generations = 5\n")


def test_init_refuses_foreign_directory(tmp_path):
    (tmp_path / "thesis.tex").write_text("x")
    (tmp_path / "config.toml").write_text("x")  # a config alone is not a run
    with pytest.raises(RunDirError, match=r"not empty and is not an mtpg run.*thesis\.tex"):
        init_run_dir(tmp_path, TOML)
    with pytest.raises(RunDirError, match="no mtpg run to resume"):
        init_run_dir(tmp_path, TOML, resume=True)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["config.toml", "thesis.tex"]


def test_init_refuses_file_and_empty_resume(tmp_path):
    (tmp_path / "f").write_text("x")
    with pytest.raises(RunDirError, match="not a directory"):
        init_run_dir(tmp_path / "f", TOML)
    with pytest.raises(RunDirError, match="no mtpg run to resume"):
        init_run_dir(tmp_path / "new", TOML, resume=True)
    assert not (tmp_path / "new").exists()


def read_rows(path):
    with open(path, newline="") as fh:
        return list(csv.reader(fh))


def test_metrics_append_flush_and_truncate(tmp_path):
    path = tmp_path / "metrics.csv"
    with MetricsWriter(path, HEADER) as metrics:
        for gen in range(6):
            metrics.append({"generation": gen, "best": gen / 3, "roots": "a,b"})
            # flushed: visible to another reader at once
            assert len(read_rows(path)) == gen + 2
        assert read_rows(path)[2] == ["1", repr(1 / 3), "a,b"]
        assert metrics.truncate_after(3) == 2
        assert [r["generation"] for r in metrics.rows()] == ["0", "1", "2", "3"]
        metrics.append({"generation": 4, "best": 0.0, "roots": ""})
        with pytest.raises(ValueError, match="missing"):
            metrics.append({"generation": 5})
        with pytest.raises(ValueError, match="unknown"):
            metrics.append({"generation": 5, "best": 1, "roots": 2, "extra": 3})
    assert [r[0] for r in read_rows(path)] == ["generation", "0", "1", "2", "3", "4"]
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]


def test_metrics_reopen_checks_header_and_drops_partial_line(tmp_path):
    path = tmp_path / "metrics.csv"
    with MetricsWriter(path, HEADER) as metrics:
        metrics.append({"generation": 0, "best": 1.0, "roots": 5})
    with open(path, "a") as fh:
        fh.write("1,2.")  # a crash mid-row
    with MetricsWriter(path, HEADER) as metrics:
        metrics.append({"generation": 1, "best": 2.0, "roots": 5})
    assert read_rows(path) == [list(HEADER), ["0", "1.0", "5"], ["1", "2.0", "5"]]
    with pytest.raises(RunDirError, match="does not match"):
        MetricsWriter(path, ("generation", "best"))


def test_metrics_reopen_header_without_newline_or_empty_file(tmp_path):
    path = tmp_path / "metrics.csv"
    for content in ("generation,best,roots", ""):
        path.write_text(content)
        with MetricsWriter(path, HEADER) as metrics:
            metrics.append({"generation": 0, "best": 1.0, "roots": 5})
        assert read_rows(path) == [list(HEADER), ["0", "1.0", "5"]]


def test_metrics_truncate_needs_generation_column(tmp_path):
    with (
        MetricsWriter(tmp_path / "m.csv", ("a", "b")) as metrics,
        pytest.raises(RunDirError, match="generation"),
    ):
        metrics.truncate_after(1)


def test_champion_filename():
    assert champion_filename(("CartPole",)) == "CartPole.json"
    assert champion_filename(("Acrobot", "CartPole")) == "CartPole+Acrobot.json"
    assert (
        champion_filename(
            (
                "MountainCarContinuous",
                "Pendulum",
                "CartPole",
                "MountainCar",
                "CartCentering",
                "Acrobot",
            )
        )
        == "CartPole+Acrobot+CartCentering+Pendulum+MountainCar+MountainCarContinuous.json"
    )
    for bad in ((), ("CartPole", "CartPole"), ("Pong",)):
        with pytest.raises(ValueError):
            champion_filename(bad)


def test_write_and_read_champions(tmp_path):
    run = init_run_dir(tmp_path / "run", TOML)
    pop, roots = layered_graphs(np.random.default_rng(0), n_graphs=2, programs=4)
    champions = {
        ("Acrobot", "CartPole"): (pop, roots[0], {"score": 0.5}),
        ("Pendulum",): (pop, roots[1], None),
    }
    written = write_champions(run.path, champions)
    assert sorted(p.name for p in written) == ["CartPole+Acrobot.json", "Pendulum.json"]
    (run.champions / "README.json").write_text("{}")  # not a champion: ignored
    back = read_champions(run.path)
    assert set(back) == {("CartPole", "Acrobot"), ("Pendulum",)}
    cpop, croot, meta = back[("CartPole", "Acrobot")]
    assert meta == {"tasks": ["CartPole", "Acrobot"], "score": 0.5}
    assert croot == roots[0]
    obs = np.random.default_rng(1).uniform(-1, 1, size=(10, 2))
    a, b = ReferenceAgent(pop, roots[0]), ReferenceAgent(cpop, croot)
    assert [a.act(o).action for o in obs] == [b.act(o).action for o in obs]
