"""Licence, citation and version agree with the package metadata."""

import importlib.metadata
import tomllib
from pathlib import Path

import yaml

import mtpg

ROOT = Path(__file__).resolve().parents[1]


def test_one_version_everywhere():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    citation = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert project["version"] == mtpg.__version__ == str(citation["version"])
    assert importlib.metadata.version("mtpg") == mtpg.__version__


def test_licence_and_citation():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert project["license"] == {"text": "MIT"}
    assert (ROOT / "LICENSE").read_text().startswith("MIT License")
    citation = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    assert citation["license"] == "MIT"
    article = citation["preferred-citation"]
    assert [a["family-names"] for a in article["authors"]] == [
        "Kelly",
        "Voegerl",
        "Banzhaf",
        "Gondro",
    ]
    assert (article["journal"], article["volume"], article["year"]) == (
        "Genetic Programming and Evolvable Machines",
        22,
        2021,
    )
