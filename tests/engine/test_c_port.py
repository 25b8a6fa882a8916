"""The C yardstick of the engine benchmark does the very same work as the engine."""

import numpy as np
import pytest

from mtpg.bench import c_port
from mtpg.bench.workload import drive, make_workload

pytestmark = pytest.mark.skipif(c_port.find_compiler() is None, reason="no C compiler")


@pytest.fixture(scope="module")
def port(tmp_path_factory):
    return c_port.build(tmp_path_factory.mktemp("port"))


@pytest.mark.parametrize(("teams", "programs", "instructions"), [(3, 10, 10), (5, 4, 30)])
def test_port_equals_engine_job_by_job(port, tmp_path, teams, programs, instructions):
    work = make_workload(40, teams, programs, instructions, episodes=3, seed=5)
    engine = drive(work, 1).result
    data = tmp_path / "w.bin"
    c_port.write_input(work, data)
    run = c_port.run_port(port, data, len(work.job_roots))
    c_port.check(engine, run.result)
    assert run.cpu_seconds >= 0
    assert engine.steps.sum() > 40 * 3  # real episodes were played
    assert np.any(engine.teams > engine.steps)  # some decisions crossed teams


def test_check_names_the_first_differing_job(port, tmp_path):
    work = make_workload(10, episodes=2, seed=1)
    engine = drive(work, 1).result
    data = tmp_path / "w.bin"
    c_port.write_input(work, data)
    run = c_port.run_port(port, data, len(work.job_roots))
    run.result.instructions[7] += 1
    with pytest.raises(RuntimeError, match="job 7's instructions"):
        c_port.check(engine, run.result)


@pytest.mark.parametrize("flags", [("-Ofast",), ("-O2", "-ffast-math")])
def test_fast_math_yardstick_is_refused(tmp_path, flags):
    with pytest.raises(ValueError, match="fast-math"):
        c_port.build(tmp_path, flags=flags)


def test_limits_are_compile_time_constants_checked_against_the_input(tmp_path):
    """The limits are -D constants; an input with other limits is refused, not used."""
    src = c_port.source()
    assert "static double BIG" not in src and "MTPG_BIG" in src
    assert "memset(W, 0, g->R" not in src  # no memset per program run
    exe = c_port.build(tmp_path)
    work = make_workload(5, episodes=2, seed=2)
    data = tmp_path / "w.bin"
    c_port.write_input(work, data)
    raw = bytearray(data.read_bytes())
    raw[13 * 8 : 14 * 8] = np.float64(1e9).tobytes()  # BIG, right after the 13-word header
    data.write_bytes(bytes(raw))
    with pytest.raises(RuntimeError, match="protection limits differ"):
        c_port.run_port(exe, data, len(work.job_roots))


def test_every_pass_repeats_the_work_and_bad_passes_are_refused(tmp_path):
    """Warm passes redo the same jobs from fresh buffers, so the timed one equals the first."""
    import subprocess

    exe = c_port.build(tmp_path)
    work = make_workload(30, episodes=2, seed=3)
    data = tmp_path / "w.bin"
    c_port.write_input(work, data)
    outs = []
    for passes in ("1", "3"):
        out = tmp_path / f"out{passes}"
        done = subprocess.run([str(exe), str(data), str(out), passes], capture_output=True)
        assert done.returncode == 0
        outs.append(out.read_bytes())
    assert outs[0] == outs[1]
    bad = subprocess.run([str(exe), str(data), str(tmp_path / "x"), "0"], capture_output=True)
    assert bad.returncode == 2 and b"PASSES" in bad.stderr


@pytest.mark.parametrize("lanes", [1, 3, 32])
@pytest.mark.parametrize(("teams", "programs", "instructions"), [(3, 10, 10), (6, 4, 30)])
def test_lane_mode_equals_the_lane_engine_job_by_job(
    port, tmp_path, lanes, teams, programs, instructions
):
    """The C lane yardstick plays each root's episodes in lockstep and changes no outcome."""
    work = make_workload(30, teams, programs, instructions, episodes=8, seed=7)
    engine = drive(work, 1, lanes).result
    data = tmp_path / "w.bin"
    c_port.write_input(work, data)
    run = c_port.run_port(port, data, len(work.job_roots), lanes)
    c_port.check(engine, run.result)
    c_port.check(drive(work, 1, 0).result, run.result)  # and the scalar kernel's
    assert np.any(engine.teams > engine.steps)


def test_bad_lanes_are_refused(port, tmp_path):
    import subprocess

    work = make_workload(3, episodes=2, seed=3)
    data = tmp_path / "w.bin"
    c_port.write_input(work, data)
    argv = [str(port), str(data), str(tmp_path / "x"), "1", "-2"]
    bad = subprocess.run(argv, capture_output=True)
    assert bad.returncode == 2 and b"LANES" in bad.stderr
