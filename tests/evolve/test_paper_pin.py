"""The ``paper`` preset's semantics, random stream and checkpoint format are pinned.

The committed runs of ``results/`` are continued by later commits with
``mtpg train --resume``; these two tests fail for any change that would make such a
continuation differ from an uninterrupted run of the commit that started it
(``tests/paperpin.py`` says what is stored and what to do when they fail).
"""

import json
import shutil

from mtpg.io.runschema import SCHEMA_FILE, UNVERSIONED, read_schema
from paperpin import (
    END,
    MID,
    PIN,
    TRAIN_ARGS,
    TRAIN_SETTINGS,
    metrics_without_timing,
    mtpg,
    state_digest,
)


def _expected():
    rows = metrics_without_timing(PIN / "expected" / "metrics.csv")
    digests = json.loads((PIN / "expected" / "state.json").read_text())
    return rows, digests


def test_a_fresh_paper_run_repeats_the_pinned_one(tmp_path):
    run = tmp_path / "run"
    mtpg("train", *TRAIN_ARGS, *TRAIN_SETTINGS, "--generations", str(MID), "--out", str(run))
    rows, digests = _expected()
    assert metrics_without_timing(run / "metrics.csv") == rows[: MID + 1]
    assert state_digest(run, MID) == digests[str(MID)]


def test_the_pinned_checkpoint_resumes_exactly(tmp_path):
    run = tmp_path / "run"
    shutil.copytree(PIN / "run-gen3", run)
    mtpg("train", "--resume", str(run), "--quiet", "--workers", "1", "--generations", str(END))
    rows, digests = _expected()
    assert metrics_without_timing(run / "metrics.csv") == rows
    assert (run / "tests.csv").read_text() == (PIN / "expected" / "tests.csv").read_text()
    assert state_digest(run, END) == digests[str(END)]
    # written before format.json existed, the run now records the version it is
    assert (run / SCHEMA_FILE).is_file() and read_schema(run) == UNVERSIONED
