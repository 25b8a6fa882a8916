"""``results/plan.toml`` and its reader: the committed runs' command lines, bad plans refused.

``grow_results_commands.json`` holds the ``mtpg train`` command line of every run of every
plan as ``tools/grow_results.py`` gave it when its plans were constants of the script
(written from that script, commit deabae2, before the plans became ``results/plan.toml``):
every committed run must be begun, and so grown, exactly as it was. Groups added to the plan
after that commit (``episodes6``) were appended to the file as they were begun.
"""

import json
from pathlib import Path

import pytest

from mtpg.growing.plan import PlanError, load_plan, parse_plan

ROOT = Path(__file__).resolve().parents[2]
PLAN = ROOT / "results" / "plan.toml"
BEFORE = json.loads((Path(__file__).parent / "grow_results_commands.json").read_text())


def test_every_run_of_the_plan_file_begins_as_the_old_constants_began_it(tmp_path):
    plan = load_plan(PLAN)
    assert [g.name for g in plan.groups] == list(BEFORE)
    for group in plan.groups:
        old = BEFORE[group.name]
        assert group.folder == (ROOT / old["folder"]).resolve()
        results = tmp_path / old["folder"]
        runs = group.runs(results)
        assert [(r.name, r.seed) for r in runs] == [(o["name"], o["seed"]) for o in old["runs"]]
        for run, o in zip(runs, old["runs"], strict=True):
            assert run.generations == 1000
            expected = [c.replace("{root}", str(tmp_path)) for c in o["command"]]
            assert run.command(1000, 1, begun=False) == expected, run.name


def test_a_begun_run_resumes_with_its_target_and_threads(tmp_path):
    run = load_plan(PLAN).group("robust").runs(tmp_path)[2]
    assert run.command(1000, 4, begun=True) == [
        "train", "--resume", str(tmp_path / "runs" / "TPG-robust-seed3"),
        "--generations", "1000", "--workers", "4", "--quiet",
    ]  # fmt: skip
    extra = run.command(20, 1, begun=False, extra=("--set", "x.y=1"))
    assert extra[-4:] == ["--set", "x.y=1", "--out", str(run.path)]


def test_folders_are_relative_to_the_plan_file_and_seeds_can_interleave(tmp_path):
    (tmp_path / "plan.toml").write_text(
        '[[groups]]\nname = "g"\npreset = "demo"\nfolder = "sub"\ngenerations = 5\n'
        "by_seed = true\n"
        '[[groups.runs]]\nname = "a{seed}"\nseeds = [2, 1]\n'
        '[[groups.runs]]\nname = "b{seed}"\nseeds = [1, 2]\nargs = ["--no-memory"]\n'
    )
    [group] = load_plan(tmp_path / "plan.toml").groups
    assert group.folder == tmp_path / "sub"
    assert [r.name for r in group.runs()] == ["a1", "b1", "a2", "b2"]
    assert group.runs()[1].train_args == ("--no-memory",)


GOOD = '[[groups]]\nname = "g"\npreset = "demo"\ngenerations = 5\n'
GOOD_RUNS = '[[groups.runs]]\nname = "r{seed}"\nseeds = [1]\n'


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("groups = 3", "plan: groups: expected one or more [[groups]] tables"),
        ("x = [", "plan: not valid TOML"),
        (GOOD, "plan: groups[0].runs: expected one or more"),
        (GOOD.replace("5", '"5"') + GOOD_RUNS, "plan: groups[0].generations: expected an integer"),
        (GOOD + "color = 1\n" + GOOD_RUNS, "plan: groups[0].color: unknown field"),
        (GOOD.replace('preset = "demo"\n', "") + GOOD_RUNS, "plan: groups[0].preset: expected"),
        (GOOD + GOOD_RUNS.replace("[1]", "[1, 1]"), "plan: groups[0].runs[0].seeds: expected"),
        (
            GOOD + GOOD_RUNS.replace("{seed}", ""),
            "plan: groups[0].runs[0].name: expected a pattern",
        ),
        (GOOD + GOOD_RUNS + 'interface = "x"\n', "plan: groups[0].runs[0].interface: no interface"),
        (GOOD + GOOD_RUNS + "args = [1]\n", "plan: groups[0].runs[0].args: expected a list"),
        (GOOD + GOOD_RUNS + GOOD + GOOD_RUNS, "plan: groups: the name 'g' is given twice"),
        (
            GOOD + GOOD_RUNS + GOOD.replace('"g"', '"h"') + GOOD_RUNS,
            "plan: groups: the run 'r1' is planned twice",
        ),
        (
            '[interfaces.i]\nA = "A[x=1]"\n'
            + GOOD
            + GOOD_RUNS
            + 'interface = "i"\ntasks = ["B"]\n',
            "plan: groups[0].runs[0].tasks: 'B' is not in interface 'i'",
        ),
    ],
)
def test_a_bad_plan_is_refused_in_one_line_naming_the_field(tmp_path, text, message):
    with pytest.raises(PlanError) as caught:
        parse_plan(text, tmp_path)
    assert str(caught.value).startswith(message)
    assert "\n" not in str(caught.value)


def test_an_interface_gives_its_task_specs_in_order(tmp_path):
    text = '[interfaces.i]\nA = "A[x=1]"\nB = "B"\n' + GOOD + GOOD_RUNS + 'interface = "i"\n'
    [run] = parse_plan(text, tmp_path).groups[0].runs()
    assert run.train_args == ("--tasks", "A[x=1],B")


def test_the_command_line_names_a_plan_error_in_one_line(tmp_path, capsys):
    from mtpg.cli.main import main

    (tmp_path / "plan.toml").write_text(GOOD)
    assert main(["experiment", "--plan", str(tmp_path / "plan.toml"), "--budget", "1"]) == 2
    err = capsys.readouterr().err
    assert (
        err == "mtpg experiment: error: plan.toml: groups[0].runs: expected one or more "
        "[[groups.runs]] tables\n"
    )


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--plan", str(PLAN), "--budget", "1", "--seeds", "2"], "--seeds is an option"),
        (["--plan", str(PLAN), "--budget", "1", "--preset", "paper"], "--preset is an"),
        (["--plan", str(PLAN)], "--plan needs --budget MINUTES > 0"),
        (["--plan", str(PLAN), "--budget", "1", "--results", "x"], "--results needs"),
        (["--plan", str(PLAN), "--budget", "1", "--only", "x"], "no group 'x'"),
        (["--out", "x", "--budget", "1"], "--budget is an option of mtpg experiment --plan"),
        (["--seeds", "2"], "--out DIR is required (or --plan FILE)"),
    ],
)
def test_the_two_modes_of_mtpg_experiment_keep_their_options_apart(argv, message, capsys):
    from mtpg.cli.main import main

    assert main(["experiment", *argv]) == 2
    assert message in capsys.readouterr().err
