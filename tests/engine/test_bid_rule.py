"""The decision rule's bid comparison is written once in the compiled engine, and is right.

Both compiled engines (the scalar kernel and the lane engine) call
:func:`mtpg.engine.bid_rule.takes_lead`; the plain-Python oracle and each exporter state the
rule once each. That both engines decide alike with it is proven job by job elsewhere
(tests/engine/test_lanes.py, test_decide_parity.py, the paper pin).
"""

import ast
from pathlib import Path

import numpy as np
from numba import njit

from mtpg.engine.bid_rule import NO_BID, takes_lead
from mtpg.model.instructions import BIG

SRC = Path(__file__).parents[2] / "src" / "mtpg"
ENGINE = SRC / "engine"
#: The plain-Python reference of the tests: it states the rule on its own, on purpose.
ORACLE = "oracle.py"


def _functions_comparing_bids(path: Path) -> list[str]:
    """The functions of ``path`` holding a comparison that reads a name with ``best``.

    One entry per such comparison (``best_p < 0``, ``bid > best``, ``W[l] > best[l]``...).
    """
    tree = ast.parse(path.read_text())
    found = []
    for fn in ast.walk(tree):
        if not isinstance(fn, ast.FunctionDef):
            continue
        for node in ast.walk(fn):
            if isinstance(node, ast.Compare):
                names = {n.id for n in ast.walk(node) if isinstance(n, ast.Name)}
                if any("best" in name for name in names):
                    found.append(fn.name)
    return found


def test_the_compiled_engine_compares_bids_in_one_function():
    where = {
        (path.name, fn)
        for path in sorted(ENGINE.glob("*.py"))
        if path.name != ORACLE
        for fn in _functions_comparing_bids(path)
    }
    assert where == {("bid_rule.py", "takes_lead")}
    assert _functions_comparing_bids(ENGINE / "bid_rule.py") == ["takes_lead"]  # once
    # the two engines call it
    for module in ("episode_kernels.py", "lane_decide.py"):
        assert "takes_lead(" in (ENGINE / module).read_text()


def test_the_oracle_and_each_exporter_state_the_rule_once():
    assert len(set(_functions_comparing_bids(ENGINE / ORACLE))) == 1  # one function
    assert (SRC / "export" / "python.py").read_text().count("bid > best") == 1
    assert (SRC / "export" / "c.py").read_text().count("bid > best") == 1


MARKS = np.array([3, 7, 3], dtype=np.int64)  # teams 0 and 2 visited in decision 3
STAMP = 3


def test_an_atomic_program_is_always_eligible():
    # its ``at`` is never read: any index, even one past the marks
    assert takes_lead(-1, MARKS, 0, STAMP, 0.0, NO_BID)
    assert takes_lead(-3, MARKS, np.uint64(2**64 - 1), STAMP, -BIG, NO_BID)


def test_a_pointer_to_a_visited_team_is_not_eligible():
    assert not takes_lead(0, MARKS, 0, STAMP, BIG, NO_BID)
    assert not takes_lead(2, MARKS, 2, STAMP, BIG, -BIG)
    assert takes_lead(1, MARKS, 1, STAMP, 0.0, NO_BID)  # team 1: marked in another decision


def test_only_a_strictly_higher_bid_takes_the_lead():
    assert takes_lead(-1, MARKS, 0, STAMP, 0.5, 0.25)
    assert not takes_lead(-1, MARKS, 0, STAMP, 0.5, 0.5)  # a tie: the earlier keeps it
    assert not takes_lead(-1, MARKS, 0, STAMP, 0.0, -0.0)  # +0 and -0 tie
    assert not takes_lead(1, MARKS, 1, STAMP, 0.25, 0.5)


def test_the_first_eligible_program_takes_the_lead_whatever_its_bid():
    assert NO_BID < -BIG  # every bid an instruction can leave is within [-BIG, BIG]
    for bid in (-BIG, -1.0, -0.0, 0.0, 1e-300, BIG):
        assert takes_lead(-1, MARKS, 0, STAMP, bid, NO_BID)
        assert takes_lead(1, MARKS, 1, STAMP, bid, NO_BID)


@njit(cache=True)
def _winner(acts, bids, marks, stamp):
    """The team's winner as both engines find it: the rule over the programs in order."""
    best, best_p = NO_BID, -1
    for p in range(len(acts)):
        if takes_lead(acts[p], marks, np.uint64(max(acts[p], 0)), stamp, bids[p], best):
            best, best_p = bids[p], p
    return best_p


def _first_highest_eligible(acts, bids, marks, stamp):
    """The rule in words: the earliest of the highest bids among the eligible programs."""
    eligible = [p for p, a in enumerate(acts) if a < 0 or marks[a] != stamp]
    top = max(bids[p] for p in eligible)
    return next(p for p in eligible if bids[p] == top)


def test_the_rule_picks_the_earliest_highest_eligible_bid():
    rng = np.random.default_rng(0)
    for _ in range(300):
        n = int(rng.integers(1, 8))
        acts = rng.integers(-3, 3, n).astype(np.int64)
        acts[rng.integers(n)] = -1  # every team holds an atomic program
        bids = rng.choice([-BIG, -1.0, -0.0, 0.0, 0.5, 1.0, BIG], n)  # many ties
        marks = rng.choice([STAMP, STAMP - 1], 3).astype(np.int64)
        assert _winner(acts, bids, marks, STAMP) == _first_highest_eligible(
            acts, bids, marks, STAMP
        )
