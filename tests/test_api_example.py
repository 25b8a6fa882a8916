"""The examples of docs/api.md run as written, and the first needs only ``import mtpg``."""

import re
from pathlib import Path

DOC = Path(__file__).resolve().parents[1] / "docs" / "api.md"


def _blocks() -> list[str]:
    return re.findall(r"```python\n(.*?)```", DOC.read_text(encoding="utf-8"), re.S)


def test_the_first_example_imports_mtpg_alone():
    first = _blocks()[0]
    imports = [ln for ln in first.splitlines() if re.match(r"\s*(import|from) ", ln)]
    assert imports == ["import mtpg"]
    assert "mtpg." in first and not re.search(r"\bmtpg\.[a-z_]+\.[a-z_]+", first)


def test_the_api_page_examples_run(tmp_path, monkeypatch, capsys):
    blocks = _blocks()
    assert len(blocks) == 2  # the API, then a policy in a Gymnasium loop
    monkeypatch.chdir(tmp_path)
    scope = {"__name__": "__api_example__"}
    for block in blocks:  # the second continues the first
        exec(compile(block, str(DOC), "exec"), scope)
    out = capsys.readouterr().out
    assert "stopped after generation 6" in out
    assert "runs/api-demo: generation 10 of 10 (finished)" in out
    assert re.search(r"^CartPole +-?[\d.]+ +[\d.]+ +(-?[\d.]+|n/a) +[\d.]+ +", out, re.M)
    assert '{"CartPole": {"mean": ' in out
    assert (tmp_path / "runs/api-demo/analysis/index.html").is_file()
    metrics = (tmp_path / "runs/api-demo/metrics.csv").read_text().splitlines()
    assert len(metrics) == 11  # header and 10 generations: the resume finished the run
