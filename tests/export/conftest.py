"""Fixtures of the export tests: the compiler, evolved graphs, and exported-code runners."""

import importlib.util
import itertools

import pytest

from mtpg.envs.specs.contract import TASK_NAMES
from mtpg.export.c import write_c
from mtpg.export.common import prepare
from mtpg.export.harness import build_driver, compile_driver, find_compiler, run_check
from mtpg.export.python import write_python
from tinyruns import tiny_args

_counter = itertools.count()


@pytest.fixture(scope="session")
def cc():
    """The system C compiler; the C tests skip, saying why, when there is none."""
    path = find_compiler()
    if path is None:
        pytest.skip("no C compiler (CC, cc, gcc or clang) found: the exported C cannot be built")
    return path


@pytest.fixture(scope="session")
def evolved(tmp_path_factory):
    """Distinct champions of a tiny six-task run with hierarchy (p_atomic = 0.5)."""
    from mtpg.cli.main import main
    from mtpg.io.rundir import read_champions

    out = tmp_path_factory.mktemp("export-run") / "run"
    args = tiny_args(",".join(TASK_NAMES), root_size=16, team__p_atomic=0.5)
    assert main(["train", *args, "--generations", "6", "--seed", "3", "--out", str(out)]) == 0
    seen, cases = set(), []
    for names, (pop, root, meta) in read_champions(out).items():
        key = (root, tuple(sorted(pop.programs)))
        if key not in seen:
            seen.add(key)
            cases.append(("+".join(names), pop, root, meta))
    return out, cases


@pytest.fixture(scope="session")
def drivers(cc, tmp_path_factory):
    """The C driver compiled once per session: plain and with ``-DMTPG_TRACE``."""
    folder = tmp_path_factory.mktemp("drivers")
    return {
        trace: compile_driver(folder / f"driver{int(trace)}.o", trace=trace, compiler=cc)
        for trace in (False, True)
    }


@pytest.fixture
def c_runner(cc, drivers, tmp_path):
    """Exports a graph to C, builds it with the driver, returns its decisions on a stream."""

    def run(pop, root, stream, no_memory=False, trace=False, opt="-O2"):
        graph = prepare(pop, root, no_memory=no_memory)
        folder = tmp_path / f"c{next(_counter)}"
        write_c(graph, folder, "champ")
        exe = build_driver(
            folder,
            "champ",
            folder / "driver",
            trace=trace,
            opt=opt,
            compiler=cc,
            driver_object=drivers[trace],
        )
        return run_check(exe, stream)

    return run


@pytest.fixture
def py_runner(tmp_path):
    """Exports a graph to Python, imports it and returns its decisions on a stream."""

    def run(pop, root, stream, no_memory=False):
        graph = prepare(pop, root, no_memory=no_memory)
        path = write_python(graph, tmp_path / f"champ{next(_counter)}.py")
        spec = importlib.util.spec_from_file_location(path.stem, path)
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        out = []
        for t, o in enumerate(stream.obs.tolist()):
            if stream.starts[t]:
                mod.reset()
            a_d, a_c = mod.act(o)
            out.append((a_d, a_c, list(mod.last_teams)))
        return out

    return run
