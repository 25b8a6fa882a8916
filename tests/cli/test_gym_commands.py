"""The commands around a run on Gymnasium tasks: show, replay, analyze, envs.

One tiny CartPole-v1 run (Gymnasium's, which renders) and one run of a user module's
environment (which does not) are trained once for the module; every command either works
on them or refuses in one line naming what does not apply.
"""

import json
import os
import subprocess
import sys
import textwrap

import gymnasium as gym
import numpy as np
import pytest

from mtpg.cli.main import main

CARTPOLE = "gym:CartPole-v1"
LINE_TASK = "gym:linemod2:Line-v0"
LINE = textwrap.dedent(
    '''
    """A point on a line; no render modes."""
    import gymnasium as gym
    import numpy as np
    from gymnasium import spaces


    class Line(gym.Env):
        def __init__(self):
            self.observation_space = spaces.Box(-2.0, 2.0, (1,), dtype=np.float64)
            self.action_space = spaces.Discrete(2)

        def reset(self, *, seed=None, options=None):
            super().reset(seed=seed)
            self.x = float(self.np_random.uniform(-1.0, 1.0))
            return np.array([self.x]), {}

        def step(self, action):
            self.x = float(np.clip(self.x + (0.1 if action else -0.1), -2.0, 2.0))
            return np.array([self.x]), -abs(self.x), False, False, {}


    gym.register("Line-v0", entry_point=Line, max_episode_steps=15)
    '''
)
SMALL = ["--preset", "demo", "--workers", "1", "--quiet", "--set", "team.root_size=12"]
SMALL += ["--set", "team.n_elite=2", "--set", "team.min_elite_total=0"]
SMALL += ["--set", "evaluation.test_interval=2", "--set", "evaluation.test_episodes=2"]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """``(cartpole run, line run, environment for subprocesses)``, trained once."""
    root = tmp_path_factory.mktemp("gymruns")
    folder = root / "usercode"
    folder.mkdir()
    (folder / "linemod2.py").write_text(LINE)
    env = {k: v for k, v in os.environ.items() if k != "MTPG_TEST_STOP_AT"}
    env["PYTHONPATH"] = os.pathsep.join([str(folder), env.get("PYTHONPATH", "")])
    for task, name in ((CARTPOLE, "cp"), (LINE_TASK, "line")):
        done = subprocess.run(
            [sys.executable, "-m", "mtpg", "train", *SMALL, "--tasks", task]
            + ["--generations", "2", "--out", str(root / name)],
            env=env,
            capture_output=True,
            text=True,
        )
        assert done.returncode == 0, done.stderr
    with pytest.MonkeyPatch.context() as patch:  # in-process commands import it too
        patch.syspath_prepend(str(folder))
        yield root / "cp", root / "line", env


def one_error_line(err: str, command: str) -> str:
    lines = [x for x in err.strip().splitlines() if x.strip()]
    assert len(lines) == 1 and lines[0].startswith(f"mtpg {command}: error: "), err
    return lines[0]


def test_show_names_the_runs_interface_and_tasks(runs, capsys):
    assert main(["show", str(runs[0])]) == 0
    out = capsys.readouterr().out
    assert "interface: 4 observed inputs s[0..3], 2 atomic actions 0..1" in out
    assert f"meta tasks: {CARTPOLE}" in out


def test_replay_traces_the_episodes_evaluate_scores(runs, tmp_path, capsys):
    from mtpg.analysis.graph.replay import load_replay

    cp = runs[0]
    assert main(["evaluate", str(cp), "--episodes", "3", "--json"]) == 0
    scored = json.loads(capsys.readouterr().out)[CARTPOLE]
    out = tmp_path / "r.npz"
    assert main(["replay", str(cp), "--task", CARTPOLE, "--episodes", "3", "--out", str(out)]) == 0
    assert "episode seed 1000000: return" in capsys.readouterr().out
    replay = load_replay(out)
    assert np.mean(replay["returns"]) == scored["mean"]
    assert np.std(replay["returns"]) == scored["std"]
    n = replay.n_steps
    assert replay["observation"].shape == (n, 4) and replay["raw_observation"].shape == (n, 4)
    assert replay["hidden_state"].shape == (n, 0) and replay["final_state"].shape == (3, 0)
    assert replay["env_action_c"].shape == (n, 0)
    assert set(replay["env_action_d"].tolist()) <= {0, 1}
    assert len(replay["visit_offsets"]) == n + 1 and replay.counts("visit").min() >= 1
    # the recorded actions, played in a plain Gymnasium loop, give the recorded episode
    env = gym.make("CartPole-v1")
    sl = replay.episode_slice(1)
    obs, _ = env.reset(seed=int(replay["episode_seeds"][1]))
    for i in range(sl.start, sl.stop):
        assert np.array_equal(np.asarray(obs, dtype=np.float64), replay["raw_observation"][i])
        obs, reward, *_ = env.step(int(replay["env_action_d"][i]))
        assert reward == replay["reward"][i]


def test_replay_video_uses_the_environments_frames(runs, tmp_path, capsys):
    from PIL import Image

    gif = tmp_path / "cp.gif"
    args = ["replay", str(runs[0]), "--task", CARTPOLE, "--video", str(gif), "--max-frames", "4"]
    assert main(args) == 0
    assert f"wrote {gif} (4 frames)" in capsys.readouterr().out
    assert Image.open(gif).n_frames == 4


def test_replay_video_of_a_task_that_cannot_render_is_refused_in_one_line(runs, tmp_path):
    out, gif = tmp_path / "line.npz", tmp_path / "line.gif"
    done = subprocess.run(
        [sys.executable, "-m", "mtpg", "replay", str(runs[1]), "--task", LINE_TASK]
        + ["--out", str(out), "--video", str(gif)],
        env=runs[2],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 2
    line = one_error_line(done.stderr, "replay")
    assert f"task {LINE_TASK} cannot render video frames" in line and "without --video" in line
    assert not out.exists() and not gif.exists()  # refused before any work
    assert main(["replay", str(runs[1]), "--task", LINE_TASK, "--out", str(out)]) == 0
    assert out.exists()


def test_analyze_runs_what_applies_and_says_what_does_not(runs, tmp_path, capsys):
    out = tmp_path / "an"
    assert main(["analyze", str(runs[0]), "--episodes", "2", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert f"{CARTPOLE}: no velocity prediction" in printed
    names = {p.name for p in out.iterdir()}
    assert {"team_graph.png", "register_access.png", "index.html", "analysis.json"} <= names
    assert "timeseries_gym_CartPole-v1.png" in names
    assert not any(n.startswith("decomposition") for n in names)
    summary = json.loads((out / "analysis.json").read_text())["tasks"][CARTPOLE]
    assert summary["pearson_r"] is None and "hidden velocity" in summary["not_applicable"]
    assert summary["visit_rate"]["team 1"] == 1.0
    args = ["analyze", str(runs[0]), "--episodes", "2", "--out", str(tmp_path / "x")]
    assert main([*args, "--decompose-task", CARTPOLE]) == 2
    line = one_error_line(capsys.readouterr().err, "analyze")
    assert "hidden velocity" in line


def test_the_decomposition_goes_to_a_task_with_a_hidden_state():
    from mtpg.analysis.graph.page import default_decompose_task

    assert default_decompose_task([CARTPOLE, "Acrobot"]) == "Acrobot"
    assert default_decompose_task([CARTPOLE, "Acrobot", "Pendulum"]) == "Pendulum"
    assert default_decompose_task([CARTPOLE]) is None


def test_envs_lists_gymnasium_tasks_by_name_or_from_a_run(runs, capsys):
    assert main(["envs", "--tasks", f"{CARTPOLE},CartPole"]) == 0
    out = capsys.readouterr().out
    assert "4 inputs: 2 linear, 2 tanh" in out and "Discrete(2): 0 + a_d mod 2" in out
    assert "s[1] [-inf, inf]: tanh" in out and "s[0] [-4.8, 4.8]: linear" in out
    assert "no best given: scores are raw" in out
    row = next(x for x in out.splitlines() if x.startswith("0 "))
    assert "CartPole" in row and "195" in row  # a registered task's row as the default's
    assert main(["envs", "--run", str(runs[1])]) == 0
    out = capsys.readouterr().out
    assert LINE_TASK in out and "1 inputs: 1 linear, 0 tanh" in out and "  15  " in out
    assert main(["envs", "--tasks", CARTPOLE, "--run", str(runs[1])]) == 2
    one_error_line(capsys.readouterr().err, "envs")
    assert main(["envs", "--tasks", "gym:nomod:X-v0"]) == 2
    assert "module 'nomod' does not import" in one_error_line(capsys.readouterr().err, "envs")
