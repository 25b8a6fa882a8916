"""Every preset is named wherever presets are, and the presets table is the code's."""

import re
from pathlib import Path

import pytest

from mtpg.cli.main import main
from mtpg.config import build_config, to_dict
from mtpg.presets import PRESETS

ROOT = Path(__file__).resolve().parents[1]


def _help(command, capsys):
    with pytest.raises(SystemExit):
        main([command, "--help"])
    return " ".join(capsys.readouterr().out.split())


@pytest.mark.parametrize("command", ["train", "experiment"])
def test_help_names_every_preset(command, capsys):
    text = _help(command, capsys)
    names = list(PRESETS)
    assert f"{', '.join(names[:-1])} or {names[-1]}" in text


@pytest.mark.parametrize(
    "doc", ["README.md", "docs/training.md", "docs/architecture.md", "CHANGELOG.md"]
)
def test_documents_about_presets_name_every_preset(doc):
    text = (ROOT / doc).read_text(encoding="utf-8")
    for name in PRESETS:
        assert f"`{name}`" in text, f"{doc} does not name the {name} preset"


def _presets_table():
    text = (ROOT / "docs" / "training.md").read_text(encoding="utf-8")
    section = text.split("## Presets", 1)[1].split("\n\n", 2)[1]
    rows = [
        [c.strip() for c in line.strip("|").split("|")]
        for line in section.splitlines()
        if line.startswith("|")
    ]
    return rows[0], rows[2:]


def test_the_presets_table_has_a_column_per_preset_and_its_values_are_the_code_s():
    header, rows = _presets_table()
    assert header[1:] == [f"`{name}`" for name in PRESETS]
    checked = 0
    for row in rows:
        fields = re.findall(r"`([\w.]+)`", row[0]) or [row[0]]
        if fields[0] in ("tasks", "everything else"):
            continue
        section = fields[0].rpartition(".")[0]
        keys = [f if "." in f or not section else f"{section}.{f}" for f in fields]
        for name, cell in zip(PRESETS, row[1:], strict=True):
            settings = to_dict(build_config(name))
            numbers = [int(v) for v in re.findall(r"^\d+|(?<= / )\d+", cell)]
            assert len(numbers) == len(keys), (row, cell)
            for key, number in zip(keys, numbers, strict=True):
                value = settings
                for part in key.split("."):
                    value = value[part]
                assert value == number, f"{key} of {name}: table {number}, code {value}"
                checked += 1
    assert checked >= 8 * len(PRESETS)
