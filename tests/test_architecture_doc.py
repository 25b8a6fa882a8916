"""docs/architecture.md points at files that exist, and README.md links it."""

import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DOC = ROOT / "docs" / "architecture.md"


def test_every_path_in_the_architecture_page_exists():
    text = DOC.read_text(encoding="utf-8")
    links = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", text)
    quoted = re.findall(r"`((?:src|tests|docs|tools)/[^`<>*]+)`", text)
    paths = [(DOC.parent / link).resolve() for link in links]
    paths += [ROOT / p for p in quoted]
    assert len(paths) > 40
    missing = [str(p.relative_to(ROOT)) for p in paths if not p.exists()]
    assert not missing, missing


def test_the_readme_links_the_architecture_page():
    assert "(docs/architecture.md)" in (ROOT / "README.md").read_text(encoding="utf-8")
