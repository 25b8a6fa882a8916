"""The README's path for a newcomer: quick start, then "After the demo", as printed.

The commands are taken from the README itself; the training and the experiment get
settings that make them take seconds (the paths they print do not depend on them).
"""

import re
import subprocess
import sys
from pathlib import Path

import pytest

README = (Path(__file__).resolve().parents[2] / "README.md").read_text()
#: Appended to `train` and `experiment`: two tasks, small populations, few generations.
QUICK = ["--tasks", "CartPole,MountainCar", "--set", "team.root_size=30"]


def mtpg_commands(section):
    text = README.split(section, 1)[1]
    block = re.search(r"```sh\n(.*?)```", text, re.S).group(1)
    out = []
    for line in block.splitlines():
        command = line.split(" #")[0].split(" | ")[0].strip()
        command = command.split("&& ")[-1]  # the quick start installs first
        if command.startswith(".venv/bin/mtpg "):
            out.append(command.split()[1:])
    return out


def run(args, cwd):
    res = subprocess.run(
        [sys.executable, "-m", "mtpg", *args], cwd=cwd, capture_output=True, text=True
    )
    assert res.returncode == 0, res.stderr
    return res.stdout, res.stderr


@pytest.mark.slow
def test_quick_start_then_report_evaluate_analyze_show_experiment(tmp_path):
    [train] = mtpg_commands("## Quick start")
    assert train == ["train", "--preset", "demo", "--out", "runs/demo"]
    _, err = run([*train, *QUICK, "--generations", "6"], tmp_path)
    assert "run directory: runs/demo " in err and "done: runs/demo" in err
    steps = mtpg_commands("### After the demo")
    assert [s[0] for s in steps] == ["report", "evaluate", "analyze", "show", "experiment"]
    printed = {}
    for step in steps:
        extra = [*QUICK, "--generations", "2"] if step[0] == "experiment" else []
        printed[step[0]] = run([*step, *extra], tmp_path)[0]  # standard output
    assert printed["report"].strip().endswith("runs/demo/report/index.html")
    assert printed["evaluate"].startswith("runs/demo: all-task champion at generation 6")
    assert printed["analyze"].strip().endswith("runs/demo/analysis/index.html")
    assert printed["show"].startswith("runs/demo: root team")
    assert printed["experiment"].strip().endswith("runs/demo-experiment/report/index.html")
    for path in ("runs/demo/report/index.html", "runs/demo-experiment/TPG-seed0/config.toml"):
        assert (tmp_path / path).is_file()
    assert "mtpg train --resume runs/demo" in README
