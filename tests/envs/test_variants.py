"""Task variants: parsing, refusal of bad strings, base dynamics, Gymnasium parity, engine."""

from __future__ import annotations

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

from mtpg.engine.batch import Episodes, evaluate_roots
from mtpg.engine.compile import compile_population
from mtpg.engine.oracle import ReferenceAgent, reference_episode
from mtpg.engine.random_populations import tangled_population
from mtpg.engine.trace import trace_episode
from mtpg.envs import PREV_FORCE_SLOT, env_observe, env_reset, env_step
from mtpg.envs.gym_api.registration import register
from mtpg.envs.specs.contract import CARTPOLE
from mtpg.envs.taskset.task_table import VARIANT_ID_BASE, TaskTable
from mtpg.envs.taskset.variants import canonical, gym_id

CP500 = "CartPole[max_steps=500]"


def test_canonical_names_and_gym_ids() -> None:
    assert canonical("CartPole") == "CartPole"
    assert canonical("CartPole[ max_steps = 500.0 ]") == CP500
    assert canonical("Pendulum[observe=theta;gravity=9.81]") == (
        "Pendulum[gravity=9.81;observe=theta]"
    )
    assert gym_id(CP500) == "mtpg/CartPole-max_steps_500-v0"
    assert gym_id("CartPole[observe=x+theta]") == "mtpg/CartPole-observe_x.theta-v0"
    table = TaskTable.from_names([CP500, "CartPole"])
    assert table.id_of("CartPole[max_steps=500.0]") == table.id_of(CP500) >= VARIANT_ID_BASE
    assert table.id_of("CartPole") == CARTPOLE
    spec = table.spec(CP500)
    assert spec.max_steps == 500 and spec.base == "CartPole" and spec.gym_id == gym_id(CP500)
    assert np.isnan(spec.reference.random)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("CartPole[max_step=500]", "unknown key 'max_step'; allowed: max_steps, force, tau"),
        ("CartPole[max_steps=0]", "max_steps: a whole number >= 1"),
        ("CartPole[max_steps=2.5]", "max_steps: a whole number >= 1"),
        ("CartPole[gravity=heavy]", "gravity: 'heavy' is not a number"),
        ("CartPole[gravity=inf]", "gravity: must be finite"),
        ("Pendulum[observe=phi]", "unknown state variable 'phi'; allowed: theta, theta_dot"),
        ("Pendulum[observe=theta+theta_dot+theta]", "one or two distinct state variables"),
        ("Cartpole[max_steps=5]", "unknown base task 'Cartpole'; choose from CartPole"),
        ("CartPole[max_steps]", "max_steps: missing '=value'"),
        ("CartPole[]", "no settings; allowed keys: max_steps"),
        ("CartPole[max_steps=5", "write a variant as Base[key=value;key=value]"),
        ("CartPole[tau=0.1;tau=0.2]", "tau: set twice"),
    ],
)
def test_bad_variants_are_refused_in_one_line(text: str, message: str) -> None:
    with pytest.raises(ValueError, match=None) as info:
        canonical(text)
    assert message in str(info.value) and "\n" not in str(info.value)
    assert str(info.value).startswith(f"task {text!r}")


def play(task: int, seed: int, actions) -> tuple[list[np.ndarray], list[tuple]]:
    from mtpg.envs import sample_start

    params = TaskTable.from_names([]).params
    state = np.zeros(6)
    env_reset(task, params, sample_start(task, np.random.default_rng(seed)), state)
    states, outcomes = [state.copy()], []
    for t in range(len(actions)):
        out = env_step(task, params, state, int(actions[t]), 0.0)
        states.append(state.copy())
        outcomes.append(out)
        if out[1] or out[2]:
            break
    return states, outcomes


def balance(state: np.ndarray) -> int:
    return 0 if state[2] + 0.3 * state[3] > 0 else 2  # 0 -> +10 N, 2 -> -10 N


def test_variant_reproduces_its_base_step_for_step_and_gymnasium_cartpole_v1() -> None:
    table = TaskTable.from_names([CP500])
    v, params = table.ids[0], table.params
    gym = gymnasium.make("CartPole-v1")  # Gymnasium's own 500-step CartPole
    for seed in range(3):
        from mtpg.envs import sample_start

        ours = np.zeros(6)
        env_reset(v, params, sample_start(v, np.random.default_rng(seed), table), ours)
        base = np.zeros(6)
        env_reset(CARTPOLE, params, sample_start(CARTPOLE, np.random.default_rng(seed)), base)
        gym.reset(seed=seed)
        np.testing.assert_array_equal(ours[:4], gym.unwrapped.state)  # float64 inside
        for t in range(500):
            a = balance(ours)
            reward, terminated, truncated = env_step(v, params, ours, a, 0.0)
            if t < 200:  # the base task until its own time limit: the same states, bit for bit
                base_out = env_step(CARTPOLE, params, base, a, 0.0)
                assert np.array_equal(base[:5], ours[:5]) and base_out[:2] == (reward, terminated)
            _, r, g_term, g_trunc, _ = gym.step(1 if a == 0 else 0)
            np.testing.assert_allclose(ours[:4], gym.unwrapped.state, rtol=0, atol=1e-9)
            assert (reward, terminated, truncated) == (r, g_term, g_trunc)
            if terminated or truncated:
                break
        assert ours[PREV_FORCE_SLOT] in (10.0, -10.0)
    assert truncated and t == 499  # the balancing law reaches the 500-step limit


def test_observe_variant_scales_the_chosen_state_variables() -> None:
    table = TaskTable.from_names(
        [
            "CartPole[observe=x_dot+theta_dot]",
            "Pendulum[observe=theta_dot]",
            "Pendulum[observe=theta]",
        ]
    )
    both, one, wrapped = table.ids
    params = table.params  # the table has the variants' rows
    state = np.array([0.3, 1.5, -0.1, -3.5, 10.0, 0.0])
    obs = np.zeros(2)
    env_observe(both, params, state, 0.25, obs)
    assert obs.tolist() == [2.0 * (1.5 + 3.0) / 6.0 - 1.0, -1.0]
    pend = np.array([2 * np.pi + 0.5, 4.0, 0, 0, 2.0, 0.0])
    env_observe(one, params, pend, 0.25, obs)
    assert obs.tolist() == [0.5, 0.25]  # theta_dot / 8, then the noise input
    env_observe(wrapped, params, pend, 0.25, obs)
    assert obs[0] == pytest.approx(0.5 / np.pi, abs=1e-12) and obs[1] == 0.25


@pytest.mark.filterwarnings("ignore:.*Box action space.*:UserWarning")
@pytest.mark.parametrize(
    "name", [CP500, "Pendulum[observe=theta_dot;max_steps=50]", "Pendulum[noise=0.2;observe=theta]"]
)
def test_variant_environments_pass_check_env(name: str) -> None:
    for action in ("paper", "native"):
        env = gymnasium.make(register(name), action=action)
        check_env(env.unwrapped)
        env.close()


@pytest.mark.parametrize(
    "name",
    [
        CP500,
        "MountainCar[observe=velocity;max_steps=80]",
        "CartPole[noise=0.3]",
        "Pendulum[max_steps=80;noise=0.1;observe=theta]",
    ],
)
def test_engine_plays_a_variant_like_the_reference_interpreter(name: str) -> None:
    table = TaskTable.from_names([name])
    task = table.ids[0]
    pop = tangled_population(np.random.default_rng(3), 6, 20, 12, 4, 0.5)
    roots = list(pop.teams)[:3]
    episodes = Episodes.grid([task], [0, 1], table)
    cp = compile_population(pop, fold_constants=False)  # traced below
    returns, result = evaluate_roots(compile_population(pop), roots, episodes)
    eps = episodes.obs_noise if episodes.obs_noise.shape[1] else [None, None]
    assert ("noise=" in name) == (episodes.obs_noise.shape[1] > 0)
    for i, root in enumerate(roots):
        for e in range(2):
            total, steps = reference_episode(
                ReferenceAgent(pop, root),
                task,
                episodes.starts[e],
                episodes.noise[e],
                eps[e],
                table.params,
            )
            assert returns[i, e] == total and result.steps[i * 2 + e] == steps
            trace = trace_episode(
                cp,
                root,
                task,
                episodes.starts[e],
                episodes.noise[e],
                obs_noise=eps[e],
                params=table.params,
            )
            assert len(trace.actions) == steps <= table.spec(task).max_steps
