"""The fault-injection points: known phases only, one way of calling them."""

import ast
import signal
from pathlib import Path

import pytest

from mtpg import _faults
from stopruns import ARGS, mtpg

SRC = Path(_faults.__file__).parent


def test_entries_are_parsed_with_kill_by_default():
    moments = _faults.parse(" vary:4, test:5:term,,checkpoint:0:HUP ")
    assert moments == {
        ("vary", 4): signal.SIGKILL,
        ("test", 5): signal.SIGTERM,
        ("checkpoint", 0): signal.SIGHUP,
    }
    assert _faults.parse("") == {}


def test_an_unknown_phase_is_refused_naming_every_phase():
    with pytest.raises(ValueError) as err:
        _faults.parse("vary:1,vray:4:KILL")
    text = str(err.value)
    assert text.startswith("MTPG_TEST_STOP_AT: unknown phase 'vray' in 'vray:4:KILL'")
    assert text.endswith("the phases are " + ", ".join(_faults.PHASES))
    assert "\n" not in text


@pytest.mark.parametrize(
    ("text", "why"),
    [
        ("vary", "must look like PHASE:GENERATION"),
        ("vary:x", "must look like PHASE:GENERATION"),
        ("vary:1:2:3", "must look like PHASE:GENERATION"),
        ("vary:1:STOP", "unknown signal 'STOP' in 'vary:1:STOP'; use KILL, TERM, INT, HUP"),
    ],
)
def test_a_malformed_entry_is_refused(text, why):
    with pytest.raises(ValueError, match=why):
        _faults.parse(text)


def test_a_point_of_an_unknown_phase_is_a_mistake_in_the_caller():
    with pytest.raises(ValueError, match="unknown fault-injection phase 'vray'"):
        _faults.point("vray", 1)
    _faults.point("vary", 1)  # known, not asked for: nothing happens


def point_calls():
    """``(file, phase)`` of every ``point(...)`` call in the package, by parsing it."""
    calls = []
    for path in sorted(SRC.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Call):
                name = getattr(node.func, "id", getattr(node.func, "attr", None))
                if name == "point":
                    arg = node.args[0] if node.args else None
                    phase = arg.value if isinstance(arg, ast.Constant) else None
                    calls.append((str(path.relative_to(SRC)), phase))
    return calls


def test_every_phase_is_passed_once_by_name_through_the_one_function():
    calls = point_calls()
    assert sorted(phase for _, phase in calls) == sorted(_faults.PHASES), calls
    importers = set()
    for path in SRC.rglob("*.py"):
        text = path.read_text()
        assert "testhook" not in text, path
        if "mtpg._faults" in text:
            importers.add(str(path.relative_to(SRC)))
            assert "from mtpg._faults import " in text, path
    assert importers == {file for file, _ in calls} | {"evolve/session.py"}


def test_a_typo_in_the_variable_stops_the_run_before_it_writes_anything(tmp_path):
    run = tmp_path / "run"
    res = mtpg("train", *ARGS, "--out", str(run), env={"MTPG_TEST_STOP_AT": "comit:3"})
    assert res.returncode == 2
    assert res.stderr.splitlines() == [
        "mtpg train: error: MTPG_TEST_STOP_AT: unknown phase 'comit' in 'comit:3'; the "
        "phases are " + ", ".join(_faults.PHASES)
    ]
    assert not run.exists()
