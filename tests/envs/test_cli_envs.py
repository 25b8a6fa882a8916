from __future__ import annotations

import pytest

from mtpg.cli.main import main
from mtpg.envs import TASK_NAMES


def test_envs_command_prints_every_task(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["envs"]) == 0
    out = capsys.readouterr().out
    for name in TASK_NAMES:
        assert name in out
    assert "195" in out and "-123.1" in out and "999" in out
