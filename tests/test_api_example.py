"""The example of docs/api.md runs as written."""

import re
from pathlib import Path

DOC = Path(__file__).resolve().parents[1] / "docs" / "api.md"


def test_the_api_page_example_runs(tmp_path, monkeypatch, capsys):
    blocks = re.findall(r"```python\n(.*?)```", DOC.read_text(), re.S)
    assert len(blocks) == 1
    monkeypatch.chdir(tmp_path)
    exec(compile(blocks[0], str(DOC), "exec"), {"__name__": "__api_example__"})
    out = capsys.readouterr().out
    assert "stopped after generation 6" in out
    assert re.search(r"CartPole: -?[\d.]+ \+- [\d.]+, normalised -?[\d.]+", out)
    assert (tmp_path / "runs/api-demo/analysis/index.html").is_file()
    metrics = (tmp_path / "runs/api-demo/metrics.csv").read_text().splitlines()
    assert len(metrics) == 11  # header and 10 generations: the resume finished the run
