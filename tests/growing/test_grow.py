"""``mtpg experiment --plan`` (and ``tools/grow_results.py``, which calls it): runs grown in
slices equal uninterrupted runs, and are committed."""

import csv
import subprocess
import tarfile

from mtpg.cli.main import main as mtpg_main
from mtpg.growing.plan import load_plan
from mtpg.io.checkpoint import load_checkpoint
from stopruns import SETTINGS, mtpg, without_timing
from tinyruns import tiny_args
from toolmodules import load_tool

GENERATIONS = 24
#: A run some ten times slower than ``SETTINGS``'s.
SLOW = tiny_args("CartPole,MountainCar", root_size=200, n_elite=40, evaluation__train_episodes=100)


def _tool():
    return load_tool("grow_results")


def _plan(folder, *runs):
    """A plan file in ``folder``: one group ``paper`` of ``(name, seed, args)`` runs."""
    text = '[[groups]]\nname = "paper"\npreset = "paper"\nfolder = "."\ngenerations = 1000\n'
    for name, seed, args in runs:
        text += f'[[groups.runs]]\nname = "{name}"\nseeds = [{seed}]\n'
        text += f"args = {list(args)!r}\n".replace("'", '"')
    (folder / "plan.toml").write_text(text)
    return folder / "plan.toml"


def _git(repo, *args):
    return subprocess.run(["git", *args], cwd=repo, capture_output=True, text=True, check=True)


def _repo(tmp_path, monkeypatch):
    """A git repository with a ``results/`` folder, committing as the tests."""
    for key in ("AUTHOR", "COMMITTER"):
        monkeypatch.setenv(f"GIT_{key}_NAME", "mtpg tests")
        monkeypatch.setenv(f"GIT_{key}_EMAIL", "tests@mtpg.invalid")
    repo = tmp_path / "repo"
    (repo / "results").mkdir(parents=True)
    _git(repo, "init", "-q")
    _git(repo, "commit", "-q", "--allow-empty", "-m", "start")
    return repo


def test_slices_of_a_grown_run_add_up_to_an_uninterrupted_run(tmp_path, monkeypatch):
    repo = _repo(tmp_path, monkeypatch)
    plan = _plan(
        repo / "results", ("TPG-seed{seed}", 3, []), ("TPG-NoMemory-seed{seed}", 3, ["--no-memory"])
    )
    _git(repo, "add", "results/plan.toml")
    _git(repo, "commit", "-q", "-m", "the plan")
    monkeypatch.setattr("mtpg.growing.tidy.KEEP_TESTS_EVERY", 8)
    argv = ["experiment", "--plan", str(plan), "--budget", "5", "--unchecked"]
    argv += [f"--train-arg={a}" for a in SETTINGS]
    # two sittings, the second one in slices of about 2 seconds
    assert mtpg_main([*argv, "--generations", "10"]) == 0
    assert mtpg_main([*argv, "--generations", str(GENERATIONS), "--slice", "0.04"]) == 0

    for run in load_plan(plan).groups[0].runs():
        name, seed = run.name, run.seed
        grown = repo / "results" / "runs" / name
        ref = tmp_path / name
        args = ["train", "--preset", "paper", "--seed", str(seed), *run.train_args, *SETTINGS]
        assert mtpg(*args, "--generations", str(GENERATIONS), "--out", str(ref)).returncode == 0
        for table in ("metrics.csv", "tests.csv"):
            assert without_timing((grown / table).read_text()) == without_timing(
                (ref / table).read_text()
            )
        ckpts = sorted(p.name for p in (grown / "checkpoints").iterdir())
        assert ckpts == [f"gen-{GENERATIONS:06d}.json.gz"]
        final = ckpts[0]
        assert (grown / "checkpoints" / final).read_bytes() == (
            ref / "checkpoints" / final
        ).read_bytes()
        assert not (grown / "champions").exists()
        with tarfile.open(grown / "champions.tar.xz") as tar:
            tar.extractall(tmp_path / f"{name}-unpacked", filter="data")
        for graph in (ref / "champions").iterdir():
            packed = tmp_path / f"{name}-unpacked" / "champions" / graph.name
            assert packed.read_bytes() == graph.read_bytes()
        kept = sorted(p.name for p in (grown / "tests").iterdir())
        assert kept == ["archive.tar.xz", "gen-000024"]
        with tarfile.open(grown / "tests" / "archive.tar.xz") as tar:
            tar.extractall(tmp_path / f"{name}-tests", filter="data")
        assert sorted(p.name for p in (tmp_path / f"{name}-tests").iterdir()) == [
            "gen-000008",
            "gen-000016",
        ]
        for folder in ("gen-000008", "gen-000016"):
            for graph in (ref / "tests" / folder).iterdir():
                packed = tmp_path / f"{name}-tests" / folder / graph.name
                assert packed.read_bytes() == graph.read_bytes()
        for graph in (ref / "tests" / "gen-000024").iterdir():
            assert (grown / "tests" / "gen-000024" / graph.name).read_bytes() == graph.read_bytes()
        rows = list(csv.DictReader(open(grown / "provenance.csv")))
        assert len(rows) >= 2 and rows[0]["from_generation"] == "0"
        assert rows[-1]["to_generation"] == str(GENERATIONS)
        for a, b in zip(rows, rows[1:], strict=False):
            assert a["to_generation"] == b["from_generation"]
        assert {r["mtpg_commit"] for r in rows} == {"unchecked"}

    assert _git(repo, "status", "--porcelain").stdout == ""
    log = _git(repo, "log", "--format=%s").stdout.splitlines()
    assert len(log) >= 2 and log[0].startswith("results: grow")
    tracked = _git(repo, "ls-files").stdout
    assert ".lock" not in tracked and ".log" not in tracked


def test_the_last_run_left_takes_the_threads_of_the_runs_that_finished(
    tmp_path, monkeypatch, capsys
):
    """Through ``tools/grow_results.py``, whose flags keep their meaning."""
    repo = _repo(tmp_path, monkeypatch)
    tool = _tool()
    near = ("TPG-seed{seed}", 3, [])  # then seeds 3 and 4
    argv = ["--budget", "5", "--unchecked", "--results", str(repo / "results")]
    monkeypatch.setattr(tool, "PLAN_FILE", _plan(tmp_path, near))
    near_args = [f"--train-arg={a}" for a in SETTINGS]
    assert tool.main([*argv, *near_args, "--generations", "16"]) == 0
    (tmp_path / "plan.toml").write_text(
        (tmp_path / "plan.toml").read_text().replace("seeds = [3]", "seeds = [3, 4]")
    )
    capsys.readouterr()
    # the run begun now is slower, so that it is still running when the other ends
    far_args = [f"--train-arg={a}" for a in SLOW]
    assert tool.main([*argv, *far_args, "--generations", str(GENERATIONS)]) == 0
    assert "TPG-seed4: on 2 threads from " in capsys.readouterr().out

    grown = repo / "results" / "runs" / "TPG-seed4"
    rows = list(csv.DictReader(open(grown / "provenance.csv")))
    # one thread until the other run ended (no row if it had not finished a generation)
    assert [r["workers"] for r in rows] in (["1", "2"], ["2"])
    assert rows[0]["from_generation"] == "0" and rows[-1]["to_generation"] == str(GENERATIONS)
    for a, b in zip(rows, rows[1:], strict=False):
        assert a["to_generation"] == b["from_generation"]
    message = _git(repo, "log", "-1", "--format=%s").stdout
    for r in rows:  # each process's own generations
        assert f"TPG-seed4 {r['from_generation']}->{r['to_generation']}" in message
    ref = tmp_path / "ref"
    args = ["train", "--preset", "paper", "--seed", "4", *SLOW]
    assert mtpg(*args, "--generations", str(GENERATIONS), "--out", str(ref)).returncode == 0
    for table in ("metrics.csv", "tests.csv"):
        assert without_timing((grown / table).read_text()) == without_timing(
            (ref / table).read_text()
        )
    # the same state; the configuration it stores names the threads it ran on
    final = f"gen-{GENERATIONS:06d}.json.gz"
    states = [load_checkpoint(d / "checkpoints" / final) for d in (grown, ref)]
    assert [s["config"].pop("workers") for s in states] == [2, 1]
    assert states[0] == states[1]
