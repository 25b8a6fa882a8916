"""The documents quote only paths that exist, options that ``--help`` lists, no stale counts.

Every Markdown file of the project (README.md, CHANGELOG.md, docs/*.md, examples/) is read:

- a relative link or a quoted repository path (``src/...``, ``docs/...``, ``tools/...``,
  ...) must exist in the checkout;
- an option written after ``mtpg COMMAND`` in a code span, a command block or a row of the
  README's command table must be an option of that command's parser;
- counts that change with every commit (tests in the suite, lines of code) are not quoted;
- a link's anchor names a heading of its page; examples import no ``mtpg.cli`` name;
- figures quoted from the code (instruction set, subsets, bootstrap settings, seeds) are
  the code's, and the README's results are those ``mtpg report --results`` wrote.

Other checked quotes live beside what they check: the presets table
(``tests/test_presets_documented.py``) and the progress line of docs/report.md
(``tests/cli/test_progress_doc.py``).
"""

import argparse
import re
from pathlib import Path

import pytest

from mtpg.cli.main import build_parser

ROOT = Path(__file__).resolve().parents[1]
DOCS = sorted(
    [ROOT / "README.md", ROOT / "CHANGELOG.md", *(ROOT / "docs").glob("*.md")]
    + list((ROOT / "examples").rglob("*.md"))
)
#: Top-level folders of the repository a document may point into.
TOP = ("src", "tests", "docs", "tools", "examples", "benchmarks", "results", "spec")
#: Placeholders of a path pattern (``gen-NNNNNN``, ``<task>``, ``*``, ``...``).
PATTERN = re.compile(r"[<>*{}]|NNN|\.\.\.|\bRUN\b|X+\b")


def _doc_id(path: Path) -> str:
    return str(path.relative_to(ROOT))


def _without_fenced_output(text: str) -> str:
    """The text without ``text`` blocks (printed output may name paths of a run)."""
    return re.sub(r"```text\n.*?```", "", text, flags=re.S)


def quoted_paths(doc: Path) -> list[tuple[str, Path]]:
    """``(as written, resolved path)`` of every link and quoted repository path."""
    text = _without_fenced_output(doc.read_text(encoding="utf-8"))
    out = []
    for link in re.findall(r"\]\(([^)\s#]+)(?:#[^)]*)?\)", text):
        if re.match(r"[a-z]+:", link):  # a web address or mail link
            continue
        out.append((link, (doc.parent / link).resolve()))
    for path in re.findall(r"`((?:" + "|".join(TOP) + r")/[^`\s]*)`", text):
        if PATTERN.search(path):
            continue
        out.append((path, ROOT / path.split("::")[0].rstrip(":")))
    return out


@pytest.mark.parametrize("doc", DOCS, ids=_doc_id)
def test_every_path_a_document_quotes_exists(doc):
    missing = [written for written, path in quoted_paths(doc) if not path.exists()]
    assert not missing, f"{_doc_id(doc)} quotes paths that do not exist: {missing}"


def _commands() -> dict[str, set[str]]:
    """The options of every ``mtpg`` command (``bench engine`` as ``bench``: its subcommand)."""
    parser = build_parser()
    out: dict[str, set[str]] = {"": set(parser._option_string_actions)}
    stack = [("", parser)]
    while stack:
        name, p = stack.pop()
        for action in p._actions:
            if isinstance(action, argparse._SubParsersAction):
                for sub, sp in action.choices.items():
                    full = f"{name} {sub}".strip()
                    out[full] = set(sp._option_string_actions)
                    stack.append((full, sp))
    return out


COMMANDS = _commands()


def _command_of(words: list[str]) -> str | None:
    """The longest known command the words after ``mtpg`` start with."""
    for n in (2, 1):
        name = " ".join(words[:n])
        if name in COMMANDS:
            return name
    return None


def mtpg_invocations(doc: Path) -> list[tuple[str, list[str], str]]:
    """``(command, options, where)`` of every ``mtpg ...`` the document writes."""
    text = doc.read_text(encoding="utf-8")
    pieces = re.findall(r"`([^`\n]+)`", text)  # inline code spans
    for block in re.findall(r"```(?:sh|bash|console|text)?\n(.*?)```", text, flags=re.S):
        pieces += block.splitlines()
    pieces += [line for line in text.splitlines() if line.startswith("| `mtpg ")]  # the table
    out = []
    for piece in pieces:
        for match in re.finditer(
            r"(?:^|[\s/(`])mtpg\s+([a-z][\w-]*(?:\s+[a-z][\w-]*)?)(.*)", piece
        ):
            words = match.group(1).split()
            command = _command_of(words)
            if command is None:
                continue
            rest = " ".join(words[len(command.split()) :]) + match.group(2)
            rest = rest.split(" | ")[0] if not piece.startswith("| `mtpg") else rest
            rest = re.split(r"\bmtpg\s", rest)[0]  # the next command starts its own check
            options = re.findall(r"(?<![\w-])(--[a-z][\w-]*)", rest)
            out.append((command, options, piece.strip()[:80]))
    return out


@pytest.mark.parametrize("doc", DOCS, ids=_doc_id)
def test_every_option_a_document_gives_a_command_is_in_its_help(doc):
    unknown = [
        f"mtpg {command} {option} ({where})"
        for command, options, where in mtpg_invocations(doc)
        for option in options
        if option not in COMMANDS[command]
    ]
    assert not unknown, f"{_doc_id(doc)}: options that --help does not list: {unknown}"


def test_the_option_check_sees_the_documents_commands():
    found = {c for doc in DOCS for c, _, _ in mtpg_invocations(doc)}
    assert {"train", "evaluate", "report", "export", "experiment", "bench engine"} <= found
    readme = {
        o for c, opts, _ in mtpg_invocations(ROOT / "README.md") if c == "train" for o in opts
    }
    assert {"--preset", "--resume", "--no-memory", "--set"} <= readme


#: Counts of a changing code base: tests in the suite, lines of code.
VOLATILE = re.compile(r"\b\d[\d,]* (?:tests|test functions|lines of (?:code|Python))\b")


@pytest.mark.parametrize("doc", DOCS, ids=_doc_id)
def test_no_document_quotes_counts_that_change_with_every_commit(doc):
    found = VOLATILE.findall(doc.read_text(encoding="utf-8"))
    assert not found, f"{_doc_id(doc)} quotes {found}"


def test_the_checks_catch_a_missing_path_a_foreign_option_and_a_count(tmp_path):
    doc = tmp_path / "bad.md"
    doc.write_text(
        "See [x](nowhere.md) and `tools/no_such_tool.py`.\n\n"
        "```sh\nmtpg train --preset demo --no-such-option\n```\n\n"
        "The suite runs 1,207 tests.\n"
    )
    assert [w for w, p in quoted_paths(doc) if not p.exists()] == [
        "nowhere.md",
        "tools/no_such_tool.py",
    ]
    [(command, options, _)] = mtpg_invocations(doc)
    assert command == "train" and "--no-such-option" not in COMMANDS[command]
    assert VOLATILE.findall(doc.read_text()) == ["1,207 tests"]


def _slug(heading: str) -> str:
    """The anchor a Markdown heading gets (GitHub's rule: lower case, spaces to hyphens)."""
    text = re.sub(r"[^\w\- ]", "", heading.strip().lower())
    return text.replace(" ", "-")


@pytest.mark.parametrize("doc", DOCS, ids=_doc_id)
def test_every_anchor_a_document_links_exists(doc):
    text = _without_fenced_output(doc.read_text(encoding="utf-8"))
    broken = []
    for target, anchor in re.findall(r"\]\(([^)\s#]*)#([^)\s]+)\)", text):
        if re.match(r"[a-z]+:", target):
            continue
        page = (doc.parent / target).resolve() if target else doc
        if page.suffix != ".md" or not page.exists():
            continue
        headings = re.findall(r"^#+ (.+)$", page.read_text(encoding="utf-8"), flags=re.M)
        if anchor not in {_slug(h) for h in headings}:
            broken.append(f"{target}#{anchor}")
    assert not broken, f"{_doc_id(doc)} links anchors that no heading has: {broken}"


@pytest.mark.parametrize("doc", DOCS, ids=_doc_id)
def test_examples_import_only_what_is_public(doc):
    """docs/api.md: ``mtpg.cli.*`` is not public, so no example imports from it."""
    blocks = re.findall(r"```python\n(.*?)```", doc.read_text(encoding="utf-8"), flags=re.S)
    imports = [ln for b in blocks for ln in b.splitlines() if re.match(r"\s*from mtpg\.cli", ln)]
    assert not imports, f"{_doc_id(doc)}: {imports}"


def test_the_results_summary_quotes_the_committed_results_as_results_readme_has_them():
    """The paragraph's numbers (docs/results-summary.md) are those the results page has."""
    summary = (ROOT / "docs" / "results-summary.md").read_text(encoding="utf-8")
    results = (ROOT / "results" / "README.md").read_text(encoding="utf-8")
    item = summary.split("- **The paper's experiment, in the repository**", 1)[1]
    item = " ".join(item.split("\n#", 1)[0].split())
    six = r"(-?\d\.\d\d)" + r" / (-?\d\.\d\d)" * 5
    rows = re.findall(six, item)
    assert len(rows) >= 4
    for row in rows:  # each is a row of one of the page's per-task tables
        assert "| " + " | ".join(row) + " |" in results, row
    [iqm] = re.findall(r"\d\.\d\d \[\d\.\d\d, \d\.\d\d\]", item)
    assert f"IQM over TPG seeds and all tasks: {iqm}." in results


@pytest.mark.parametrize("doc", ["README.md", "docs/results-summary.md"])
def test_the_readme_answers_does_it_reproduce_the_paper_as_the_results_page_does(doc):
    """The README's answer is the page's, word for word (``robust_section.answer`` writes it)."""
    readme = " ".join((ROOT / doc).read_text(encoding="utf-8").split())
    results = (ROOT / "results" / "README.md").read_text(encoding="utf-8")
    [answer] = [ln for ln in results.splitlines() if ln.startswith("**Does it reproduce")]
    assert f"- {answer} " in readme


def test_the_architecture_page_names_the_runs_mtpg_experiment_plans():
    from mtpg.evolve.experiment import plan

    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    named = set(re.findall(r"`(TPG[\w-]*-seed\d+)`", text))
    planned = {run.path.name for run in plan(Path("x"), 1, 1)}
    assert named and named <= planned, named - planned


def _flat(path: str) -> str:
    return " ".join((ROOT / path).read_text(encoding="utf-8").split())


def test_constants_the_documents_quote_are_the_code_s():
    """Figures of the code itself, quoted in prose, equal the code's constants."""
    from mtpg.analysis.runs import statistics
    from mtpg.config import build_config
    from mtpg.envs.taskset import episode_seeds as protocol
    from mtpg.model.instructions import CONSTANTS, OP_NAMES, RegisterLayout

    layout = RegisterLayout()
    concepts = _flat("docs/concepts.md")
    assert (
        f"({len(OP_NAMES)} operations, {layout.n_registers} private registers, "
        f"{len(CONSTANTS)} constants)" in concepts
    )
    assert f"**Memory bank**: {layout.n_memory} registers" in concepts
    paper = build_config("paper")
    assert paper.evaluation.n_subsets == 63 and "each of the 63 non-empty sets" in concepts
    new_roots = paper.evaluation.n_subsets * paper.elites_per_subset
    assert f"{new_roots:,} new roots per generation" in _flat("docs/first-run.md")
    report = _flat("docs/report.md")
    assert f"over {statistics.N_RESAMPLES:,} resamples" in report
    assert f"({statistics.N_RESAMPLES_PROFILE:,} resamples per threshold)" in report
    assert f"generator is seeded (seed {statistics.BOOTSTRAP_SEED})" in report
    assert f"`{protocol.TEST_SEED_BASE:,} + k`" in report
    assert f"`{protocol.RANDOM_SEED_BASE:,} + i`" in report
