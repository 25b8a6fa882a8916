"""Reference scores given by the user for a variant, with their source."""

from __future__ import annotations

import math

import numpy as np
import pytest

from mtpg.config import ConfigError, build_config, from_dict, to_dict, to_toml
from mtpg.envs.taskset.reference_scores import normalise, reference_of
from mtpg.envs.taskset.task_table import GivenReference, TaskTable, parse_given
from mtpg.evolve.persist import identity_fields, run_identity


def test_an_entry_reads_back_from_its_text():
    given = GivenReference("CartPole[max_steps=500]", 500.0, "the time limit, 1 per step", 22.5)
    assert parse_given(given.text()) == given
    plain = parse_given("CartPole[max_steps=500]: best=475, source=solved, per Gymnasium")
    assert plain == GivenReference("CartPole[max_steps=500]", 475.0, "solved, per Gymnasium")


@pytest.mark.parametrize(
    ("text", "fault"),
    [
        ("CartPole: best=1, source=x", "registered task"),
        ("CartPole[max_steps=500] best=1, source=x", "write TASK:"),
        ("CartPole[max_steps=0500]: best=1, source=x", "spell it"),
        ("CartPole[max_steps=500]: best=1", "needs source"),
        ("CartPole[max_steps=500]: random=1, source=x", "needs best"),
        ("CartPole[max_steps=500]: best=one, source=x", "best: 'one' is not a number"),
        ("CartPole[max_steps=500]: best=inf, source=x", "must be finite"),
        ("CartPole[max_steps=500]: top=1, source=x", "unknown setting 'top=1'"),
        ("CartPole[max_steps=500]: best=1, best=2, source=x", "best given twice"),
        ("CartPole[max_steps=500]: best=1, random=1, source=x", "best equals random"),
    ],
)
def test_a_bad_entry_is_refused_naming_the_fault(text, fault):
    with pytest.raises(ValueError, match=fault.replace("[", r"\[").replace("]", r"\]")):
        parse_given(text)


def test_a_task_table_gives_the_reference_and_it_normalises(tmp_path):
    toml = tmp_path / "run.toml"
    toml.write_text(
        '[[task]]\nbase = "CartPole"\nmax_steps = 401\n'
        'reference = { best = 401, random = 21.0, source = "the time limit" }\n'
        '[[task]]\nbase = "Acrobot"\n'
    )
    cfg = build_config("demo", toml)
    name = "CartPole[max_steps=401]"
    assert cfg.evaluation.tasks == (name, "Acrobot")
    assert cfg.evaluation.references == (f"{name}: best=401, random=21.0, source=the time limit",)
    table = cfg.evaluation.task_table()
    ref = reference_of(name, table)
    assert (ref.best, ref.random) == (401.0, 21.0)
    assert math.isnan(ref.random_std)
    assert ref.source == "random given; best given: the time limit"
    assert normalise(table.id_of(name), 211.0, table=table) == pytest.approx((211.0 - 21.0) / 380.0)
    again = tmp_path / "again.toml"
    again.write_text(to_toml(cfg))
    assert build_config("demo", again) == cfg
    assert from_dict(to_dict(cfg)) == cfg


def test_without_random_the_random_score_is_measured():
    name = "Pendulum[max_steps=57]"
    data = {"evaluation": {"tasks": [name], "references": [f"{name}: best=-10, source=guess"]}}
    ref = reference_of(name, from_dict(data).evaluation.task_table())
    assert ref.best == -10.0 and ref.source == "random measured; best given: guess"
    assert np.isfinite(ref.random) and ref.random_std > 0


@pytest.mark.parametrize(
    ("references", "fault"),
    [
        (["Acrobot[max_steps=77]: best=-50, source=x"], "must name a task of evaluation.tasks"),
        (["MountainCar[max_steps=88]: best=-50"], "needs source"),
        (
            ["MountainCar[max_steps=88]: best=-50, source=x"] * 2,
            "gives a task twice",
        ),
    ],
)
def test_a_bad_config_entry_names_the_field(references, fault):
    data = {"evaluation": {"tasks": ["MountainCar[max_steps=88]"], "references": references}}
    with pytest.raises(ConfigError, match=f"evaluation.references.*{fault}"):
        from_dict(data)


def test_two_runs_keep_their_own_references_and_validating_changes_nothing():
    name = "MountainCar[max_steps=99]"
    a = from_dict({"evaluation": {"tasks": [name], "references": [f"{name}: best=-50, source=a"]}})
    b = from_dict({"evaluation": {"tasks": [name], "references": [f"{name}: best=-60, source=b"]}})
    plain = from_dict({"evaluation": {"tasks": [name]}})
    assert reference_of(name, a.evaluation.task_table()).best == -50.0
    assert reference_of(name, b.evaluation.task_table()).best == -60.0
    assert reference_of(name, plain.evaluation.task_table()).best == -110.0  # the base's
    with pytest.raises(ValueError, match="not in the run"):
        TaskTable.from_names(["CartPole"], [f"{name}: best=-50, source=a"])


def test_references_enter_the_identity_only_when_given():
    name = "CartPole[max_steps=402]"
    plain = from_dict({"evaluation": {"tasks": [name]}})
    given = from_dict(
        {"evaluation": {"tasks": [name], "references": [f"{name}: best=402, source=limit"]}}
    )
    assert run_identity(plain) != run_identity(given)
    assert "references" not in identity_fields(plain)["evaluation"]
    assert "references" in identity_fields(given)["evaluation"]


def test_both_ways_of_giving_references_at_once_are_refused(tmp_path):
    toml = tmp_path / "run.toml"
    toml.write_text(
        '[evaluation]\nreferences = []\n[[task]]\nbase = "CartPole"\nmax_steps = 403\n'
        'reference = { best = 403, source = "x" }\n'
    )
    with pytest.raises(ConfigError, match="not both"):
        build_config("demo", toml)
