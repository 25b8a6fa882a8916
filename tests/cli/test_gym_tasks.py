"""Any Gymnasium environment as a task, end to end, from a module outside the repository.

A temporary module registers a small environment (``gym:linemod:Line-v0``); the CLI
trains it, evaluates it, stops and resumes it exactly, exports it, and ``mtpg.Policy``
plays it in a hand-written loop with the same returns as ``mtpg evaluate``. Gymnasium's own
CartPole-v1 is checked the same way.
"""

import json
import os
import shutil
import subprocess
import sys
import textwrap

import gymnasium as gym
import numpy as np
import pytest

from stopruns import assert_same_run

LINE = textwrap.dedent(
    '''
    """A cart on a line: reach the origin and stay there (one input has no finite bound)."""
    import os

    import gymnasium as gym
    import numpy as np
    from gymnasium import spaces

    FAIL = os.environ.get("LINE_FAIL", "")  # how the tests break it: step, nan or out


    class Line(gym.Env):
        def __init__(self, start=0.8):
            self.start = start
            self.observation_space = spaces.Box(
                np.array([-2.0, -np.inf]), np.array([2.0, np.inf]), dtype=np.float64
            )
            self.action_space = spaces.Discrete(3)

        def reset(self, *, seed=None, options=None):
            super().reset(seed=seed)
            self.x = float(self.np_random.uniform(-self.start, self.start))
            self.v = 0.0
            return np.array([self.x, self.v]), {}

        def step(self, action):
            if FAIL == "step":
                raise RuntimeError("broken")
            self.v = 0.8 * self.v + 0.1 * (int(action) - 1)
            self.x = float(np.clip(self.x + self.v, -2.0, 2.0))
            reward = -abs(self.x)
            obs = np.array([self.x, self.v])
            if FAIL == "nan":
                obs[1] = np.nan
            if FAIL == "out":
                obs[0] = 5.0
            return obs, reward, abs(self.x) >= 2.0, False, {}


    gym.register("Line-v0", entry_point=Line, max_episode_steps=40)
    '''
)
TASK = "gym:linemod:Line-v0"
SMALL = ["--preset", "demo", "--workers", "1", "--quiet", "--set", "team.root_size=20"]
SMALL += ["--set", "team.n_elite=2", "--set", "team.min_elite_total=0"]
SMALL += ["--set", "evaluation.test_interval=2", "--set", "evaluation.test_episodes=4"]
SMALL += ["--set", "checkpoint_interval=2"]


@pytest.fixture
def user_module(tmp_path, monkeypatch):
    folder = tmp_path / "usercode"
    folder.mkdir()
    (folder / "linemod.py").write_text(LINE)
    monkeypatch.syspath_prepend(str(folder))
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(folder), env.get("PYTHONPATH", "")])
    env.pop("MTPG_TEST_STOP_AT", None)
    return env


def run(env, *args):
    done = subprocess.run(
        [sys.executable, "-m", "mtpg", *args], env=env, capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr
    return done.stdout


def play(policy, env, episodes):
    """Returns of ``policy`` in a plain Gymnasium loop on the first held-out seeds."""
    returns = []
    for k in range(episodes):
        obs, _ = env.reset(seed=1_000_000 + k)
        policy.reset()
        total, done = 0.0, False
        while not done:
            action = policy.act(obs)
            assert env.action_space.contains(action)
            obs, reward, terminated, truncated, _ = env.step(action)
            total += float(reward)
            done = terminated or truncated
        returns.append(total)
    return returns


def test_a_user_environment_trains_resumes_exactly_exports_and_acts_as_a_policy(
    tmp_path, user_module
):
    import mtpg

    whole, stopped = tmp_path / "whole", tmp_path / "stopped"
    train = [*SMALL, "--tasks", TASK, "--generations", "6"]
    run(user_module, "train", *train, "--out", str(whole))
    # killed mid-evaluation of generation 4 (SIGKILL), then resumed
    killed = subprocess.run(
        [sys.executable, "-m", "mtpg", "train", *train, "--out", str(stopped)],
        env={**user_module, "MTPG_TEST_STOP_AT": "evaluate:4:KILL"},
        capture_output=True,
    )
    assert killed.returncode != 0
    run(user_module, "train", "--resume", str(stopped), "--quiet")
    assert_same_run(whole, stopped)

    scored = json.loads(run(user_module, "evaluate", str(whole), "--episodes", "5", "--json"))
    assert scored[TASK]["episodes"] == 5

    # mtpg.Policy in a plain Gymnasium loop: the held-out seeds, the same returns bit for bit
    returns = play(mtpg.Policy.load(whole), gym.make("linemod:Line-v0"), 5)
    assert np.mean(returns) == scored[TASK]["mean"]
    assert np.std(returns) == scored[TASK]["std"]

    out = tmp_path / "agent.py"
    run(user_module, "export", str(whole), "--lang", "python", "--out", str(out))
    assert "float(obs[1])" in out.read_text()


def test_two_policies_keep_their_own_memory(tmp_path, user_module):
    import mtpg

    folder = tmp_path / "run"
    run(user_module, "train", *SMALL, "--tasks", TASK, "--generations", "2", "--out", str(folder))
    a, b = mtpg.Policy.load(folder), mtpg.Policy.load(folder)
    obs = np.array([0.5, 0.1])
    first = [a.act(obs) for _ in range(5)]
    b.act(obs)  # b's memory moves on; a's must not notice
    a.reset()
    assert [a.act(obs) for _ in range(5)] == first


def test_gymnasium_cartpole_evaluates_as_a_plain_gymnasium_loop_replays_it(tmp_path):
    import mtpg

    folder = tmp_path / "cp"
    env = {k: v for k, v in os.environ.items() if k != "MTPG_TEST_STOP_AT"}
    args = [*SMALL, "--tasks", "gym:CartPole-v1", "--generations", "2", "--out", str(folder)]
    run(env, "train", *args)
    scored = json.loads(run(env, "evaluate", str(folder), "--episodes", "3", "--json"))
    returns = play(mtpg.Policy.load(folder), gym.make("CartPole-v1"), 3)
    assert np.mean(returns) == scored["gym:CartPole-v1"]["mean"]


def test_a_failing_environment_stops_the_run_in_one_line_and_loses_nothing(tmp_path, user_module):
    from mtpg.io.checkpoint import list_checkpoints

    train = [*SMALL, "--tasks", TASK, "--generations", "4"]
    whole, killed = tmp_path / "whole", tmp_path / "killed"
    run(user_module, "train", *train, "--out", str(whole))
    subprocess.run(  # killed in generation 3: generation 2 is committed
        [sys.executable, "-m", "mtpg", "train", *train, "--out", str(killed)],
        env={**user_module, "MTPG_TEST_STOP_AT": "evaluate:3:KILL"},
        capture_output=True,
    )
    (killed / ".lock").unlink(missing_ok=True)
    for mode, message in (
        ("step", "step raised RuntimeError: broken"),
        ("nan", "observation[1] = nan is not finite"),
        ("out", "observation[0] = 5.0 is outside its declared bounds [-2.0, 2.0]"),
    ):
        broken = tmp_path / mode
        shutil.copytree(killed, broken)
        failed = subprocess.run(
            [sys.executable, "-m", "mtpg", "train", "--resume", str(broken), "--quiet"],
            env={**user_module, "LINE_FAIL": mode},
            capture_output=True,
            text=True,
        )
        assert failed.returncode != 0
        errors = [x for x in failed.stderr.splitlines() if x.startswith("mtpg train: error")]
        assert len(errors) == 1 and failed.stderr.strip().endswith(errors[0]), failed.stderr
        # training episodes reset with seeds 10**9 + k: no test seed below 10**9 replays one
        assert f"task {TASK}: episode seed 1000000000: " in errors[0]
        assert message in errors[0]
        assert list_checkpoints(broken)[-1][0] == 2  # the last completed generation is kept
        run(user_module, "train", "--resume", str(broken), "--quiet")
        assert_same_run(whole, broken)
