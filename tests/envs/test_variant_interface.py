"""The interface keys of variants: ``obs_low/obs_high``, ``noise_low/noise_high``, cos/sin.

They let a run use the observation interface of the authors' published code (MountainCar's
position in [0, 1] and U[-pi, pi] noise; Pendulum observing cos and sin of its angle)
beside the paper's, for the confusion study of docs/variants-study.md.
"""

from __future__ import annotations

import math

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from mtpg.engine.batch import Episodes, evaluate_roots
from mtpg.engine.compile import compile_population
from mtpg.engine.oracle import ReferenceAgent, reference_episode
from mtpg.engine.random_populations import tangled_population
from mtpg.envs import env_observe
from mtpg.envs.gym_api.registration import register
from mtpg.envs.taskset.task_table import TaskTable
from mtpg.envs.taskset.variants import canonical, observation_bounds, task_spec

MC = "MountainCar[noise_high=pi;noise_low=-pi;obs_high=1;obs_low=0]"
CC = "CartCentering[noise_high=1;noise_low=-1]"
PEND = "Pendulum[max_steps=300;observe=cos(theta)+sin(theta)]"


def test_names_are_canonical_with_pi_spelled_out() -> None:
    assert canonical(MC) == (
        "MountainCar[noise_high=3.141592653589793;noise_low=-3.141592653589793;"
        "obs_high=1.0;obs_low=0.0]"
    )
    assert task_spec(MC).observed == "position scaled to [0, 1], noise U[-3.14159, 3.14159]"
    assert task_spec(PEND).observed == "cos(theta), sin(theta)"
    assert task_spec(CC).observed == "x scaled, noise U[-1, 1]"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("CartPole[noise_low=-1]", "has no noise input"),
        ("Pendulum[observe=theta+theta_dot;noise_high=2]", "has no noise input"),
        ("MountainCar[obs_low=1]", "obs_low must be below obs_high"),
        ("MountainCar[noise_low=2;noise_high=1]", "noise_low must be below noise_high"),
        ("Pendulum[observe=cos(theta_dot)]", r"unknown state variable 'cos\(theta_dot\)'"),
        ("CartPole[obs_low=0;noise=0.1]", "cannot go with obs_low/obs_high"),
        ("MountainCar[noise_low=tau]", "noise_low: 'tau' is not a number"),
    ],
)
def test_contradictions_are_refused_naming_the_key(text: str, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        canonical(text)


def test_the_inputs_take_the_ranges_the_variant_sets() -> None:
    table = TaskTable.from_names([MC, CC, PEND])
    mc, cc, pend = table.ids
    params = table.params
    obs = np.zeros(2)
    for x, u in [(-1.2, 0.0), (0.6, 0.999), (-0.3, 0.5), (0.0, 0.123)]:
        env_observe(mc, params, np.array([x, 0.0, 0, 0, 0, 0, 0, 0.0]), u, obs)
        assert obs[0] == pytest.approx((x + 1.2) / 1.8, abs=1e-15) and 0.0 <= obs[0] <= 1.0
        assert obs[1] == -math.pi + 2 * math.pi * u  # unclipped: beyond [-1, 1]
        env_observe(cc, params, np.array([x, 0.0, 0, 0, 0, 0, 0, 0.0]), u, obs)
        assert obs[1] == -1.0 + 2.0 * u
        env_observe(pend, params, np.array([x * 7, 1.0, 0, 0, 0, 0, 0, 0.0]), u, obs)
        assert obs.tolist() == [math.cos(x * 7), math.sin(x * 7)]  # as they are
    env_observe(mc, params, np.array([np.nan, 0.0, 0, 0, 0, 0, 0, 0.0]), 0.5, obs)
    assert obs[0] == 0.5  # a NaN becomes the middle of the range
    low, high = observation_bounds(table.spec(mc))
    assert low.tolist() == [0.0, -math.pi] and high.tolist() == [1.0, math.pi]
    assert observation_bounds(table.spec(pend))[0].tolist() == [-1.0, -1.0]


def test_variants_without_the_keys_observe_as_before() -> None:
    table = TaskTable.from_names(["Pendulum[observe=theta]"])
    task, params = table.ids[0], table.params  # the table has the variant's row
    state = np.array([2.0, 4.0, 0, 0, 0, 0, 0, 0.0])
    obs = np.zeros(2)
    env_observe(task, params, state, 0.3, obs)
    wrapped = ((2.0 + math.pi) % (2 * math.pi)) - math.pi
    assert obs.tolist() == [2.0 * (wrapped + math.pi) / (2 * math.pi) - 1.0, 0.3]


@pytest.mark.filterwarnings("ignore:.*Box action space.*:UserWarning")
@pytest.mark.parametrize("name", [MC, PEND])
def test_interface_variants_pass_check_env(name: str) -> None:
    env = gymnasium.make(register(name), action="native")
    check_env(env.unwrapped)
    env.close()


@pytest.mark.parametrize("name", [MC, CC, PEND])
def test_engine_plays_them_like_the_reference_interpreter(name: str) -> None:
    table = TaskTable.from_names([name])
    task = table.ids[0]
    pop = tangled_population(np.random.default_rng(4), 6, 20, 12, 4, 0.5)
    roots = list(pop.teams)[:3]
    episodes = Episodes.grid([task], [0, 1], table)
    returns, result = evaluate_roots(compile_population(pop), roots, episodes)
    for i, root in enumerate(roots):
        for e in range(2):
            total, steps = reference_episode(
                ReferenceAgent(pop, root),
                task,
                episodes.starts[e],
                episodes.noise[e],
                None,
                table.params,
            )
            assert returns[i, e] == total and result.steps[i * 2 + e] == steps
