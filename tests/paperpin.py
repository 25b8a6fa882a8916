"""The pinned short run of the ``paper`` preset: what the committed results rely on.

The runs in ``results/`` grow over many sittings and commits with ``mtpg train --resume``.
That is only exact if every later commit keeps the ``paper`` preset's semantics, its
random stream and its checkpoint format readable. ``tests/data/paper-pin/`` holds a short
paper-preset run (seed 1, six generations, a checkpoint every three and a test point at
five) made by the commit named in its ``COMMIT`` file:

* ``run-gen3/``: the run directory as committed after generation 3 (checkpoint included);
* ``expected/``: ``metrics.csv`` without its timing columns and ``tests.csv`` after
  generation 6, and ``state.json``: digests of the whole run state (population, scores,
  elites, champions, generator) after generations 3 and 6.

``tests/evolve/test_paper_pin.py`` reruns it from scratch and resumes the stored
checkpoint. A change that makes those tests fail alters the paper preset: it must say so,
regenerate the pin (``python tests/paperpin.py``, which also writes ``COMMIT``) and restart
the runs in ``results/`` from generation 0 (``results/README.md``).
"""

from __future__ import annotations

import csv
import hashlib
import io
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

PIN = Path(__file__).parent / "data" / "paper-pin"
#: The pinned run: the ``paper`` preset with seed 1, a checkpoint every three generations.
TRAIN_ARGS = ["--preset", "paper", "--seed", "1", "--workers", "2", "--quiet"]
TRAIN_SETTINGS = ["--set", "checkpoint_interval=3"]
#: Generations of the stored run directory and of the whole pinned run.
MID, END = 3, 6
#: Parts of a checkpoint that make up the run state (the rest is identity and settings).
STATE_KEYS = ("generation", "population", "scores", "elites", "champions", "rng")


def mtpg(*args: str) -> subprocess.CompletedProcess:
    """``python -m mtpg ARGS``, output captured, failing loudly."""
    env = {k: v for k, v in os.environ.items() if k != "MTPG_TEST_STOP_AT"}
    done = subprocess.run(
        [sys.executable, "-m", "mtpg", *args], env=env, capture_output=True, text=True
    )
    if done.returncode != 0:
        raise RuntimeError(f"mtpg {' '.join(args)}: exit {done.returncode}: {done.stderr}")
    return done


def metrics_without_timing(path: Path) -> list[list[str]]:
    """The rows of a ``metrics.csv``, timing columns removed."""
    from mtpg.evolve.columns import TIMING_COLUMNS

    rows = list(csv.reader(io.StringIO(path.read_text())))
    keep = [i for i, c in enumerate(rows[0]) if c not in TIMING_COLUMNS]
    return [[r[i] for i in keep] for r in rows]


def state_digest(run_dir: Path, generation: int) -> str:
    """SHA-256 of the canonical JSON of a checkpoint's run state."""
    from mtpg.io.checkpoint import load_checkpoint

    ckpt = Path(run_dir) / "checkpoints" / f"gen-{generation:06d}.json.gz"
    payload = load_checkpoint(ckpt)
    state = {k: payload[k] for k in STATE_KEYS}
    text = json.dumps(state, sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


def write_pin() -> None:
    """Runs the pinned run and writes ``tests/data/paper-pin/`` anew."""
    with tempfile.TemporaryDirectory() as tmp:
        run = Path(tmp) / "run"
        mtpg("train", *TRAIN_ARGS, *TRAIN_SETTINGS, "--generations", str(MID), "--out", str(run))
        if PIN.exists():
            shutil.rmtree(PIN)
        (PIN / "expected").mkdir(parents=True)
        shutil.copytree(run, PIN / "run-gen3", ignore=shutil.ignore_patterns(".lock"))
        mid = state_digest(run, MID)
        mtpg("train", "--resume", str(run), "--quiet", "--generations", str(END))
        rows = metrics_without_timing(run / "metrics.csv")
        with open(PIN / "expected" / "metrics.csv", "w", newline="") as f:
            csv.writer(f).writerows(rows)
        shutil.copy(run / "tests.csv", PIN / "expected" / "tests.csv")
        digests = {str(MID): mid, str(END): state_digest(run, END)}
        (PIN / "expected" / "state.json").write_text(json.dumps(digests, indent=1) + "\n")
    commit = subprocess.run(
        ["git", "rev-parse", "HEAD"], capture_output=True, text=True, cwd=PIN
    ).stdout.strip()
    (PIN / "COMMIT").write_text(f"{commit}\n")


if __name__ == "__main__":
    write_pin()
    print(f"wrote {PIN}")
