"""Run-state payloads and checkpoints of a run: every consistency rule with its message.

Each rule of :func:`mtpg.evolve.persist.state_from_payload` and
:func:`mtpg.evolve.session.load_state` is broken on purpose in a hand-edited payload or
checkpoint, and the refusal's exact message is checked (it names the problem); the
states at the edge of each rule (generation 0, a payload without a run identity) must
load.
"""

from __future__ import annotations

import copy
import json
import re
import shutil

import numpy as np
import pytest

from mtpg.config import build_config
from mtpg.envs.specs.contract import N_OBS
from mtpg.evolve.persist import run_identity, state_from_payload, state_to_payload
from mtpg.evolve.session import Session, load_state
from mtpg.evolve.trainer import Trainer
from mtpg.io.checkpoint import (
    CheckpointError,
    checkpoint_generation,
    checkpoint_path,
    list_checkpoints,
)
from mtpg.io.serialize import FormatError


def tiny(*extra: str):
    return build_config(
        "paper",
        overrides=[
            "team.root_size=8",
            "team.n_elite=2",
            "team.init_team_size=2",
            "evaluation.train_episodes=1",
            "evaluation.test_episodes=1",
            "evaluation.test_interval=0",
            'evaluation.tasks=["CartPole", "MountainCar"]',
            "generations=2",
            *extra,
        ],
    )


@pytest.fixture(scope="module")
def payload() -> dict:
    """A JSON round-tripped payload of generation 1 (two tasks, three subsets)."""
    trainer = Trainer(tiny())
    trainer.run_generation()
    return json.loads(json.dumps(state_to_payload(trainer.state)))


def refused(payload: dict) -> str:
    with pytest.raises(FormatError) as err:
        state_from_payload(payload)
    return str(err.value)


def test_generation_zero_state_loads_without_layout_or_champions() -> None:
    # a run that has not started: empty population of the default layout, no champions
    cfg = tiny("program.n_registers=4", "program.n_memory=3")
    data = json.loads(json.dumps(state_to_payload(Trainer(cfg).state)))
    assert data["champions"] == [] and data["generation"] == 0
    state, config = state_from_payload(data)
    assert state.generation == 0 and config == cfg and state.champions == []


def test_payload_without_a_run_identity_still_loads(payload) -> None:
    data = {k: v for k, v in payload.items() if k != "run"}
    state, _ = state_from_payload(data)
    assert state.generation == 1


def test_scores_are_float64_even_when_written_as_integers(payload) -> None:
    data = copy.deepcopy(payload)
    data["scores"] = [[root, [int(x) for x in row]] for root, row in data["scores"]]
    state, _ = state_from_payload(data)
    assert all(row.dtype == np.float64 for row in state.scores.values())


def test_run_identity_must_match_the_configuration(payload) -> None:
    data = dict(payload, run="0123456789abcdef")
    assert refused(data) == "run state: its run identity does not match its configuration"


def test_bad_configuration_is_named(payload) -> None:
    data = copy.deepcopy(payload)
    data["config"]["team"]["n_elite"] = 0
    assert refused(data) == "run state: config: team.n_elite must be >= 1, got 0"


def test_negative_generation_is_refused(payload) -> None:
    data = dict(payload, generation=-1)
    assert refused(data) == "run state: generation must be >= 0, got -1"


def test_layout_must_match_the_configuration_from_generation_one(payload) -> None:
    data = copy.deepcopy(payload)
    data["config"]["program"]["n_registers"] = 4
    del data["run"]
    message = refused(data)
    assert message.startswith("run state: population layout RegisterLayout(n_registers=8")
    assert message.endswith(f"does not match the configuration (4, 8, {N_OBS}, 3)")


def test_scores_must_have_one_entry_per_task(payload) -> None:
    data = copy.deepcopy(payload)
    first, second = data["scores"][0][0], data["scores"][1][0]
    data["scores"][0][1] = [1.0]
    data["scores"][1][1] = [1.0, 2.0, 3.0]
    message = refused(data)
    assert message == f"run state: root {first} has scores for the wrong number of tasks"
    assert second != first


def test_a_started_run_needs_every_champion_scored(payload) -> None:
    data = dict(payload, champions=payload["champions"][:2])
    assert refused(data) == "run state: needs the champions of 3 task subsets"
    data = dict(payload, champions=[999_999, 999_998, payload["champions"][2]])
    assert refused(data) == "run state: champion 999999 has no score"


# --- checkpoints of a run directory ---------------------------------------------------------


@pytest.fixture(scope="module")
def run_dir(tmp_path_factory):
    run = tmp_path_factory.mktemp("persist") / "run"
    Session(run, tiny("checkpoint_interval=1")).run_all()
    return run


def test_load_state_defaults_to_the_latest_checkpoint(run_dir) -> None:
    state = load_state(run_dir, tiny("checkpoint_interval=1"))
    assert state is not None and state.generation == 2
    assert [g for g, _ in list_checkpoints(run_dir)] == [1, 2]
    older = load_state(run_dir, tiny("checkpoint_interval=1"), list_checkpoints(run_dir)[0][1])
    assert older.generation == 1


def test_checkpoint_holding_another_generation_than_its_name(run_dir, tmp_path) -> None:
    run = tmp_path / "run"
    shutil.copytree(run_dir, run)
    renamed = checkpoint_path(run, 7)
    shutil.copy(checkpoint_path(run, 2), renamed)
    with pytest.raises(CheckpointError) as err:
        load_state(run, tiny(), renamed)
    assert str(err.value) == (
        f"{renamed}: holds generation 2 but its name says 7; refusing it (nothing was changed)"
    )


def test_checkpoint_of_another_run_names_the_differences(run_dir) -> None:
    ckpt = checkpoint_path(run_dir, 2)
    with pytest.raises(CheckpointError) as err:
        load_state(run_dir, tiny("seed=5", "team.p_add=0.5"))
    assert str(err.value) == (
        f"{ckpt}: belongs to another run (differs from this run's config.toml in seed, "
        "team.p_add); refusing it (nothing was changed)"
    )


def test_identity_differing_in_no_named_field_says_identity(run_dir) -> None:
    # -0.0 == 0.0, so no field differs, yet the stored JSON (and so the identity) does
    zero, minus_zero = tiny("team.p_crossover=0.0"), tiny("team.p_crossover=-0.0")
    assert run_identity(zero) != run_identity(minus_zero)
    run = run_dir.parent / "signed-zero"
    session = Session(run, zero)
    session.trainer.run_generation()
    path = session.checkpoint()  # a commit outside run_all (as on a stop signal)
    session.close()
    assert checkpoint_generation(path) == 1 and session.saved_generation == 1
    with pytest.raises(CheckpointError) as err:
        load_state(run, minus_zero)
    assert re.search(r"config\.toml in identity\); refusing it", str(err.value))


def test_run_identity_is_stable_and_recorded_in_every_payload(payload) -> None:
    """Checkpoints of earlier versions must keep matching: the identity is pinned.

    It is the first 16 hex digits of the SHA-256 of the identity fields as compact,
    key-sorted JSON; changing that text (key order, separators, length) would make
    every existing run refuse its own checkpoints.
    """
    assert run_identity(build_config("paper")) == "19fed709cd1053fd"
    assert run_identity(build_config("demo")) == "c6607c29d97f52e0"
    assert payload["run"] == run_identity(tiny())
