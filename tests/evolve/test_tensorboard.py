"""mtpg train --tensorboard DIR writes event files whose scalars are the run's own numbers."""

import csv
import struct
import sys

import pytest

from mtpg.cli.main import main
from tinyruns import tiny_args

pytest.importorskip("tensorboardX")


def read_events(logdir):
    """Every scalar of every event file in ``logdir``: {tag: {step: value}}.

    Reads the TFRecord framing itself (length, its CRC, the record, its CRC; the CRCs are
    checked) and parses each record with the Event protocol buffer.
    """
    from tensorboardX.crc32c import crc32c
    from tensorboardX.proto.event_pb2 import Event

    def masked(data):
        crc = crc32c(data)
        return (((crc >> 15) | (crc << 17)) + 0xA282EAD8) & 0xFFFFFFFF

    out = {}
    files = sorted(logdir.glob("events.out.tfevents.*"))
    assert files, f"no event file in {logdir}"
    for path in files:
        data = path.read_bytes()
        pos = 0
        while pos < len(data):
            header = data[pos : pos + 8]
            (length,) = struct.unpack("<Q", header)
            (length_crc,) = struct.unpack("<I", data[pos + 8 : pos + 12])
            assert length_crc == masked(header)
            record = data[pos + 12 : pos + 12 + length]
            (record_crc,) = struct.unpack("<I", data[pos + 12 + length : pos + 16 + length])
            assert record_crc == masked(record)
            pos += 16 + length
            event = Event.FromString(record)
            for value in event.summary.value:
                out.setdefault(value.tag, {})[event.step] = value.simple_value
    return out


def rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def test_a_run_s_event_files_hold_its_metrics_and_test_scores(tmp_path):
    run, logdir = tmp_path / "run", tmp_path / "tb"
    args = tiny_args(evaluation__test_interval=2)
    argv = ["train", *args, "--generations", "3", "--out", str(run), "--tensorboard", str(logdir)]
    assert main(argv) == 0
    scalars = read_events(logdir)
    metrics = rows(run / "metrics.csv")
    assert [int(r["generation"]) for r in metrics] == [1, 2, 3]
    for row in metrics:
        g = int(row["generation"])
        assert scalars["train/best/CartPole"][g] == pytest.approx(float(row["best_CartPole"]))
        assert scalars["train/median/CartCentering"][g] == pytest.approx(
            float(row["median_CartCentering"])
        )
        assert scalars["population/teams"][g] == float(row["teams"])
        assert scalars["population/banks_in_use"][g] == float(row["banks_in_use"])
    tests = [r for r in rows(run / "tests.csv") if r["subset"] == "CartPole+CartCentering"]
    assert sorted(scalars["test/all_tasks/CartPole"]) == [2, 3]  # the test points
    for row in tests:
        g = int(float(row["generation"]))
        assert scalars["test/all_tasks/CartPole"][g] == pytest.approx(float(row["test_CartPole"]))

    # resuming adds generations beside the earlier ones, with the same tags
    assert main(["train", "--resume", str(run), "--generations", "4", "--quiet",
                 "--tensorboard", str(logdir)]) == 0  # fmt: skip
    assert sorted(read_events(logdir)["population/teams"]) == [1, 2, 3, 4]


def test_without_the_extra_the_option_is_one_line_and_writes_nothing(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "tensorboardX", None)  # as if not installed
    run = tmp_path / "run"
    argv = ["train", *tiny_args(), "--generations", "1", "--out", str(run), "--tensorboard", "tb"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and 'pip install -e ".[tensorboard]"' in err
    assert not run.exists()


def test_off_by_default(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["train", *tiny_args(), "--generations", "1", "--out", "run"]) == 0
    assert not list(tmp_path.rglob("events.out.tfevents.*"))
