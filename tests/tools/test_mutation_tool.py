"""``tools/mutation.py``: every mutant still applies to the code it names.

A refactoring that rewrites a line a hand mutant replaces leaves the mutant unable to
apply (it needs its ``old`` text exactly once); this catches that in the default suite
rather than on the next mutation run.
"""

import glob
from pathlib import Path

from toolmodules import load_tool

ROOT = Path(__file__).parents[2]


def _tool():
    return load_tool("mutation")


def test_every_hand_mutant_finds_its_line_exactly_once():
    tool = _tool()
    stale = [m.name for m in tool.HAND_MUTANTS if (ROOT / m.path).read_text().count(m.old) != 1]
    assert stale == []
    for m in tool.HAND_MUTANTS:
        assert all((ROOT / t).exists() for t in m.tests), m.name


def test_every_mutmut_module_names_existing_sources_and_tests():
    tool = _tool()
    for name, (sources, tests) in tool.MODULES.items():
        for pattern in sources:
            assert glob.glob(str(ROOT / pattern)), (name, pattern)
        for test in tests:
            assert (ROOT / test).exists(), (name, test)
