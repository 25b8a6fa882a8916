"""A compiled task of two continuous dimensions: ``a_c[j]`` is ``m[j]``, end to end.

The user module (written to a temporary folder) is a point reaching a target in the plane:
four inputs, no discrete action, and a two-dimensional continuous action, the velocity.
The engine (the lane engine and the scalar loop, one and two threads), ``mtpg.Policy``,
the exported Python module and a plain loop over the task's own functions agree bit for
bit; a run whose banks are smaller than the task's action is refused in one line.
"""

import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

TASK = "userreach:REACH"
REACH = textwrap.dedent(
    '''
    """Reach a target in the plane: the action is the velocity, two continuous outputs."""
    import numpy as np
    from numba import njit

    from mtpg import CompiledTask


    @njit
    def observe(p, s, noise, obs):
        obs[0] = s[0]
        obs[1] = s[1]
        obs[2] = s[2] - s[0]
        obs[3] = s[3] - s[1]


    @njit
    def step(p, s, a_d, a_c):
        s[0] = min(max(s[0] + p[2] * a_c[0], -1.0), 1.0)
        s[1] = min(max(s[1] + p[2] * a_c[1], -1.0), 1.0)
        d = abs(s[2] - s[0]) + abs(s[3] - s[1])
        return -d, d < 0.05


    def start(rng):
        return rng.uniform(-0.8, 0.8, 4)


    REACH = CompiledTask("Reach", observe, step, start, n_obs=4, n_actions=0,
                         n_continuous=2, state_dim=4, max_steps=30, params=(0.2,),
                         action_bound=0.5)
    '''
)
SMALL = ["--preset", "demo", "--workers", "1", "--quiet", "--set", "team.root_size=20"]
SMALL += ["--set", "team.n_elite=2", "--set", "team.min_elite_total=0"]
SMALL += ["--set", "evaluation.test_interval=2", "--set", "evaluation.test_episodes=4"]


@pytest.fixture
def user_module(tmp_path, monkeypatch):
    folder = tmp_path / "usercode"
    folder.mkdir()
    (folder / "userreach.py").write_text(REACH)
    monkeypatch.syspath_prepend(str(folder))
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(folder), env.get("PYTHONPATH", "")])
    env.pop("MTPG_TEST_STOP_AT", None)
    return env


def call(env, *args):
    return subprocess.run(
        [sys.executable, "-m", "mtpg", *args], env=env, capture_output=True, text=True
    )


def clipped(m, bound):
    """The engine's treatment of one continuous output: finite, then clipped."""
    v = m if m - m == 0.0 else 0.0
    return min(max(v, -bound), bound)


def play(task, decide, seed, swap=False):
    """One episode of the task's own functions, ``decide(obs) -> m[0..2)``."""
    p = task.parameters()
    rng = np.random.default_rng(seed)
    s = task.sample_start(rng)
    noise = rng.random(task.max_steps + 1)
    obs = np.zeros(task.n_obs)
    task.observe(p, s, noise[0], obs)
    total = 0.0
    for t in range(task.max_steps):
        m = decide(obs)
        a_c = np.array([clipped(m[0], p[1]), clipped(m[0 if swap else 1], p[1])])
        reward, terminated = task.step(p, s, 0, a_c)
        total += reward
        if terminated:
            break
        task.observe(p, s, noise[t + 1], obs)
    return total


def test_the_engine_hands_m0_and_m1_to_the_step(user_module):
    from mtpg.engine.batch import Episodes, evaluate_roots
    from mtpg.engine.compile import compile_population
    from mtpg.engine.live import LiveDecider
    from mtpg.engine.random_populations import layered_graphs
    from mtpg.envs.specs.compiled_task import load
    from mtpg.envs.taskset.task_table import TaskTable
    from mtpg.model.instructions import RegisterLayout

    table = TaskTable.from_names([TASK])
    assert table.shape == (4, 1, 2)
    pop, roots = layered_graphs(np.random.default_rng(7), 12, layout=RegisterLayout(n_obs=4))
    cp = compile_population(pop)
    seeds = list(range(40, 46))
    episodes = Episodes.grid([table.ids[0]], seeds, table)
    got, done = evaluate_roots(cp, roots, episodes)
    for lanes in (0, 32):
        for threads in (1, 2):
            other, res = evaluate_roots(cp, roots, episodes, threads=threads, lanes=lanes)
            assert other.tobytes() == got.tobytes(), (lanes, threads)
            assert np.array_equal(res.instructions, done.instructions)
    task, differs = load(TASK), 0
    for r, root in enumerate(roots):
        live = LiveDecider(cp, np.array([cp.team_index(root)]), n_continuous=2)

        def decide(obs, live=live):
            return live.decide(np.zeros(1, dtype=np.int64), obs.reshape(1, -1))[1][0]

        for k, seed in enumerate(seeds):
            live.reset(0)
            assert play(task, decide, seed) == got[r, k], (root, seed)
            live.reset(0)
            differs += play(task, decide, seed, swap=True) != got[r, k]
    assert differs > 0  # m[1] is not m[0]: the comparison above can fail


def test_a_two_dimensional_task_trains_acts_and_exports(tmp_path, user_module):
    import mtpg
    from mtpg.envs.specs.compiled_task import load

    run_dir = tmp_path / "run"
    train = call(
        user_module, "train", *SMALL, "--tasks", TASK, "--generations", "2", "--out", str(run_dir)
    )
    assert train.returncode == 0, train.stderr
    done = call(user_module, "evaluate", str(run_dir), "--episodes", "5", "--json")
    assert done.returncode == 0, done.stderr
    scored = json.loads(done.stdout)[TASK]
    task, policy = load(TASK), mtpg.Policy.load(run_dir)

    def decide(obs):
        a_d, a_c = policy.act(obs)
        assert a_d == 0 and a_c.shape == (2,)
        return a_c

    returns = []
    for k in range(5):
        policy.reset()
        returns.append(play(task, decide, 1_000_000 + k))
    assert np.mean(returns) == scored["mean"] and np.std(returns) == scored["std"]

    module = tmp_path / "champion.py"
    exported = call(user_module, "export", str(run_dir), "--lang", "python", "--out", str(module))
    assert exported.returncode == 0, exported.stderr
    spec = {"__name__": "champion"}
    exec(compile(module.read_text(), str(module), "exec"), spec)
    rng = np.random.default_rng(3)
    policy.reset()
    spec["reset"]()
    for _ in range(20):
        obs = rng.uniform(-1, 1, 4)
        _, a_c = policy.act(obs)
        _, m0 = spec["act"](obs)
        assert spec["continuous"](2) == (m0, a_c[1]) and m0 == a_c[0]


def test_banks_smaller_than_the_action_are_refused_in_one_line(tmp_path, user_module):
    done = call(
        user_module,
        "train",
        *SMALL,
        "--tasks",
        TASK,
        "--generations",
        "2",
        "--set",
        "program.n_memory=1",
        "--out",
        str(tmp_path / "r"),
    )
    assert done.returncode != 0
    assert "Traceback" not in done.stderr and len(done.stderr.strip().splitlines()) == 1
    assert "takes 2 continuous outputs" in done.stderr and "program.n_memory" in done.stderr
    assert not (tmp_path / "r").exists()
