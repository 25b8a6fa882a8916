"""Every bad input gives one line on stderr, a non-zero exit and an unchanged run directory."""

import json
import os
import resource
import signal
import subprocess
import sys

import pytest

from mtpg.cli.main import main
from tinyruns import tiny_args

TINY = tiny_args("CartPole,MountainCar", root_size=12, n_elite=2)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """A finished run R, its graph G and a set of bad files, made once."""
    d = tmp_path_factory.mktemp("bad")
    run = d / "R"
    assert main(["train", *TINY, "--generations", "2", "--out", str(run)]) == 0
    graph = json.loads((run / "champions" / "CartPole.json").read_text())
    out = {"R": run, "G": run / "champions" / "CartPole.json", "D": d, "NEW": d / "new"}

    def write(name, data):
        path = d / name
        path.write_bytes(data if isinstance(data, bytes) else data.encode())
        out[name] = path

    write("deep.toml", "a = " + "[" * 50000 + "]" * 50000 + "\n")
    write("binary.toml", b"\xff\xfe\x00bad")
    write("bad.toml", "[team\nn_elite = 1\n")
    write("unknown.toml", "[team]\nfoo = 1\n")
    write("deep.json", "[" * 200000 + "]" * 200000)
    write("notjson.json", "this is not json")
    write("list.json", "[1, 2, 3]")
    for name, change in {
        "nobs1.json": lambda g: g["layout"].update(n_obs=1),
        "bigid.json": lambda g: g["teams"][0].update(id=2**63),
        "hugeid.json": lambda g: g.update(root=10**30),
        "regs.json": lambda g: g["layout"].update(n_memory=10**9),
        "deepmeta.json": lambda g: g.update(meta={"a": json.loads("[" * 100 + "]" * 100)}),
    }.items():
        g = json.loads(json.dumps(graph))
        change(g)
        write(name, json.dumps(g))
    write("afile", "x")
    return out


# (argv with {placeholders}, exit status, a fragment of the one-line message)
CASES = [
    # sizes from the issue: refused at once by hard limits
    (
        ["train", *TINY, "--set", "team.root_size=1000000000", "--out", "{NEW}"],
        2,
        "team.root_size must be <=",
    ),
    (
        ["train", *TINY, "--set", "team.n_elite=1000000000", "--out", "{NEW}"],
        2,
        "team.n_elite must be <=",
    ),
    (
        ["train", *TINY, "--set", "team.init_team_size=1000000000", "--out", "{NEW}"],
        2,
        "team.init_team_size must be <=",
    ),
    (
        ["train", *TINY, "--set", "program.init_max_length=1000000000", "--out", "{NEW}"],
        2,
        "program.init_max_length must be <=",
    ),
    (
        ["train", *TINY, "--set", "evaluation.train_episodes=1000000000", "--out", "{NEW}"],
        2,
        "evaluation.train_episodes must be <=",
    ),
    (
        ["train", *TINY, "--set", "evaluation.test_episodes=1000000000", "--out", "{NEW}"],
        2,
        "evaluation.test_episodes must be <=",
    ),
    (
        [
            "train",
            *TINY,
            "--set",
            "team.root_size=1000000",
            "--set",
            "team.init_team_size=100000",
            "--set",
            "team.max_team_size=100000",
            "--out",
            "{NEW}",
        ],
        2,
        "needs an estimated",
    ),
    (
        [
            "train",
            *TINY,
            "--set",
            "evaluation.train_episodes=100000",
            "--set",
            "team.root_size=100000",
            "--out",
            "{NEW}",
        ],
        2,
        "decisions",
    ),
    # options
    (["train", *TINY, "--tasks", "", "--out", "{NEW}"], 2, "--tasks: empty list"),
    (["train", *TINY, "--tasks", " , ", "--out", "{NEW}"], 2, "--tasks: empty list"),
    (["train", *TINY, "--tasks", "Pong", "--out", "{NEW}"], 2, "evaluation.tasks must be among"),
    (["train", *TINY, "--tasks", "CartPole,CartPole", "--out", "{NEW}"], 2, "must not repeat"),
    (["train", *TINY, "--seed", "9223372036854775808", "--out", "{NEW}"], 2, "seed must be <="),
    (["train", *TINY, "--seed", "-1", "--out", "{NEW}"], 2, "seed must be >= 0"),
    (["train", *TINY, "--generations", "-1", "--out", "{NEW}"], 2, "generations must be >= 1"),
    (["train", *TINY, "--generations", "0", "--out", "{NEW}"], 2, "generations must be >= 1"),
    (["train", *TINY, "--generations", "ten", "--out", "{NEW}"], 2, "invalid int value"),
    (["train", *TINY, "--workers", "0", "--out", "{NEW}"], 2, "workers must be >= 1"),
    (["train", *TINY, "--workers", "100000", "--out", "{NEW}"], 2, "workers must be <="),
    (["train", *TINY, "--preset", "huge", "--out", "{NEW}"], 2, "unknown preset"),
    (["train", *TINY, "--bogus", "--out", "{NEW}"], 2, "unrecognized arguments"),
    (
        ["train", *TINY, "--set", "team.n_elite", "--out", "{NEW}"],
        2,
        "must look like section.field=value",
    ),
    (["train", *TINY, "--set", "=5", "--out", "{NEW}"], 2, "must look like section.field=value"),
    (
        ["train", *TINY, "--set", "team..x=5", "--out", "{NEW}"],
        2,
        "must look like section.field=value",
    ),
    (["train", *TINY, "--set", "team.bogus=1", "--out", "{NEW}"], 2, "unknown field 'team.bogus'"),
    (["train", *TINY, "--set", "team=1", "--out", "{NEW}"], 2, "team must be a table"),
    (
        ["train", *TINY, "--set", "program.p_swap=nan", "--out", "{NEW}"],
        2,
        "program.p_swap must be in [0, 1]",
    ),
    (
        ["train", *TINY, "--set", "program.p_swap=inf", "--out", "{NEW}"],
        2,
        "program.p_swap must be in [0, 1]",
    ),
    (
        ["train", "--set", "evaluation.tasks=[]", "--out", "{NEW}"],
        2,
        "must name at least one task",
    ),
    (
        ["train", *TINY, "--set", "evaluation.tasks=" + "[" * 5000 + "]" * 5000, "--out", "{NEW}"],
        2,
        "nested too deeply",
    ),
    (
        [
            "train",
            *TINY,
            "--set",
            "program.max_length=5",
            "--set",
            "program.init_max_length=6",
            "--out",
            "{NEW}",
        ],
        2,
        "program.max_length must be >= program.init_max_length",
    ),
    # files given as options
    (["train", *TINY, "--config", "{D}", "--out", "{NEW}"], 2, "is a directory"),
    (["train", *TINY, "--config", "{deep.toml}", "--out", "{NEW}"], 2, "nested too deeply"),
    (["train", *TINY, "--config", "{binary.toml}", "--out", "{NEW}"], 2, "not UTF-8"),
    (["train", *TINY, "--config", "{bad.toml}", "--out", "{NEW}"], 2, "not valid TOML"),
    (
        ["train", *TINY, "--config", "{unknown.toml}", "--out", "{NEW}"],
        2,
        "unknown field 'team.foo'",
    ),
    (["train", *TINY, "--config", "{D}/missing.toml", "--out", "{NEW}"], 2, "no such file"),
    # run directories
    (["train", *TINY, "--out", "{R}"], 2, "already holds an mtpg run"),
    (["train", *TINY, "--out", "{afile}"], 2, "exists and is not a directory"),
    (["train", *TINY, "--out", "{D}"], 2, "not empty and is not an mtpg run"),
    (["train", "--resume", "{NEW}"], 2, "holds no mtpg run"),
    (["train", "--resume", "{D}"], 2, "holds no mtpg run"),
    (["train", "--resume", "{afile}"], 2, "not a directory"),
    (
        ["train", "--resume", "{R}", "--seed", "99"],
        2,
        "cannot resume with a different configuration (differs in seed)",
    ),
    (["train", "--resume", "{R}", "--tasks", ""], 2, "--tasks: empty list"),
    # evaluate
    (["evaluate", "{G}", "--episodes", "100000000"], 2, "--episodes must be in 1.."),
    (["evaluate", "{G}", "--episodes", "0"], 2, "--episodes must be in 1.."),
    (["evaluate", "{G}", "--seed", "9223372036854775807"], 2, "--seed must be in 0.."),
    (["evaluate", "{G}", "--workers", "0"], 2, "--workers must be in 1.."),
    (["evaluate", "{G}", "--tasks", ""], 2, "--tasks: empty list"),
    (["evaluate", "{G}", "--tasks", "Pong"], 2, "unknown task 'Pong'"),
    (["evaluate", "{nobs1.json}"], 2, "layout.n_obs must be >= 2 to play the registered"),
    (["evaluate", "{bigid.json}"], 2, "must fit a 64-bit integer"),
    (["evaluate", "{hugeid.json}"], 2, "must fit a 64-bit integer"),
    (["evaluate", "{regs.json}"], 2, "layout.n_memory must be <= 256"),
    (["evaluate", "{deepmeta.json}"], 2, "nested deeper than"),
    (["evaluate", "{deep.json}"], 2, "nested too deeply"),
    (["evaluate", "{notjson.json}"], 2, "not valid JSON"),
    (["evaluate", "{list.json}"], 2, "graph must be a JSON object"),
    (["evaluate", "{D}/missing.json"], 2, "missing.json: no such graph file or run directory"),
    (["evaluate", "{D}"], 2, ": not an mtpg run directory (no config.toml)"),
    (["evaluate", "{deep.toml}"], 2, "not valid JSON"),
    # experiment
    (["experiment", "--out", "{NEW}", "--seeds", "0"], 2, "--seeds and --parallel must be >= 1"),
    (["experiment", "--out", "{NEW}", "--seeds", "100000"], 2, "must be <= 1000"),
    (["experiment", "--out", "{NEW}", "--tasks", ""], 2, "--tasks: empty list"),
    (["experiment", "--out", "{afile}"], 2, "exists and is not a directory"),
    (
        ["experiment", "--out", "{NEW}", "--set", "team.root_size=1000000000"],
        2,
        "team.root_size must be <=",
    ),
]


def fill(argv, files):
    out = []
    for a in argv:
        for key, value in files.items():
            a = a.replace("{" + key + "}", str(value))
        out.append(a)
    return out


def snapshot(path):
    return {p: p.read_bytes() for p in sorted(path.rglob("*")) if p.is_file()}


@pytest.mark.parametrize(
    ("argv", "code", "message"), CASES, ids=[f"{i:02d}-{c[0][0]}" for i, c in enumerate(CASES)]
)
def test_bad_input_is_one_line_and_changes_nothing(files, capsys, argv, code, message):
    before = snapshot(files["D"])
    with (
        pytest.raises(SystemExit)
        if "--generations" in argv and "ten" in argv or "--bogus" in argv
        else _nothing() as info
    ):
        result = main(fill(argv, files))
    if info is not None and info.value is not None:
        result = info.value.code
    err = capsys.readouterr().err
    assert result == code, err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert message in lines[0]
    assert "Traceback" not in err
    assert snapshot(files["D"]) == before
    assert not files["NEW"].exists()


class _Holder:
    value = None


class _nothing:  # a context manager standing in for pytest.raises
    def __enter__(self):
        return _Holder()

    def __exit__(self, *exc):
        return False


def _mtpg(*args, **kw):
    return subprocess.run([sys.executable, "-m", "mtpg", *args], capture_output=True, **kw)


def test_output_piped_into_head_ends_quietly(files):
    # a reader that is gone before the first write: the write fails with EPIPE at once
    probe = (
        "import os, sys; from mtpg.cli.main import main; r, w = os.pipe(); os.close(r);"
        "os.dup2(w, 1); sys.exit(main(['evaluate', sys.argv[1], '--episodes', '2']))"
    )
    res = subprocess.run([sys.executable, "-c", probe, str(files["G"])], capture_output=True)
    assert (res.returncode, res.stderr) == (141, b"")


def test_debug_shows_the_traceback(files, capsys):
    assert main(["--debug", "evaluate", str(files["notjson.json"])]) == 2
    err = capsys.readouterr().err
    assert "Traceback" in err and err.strip().splitlines()[-1].startswith("mtpg evaluate: error:")
    assert main(["evaluate", str(files["notjson.json"]), "--debug"]) == 2
    assert "Traceback" in capsys.readouterr().err


def _file_size_limit(limit):
    def apply():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, limit))

    return apply


def test_full_disk_is_a_runtime_failure_and_the_run_resumes(tmp_path):
    """A write that fails (here: a file-size limit, like a full disk) exits 1 in one line."""
    run = tmp_path / "run"
    args = ["train", *TINY, "--generations", "3", "--out", str(run)]
    res = _mtpg(*args, preexec_fn=_file_size_limit(1000), text=True)
    assert res.returncode == 1, res.stderr
    lines = res.stderr.strip().splitlines()
    assert "Traceback" not in res.stderr
    assert lines[-1].startswith("mtpg train: error:") and "File too large" in lines[-1]
    assert len([x for x in lines if "error" in x]) == 1
    res = _mtpg("train", "--resume", str(run), "--quiet", text=True)
    assert res.returncode == 0, res.stderr
    ref = tmp_path / "ref"
    assert main([*args[:-1], str(ref)]) == 0
    from stopruns import assert_same_run

    assert_same_run(ref, run)


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only directories")
def test_read_only_directory_is_a_runtime_failure(tmp_path):
    parent = tmp_path / "ro"
    parent.mkdir()
    parent.chmod(0o500)
    try:
        res = _mtpg("train", *TINY, "--generations", "1", "--out", str(parent / "run"), text=True)
    finally:
        parent.chmod(0o700)
    assert res.returncode == 1
    assert len(res.stderr.strip().splitlines()) == 1 and "Permission denied" in res.stderr


def test_overrides_are_validated_together_in_any_order():
    from mtpg.config import build_config

    a = ["program.init_max_length=2000", "program.max_length=3000"]
    assert build_config("demo", None, a) == build_config("demo", None, a[::-1])
    assert build_config("demo", None, a).program.init_max_length == 2000


def test_permission_denied_is_a_runtime_failure(tmp_path, capsys, monkeypatch):
    import mtpg.io.rundir

    def refuse(path, data, before_replace=None):
        raise PermissionError(13, "Permission denied", str(path))

    monkeypatch.setattr(mtpg.io.rundir, "atomic_write_bytes", refuse)
    assert main(["train", *TINY, "--generations", "1", "--out", str(tmp_path / "run")]) == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1
    assert err[0].endswith("config.toml: Permission denied") and "Traceback" not in err[0]
