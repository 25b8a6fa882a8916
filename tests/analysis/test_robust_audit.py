"""``mtpg.analysis.results.audit``: the audit of issue 52 item 3, on a tiny run trained here."""

import numpy as np
import pytest

from mtpg.analysis.results import audit as robust_audit
from mtpg.analysis.results import audit_page
from stopruns import mtpg
from tinyruns import tiny_args

TASKS = "CartPole,CartCentering,Pendulum"


@pytest.fixture(scope="module")
def results(tmp_path_factory):
    """A results folder with one tiny ``robust`` run (3 tasks, 4 generations, 5 test episodes)."""
    folder = tmp_path_factory.mktemp("results")
    settings = tiny_args(TASKS, root_size=16, n_elite=2, evaluation__test_interval=2)
    done = mtpg(
        "train", "--preset", "robust", "--seed", "1", *settings,
        "--set", "evaluation.test_episodes=5", "--generations", "4",
        "--out", str(folder / "runs" / "TPG-robust-seed1"),
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    return folder


@pytest.fixture(scope="module")
def audit(results):
    return robust_audit.audit_run(results / "runs" / "TPG-robust-seed1", episodes=5)


def test_the_failure_modes_account_for_every_test_episode(results, audit):
    from mtpg.analysis.runs.loading import load_run

    pend, cart = audit["a"]["Pendulum"], audit["a"]["CartCentering"]
    assert pend["episodes"] == cart["episodes"] == 5
    assert 0 <= pend["balanced"] <= pend["reached"] <= 5
    assert 0.0 <= pend["upright"] <= 1.0
    ends = cart["captured"] + cart["left"] + cart["right"] + cart["timeout"]
    assert ends == 5
    assert cart["start_side"] <= cart["left"] + cart["right"]
    shares = cart["ret_captured"] + cart["ret_off"] + cart["ret_timeout"]
    assert shares == pytest.approx(cart["mean"])
    assert pend["ret_balanced"] + pend["ret_lost"] + pend["ret_never"] == pytest.approx(
        pend["mean"]
    )
    assert cart["optimal_steps"] > 0
    assert set(audit["a"]["other"]) == {"CartPole"}
    run = load_run(results / "runs" / "TPG-robust-seed1")
    assert pend["mean"] == pytest.approx(run.row(run.full_set)["test_Pendulum"])


def test_the_oracle_finds_no_root_worse_than_the_best_and_counts_the_clones(audit):
    for task in robust_audit.WORST:
        d = audit["d"][task]
        assert d["roots"] >= 2
        assert d["best"] >= d["champion"] and d["best"] >= d["top"]
        assert 0 <= d["better"] < d["roots"]
        assert len(d["confirm"]) == len(d["min6"]) == 3
        assert d["min6"][0] <= d["confirm"][0]  # the worst of the tasks is at most this one
    c = audit["c"]
    assert c["champion_rank"] >= 1
    assert 1 <= c["groups"] <= robust_audit.TOP
    assert c["near"] >= c["identical"] >= 0
    tr, te, se = audit["e"]["Pendulum"]
    assert te == pytest.approx(audit["a"]["Pendulum"]["norm"])
    assert se >= 0


def test_a_copied_root_is_a_clone_and_a_fresh_one_is_not(results):
    from mtpg.evolve.persist import state_from_payload
    from mtpg.io.checkpoint import latest_checkpoint, load_checkpoint

    run = results / "runs" / "TPG-robust-seed1"
    state, _ = state_from_payload(load_checkpoint(latest_checkpoint(run)))
    pop = state.population
    top, _ = robust_audit.top_roots(state, k=3)
    assert top[0] == state.champions[-1] and len(top) == 3
    champion = top[0]
    copy = pop.add_team(list(pop.teams[champion].programs)).id
    fresh_prog = pop.add_program(np.zeros((1, 4), np.int32), -1, pop.new_bank())
    fresh = pop.add_team([fresh_prog.id]).id
    c = robust_audit.clones(pop, [champion, copy, fresh])
    assert (c["identical"], c["near"], c["groups"]) == (1, 1, 2)


def test_slopes_of_a_line_and_the_end_of_a_cart_episode():
    gens = np.arange(800, 1001)
    s = robust_audit.slope(gens, 0.5 * gens + 3.0, span=2.0)
    assert (s.raw, s.norm) == pytest.approx((50.0, 25.0))
    assert s.half == pytest.approx(0.0, abs=1e-6)
    off_left = np.array([[-0.5, -0.2], [-1.0, -0.8], [-1.6, -1.0]])
    captured = np.array([[0.3, 0.0], [0.005, 0.001]])
    modes = robust_audit.cartcentering_modes(
        [(off_left, -1.2), (captured, -0.01)], np.array([-0.5, 0.3])
    )
    assert (modes["left"], modes["right"], modes["start_side"]) == (1, 0, 1)
    assert (modes["captured"], modes["capture_steps"]) == (1, 1.0)


def test_a_balanced_and_a_spinning_pendulum():
    still = np.zeros((201, 6))
    spin = np.zeros((201, 6))
    spin[:, 0] = np.linspace(1.0, 1.0 + 4 * np.pi, 201)  # two turns, upright only in passing
    modes = robust_audit.pendulum_modes([(still, -1.0), (spin, -900.0)])
    assert (modes["reached"], modes["balanced"], modes["swing_up"]) == (2, 1, 0.0)
    assert modes["turns"] == pytest.approx(1.0)  # the mean of 0 and 2
    assert modes["ret_balanced"] == -0.5 and modes["ret_lost"] == -450.0


def test_write_puts_the_block_between_the_markers_and_keeps_the_prose(results, tmp_path):
    doc = tmp_path / "docs" / "robust-audit.md"
    doc.parent.mkdir()
    doc.write_text(f"# Title\n\nProse.\n\n{robust_audit.BEGIN}\nold\n{robust_audit.END}\n\nEnd.\n")
    out = tmp_path / "results"
    written = audit_page.write(results, out, episodes=5, oracle_episodes=3)
    assert written == doc
    text = doc.read_text()
    assert text.startswith("# Title\n\nProse.\n") and text.endswith("\n\nEnd.\n")
    assert "old" not in text and "| TPG-robust-seed1 |" in text
    assert "mtpg report --results results --page robust-audit" in text
    for part in ("(a)", "(b)", "(c)", "(d)", "(e)"):
        assert f"### {part}" in text
