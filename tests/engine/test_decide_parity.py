"""The production decision kernel (``decide``, as training calls it) against the reference.

Step by step: the action, ``a_c``, the teams visited and every memory bank after every
decision, with memory on and in the no-memory ablation, on generated graphs and on
graphs from a real evolved population.
"""

import numpy as np
import pytest
from hypothesis import given, settings

from decide_stepper import play_episode, production_steps
from graph_strategies import tangled_cases
from mtpg.config import build_config
from mtpg.engine.batch import Episodes, evaluate_roots
from mtpg.engine.compile import compile_population
from mtpg.engine.oracle import ReferenceAgent
from mtpg.engine.random_populations import layered_graphs
from mtpg.envs import TASK_PARAMS, env_observe, env_reset, env_step
from mtpg.envs.specs.contract import STATE_SIZE, TASK_NAMES
from mtpg.envs.taskset.episode_seeds import held_out_seeds
from mtpg.evolve.trainer import Trainer
from mtpg.model.graph import check_invariants
from mtpg.model.instructions import RegisterLayout

EXTREME = [0.0, 1.0, -1.0, 1e-300, -1e-300, 1e10, -1e10, 1e300, -1e300, 0.5]


def observations(rng, n):
    obs = rng.uniform(-1, 1, size=(n, 2))
    mask = rng.random((n, 2)) < 0.2
    obs[mask] = rng.choice(EXTREME, size=mask.sum())
    return obs


def assert_step(cp, steps, t, decision, agent):
    """Decision ``t`` of the production kernel equals the reference decision."""
    assert steps.actions[t, 0] == decision.action, t
    assert steps.actions[t, 1] == decision.continuous, t  # bit for bit
    visited = [int(cp.team_ids[x]) for x in steps.visited(t)]
    assert sorted(visited) == sorted(decision.teams), t
    assert steps.teams[t] == len(decision.teams), t  # every team visited once
    m = cp.layout.n_memory
    for dense, bank_id in enumerate(cp.bank_ids.tolist()):
        want = agent.memory.get(bank_id, [0.0] * m)
        assert steps.memory[t, dense * m : (dense + 1) * m].tolist() == want, (t, bank_id)


def compare_sequence(pop, root, obs, marks, no_memory):
    cp = compile_population(pop, fold_constants=False)
    steps = production_steps(cp, root, obs, marks, no_memory=no_memory)
    agent = ReferenceAgent(pop, root, no_memory=no_memory)
    for t, o in enumerate(obs):
        if t == 0 or marks[t] != marks[t - 1]:
            agent.reset()
        assert_step(cp, steps, t, agent.act(o), agent)
    return steps


@settings(max_examples=40, deadline=None, derandomize=True)
@given(case=tangled_cases())
def test_decide_matches_reference_on_generated_graphs(case):
    rng, pop, no_memory = case
    check_invariants(pop)
    root = int(rng.choice(list(pop.teams)))
    # three episodes back to back on one set of buffers: the lazy bank reset must make
    # every bank read zero again at each episode start
    marks = np.repeat([0, 1, 5], [6, 5, 4])
    steps = compare_sequence(pop, root, observations(rng, len(marks)), marks, no_memory)
    assert set(np.unique(steps.actions[:, 0])) <= {0, 1, 2}


@pytest.mark.parametrize("no_memory", [False, True])
def test_decide_matches_reference_on_layered_graphs(no_memory):
    rng = np.random.default_rng(7)
    pop, roots = layered_graphs(rng, 4, teams=3, programs=10, instructions=10)
    for root in roots:
        compare_sequence(pop, root, observations(rng, 20), np.zeros(20, np.int64), no_memory)


@pytest.mark.parametrize("n_registers", [1, 3, 4, 12])
def test_decide_matches_reference_with_other_register_counts(n_registers):
    # eight registers take the kernel's straight-line clear; every other count its loop
    rng = np.random.default_rng(11)
    layout = RegisterLayout(n_registers=n_registers, n_memory=3)
    pop, roots = layered_graphs(rng, 3, teams=3, programs=6, instructions=12, layout=layout)
    for root in roots:
        compare_sequence(pop, root, observations(rng, 12), np.repeat([0, 1], 6), False)


def test_memory_modes_differ_on_generated_graphs():
    """The comparison has teeth: memory on and off give different kernel outputs."""
    rng = np.random.default_rng(11)
    pop, roots = layered_graphs(rng, 6, teams=3, programs=10, instructions=12)
    cp = compile_population(pop, fold_constants=False)
    obs = observations(rng, 15)
    on = [production_steps(cp, r, obs).memory for r in roots]
    off = [production_steps(cp, r, obs, no_memory=True).memory for r in roots]
    assert any(not np.array_equal(a, b) for a, b in zip(on, off, strict=True))


# --------------------------------------------------------------------------- evolved graphs

EVOLVED_TASKS = ("CartPole", "Pendulum", "MountainCarContinuous")


@pytest.fixture(scope="module")
def evolved():
    """A population evolved for a few generations on three tasks, with hierarchy."""
    config = build_config(
        "paper",
        overrides=[
            "team.root_size=30",
            "team.n_elite=3",
            "team.init_team_size=4",
            "team.p_atomic=0.6",
            "team.p_memory=0.5",
            "team.p_action=0.5",
            "team.p_new=0.5",
            "evaluation.train_episodes=1",
            "evaluation.tasks=[" + ", ".join(f'"{t}"' for t in EVOLVED_TASKS) + "]",
            "generations=10",
        ],
    )
    trainer = Trainer(config)
    while not trainer.done:
        trainer.run_generation()
    pop = trainer.state.population
    check_invariants(pop)
    assert any(not p.is_atomic for p in pop.programs.values()), "no hierarchy evolved"
    assert len(pop.banks_in_use()) < len(pop.programs), "no memory sharing evolved"
    return trainer


def reference_steps(pop, root, task, start, noise, no_memory, check):
    """Plays an episode with the reference agent, calling ``check(t, obs, decision)``."""
    agent = ReferenceAgent(pop, root, no_memory=no_memory)
    state, obs = np.zeros(STATE_SIZE), np.zeros(2)
    env_reset(task, TASK_PARAMS, start, state)
    env_observe(task, TASK_PARAMS, state, noise[0], obs)
    t, rewards = 0, []
    while True:
        decision = agent.act(obs)
        check(t, obs, decision, agent)
        reward, terminated, truncated = env_step(
            task, TASK_PARAMS, state, decision.action, decision.continuous
        )
        rewards.append(reward)
        t += 1
        if terminated or truncated:
            return np.array(rewards)
        env_observe(task, TASK_PARAMS, state, noise[t], obs)


@pytest.mark.parametrize("no_memory", [False, True])
def test_decide_matches_reference_on_evolved_graphs(evolved, no_memory):
    pop = evolved.state.population
    cp = compile_population(pop, fold_constants=False)
    task_ids = [TASK_NAMES.index(t) for t in EVOLVED_TASKS]
    episodes = Episodes.grid(task_ids, held_out_seeds(1))
    # every root, plus internal teams entered through pointers (they decide as roots too)
    internal = sorted({p.action for p in pop.programs.values() if not p.is_atomic})
    deep = [r for r in pop.roots() if len(pop.reachable(r)) > 1]
    assert deep, "no evolved root has a graph of more than one team"
    starts = pop.roots()[:4] + deep[:2] + internal[:2]
    for root in dict.fromkeys(starts):
        for row in range(len(episodes.tasks)):
            steps, obs, rewards = play_episode(cp, root, episodes, row, no_memory)
            task = int(episodes.tasks[row])

            def check(t, o, decision, agent, steps=steps, obs=obs):
                assert obs[t].tolist() == o.tolist(), t
                assert_step(cp, steps, t, decision, agent)

            want = reference_steps(
                pop, root, task, episodes.starts[row], episodes.noise[row], no_memory, check
            )
            assert len(want) == len(steps.actions)
            assert rewards.tolist() == want.tolist()


def test_stepper_totals_equal_the_batch_kernel(evolved):
    """The step-by-step driver and the batch kernel training uses are one computation."""
    pop = evolved.state.population
    cp = compile_population(pop, fold_constants=False)  # the stepper traces
    episodes = Episodes.grid([TASK_NAMES.index(t) for t in EVOLVED_TASKS], [0])
    roots = pop.roots()
    for no_memory in (False, True):
        returns, result = evaluate_roots(
            compile_population(pop), roots, episodes, no_memory=no_memory
        )  # folded
        for i, root in enumerate(roots):
            for row in range(len(episodes.tasks)):
                steps, _, rewards = play_episode(cp, root, episodes, row, no_memory)
                job = i * len(episodes.tasks) + row
                total = 0.0
                for r in rewards.tolist():  # summed in step order, as the kernel does
                    total += r
                assert total == returns[i, row]
                assert len(rewards) == result.steps[job]
                assert steps.teams.sum() == result.teams[job]
                assert steps.instructions.sum() == result.instructions[job]
