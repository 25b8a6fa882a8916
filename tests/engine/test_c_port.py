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
