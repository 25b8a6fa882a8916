"""``mtpg bench engine`` runs end to end on a tiny workload and ends with one JSON line."""

import json

import pytest

from mtpg.cli.main import main
from mtpg.export.harness import find_compiler

KEYS = {
    "decisions_per_s",
    "instructions_per_decision",
    "teams_per_decision",
    "threads",
    "reference_decisions_per_s",
    "pytpg_decisions_per_s",
    "graphs",
    "episodes",
    "seconds",
    "machine",
}


def test_bench_engine_prints_json_last(capsys):
    argv = ["bench", "engine", "--graphs", "20", "--episodes", "3", "--repeats", "1"]
    code = main([*argv, "--reference-graphs", "2", "--no-pytpg"])
    assert code == 0
    lines = capsys.readouterr().out.strip().splitlines()
    result = json.loads(lines[-1])
    assert KEYS <= set(result)
    assert result["threads"] == 1
    assert result["graphs"] == 20 and result["episodes"] == 3
    assert result["decisions"] >= 20 * 3
    assert result["engine_vs_c"] is None
    assert result["decisions_per_s"] > 0
    assert result["reference_decisions_per_s"] > 0
    assert result["pytpg_decisions_per_s"] is None
    assert 0.3 < result["pointer_fraction"] < 0.5
    assert result["instructions_per_decision"] > 0


def test_bench_engine_on_two_threads_reports_interleaved_scaling(capsys):
    """Above one thread every timed run is paired with a one-thread run (same results)."""
    argv = ["bench", "engine", "--graphs", "30", "--episodes", "2", "--repeats", "3"]
    assert main([*argv, "--threads", "2", "--reference-graphs", "0", "--no-pytpg"]) == 0
    out = capsys.readouterr().out
    assert "interleaved pairs" in out
    result = json.loads(out.strip().splitlines()[-1])
    assert result["threads"] == 2
    assert len(result["scaling_all"]) == 3 and result["scaling"] > 0
    assert result["one_thread_decisions_per_s"] > 0


def test_bench_engine_one_thread_has_no_scaling(capsys):
    argv = ["bench", "engine", "--graphs", "5", "--episodes", "2", "--repeats", "1"]
    assert main([*argv, "--reference-graphs", "0", "--no-pytpg"]) == 0
    result = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert result["scaling"] is None and "scaling_all" not in result


def test_bench_engine_rejects_bad_threads(capsys):
    code = main(["bench", "engine", "--graphs", "2", "--episodes", "5", "--threads", "0"])
    assert code == 2
    assert "threads" in capsys.readouterr().err


@pytest.mark.skipif(find_compiler() is None, reason="no C compiler")
def test_bench_engine_c_port_matches_and_is_timed(capsys):
    """``--c`` checks the C port against the engine job by job, then times both."""
    argv = ["bench", "engine", "--graphs", "30", "--episodes", "2", "--repeats", "2", "--c"]
    assert main([*argv, "--reference-graphs", "0", "--no-pytpg"]) == 0
    out = capsys.readouterr().out
    assert "equal the engine's" in out
    result = json.loads(out.strip().splitlines()[-1])
    assert result["c_decisions_per_s"] > 0 and result["engine_vs_c"] > 0
    assert len(result["engine_vs_c_all"]) == 2


@pytest.mark.skipif(find_compiler() is None, reason="no C compiler")
def test_bench_engine_c_defaults_to_o3_with_o2_beside(capsys):
    argv = ["bench", "engine", "--graphs", "20", "--episodes", "2", "--repeats", "1", "--c"]
    assert main([*argv, "--reference-graphs", "0", "--no-pytpg"]) == 0
    out = capsys.readouterr().out
    result = json.loads(out.strip().splitlines()[-1])
    assert result["c_flags"] == "-O3 -march=native"
    assert result["c_beside"]["c_flags"] == "-O2 -march=native"
    assert result["c_beside"]["engine_vs_c"] > 0
    assert "C built with -O2 -march=native:" in out
