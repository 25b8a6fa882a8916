"""Every help text reads as printed: no doubled percent signs, defaults stated, a version."""

import argparse
import importlib.metadata
import subprocess
import sys

import pytest

from mtpg.cli.main import build_parser


def every_parser(parser):
    yield parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for sub in action.choices.values():
                yield from every_parser(sub)


def test_no_help_text_prints_a_doubled_percent_sign():
    texts = [p.format_help() for p in every_parser(build_parser())]
    assert len(texts) > 10
    for text in texts:
        assert "%%" not in text
    report = next(t for t in texts if t.startswith("usage: mtpg report"))
    assert "95% stratified" in report


@pytest.mark.parametrize("prog", [p.prog for p in every_parser(build_parser())])
def test_no_help_option_prints_a_doubled_percent_sign(prog, capsys):
    from mtpg.cli.main import main

    with pytest.raises(SystemExit) as done:
        main([*prog.split()[1:], "--help"])
    assert done.value.code == 0
    text = capsys.readouterr().out
    assert text.startswith(f"usage: {prog}") and "%%" not in text


def test_version_is_the_installed_package_version():
    out = subprocess.run(
        [sys.executable, "-m", "mtpg", "--version"], capture_output=True, text=True, check=True
    ).stdout
    assert out.strip() == f"mtpg {importlib.metadata.version('mtpg')}"


@pytest.mark.parametrize(
    ("command", "option", "words"),
    [
        ("report", "--out", "inside the first RUN_DIR"),
        ("analyze", "--out", "inside a run directory"),
        ("train", "--workers", "1 paper and robust, 2 demo"),
        ("train", "--no-crossover", "team.p_crossover=0"),
        ("train", "--set", "top-level fields take no section"),
    ],
)
def test_options_state_what_they_do_and_their_defaults(command, option, words):
    parser = next(p for p in every_parser(build_parser()) if p.prog == f"mtpg {command}")
    action = next(a for a in parser._actions if option in a.option_strings)
    assert words in " ".join(action.help.split())
