import json

from mtpg.cli.main import main
from mtpg.envs.taskset.episode_seeds import TRAIN_SEED_BASE
from mtpg.envs.taskset.episode_seeds import held_out_seeds as make_test_seeds
from tinyruns import tiny_args

TINY = tiny_args()


def test_evaluate_run_and_graph_json(tmp_path, capsys):
    out = tmp_path / "run"
    assert main(["train", *TINY, "--generations", "2", "--out", str(out)]) == 0
    capsys.readouterr()
    assert main(["evaluate", str(out), "--episodes", "5", "--json"]) == 0
    data = json.loads(capsys.readouterr().out.strip().splitlines()[-1])
    assert set(data) == {"CartPole", "CartCentering"}
    for row in data.values():
        assert {"mean", "std", "episodes", "normalised"} <= set(row)
        assert row["episodes"] == 5
    graph = out / "champions" / "CartPole.json"
    assert main(["evaluate", str(graph), "--episodes", "3", "--tasks", "MountainCar"]) == 0
    assert "MountainCar" in capsys.readouterr().out


def test_holdout_seeds_are_disjoint_from_training():
    from mtpg.config import build_config

    seeds = make_test_seeds(100, offset=7)
    most_training = build_config("paper").evaluation.train_episodes * 1000
    assert len(set(seeds)) == 100 and seeds.min() > TRAIN_SEED_BASE + most_training


def test_evaluate_missing_file_is_a_clear_error(tmp_path, capsys):
    assert main(["evaluate", str(tmp_path / "nope.json")]) == 2
    assert "nope.json" in capsys.readouterr().err
