"""``tools/memorisation_doc.py``: docs/memorisation.md's figures are what the tool writes."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).parents[2]
TOOL = ROOT / "tools" / "memorisation_doc.py"
PAGE = ROOT / "docs" / "memorisation.md"


def test_a_page_without_the_markers_is_refused(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("# no section\n", encoding="utf-8")
    done = subprocess.run(
        [sys.executable, str(TOOL), "--page", str(page)], capture_output=True, text=True
    )
    assert done.returncode != 0 and "no <!-- probe:begin -->" in done.stderr
    assert page.read_text(encoding="utf-8") == "# no section\n"


@pytest.mark.slow
def test_the_committed_page_is_regenerated_unchanged(tmp_path):
    page = tmp_path / "memorisation.md"
    shutil.copy(PAGE, page)
    before = {p: p.stat().st_mtime_ns for p in (ROOT / "results" / "runs").rglob("*")}
    subprocess.run([sys.executable, str(TOOL), "--page", str(page)], check=True)
    assert page.read_text(encoding="utf-8") == PAGE.read_text(encoding="utf-8")
    after = {p: p.stat().st_mtime_ns for p in (ROOT / "results" / "runs").rglob("*")}
    assert after == before, "the probe wrote into a committed run"
