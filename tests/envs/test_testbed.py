"""The testbed for other RL libraries: native single-action environments and MultiTask-v0."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest
from gymnasium import spaces
from gymnasium.utils.env_checker import check_env

from mtpg.envs import make_episodes
from mtpg.envs.gym_api.multitask import MultiTaskEnv, box_to_pair
from mtpg.envs.gym_api.registration import MULTITASK_ID
from mtpg.envs.specs.registry import PAPER_TASKS, TASKS


@pytest.mark.filterwarnings("ignore:.*Box action space.*:UserWarning")  # Pendulum's [-2, 2]
@pytest.mark.parametrize("task", range(len(TASKS)), ids=[t.name for t in TASKS])
def test_native_action_env_passes_check_env(task: int) -> None:
    env = gymnasium.make(TASKS[task].gym_id, action="native")
    space = env.action_space
    if TASKS[task].continuous:
        assert isinstance(space, spaces.Box) and space.shape == (1,)
        assert space.high[0] == TASKS[task].bound == -space.low[0]
    else:
        assert space == spaces.Discrete(3)
    check_env(env.unwrapped)
    env.close()


@pytest.mark.parametrize("task", range(len(TASKS)), ids=[t.name for t in TASKS])
def test_native_action_plays_the_paper_dynamics(task: int) -> None:
    spec = TASKS[task]
    native = gymnasium.make(spec.gym_id, action="native").unwrapped
    paper = gymnasium.make(spec.gym_id).unwrapped
    rng = np.random.default_rng(task)
    a, _ = native.reset(seed=11)
    b, _ = paper.reset(seed=11)
    for _ in range(60):
        assert np.array_equal(a, b)
        if spec.continuous:
            u = rng.uniform(-spec.bound, spec.bound)
            ra = native.step(np.array([u]))
            rb = paper.step((1, np.array([u])))
        else:
            k = int(rng.integers(3))
            ra = native.step(k)
            rb = paper.step((k, np.array([0.0])))
        a, b = ra[0], rb[0]
        assert ra[1:4] == rb[1:4]
        assert np.array_equal(ra[4]["state"], rb[4]["state"])
        if ra[2] or ra[3]:
            break


def test_bad_action_interface_is_refused() -> None:
    with pytest.raises(ValueError, match="action must be one of paper, native"):
        gymnasium.make("mtpg/CartPole-v0", action="joint")


@pytest.mark.filterwarnings("ignore:.*Box action space.*:UserWarning")  # tuple's infinite a_c
@pytest.mark.parametrize("action", ["box", "tuple"])
@pytest.mark.parametrize("order", ["random", "cycle"])
def test_multitask_passes_check_env(action: str, order: str) -> None:
    env = gymnasium.make(MULTITASK_ID, action=action, order=order)
    check_env(env.unwrapped)
    env.close()


def test_multitask_draws_tasks_from_its_seed_and_labels_only_info() -> None:
    env = MultiTaskEnv()
    obs, info = env.reset(seed=3)
    assert obs.shape == (2,) and env.observation_space.contains(obs)
    seen = [info["task"]] + [env.reset()[1]["task"] for _ in range(59)]
    assert set(seen) == set(PAPER_TASKS)
    again = MultiTaskEnv()
    repeat = [again.reset(seed=3)[1]["task"]] + [again.reset()[1]["task"] for _ in range(59)]
    assert repeat == seen
    cycle = MultiTaskEnv(tasks=("Pendulum", "CartPole"), order="cycle")
    names = [cycle.reset(seed=0)[1]["task"]] + [cycle.reset()[1]["task"] for _ in range(3)]
    assert names == ["Pendulum", "CartPole", "Pendulum", "CartPole"]


def test_multitask_replays_a_chosen_episode() -> None:
    env = MultiTaskEnv(tasks=("CartPole", "Acrobot"))
    obs, info = env.reset(options={"task": "Acrobot", "episode_seed": 1_000_000})
    single = gymnasium.make("mtpg/Acrobot-v0").unwrapped
    want, _ = single.reset(seed=1_000_000)
    assert info == {"task": "Acrobot", "episode_seed": 1_000_000}
    assert np.array_equal(obs, want)
    starts, _ = make_episodes(np.array([1]), np.array([1_000_000]))
    assert np.array_equal(env._envs["Acrobot"]._state[:4], starts[0, :4])
    for u in (0.9, -0.4, 2.0):
        got = env.step(np.array([0.0, u]))  # Acrobot's bound is 1: a_c = u
        ref = single.step((1, np.array([u])))
        assert np.array_equal(got[0], ref[0]) and got[1:4] == ref[1:4]
        assert got[4] == {"task": "Acrobot"}
    with pytest.raises(ValueError, match="not among"):
        env.reset(options={"task": "Pendulum"})


def test_box_action_thirds_and_bounds() -> None:
    assert box_to_pair([0.9, 0.5], 1.0) == (0, 0.5)
    assert box_to_pair([0.2, -0.5], 2.0) == (1, -1.0)
    assert box_to_pair([-0.34, 1.0], 2.0) == (2, 2.0)
    env = MultiTaskEnv(tasks=("Pendulum",))
    assert env.action_space == spaces.Box(-1.0, 1.0, (2,), dtype=np.float64)
    env.reset(seed=0)
    single = gymnasium.make("mtpg/Pendulum-v0").unwrapped
    single.reset(seed=env.reset(seed=0)[1]["episode_seed"])
    got = env.step(np.array([0.0, -0.75]))  # Pendulum's bound is 2: a_c = -1.5
    assert got[1] == single.step((1, np.array([-1.5])))[1]
    with pytest.raises(ValueError, match="order must be one of random, cycle"):
        MultiTaskEnv(order="shuffled")
    with pytest.raises(ValueError, match="unknown task 'Cart'"):
        MultiTaskEnv(tasks=("Cart",))
