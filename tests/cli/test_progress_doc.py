"""docs/report.md's progress line is what its command prints, but for the timing columns."""

import re
import shlex
import subprocess
import sys
from pathlib import Path

DOC = (Path(__file__).resolve().parents[2] / "docs" / "report.md").read_text(encoding="utf-8")
SECTION = DOC.split("## Progress while training", 1)[1]
#: The columns that depend on the machine: seconds per generation, time left, decisions/s.
TIMING = re.compile(r"[\d.]+ s/gen \| left \S+ \| [\d.]+[kM]? dec/s")


def test_the_documented_progress_line_is_printed_by_the_documented_command(tmp_path):
    command = re.search(r"```sh\n(mtpg train [^\n]+)\n```", SECTION).group(1)
    quoted = re.search(r"```text\n(gen [^\n]+)\n```", SECTION).group(1)
    args = shlex.split(command)[1:]
    res = subprocess.run(
        [sys.executable, "-m", "mtpg", *args], cwd=tmp_path, capture_output=True, text=True
    )
    assert res.returncode == 0, res.stderr
    generation = quoted.split()[1]
    [printed] = [ln for ln in res.stderr.splitlines() if ln.startswith(f"gen {generation} ")]
    assert TIMING.search(printed) and TIMING.search(quoted)
    assert TIMING.sub("T", printed) == TIMING.sub("T", quoted)
