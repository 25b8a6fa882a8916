"""``tools/check_resume.py``: a committed run resumed from an earlier commit is compared."""

import csv
import subprocess

from stopruns import SETTINGS
from toolmodules import load_tool


def _tool(name):
    return load_tool(name)


def _git(repo, *args):
    return subprocess.run(["git", *args], cwd=repo, capture_output=True, text=True, check=True)


def test_resume_from_an_earlier_commit_is_checked(tmp_path, monkeypatch, capsys):
    for key in ("AUTHOR", "COMMITTER"):
        monkeypatch.setenv(f"GIT_{key}_NAME", "mtpg tests")
        monkeypatch.setenv(f"GIT_{key}_EMAIL", "tests@mtpg.invalid")
    repo = tmp_path / "repo"
    results = repo / "results"
    results.mkdir(parents=True)
    _git(repo, "init", "-q")
    _git(repo, "commit", "-q", "--allow-empty", "-m", "start")
    from mtpg.cli.main import main as mtpg_main

    plan = tmp_path / "plan.toml"  # outside the repository, its folder inside
    plan.write_text(
        '[[groups]]\nname = "paper"\npreset = "paper"\nfolder = "repo/results"\n'
        'generations = 1000\n[[groups.runs]]\nname = "TPG-seed{seed}"\nseeds = [3]\n'
    )
    argv = ["experiment", "--plan", str(plan), "--budget", "5", "--unchecked"]
    argv += [f"--train-arg={a}" for a in SETTINGS]
    assert mtpg_main([*argv, "--generations", "5"]) == 0  # a commit at generation 5
    assert mtpg_main([*argv, "--generations", "9"]) == 0  # and one at 9

    check = _tool("check_resume")
    assert check.main(["--results", str(results), "--record"]) == 0
    out = capsys.readouterr().out
    # from generation 5 to the next test point, 6 (test_interval 2)
    assert "TPG-seed3: resumed 5 -> 6 from" in out and "EQUAL" in out
    (row,) = csv.DictReader((results / "resume_check.csv").open())
    assert (row["from_generation"], row["to_generation"], row["result"]) == ("5", "6", "equal")
    first_commit = _git(repo, "log", "--format=%H").stdout.split()[1]
    assert row["resumed_from_commit"] == first_commit

    # a committed row that a resume does not repeat is found
    metrics = results / "runs" / "TPG-seed3" / "metrics.csv"
    lines = metrics.read_text().splitlines()
    row = lines[6].split(",")  # generation 6
    row[2] = str(int(row[2]) + 1)  # teams
    lines[6] = ",".join(row)
    metrics.write_text("\n".join(lines) + "\n")
    _git(repo, "commit", "-q", "-m", "tamper", "--", str(metrics))
    assert check.main(["--results", str(results), "--generations", "2"]) == 1
    assert "DIFFERENT at generations [6]" in capsys.readouterr().out
