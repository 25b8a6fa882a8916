"""Variants with Gaussian observation noise: ``Task[noise=SD]``."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest

from mtpg.engine.batch import Episodes
from mtpg.engine.compile import compile_population
from mtpg.engine.random_populations import tangled_population
from mtpg.engine.trace import trace_episode
from mtpg.envs import env_observe, env_reset, sample_start
from mtpg.envs.gym_api.registration import register
from mtpg.envs.taskset.episodes import draw_episodes, make_episodes
from mtpg.envs.taskset.task_table import TaskTable
from mtpg.envs.taskset.variants import canonical, obs_noise_sd, task_spec

NOISY = "Pendulum[noise=0.25;observe=theta]"


def test_the_noise_key_is_canonical_and_checked():
    assert canonical("Pendulum[observe=theta;noise=0.10]") == "Pendulum[noise=0.1;observe=theta]"
    assert obs_noise_sd(task_spec("CartPole[noise=0.3]")) == 0.3
    assert "observation noise sd 0.3" in task_spec("CartPole[noise=0.3]").observed
    with pytest.raises(ValueError, match="noise: a standard deviation >= 0, got '-1'"):
        canonical("CartPole[noise=-1]")


def test_noise_draws_come_after_the_episode_and_leave_other_tasks_alone():
    table = TaskTable.from_names(["Pendulum", NOISY, "CartPole"])
    tasks = np.array(table.ids)
    seeds = np.array([7, 7, 8])
    starts, noise, eps = draw_episodes(tasks, seeds, table)
    plain_starts, plain_noise = make_episodes(tasks, seeds, table)
    assert np.array_equal(starts, plain_starts) and np.array_equal(noise, plain_noise)
    k = table.spec(int(tasks[1])).max_steps + 1
    rng = np.random.default_rng(7)
    sample_start(int(tasks[1]), rng, table)
    rng.random(k)
    assert np.array_equal(eps[1, :k], rng.standard_normal((k, 2)))
    assert not eps[0].any() and not eps[2].any()
    assert draw_episodes(tasks[[0, 2]], seeds[[0, 2]], table)[2].shape == (2, 0, 2)


def test_the_noise_is_added_to_the_observed_input_and_clipped():
    table = TaskTable.from_names([NOISY, "Pendulum[observe=theta]"])
    noisy, base = table.ids
    params = table.params
    state = np.zeros(8)
    env_reset(noisy, params, np.array([0.3, 0.1, 0, 0, 0, 0, 0, 0.0]), state)
    clean, seen = np.zeros(2), np.zeros(2)
    env_observe(base, params, state, 0.6, clean)
    for e0, e1 in [(0.5, -2.0), (-1.0, 3.0), (10.0, 0.0)]:
        env_observe(noisy, params, state, 0.6, seen, np.array([e0, e1]))
        assert seen[0] == min(1.0, clean[0] + 0.25 * e0)
        assert seen[1] == clean[1] == 0.6  # the U[0, 1] noise input is left alone


def test_the_gymnasium_environment_plays_the_engines_episode():
    tasks = TaskTable.from_names([NOISY])
    task = tasks.ids[0]
    pop = tangled_population(np.random.default_rng(5), 6, 20, 12, 4, 0.5)
    cp = compile_population(pop, fold_constants=False)
    table = Episodes.grid([task], [11], tasks)
    root = list(pop.teams)[0]
    tr = trace_episode(
        cp,
        root,
        task,
        table.starts[0],
        table.noise[0],
        obs_noise=table.obs_noise[0],
        params=tasks.params,
    )
    env = gymnasium.make(register(NOISY)).unwrapped
    obs, _ = env.reset(seed=11)
    seen = [obs]
    for a_d, a_c in tr.actions:
        obs, *_ = env.step((int(a_d), np.array([a_c])))
        seen.append(obs)
    assert np.array_equal(np.array(seen[: len(tr.actions)]), tr.observations)
    assert not np.array_equal(tr.observations[:, 0], np.clip(tr.states[:-1, 0] / np.pi, -1, 1))
