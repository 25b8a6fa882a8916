"""The robust audit's demo-scale test: its block, written from the candidates' stored scores."""

import json
from pathlib import Path

from mtpg.analysis.results import audit_trial

ROOT = Path(__file__).resolve().parents[2]
TASKS = ["CartPole", "Acrobot", "CartCentering", "Pendulum", "MountainCar", "Car"]


def _arm(name: str, level: float, seeds: int = 5) -> dict:
    return {
        f"{name}-seed{s}": {t: level + 0.01 * s + 0.001 * i for i, t in enumerate(TASKS)}
        for s in range(1, seeds + 1)
    }


def _runs(folder: Path, scored: dict) -> Path:
    """A runs folder with a two-generation ``metrics.csv`` for each run of ``scored``."""
    for arm in scored.values():
        for name in arm:
            (folder / name).mkdir(parents=True)
            (folder / name / "metrics.csv").write_text("generation,decisions\n1,100\n2,300\n")
    return folder


def test_an_arm_with_no_finished_run_is_said_so():
    block = audit_trial.trial_block({"demo-resample10": _arm("demo-resample10", 0.5)}, Path("."))
    assert block[-1] == "No run of `demo-resample10-train6` has finished yet (0 of 5)."


def test_intervals_apart_and_overlapping_give_different_verdicts(tmp_path):
    old, new = audit_trial.ARMS
    apart = {old: _arm(old, 0.2), new: _arm(new, 0.8)}
    block = audit_trial.trial_block(apart, _runs(tmp_path / "a", apart))
    assert "| demo-resample10-train6 | 6 | 5 of 5 |" in "\n".join(block)
    assert "| 200 |" in "\n".join(block)  # mean decisions per generation of metrics.csv
    assert "beats it with the intervals apart" in block[-1] and "Provisional" not in block[-1]
    close = {old: _arm(old, 0.5), new: _arm(new, 0.5, seeds=3)}
    block = audit_trial.trial_block(close, _runs(tmp_path / "b", close))
    assert "does not beat it" in block[-1] and block[-1].endswith(
        "Provisional: 3 of 5 runs per arm."
    )


def test_the_committed_block_is_the_one_the_stored_scores_give(tmp_path):
    page = ROOT / "docs" / "robust-audit.md"
    copy = tmp_path / "robust-audit.md"
    copy.write_text(page.read_text())
    audit_trial.write_trial(ROOT / "results", copy)
    assert copy.read_text() == page.read_text()
    assert json.loads((ROOT / "results" / "candidates" / "candidates.json").read_text())
