"""``mtpg bench engine`` runs end to end on a tiny workload and ends with one JSON line."""

import json

from mtpg.cli.main import main

KEYS = {
    "decisions_per_s",
    "instructions_per_decision",
    "teams_per_decision",
    "threads",
    "reference_decisions_per_s",
    "pytpg_decisions_per_s",
    "graphs",
    "steps",
    "seconds",
    "machine",
}


def test_bench_engine_prints_json_last(capsys):
    argv = ["bench", "engine", "--graphs", "20", "--steps", "50", "--repeats", "1"]
    code = main([*argv, "--reference-graphs", "2", "--no-pytpg"])
    assert code == 0
    lines = capsys.readouterr().out.strip().splitlines()
    result = json.loads(lines[-1])
    assert KEYS <= set(result)
    assert result["threads"] == 1
    assert result["graphs"] == 20 and result["steps"] == 50
    assert result["decisions"] == 20 * 50
    assert result["decisions_per_s"] > 0
    assert result["reference_decisions_per_s"] > 0
    assert result["pytpg_decisions_per_s"] is None
    assert 0.3 < result["pointer_fraction"] < 0.5
    assert result["instructions_per_decision"] > 0


def test_bench_engine_rejects_bad_threads(capsys):
    code = main(["bench", "engine", "--graphs", "2", "--steps", "5", "--threads", "0"])
    assert code == 2
    assert "threads" in capsys.readouterr().err
