"""Seeds evaluated on different backends or clusters are one experiment in the report."""

from dataclasses import replace
from pathlib import Path

from mtpg.analysis.runs.loading import RunData, group_runs
from mtpg.config import build_config


def run(name, **changes):
    config = replace(build_config("demo"), **changes)
    return RunData(Path(name), config, [], "TPG")


def test_backend_address_and_dask_workers_do_not_split_a_group():
    runs = [
        run("a", seed=0),
        run("b", seed=1, backend="dask", address="tcp://10.0.0.1:8786"),
        run("c", seed=2, backend="dask", address="tcp://10.0.0.2:8786"),
        run("d", seed=3, backend="dask", dask_workers=4, workers=1),
    ]
    groups, warnings = group_runs(runs)
    assert [len(g.runs) for g in groups] == [4]
    assert warnings == []


def test_a_setting_that_changes_results_still_splits_a_group():
    groups, warnings = group_runs([run("a"), run("b", generations=20, backend="dask")])
    assert len(groups) == 2
    assert len(warnings) == 1 and "generations" in warnings[0]
    assert "backend" not in warnings[0]
