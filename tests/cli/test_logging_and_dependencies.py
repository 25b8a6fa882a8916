"""The command line shows the ``mtpg`` logger by --quiet/--debug; a missing module is one line."""

from __future__ import annotations

import logging
import re
import tomllib
from pathlib import Path

import pytest

import mtpg._extras as extras
import mtpg._kernel_cache as guard
from mtpg.cli import main as cli

PYPROJECT = tomllib.loads((Path(__file__).resolve().parents[2] / "pyproject.toml").read_text())


@pytest.fixture(autouse=True)
def _no_debug_env(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("MTPG_DEBUG", raising=False)


def _logging_refresh(monkeypatch: pytest.MonkeyPatch) -> None:
    """The kernel-cache check, which runs before every command, logs at three levels."""

    def refresh() -> bool:
        log = logging.getLogger("mtpg.somewhere")
        log.debug("a debug message")
        log.info("an info message")
        log.warning("a warning")
        return False

    monkeypatch.setattr(guard, "refresh", refresh)


def _lines(text: str) -> list[str]:
    return [line for line in text.splitlines() if "message" in line or "warning" in line]


@pytest.mark.parametrize(
    ("argv", "shown"),
    [
        (["train", "--resume", "no-such-run"], ["an info message", "warning: a warning"]),
        (["train", "--quiet", "--resume", "no-such-run"], ["warning: a warning"]),
        (
            ["--debug", "train", "--quiet", "--resume", "no-such-run"],
            ["debug: a debug message", "an info message", "warning: a warning"],
        ),
        (
            ["train", "--resume", "no-such-run", "--debug"],
            ["debug: a debug message", "an info message", "warning: a warning"],
        ),
    ],
)
def test_quiet_and_debug_set_the_level_of_the_mtpg_logger(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str], argv, shown
) -> None:
    _logging_refresh(monkeypatch)
    assert cli.main(argv) == 2  # the run does not exist
    out, err = capsys.readouterr()
    assert _lines(err) == shown and out == ""
    assert err.splitlines()[-1].startswith("mtpg train: error: no-such-run")


def test_main_leaves_the_logger_as_it_found_it(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    logger = logging.getLogger("mtpg")
    before = (list(logger.handlers), logger.level, logger.propagate)
    _logging_refresh(monkeypatch)
    cli.main(["--debug", "train", "--resume", "no-such-run"])
    assert (list(logger.handlers), logger.level, logger.propagate) == before
    capsys.readouterr()
    logging.getLogger("mtpg.somewhere").warning("after main")
    assert "after main" not in capsys.readouterr().err  # no handler of main's is left


def test_an_experiment_reports_its_runs_through_the_logger(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    from mtpg.evolve.experiment import execute, plan

    runs = plan(tmp_path, 1, 0)
    (runs[0].path / "checkpoints").mkdir(parents=True)
    (runs[0].path / "config.toml").write_text("")
    (runs[0].path / "checkpoints" / "gen-000003.json.gz").write_text("")
    with caplog.at_level(logging.INFO, logger="mtpg"):
        assert execute(runs, [], generations=3) == []  # done already: nothing starts
    assert [(r.name, r.levelname, r.getMessage()) for r in caplog.records] == [
        ("mtpg.evolve.experiment", "INFO", "TPG-seed0: done")
    ]


def test_a_missing_dependency_of_a_command_is_one_line_with_its_extra(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    import mtpg.cli.cmd_show as show

    def run(args) -> int:
        raise ModuleNotFoundError("No module named 'tensorboardX'", name="tensorboardX")

    monkeypatch.setattr(show, "run", run)
    monkeypatch.setattr(extras, "_editable_source", lambda: None)
    assert cli.main(["show", "x.json"]) == 1
    err = capsys.readouterr().err
    assert err == (
        "mtpg show: error: missing dependency: module 'tensorboardX' is not installed; it "
        "comes with the extra 'tensorboard': pip install 'mtpg[tensorboard]'\n"
    )


def test_a_missing_dependency_at_start_is_one_line_not_a_traceback(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    real = cli.importlib.import_module

    def import_module(name: str):
        if name == "mtpg.cli.cmd_bench":
            raise ModuleNotFoundError("No module named 'distributed'", name="distributed.comm")
        return real(name)

    monkeypatch.setattr(cli.importlib, "import_module", import_module)
    assert cli.main(["show", "x.json"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("mtpg: error: missing dependency: module 'distributed' is not ")
    assert "the extra 'dask': pip install" in err and err.count("\n") == 1


def test_a_missing_command_module_is_an_internal_error_not_skipped(
    monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setattr(cli, "COMMAND_MODULES", (*cli.COMMAND_MODULES, "mtpg.cli.cmd_gone"))
    assert cli.main(["show", "x.json"]) == 1
    err = capsys.readouterr().err
    assert "internal error: ModuleNotFoundError: No module named 'mtpg.cli.cmd_gone'" in err


def test_a_base_dependency_says_to_reinstall(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(extras, "_editable_source", lambda: "/src/mtpg")
    assert extras.missing_dependency("numba.core") == (
        "module 'numba' is not installed, though mtpg needs it; reinstall mtpg: "
        "pip install -e '/src/mtpg'"
    )
    assert extras.missing_dependency("no_such_module") == "module 'no_such_module' is not installed"


def _names(reqs: list[str]) -> set[str]:
    return {re.split(r"[<>=!;\[ ]", r, maxsplit=1)[0].lower() for r in reqs}


def test_every_optional_requirement_names_an_extra_that_installs_it() -> None:
    optional = {e: _names(r) for e, r in PYPROJECT["project"]["optional-dependencies"].items()}
    for name in set().union(*optional.values()):
        found, base = extras.extras_of(name.replace("-", "_"))  # as a module is named
        assert found and not base, name
        assert name in optional[found[0]], (name, found)
        others = [e for e in optional if name in optional[e] and e != "test"]
        assert found[0] != "test" or not others, (name, found)
    assert extras.extras_of("distributed")[0][0] == "dask"  # the smallest extra first
    assert extras.extras_of("dask_jobqueue")[0] == ["cluster", "test"]
