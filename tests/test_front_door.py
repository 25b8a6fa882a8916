"""The README is a front door and docs/index.md a map of every page.

- docs/index.md links every page of ``docs/``;
- the README's quick start is within its first 40 lines, its test command is the one
  ``.ci/run`` runs, and it points at the page for a user's own task;
- the README's Python example runs (with settings that make it take seconds).
"""

import re
from pathlib import Path

import pytest

import mtpg

ROOT = Path(__file__).resolve().parents[1]
README = ROOT / "README.md"
INDEX = ROOT / "docs" / "index.md"


def _links(doc: Path) -> set[Path]:
    """The files a page links, resolved."""
    text = doc.read_text(encoding="utf-8")
    return {(doc.parent / t).resolve() for t in re.findall(r"\]\(([^)\s#]+)(?:#[^)]*)?\)", text)}


def test_the_index_links_every_page_of_docs():
    pages = {p.resolve() for p in (ROOT / "docs").glob("*.md")} - {INDEX.resolve()}
    missing = sorted(p.name for p in pages - _links(INDEX))
    assert not missing, f"docs/index.md does not link {missing}"


def test_the_readme_links_the_index_and_the_results():
    links = _links(README)
    for page in ("docs/index.md", "docs/concepts.md", "docs/api.md", "results/README.md"):
        assert (ROOT / page).resolve() in links, page


def _sh_blocks(text: str) -> list[str]:
    return re.findall(r"```sh\n(.*?)```", text, re.S)


def test_the_quick_start_is_within_the_first_40_lines():
    lines = README.read_text(encoding="utf-8").splitlines()
    start = lines.index("## Quick start")
    fence = [i for i, ln in enumerate(lines) if ln.startswith("```")]
    train, tests = (ln for ln in lines[start:] if ln.startswith("python3 -m venv .venv"))
    assert lines.index(tests) < 40 and start < lines.index(train) < lines.index(tests)
    assert sum(1 for i in fence if i < 40) >= 4  # both command blocks closed by line 40


def test_the_readme_test_command_is_what_ci_runs():
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8").strip().splitlines()[-1]
    [train, tests] = _sh_blocks(README.read_text(encoding="utf-8").split("### After", 1)[0])
    assert tests.strip() == ci
    assert train.strip().startswith("python3 -m venv .venv && .venv/bin/pip install -e . && ")


def test_the_readme_names_the_page_for_your_own_task():
    text = " ".join(README.read_text(encoding="utf-8").split())
    assert "`mtpg train --tasks gym:CartPole-v1` ([docs/own-task.md](docs/own-task.md))" in text


def test_the_readme_python_example_runs(tmp_path, monkeypatch, capsys):
    [block] = re.findall(r"```python\n(.*?)```", README.read_text(encoding="utf-8"), re.S)
    assert block.splitlines()[0] == "import mtpg" and len(block.strip().splitlines()) <= 6
    real = mtpg.preset

    def quick(name, *overrides, **options):  # seconds, not minutes
        small = ("team.root_size=30", "evaluation.test_episodes=5")
        return real(name, *overrides, *small, **{**options, "generations": 3})

    monkeypatch.setattr(mtpg, "preset", quick)
    monkeypatch.chdir(tmp_path)
    scope: dict = {}
    exec(compile(block, str(README), "exec"), scope)
    assert re.search(r"^CartPole +-?[\d.]+ ", capsys.readouterr().out, re.M)
    assert isinstance(scope["policy"], mtpg.Policy)
    assert (tmp_path / "runs/two-tasks/metrics.csv").is_file()


@pytest.mark.parametrize("doc", ["docs/index.md", "docs/concepts.md", "docs/first-run.md"])
def test_the_new_pages_have_one_title(doc):
    titles = [ln for ln in (ROOT / doc).read_text(encoding="utf-8").splitlines() if ln[:2] == "# "]
    assert len(titles) == 1
