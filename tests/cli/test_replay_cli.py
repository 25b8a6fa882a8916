import pytest

from inside_graphs import single_team, writer_every_k
from mtpg.analysis.graph.replay import load_replay
from mtpg.cli.main import main
from mtpg.io.serialize import save_graph


@pytest.fixture
def graph(tmp_path):
    pop, root = single_team(action=0)  # always pushes left: CartPole falls in a few steps
    path = tmp_path / "g.json"
    save_graph(path, pop, root, {"tasks": ["CartPole"]})
    return path


def test_replay_writes_npz_and_a_gif_with_one_frame_per_step(graph, tmp_path, capsys):
    from PIL import Image

    npz, gif = tmp_path / "r.npz", tmp_path / "r.gif"
    args = ["replay", str(graph), "--task", "CartPole", "--out", str(npz), "--video", str(gif)]
    assert main(args) == 0
    out = capsys.readouterr().out
    assert "memory on (as evolved)" in out
    rep = load_replay(npz)
    n = rep.n_steps
    assert 5 <= n < 30
    assert rep["a_d"].tolist() == [0] * n
    assert rep["hidden_state"].shape == (n, 6) and rep["observation"].shape == (n, 2)
    assert rep["memory"].shape == (n, 8)
    assert rep.counts("visit").tolist() == [1] * n
    with Image.open(gif) as im:
        assert im.n_frames == n
    assert f"({n} frames)" in out


def test_replay_memory_option_and_evolved_setting(tmp_path, capsys):
    pop, root = writer_every_k()
    path = tmp_path / "nm.json"
    save_graph(path, pop, root, {"no_memory": True})
    npz = tmp_path / "r.npz"
    assert main(["replay", str(path), "--task", "MountainCar", "--out", str(npz)]) == 0
    assert "memory off (as evolved)" in capsys.readouterr().out
    rep = load_replay(npz)
    assert bool(rep["no_memory"]) and (rep["mem_age"] == 0).all()
    args = ["replay", str(path), "--task", "MountainCar", "--memory", "on", "--out", str(npz)]
    assert main(args) == 0
    assert "memory on (overriding the evolved setting)" in capsys.readouterr().out
    assert not bool(load_replay(npz)["no_memory"])


def test_replay_bad_input_is_one_line(graph, tmp_path, capsys):
    assert main(["replay", str(graph), "--task", "Nope"]) == 2
    assert "unknown task 'Nope'" in capsys.readouterr().err
    assert main(["replay", str(graph), "--task", "CartPole", "--video", "x.avi"]) == 2
    assert ".gif or .mp4" in capsys.readouterr().err


def test_mp4_without_ffmpeg_says_what_to_install(graph, tmp_path, capsys, monkeypatch):
    from matplotlib.animation import FFMpegWriter

    monkeypatch.setattr(FFMpegWriter, "isAvailable", classmethod(lambda cls: False))
    mp4 = str(tmp_path / "a.mp4")
    assert main(["replay", str(graph), "--task", "CartPole", "--video", mp4]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and 'pip install -e ".[video]"' in err
