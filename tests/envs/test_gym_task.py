"""Gymnasium environments as tasks: names, spaces, the scaling of inputs and actions."""

import re

import numpy as np
import pytest

from mtpg.envs.specs.gym_task import (
    GymTask,
    GymTaskError,
    canonical,
    continuous_action,
    parse,
    scale_obs,
)
from mtpg.envs.taskset.task_table import TaskTable


def test_names_parse_and_spell_canonically():
    assert parse("gym:CartPole-v1") == ("CartPole-v1", {})
    assert parse("gym:mod:Env-v0[b=2;a='x']") == ("mod:Env-v0", {"a": "x", "b": 2})
    assert canonical("gym:Pendulum-v1[max_episode_steps=50; g=9.81]") == (
        "gym:Pendulum-v1[g=9.81;max_episode_steps=50]"
    )
    for bad in ("gym:", "gym:X[a]", "gym:X[a=1;a=2]", "gym:X[a=1"):
        with pytest.raises(GymTaskError):
            parse(bad)


def test_finite_inputs_scale_linearly_and_unbounded_ones_through_tanh():
    low, high = np.array([-2.0, -np.inf, 0.0]), np.array([2.0, np.inf, 10.0])
    out = scale_obs(np.array([1.0, 3.0, 10.0]), low, high, "t", 0)
    assert out.tolist() == [0.5, np.tanh(3.0), 1.0]
    with pytest.raises(GymTaskError, match=r"episode seed 7: observation\[0\] = 2.5 is outside"):
        scale_obs(np.array([2.5, 0.0, 0.0]), low, high, "t", 7)


def test_memory_cells_map_onto_a_box_and_unbounded_dimensions_pass_as_they_are():
    low, high = np.array([-2.0, 0.0, -np.inf]), np.array([2.0, 1.0, np.inf])
    out = continuous_action(np.array([0.5, 7.0, -3.0]), low, high)
    assert out.tolist() == [1.0, 1.0, -3.0]


def test_cartpole_and_pendulum_read_their_spaces():
    cp = GymTask.from_name("gym:CartPole-v1")
    assert (cp.n_obs, cp.n_actions, cp.n_continuous, cp.max_steps) == (4, 2, 0, 500)
    assert cp.action(5, np.zeros(0)) == 1  # 5 mod 2
    pend = GymTask.from_name("gym:Pendulum-v1")
    assert (pend.n_obs, pend.n_actions, pend.n_continuous) == (3, 0, 1)
    assert pend.action(0, np.array([1.0])).tolist() == [2.0]  # m[0] = 1 is the top torque
    assert np.isnan(pend.scale(np.array([1.0, 0.0, 8.0]), 0)).sum() == 0


def test_a_run_s_interface_is_the_largest_of_its_tasks():
    assert TaskTable.from_names(["CartPole", "Acrobot"]).shape == (2, 3, 1)
    assert TaskTable.from_names(["gym:CartPole-v1"]).shape == (4, 2, 0)
    assert TaskTable.from_names(["CartPole", "gym:Pendulum-v1"]).shape == (3, 3, 1)


@pytest.mark.parametrize(
    ("name", "message"),
    [
        ("gym:NoSuchEnv-v0", "doesn't exist"),
        ("gym:no_such_module_here:X-v0", "module 'no_such_module_here' does not import"),
        ("gym:Blackjack-v1", "observation space Tuple is not supported (supported: Box)"),
        ("gym:CartPole-v1[bogus=1]", "making it raised TypeError"),
    ],
)
def test_a_bad_definition_is_refused_in_one_line(name, message):
    with pytest.raises(GymTaskError, match=re.escape(message)) as info:
        GymTask.from_name(name)
    assert "\n" not in str(info.value)
