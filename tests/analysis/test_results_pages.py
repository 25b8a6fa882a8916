"""Every committed results page regenerates byte for byte from ``mtpg report --results``.

The full regeneration replays champions (minutes per page), so it is marked slow; the
tables of the study pages are also checked fast, from the scores they store beside them
(``candidates.json``, ``variants.json``, whose keys are sorted: the tasks are put back in
the order of the runs' configuration, as the pages were written).
"""

import json
from pathlib import Path

import pytest

from mtpg.analysis.results import candidates, variants
from mtpg.analysis.results.pages import PAGES, regenerate
from mtpg.io.runconfig import read_run_config

ROOT = Path(__file__).resolve().parents[2]
RESULTS = ROOT / "results"


def _in_run_order(scores: dict, run: Path) -> dict:
    """``{task: x}`` in the order of the run's tasks (base names)."""
    names = [t.split("[")[0] for t in read_run_config(run).evaluation.task_table().names]
    return {t: scores[t] for t in names}


def test_the_candidates_table_is_the_one_its_stored_scores_give():
    page = (RESULTS / "candidates" / "README.md").read_text()
    stored = json.loads((RESULTS / "candidates" / "candidates.json").read_text())
    runs = RESULTS / "candidates" / "runs"
    scores = {
        group: {name: _in_run_order(s, runs / name) for name, s in by_run.items()}
        for group, by_run in stored.items()
    }
    assert candidates.render(page, scores) == page


def test_the_variants_table_is_the_one_its_stored_scores_give():
    page = (ROOT / "docs" / variants.DOC).read_text()
    stored = json.loads((RESULTS / "variants" / "variants.json").read_text())
    scores = {}
    for group, (folder, _) in variants.GROUPS.items():  # the page's order
        by_run = stored[group]
        scores[group] = {
            name: r | {"scores": _in_run_order(r["scores"], RESULTS / folder / name)}
            for name, r in by_run.items()
        }
    assert variants.render(page, scores) == page


def test_every_page_is_a_committed_file():
    assert all((ROOT / p.path).is_file() for p in PAGES.values())


def test_an_unknown_page_and_a_folder_without_runs_are_refused(tmp_path, capsys):
    from mtpg.cli.main import main

    with pytest.raises(ValueError, match="no page 'x'"):
        regenerate(RESULTS, tmp_path, ["x"])
    assert main(["report", "--results", str(tmp_path)]) == 2
    assert "no runs/ folder in it" in capsys.readouterr().err
    assert main(["report", "--results", str(RESULTS), "some-run"]) == 2
    assert main(["report", "--page", "results", "some-run"]) == 2


@pytest.mark.slow
@pytest.mark.parametrize("name", list(PAGES))
def test_the_committed_page_regenerates_byte_for_byte(name, tmp_path):
    before = {p: p.stat().st_mtime_ns for p in (RESULTS / "runs").rglob("*")}
    [written] = regenerate(RESULTS, tmp_path / "results", [name])
    assert written == tmp_path / PAGES[name].path
    assert written.read_bytes() == (ROOT / PAGES[name].path).read_bytes()
    after = {p: p.stat().st_mtime_ns for p in (RESULTS / "runs").rglob("*")}
    assert after == before, "regenerating wrote into a committed run"
