from mtpg.cli.main import main
from tinyruns import tiny_args

TINY = tiny_args(quiet=False, evaluation__test_interval=2, evaluation__test_episodes=2)


def test_experiment_runs_seeds_and_ablations_then_resumes(tmp_path, capsys):
    out = tmp_path / "exp"
    args = [
        "experiment",
        *TINY,
        "--preset",
        "paper",
        "--seeds",
        "2",
        "--parallel",
        "2",
        "--out",
        str(out),
    ]
    assert main([*args, "--generations", "2"]) == 0
    names = sorted(p.name for p in out.iterdir() if p.is_dir())
    assert names == [
        "TPG-NoHierarchy-seed0",
        "TPG-NoMemory-seed0",
        "TPG-NoXover-seed0",
        "TPG-seed0",
        "TPG-seed1",
        "report",
    ]
    assert (out / "report" / "ablations.png").is_file()
    capsys.readouterr()
    # rerunning with more generations resumes every run from its checkpoint
    assert main([*args, "--generations", "4"]) == 0
    err = capsys.readouterr().err
    assert err.count("partial -> starting") == 5
    for run in names[:-1]:
        assert (out / run / "checkpoints" / "gen-000004.json.gz").is_file()
    assert main([*args, "--generations", "4"]) == 0
    assert capsys.readouterr().err.count(": done") == 5
