"""A compiled task of a user's module (``module:ATTR``), end to end, from outside the repository.

The user module is src/mtpg/bench/user_cartpole.py copied to a temporary folder: CartPole
written against the compiled-task contract, with the built-in CartPole's dynamics and
interface, so a graph must play the same episodes and returns on both. The CLI trains it,
stops it by SIGKILL and resumes it exactly, evaluates it, and ``mtpg.Policy`` in a loop that
calls the task's own functions reproduces ``mtpg evaluate`` bit for bit. Bad definitions
are refused in one line.
"""

import json
import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from stopruns import assert_same_run

EXAMPLE = Path(__file__).parents[2] / "src" / "mtpg" / "bench" / "user_cartpole.py"
TASK = "usercart:CARTPOLE"
SMALL = ["--preset", "demo", "--workers", "1", "--quiet", "--set", "team.root_size=20"]
SMALL += ["--set", "team.n_elite=2", "--set", "team.min_elite_total=0"]
SMALL += ["--set", "evaluation.test_interval=2", "--set", "evaluation.test_episodes=4"]
SMALL += ["--set", "checkpoint_interval=2"]

THREE_INPUTS = textwrap.dedent(
    '''
    """A task observing three inputs and taking two actions: hold x near 0."""
    import numpy as np
    from numba import njit

    from mtpg import CompiledTask


    @njit
    def observe(p, s, noise, obs):
        obs[0] = s[0]
        obs[1] = s[1]
        obs[2] = noise


    @njit
    def step(p, s, a_d, a_c):
        s[1] = 0.9 * s[1] + (0.1 if a_d == 1 else -0.1)
        s[0] = s[0] + p[2] * s[1]
        return -abs(s[0]), abs(s[0]) > 1.0


    def start(rng):
        return rng.uniform(-0.5, 0.5, 2)


    HOLD = CompiledTask("Hold", observe, step, start, n_obs=3, n_actions=2, state_dim=2,
                        max_steps=50, params=(0.5,), noise_input=True)
    '''
)


@pytest.fixture
def user_module(tmp_path, monkeypatch):
    folder = tmp_path / "usercode"
    folder.mkdir()
    (folder / "usercart.py").write_text(EXAMPLE.read_text())
    (folder / "userhold.py").write_text(THREE_INPUTS)
    monkeypatch.syspath_prepend(str(folder))
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(folder), env.get("PYTHONPATH", "")])
    env.pop("MTPG_TEST_STOP_AT", None)
    return env


def call(env, *args):
    return subprocess.run(
        [sys.executable, "-m", "mtpg", *args], env=env, capture_output=True, text=True
    )


def run(env, *args):
    done = call(env, *args)
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_a_compiled_cartpole_plays_exactly_the_built_in_cartpole(user_module):
    from mtpg.engine.batch import Episodes, evaluate_roots
    from mtpg.engine.compile import compile_population
    from mtpg.engine.random_populations import layered_graphs
    from mtpg.envs.taskset.task_table import TaskTable

    pop, roots = layered_graphs(np.random.default_rng(3), 30)
    cp = compile_population(pop)
    seeds = list(range(500, 512))
    built_in = Episodes.grid([0], seeds, TaskTable.from_names(["CartPole"]))
    user = TaskTable.from_names([TASK])
    theirs = Episodes.grid([user.ids[0]], seeds, user)
    expected, done = evaluate_roots(cp, roots, built_in)
    for lanes in (0, 32):
        for threads in (1, 2):
            got, res = evaluate_roots(cp, roots, theirs, threads=threads, lanes=lanes)
            assert np.array_equal(got, expected), (lanes, threads)
            assert np.array_equal(res.instructions, done.instructions)


def test_inputs_a_task_lacks_read_zero_in_a_run_of_several_sizes(user_module):
    from mtpg.engine.batch import Episodes, evaluate_roots
    from mtpg.engine.compile import compile_population
    from mtpg.engine.random_populations import layered_graphs
    from mtpg.envs.taskset.task_table import TaskTable
    from mtpg.model.instructions import RegisterLayout

    mixed = TaskTable.from_names(["CartPole", "userhold:HOLD"])
    assert mixed.shape == (3, 3, 1)
    pop, roots = layered_graphs(np.random.default_rng(4), 20, layout=RegisterLayout(n_obs=3))
    cp = compile_population(pop)
    seeds = list(range(30, 36))
    both = Episodes.grid(list(mixed.ids), seeds, mixed)
    got, done = evaluate_roots(cp, roots, both)
    # CartPole's third input reads 0, whatever the Hold episodes before it observed
    alone, _ = evaluate_roots(cp, roots, Episodes.grid([0], seeds, mixed))
    assert np.array_equal(got[:, : len(seeds)], alone)
    assert np.isfinite(got).all()
    # the lane engine (the default above) plays three inputs as the scalar loop does
    scalar, ref = evaluate_roots(cp, roots, both, lanes=0)
    assert got.tobytes() == scalar.tobytes()
    for field in ("steps", "teams", "instructions"):
        assert np.array_equal(getattr(done, field), getattr(ref, field)), field


def test_a_compiled_task_trains_resumes_exactly_and_acts_as_a_policy(tmp_path, user_module):
    import mtpg
    from mtpg.envs.specs.compiled_task import load

    whole, stopped = tmp_path / "whole", tmp_path / "stopped"
    train = [*SMALL, "--tasks", TASK, "--generations", "6"]
    run(user_module, "train", *train, "--out", str(whole))
    killed = subprocess.run(
        [sys.executable, "-m", "mtpg", "train", *train, "--out", str(stopped)],
        env={**user_module, "MTPG_TEST_STOP_AT": "evaluate:4:KILL"},
        capture_output=True,
    )
    assert killed.returncode != 0
    run(user_module, "train", "--resume", str(stopped), "--quiet")
    assert_same_run(whole, stopped)

    scored = json.loads(run(user_module, "evaluate", str(whole), "--episodes", "5", "--json"))
    # the task's own functions in a plain loop, the held-out seeds 1_000_000 + k
    task, policy = load(TASK), mtpg.Policy.load(whole)
    p = task.parameters()
    returns = []
    for k in range(5):
        rng = np.random.default_rng(1_000_000 + k)
        s = task.sample_start(rng)
        noise = rng.random(task.max_steps + 1)
        obs = np.zeros(task.n_obs)
        task.observe(p, s, noise[0], obs)
        policy.reset()
        total = 0.0
        for t in range(task.max_steps):
            a_d, _ = policy.act(obs)
            reward, terminated = task.step(p, s, a_d, 0.0)
            total += reward
            if terminated:
                break
            task.observe(p, s, noise[t + 1], obs)
        returns.append(total)
    assert np.mean(returns) == scored[TASK]["mean"]
    assert np.std(returns) == scored[TASK]["std"]
    probe = run(user_module, "probe", str(whole))
    assert " n/a " in probe and "nan" not in probe  # raw scores: no normalised ones
    run(user_module, "show", str(whole))
    # replay traces the engine's own loop compiled for the task: evaluate's returns
    trace = tmp_path / "r.npz"
    run(user_module, "replay", str(whole), "--task", TASK, "--episodes", "5", "--out", str(trace))
    with np.load(trace) as replayed:
        assert np.mean(replayed["returns"]) == scored[TASK]["mean"]
        assert replayed["hidden_state"].shape[1] == task.state_dim  # the task's own slots
    gif = call(
        user_module, "replay", str(whole), "--task", TASK, "--video", str(tmp_path / "v.gif")
    )
    assert gif.returncode != 0 and "does not render" in gif.stderr and "Traceback" not in gif.stderr
    run(user_module, "analyze", str(whole), "--episodes", "3", "--out", str(tmp_path / "a"))
    analysed = json.loads((tmp_path / "a" / "analysis.json").read_text())
    assert "not_applicable" in analysed["tasks"][TASK]  # no velocity: said, not drawn


BAD = {
    "nomodule:TASK": "module 'nomodule' does not import (ModuleNotFoundError",
    "usercart:MISSING": "module 'usercart' has no attribute 'MISSING'",
    "usercart:np": "usercart.np is a module, not a mtpg.CompiledTask",
    "userbad:SIZES": "compiled task Sizes: n_obs must be >= 1",
    "userbad:PLAIN": "compiled task Plain: step must be a Numba function (@njit)",
    "userbad:TYPO": "No implementation of function setitem found for signature",
}
BROKEN = textwrap.dedent(
    """
    import numpy as np
    from numba import njit

    from mtpg import CompiledTask


    @njit
    def observe(p, s, noise, obs):
        obs[0] = s[0]


    @njit
    def typo(p, s, a_d, a_c):
        s[0] = "left"
        return 1.0, False


    def plain(p, s, a_d, a_c):
        return 1.0, False


    def start(rng):
        return np.zeros(1)


    TYPO = CompiledTask("Typo", observe, typo, start, n_obs=1, n_actions=2, state_dim=1)
    try:
        SIZES = CompiledTask("Sizes", observe, typo, start, n_obs=0, n_actions=2, state_dim=1)
    except ValueError as exc:
        SIZES = exc
    """
)


@pytest.mark.parametrize("name", sorted(BAD))
def test_a_bad_compiled_task_is_refused_in_one_line(tmp_path, user_module, name):
    module = BROKEN
    if name == "userbad:SIZES":  # the error is the definition's own: raise it on import
        module = module.replace("except ValueError as exc:\n    SIZES = exc", "finally:\n    pass")
    if name == "userbad:PLAIN":
        module += '\nPLAIN = CompiledTask("Plain", observe, plain, start, n_obs=1, n_actions=2,'
        module += " state_dim=1)\n"
    folder = Path(user_module["PYTHONPATH"].split(os.pathsep)[0])
    (folder / "userbad.py").write_text(module)
    out = tmp_path / "run"
    done = call(
        user_module, "train", *SMALL, "--tasks", name, "--generations", "2", "--out", str(out)
    )
    assert done.returncode != 0
    lines = done.stderr.strip().splitlines()
    assert lines[-1].startswith("mtpg train: error: "), done.stderr
    assert "Traceback" not in done.stderr
    assert BAD[name] in lines[-1], lines[-1]


@pytest.mark.slow
def test_the_task_benchmark_runs_its_three_arms_and_the_compiled_run_is_identical():
    done = subprocess.run(
        [sys.executable, "-m", "mtpg", "bench", "tasks", "--generations", "3", "--repeats", "1"],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    result = json.loads(done.stdout.strip().splitlines()[-1])
    assert result["compiled_run_identical_decisions"]
    assert all(arm["decisions_per_s"] > 0 for arm in result["arms"].values())


CONTINUOUS = textwrap.dedent(
    '''
    """A task of one continuous action and no discrete one: push x to 0 with a_c."""
    import numpy as np
    from numba import njit

    from mtpg import CompiledTask


    @njit
    def observe(p, s, noise, obs):
        obs[0] = s[0]


    @njit
    def step(p, s, a_d, a_c):
        s[1] = a_d  # always 0: the task takes no discrete action
        s[0] = s[0] + 0.1 * a_c
        return -abs(s[0]), False


    def start(rng):
        return np.array([rng.uniform(-1.0, 1.0), 0.0])


    PUSH = CompiledTask("Push", observe, step, start, n_obs=1, n_actions=0, n_continuous=1,
                        state_dim=2, max_steps=20, action_bound=2.0)
    '''
)


def test_a_task_without_a_discrete_action_reads_its_clipped_continuous_one(tmp_path, user_module):
    from mtpg.engine.batch import Episodes, evaluate_roots
    from mtpg.engine.compile import compile_population
    from mtpg.engine.random_populations import layered_graphs
    from mtpg.envs.taskset.task_table import TaskTable
    from mtpg.model.instructions import RegisterLayout

    folder = Path(user_module["PYTHONPATH"].split(os.pathsep)[0])
    (folder / "userpush.py").write_text(CONTINUOUS)
    table = TaskTable.from_names(["userpush:PUSH"])
    assert table.shape == (1, 1, 1)
    layout = RegisterLayout(n_obs=1, n_actions=1)
    pop, roots = layered_graphs(np.random.default_rng(5), 10, layout=layout)
    returns, result = evaluate_roots(
        compile_population(pop), roots, Episodes.grid([512], [1], table)
    )
    assert (result.steps == 20).all()
    # |x| moves at most 0.1 * 2.0 a step: the clip to action_bound holds
    assert (returns >= -20 * (1.0 + 0.2 * 20)).all() and np.isfinite(returns).all()
