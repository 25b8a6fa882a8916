"""``mtpg.analysis.results.memorisation_page``: docs/memorisation.md's section, rewritten."""

import pytest

from mtpg.analysis.results.memorisation_page import write


def test_a_page_without_the_markers_is_refused(tmp_path):
    page = tmp_path / "docs" / "memorisation.md"
    page.parent.mkdir()
    page.write_text("# no section\n", encoding="utf-8")
    (tmp_path / "results" / "runs").mkdir(parents=True)
    with pytest.raises(ValueError, match="no <!-- probe:begin -->"):
        write(tmp_path / "results")
    assert page.read_text(encoding="utf-8") == "# no section\n"
