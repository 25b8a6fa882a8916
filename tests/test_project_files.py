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
    [article] = citation["references"]
    assert article["type"] == "article"
    assert " ".join(article["title"].split()) == (
        "Evolving Hierarchical Memory-Prediction Machines in Multi-Task Reinforcement Learning"
    )
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


def test_citation_describes_the_software_completely():
    """The keys CFF 1.2.0 requires, plus those that make a software citation whole."""
    citation = yaml.safe_load((ROOT / "CITATION.cff").read_text())
    required = {"cff-version", "message", "title", "authors"}
    assert required <= set(citation) and citation["cff-version"] == "1.2.0"
    assert citation["type"] == "software" and citation["abstract"].strip()
    assert citation["authors"] == [{"name": "the mtpg developers"}]
    assert "references" in citation["message"]
    # nothing unverified: no identifier or address is given without being known
    assert not {"doi", "identifiers", "repository-code", "url"} & set(citation)
    assert not {"doi", "url"} & set(citation["references"][0])
