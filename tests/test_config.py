"""The run configuration: the ``paper`` preset against the paper's Tables 2 and 3, and the
validation, override and TOML paths of ``mtpg.config``.

The published values are written here by hand from the paper
(``shared/paper``, Tables 2 and 3) and the decided spec (``shared/spec/algorithm.md``).
"""

from __future__ import annotations

import math

import pytest

from mtpg.config import (
    ABLATIONS,
    PRESETS,
    ConfigError,
    EvaluationConfig,
    ProgramConfig,
    RunConfig,
    TeamConfig,
    build_config,
    from_dict,
    merge,
    parse_override,
    to_dict,
    to_toml,
)
from mtpg.model.instructions import CONSTANTS, N_OPS, OP_NAMES

ALL_TASKS = (
    "CartPole",
    "Acrobot",
    "CartCentering",
    "Pendulum",
    "MountainCar",
    "MountainCarContinuous",
)


@pytest.fixture(scope="module")
def paper() -> RunConfig:
    return build_config("paper")


def test_paper_preset_team_population_matches_table_3(paper: RunConfig) -> None:
    t = paper.team
    assert t.root_size == 1000  # R_size
    assert t.init_team_size == 10  # tmSize_init
    assert t.p_crossover == 0.2  # p_x
    assert t.p_delete == 0.7  # p_md
    assert t.p_add == 0.6  # p_ma
    assert t.p_new == 0.2  # p_mm
    assert t.p_action == 0.1  # p_mn
    assert t.p_memory == 0.1  # p_ms
    assert t.p_atomic == 0.95  # p_atomic
    assert t.min_elite_total == 0  # the paper has no such floor
    assert t.max_team_size >= 1000  # tmSize_max is unbounded: only a memory guard


def test_paper_preset_elites_follow_the_published_run(paper: RunConfig) -> None:
    assert paper.team.n_elite == 25
    assert paper.elites_per_subset == 25
    assert paper.elites_per_subset * paper.evaluation.n_subsets == 1575


def test_paper_preset_program_population_matches_table_3(paper: RunConfig) -> None:
    p = paper.program
    assert p.n_registers == 8  # size of r
    assert p.n_memory == 8  # size of m
    assert p.init_max_length == 10  # progSize_init
    assert p.p_delete == 0.5
    assert p.p_add == 0.4
    assert p.p_mutate == 1.0
    assert p.p_swap == 0.2
    assert p.max_length >= 1000  # progSize_max is unbounded: only a memory guard


def test_paper_preset_evaluation_matches_section_4_and_5(paper: RunConfig) -> None:
    ev = paper.evaluation
    assert ev.tasks == ALL_TASKS
    assert ev.n_subsets == 63
    assert ev.task_ids == (0, 1, 2, 3, 4, 5)
    assert ev.train_episodes == 5  # each new root: 5 episodes per task
    assert ev.test_episodes == 100  # champions tested on 100 episodes
    assert ev.test_interval == 5  # every 5 generations
    assert ev.no_memory is False
    assert paper.generations == 1000
    assert paper.seed == 0


def test_instruction_set_matches_table_2() -> None:
    assert N_OPS == 16
    names = "add sub mul div pow cos ln exp sqrt sin tanh square abs cube if_lt if_gt"
    assert OP_NAMES == tuple(names.split())
    want = [-0.9, -0.8, -0.7, -0.6, -0.5, -0.4, -0.3, -0.2, -0.1]
    want += [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9]
    assert CONSTANTS.tolist() == want


def test_demo_preset_is_small_and_valid() -> None:
    demo = build_config("demo")
    assert demo.team.root_size < 1000 and demo.generations < 1000
    assert demo.elites_per_subset == 4  # max(4, ceil(100 / 63) = 2)
    one = build_config("demo", overrides=['evaluation.tasks=["Pendulum"]'])
    assert one.elites_per_subset == 100  # the floor serves single-task runs
    assert set(PRESETS) == {"paper", "demo", "robust"}


def test_robust_preset_is_the_paper_with_resampled_training_episodes() -> None:
    robust, paper = to_dict(build_config("robust")), to_dict(build_config("paper"))
    assert robust["evaluation"].pop("resample_interval") == 10
    assert paper["evaluation"].pop("resample_interval") == 0
    assert robust == paper


def test_ablations_each_change_one_setting() -> None:
    for name, (key, value) in ABLATIONS.items():
        section, field = key.split(".")
        cfg = build_config("paper", overrides=[f"{key}={str(value).lower()}"])
        assert to_dict(cfg)[section][field] == value, name
    assert build_config("paper", overrides=["team.p_atomic=1.0"]).ablations == ("no-hierarchy",)
    assert build_config("paper").ablations == ()


ALL = "CartPole, Acrobot, CartCentering, Pendulum, MountainCar, MountainCarContinuous"


@pytest.mark.parametrize(
    ("override", "message"),
    [
        ("team.p_crossover=1.5", "team.p_crossover must be in [0, 1], got 1.5"),
        ("team.p_crossover=-0.1", "team.p_crossover must be in [0, 1], got -0.1"),
        ("program.p_swap=2", "program.p_swap must be in [0, 1], got 2.0"),
        ("team.root_size=0", "team.root_size must be >= 1, got 0"),
        ("team.n_elite=0", "team.n_elite must be >= 1, got 0"),
        ("team.init_team_size=1", "team.init_team_size must be >= 2, got 1"),
        ("team.min_elite_total=-1", "team.min_elite_total must be >= 0, got -1"),
        ("team.max_team_size=0", "team.max_team_size must be >= 1, got 0"),
        ("program.n_registers=0", "program.n_registers must be >= 1, got 0"),
        ("program.n_memory=0", "program.n_memory must be >= 1, got 0"),
        ("program.init_max_length=0", "program.init_max_length must be >= 1, got 0"),
        (
            "program.max_length=5",
            "program.max_length must be >= program.init_max_length, got 5",
        ),
        ("evaluation.train_episodes=0", "evaluation.train_episodes must be >= 1, got 0"),
        ("evaluation.test_episodes=0", "evaluation.test_episodes must be >= 1, got 0"),
        ("evaluation.test_interval=-1", "evaluation.test_interval must be >= 0, got -1"),
        ("evaluation.tasks=[]", "evaluation.tasks must name at least one task, got ()"),
        ('evaluation.tasks=["Pong"]', f"evaluation.tasks must be among {ALL}, got 'Pong'"),
        (
            'evaluation.tasks=["Pendulum", "Pendulum"]',
            "evaluation.tasks must not repeat a task, got ('Pendulum', 'Pendulum')",
        ),
        ("seed=-1", "seed must be >= 0, got -1"),
        ("generations=-1", "generations must be >= 1, got -1"),
        ("generations=0", "generations must be >= 1, got 0"),
        ("workers=0", "workers must be >= 1, got 0"),
        ("checkpoint_interval=0", "checkpoint_interval must be >= 1, got 0"),
        ("team.root_size=1.5", "team.root_size must be int, got float 1.5"),
        ("team.root_size=true", "team.root_size must be int, got bool True"),
        ("evaluation.no_memory=1", "evaluation.no_memory must be bool, got int 1"),
        ('team.p_add="x"', "team.p_add must be float, got str 'x'"),
        ("evaluation.tasks=3", "evaluation.tasks must be tuple[str, ...], got int 3"),
        ("team.nope=1", "unknown field 'team.nope'"),
        ("nope=1", "unknown field 'nope'"),
        ("team=3", "team must be a table, got 3"),
    ],
)
def test_invalid_values_are_refused_with_a_message_naming_the_field(
    override: str, message: str
) -> None:
    with pytest.raises(ConfigError) as err:
        build_config("paper", overrides=[override])
    assert str(err.value) == message


def test_defaults_are_the_paper_preset() -> None:
    assert build_config() == build_config("paper") == RunConfig()


def test_boundary_values_are_accepted() -> None:
    cfg = build_config(
        "paper",
        overrides=[
            "team.p_crossover=0",
            "team.p_delete=1",
            "team.init_team_size=2",
            "team.min_elite_total=0",
            "program.init_max_length=1",
            "program.max_length=1",
            "evaluation.test_interval=0",
            "generations=1",
            "seed=0",
        ],
    )
    assert cfg.team.p_crossover == 0.0 and isinstance(cfg.team.p_crossover, float)
    assert cfg.team.p_delete == 1.0
    assert cfg.program.max_length == 1 and cfg.generations == 1
    assert cfg.evaluation.test_interval == 0


def test_validation_messages_name_field_rule_and_value() -> None:
    with pytest.raises(ConfigError, match=r"^team\.p_add must be in \[0, 1\], got 1\.5$"):
        TeamConfig(p_add=1.5)
    with pytest.raises(ConfigError, match=r"^team\.init_team_size must be >= 2, got 1$"):
        TeamConfig(init_team_size=1)
    with pytest.raises(ConfigError, match=r"must be >= program\.init_max_length, got 3$"):
        ProgramConfig(init_max_length=4, max_length=3)
    with pytest.raises(ConfigError, match=r"must be among CartPole, Acrobot, .*got 'Pong'$"):
        EvaluationConfig(tasks=("Pong",))
    with pytest.raises(ConfigError, match=r"^team\.root_size must be int, got float 1\.5$"):
        build_config("paper", overrides=["team.root_size=1.5"])
    with pytest.raises(ConfigError, match=r"^unknown field 'team\.nope'$"):
        build_config("paper", overrides=["team.nope=1"])
    with pytest.raises(ConfigError, match=r"^team must be a table, got 3$"):
        build_config("paper", overrides=["team=3"])
    with pytest.raises(ConfigError, match=r"^unknown preset 'x'; choose from paper, demo, robust$"):
        build_config("x")


def test_overrides_parse_toml_values_and_bare_words() -> None:
    assert parse_override("team.p_x = 0.5") == {"team": {"p_x": 0.5}}
    assert parse_override("seed=3") == {"seed": 3}
    assert parse_override('evaluation.tasks=["A", "B"]') == {"evaluation": {"tasks": ["A", "B"]}}
    assert parse_override("a.b.c=word") == {"a": {"b": {"c": "word"}}}
    assert parse_override("x=1=2") == {"x": "1=2"}
    with pytest.raises(ConfigError, match="must look like section.field=value"):
        parse_override("team.p_x")
    cfg = build_config("paper", overrides=["team.p_crossover=1", "team.p_crossover=0.3"])
    assert cfg.team.p_crossover == 0.3  # later overrides win


def test_ints_become_floats_and_lists_become_tuples() -> None:
    cfg = merge(RunConfig(), {"team": {"p_crossover": 1}, "evaluation": {"tasks": ["Pendulum"]}})
    assert cfg.team.p_crossover == 1.0 and isinstance(cfg.team.p_crossover, float)
    assert cfg.evaluation.tasks == ("Pendulum",)
    with pytest.raises(ConfigError, match="evaluation.tasks must be tuple"):
        merge(RunConfig(), {"evaluation": {"tasks": [1, 2]}})
    with pytest.raises(ConfigError, match="team.p_crossover must be float, got bool"):
        merge(RunConfig(), {"team": {"p_crossover": True}})


def test_toml_file_then_overrides(tmp_path) -> None:
    path = tmp_path / "run.toml"
    path.write_text('seed = 4\n[team]\nn_elite = 7\n[evaluation]\ntasks = ["Acrobot"]\n')
    cfg = build_config("demo", toml_file=path, overrides=["team.n_elite=9"])
    assert (cfg.seed, cfg.team.n_elite, cfg.evaluation.tasks) == (4, 9, ("Acrobot",))
    assert cfg.team.root_size == 300  # from the preset
    path.write_text("[team]\nn_elite = 0\n")
    with pytest.raises(ConfigError, match=rf"^{path}: team\.n_elite must be >= 1"):
        build_config("paper", toml_file=path)
    path.write_text("[team\n")
    with pytest.raises(ConfigError, match=rf"^{path}: not valid TOML"):
        build_config("paper", toml_file=path)


@pytest.mark.parametrize("preset", sorted(PRESETS))
def test_toml_and_dict_round_trips_are_exact(preset: str, tmp_path) -> None:
    cfg = build_config(
        preset, overrides=['evaluation.tasks=["Pendulum", "CartPole"]', "team.p_add=0.35"]
    )
    text = to_toml(cfg)
    path = tmp_path / "c.toml"
    path.write_text(text)
    assert build_config("paper", toml_file=path) == cfg
    assert from_dict(to_dict(cfg)) == cfg
    assert to_dict(cfg)["evaluation"]["tasks"] == ["Pendulum", "CartPole"]
    assert "no_memory = false" in text and '    "Pendulum",\n    "CartPole",\n]' in text
    assert text.index("[program]") < text.index("[team]") < text.index("[evaluation]")
    assert text.endswith("\n") and text.startswith("seed = ")


def test_toml_values_are_written_as_toml_reads_them() -> None:
    import tomllib

    cfg = merge(RunConfig(), {"address": 'a"b\\c', "team": {"p_add": 0.1}})
    data = tomllib.loads(to_toml(cfg))
    assert data["address"] == 'a"b\\c' and data["team"]["p_add"] == 0.1
    assert data["evaluation"]["no_memory"] is False and data["workers"] == 1
    assert from_dict(data) == cfg


def test_subset_count_and_elites_per_subset_rounding() -> None:
    for n in range(1, 7):
        tasks = list(ALL_TASKS[:n])
        cfg = merge(RunConfig(), {"evaluation": {"tasks": tasks}})
        assert cfg.evaluation.n_subsets == 2**n - 1
        for total in (0, 1, 50, 64, 100, 1575):
            c = merge(cfg, {"team": {"n_elite": 1, "min_elite_total": total}})
            assert c.elites_per_subset == max(1, math.ceil(total / (2**n - 1)))


# --- hard limits, cross-field rules and file reading, each with its exact message ---------


@pytest.mark.parametrize(
    ("make", "key"),
    [
        (lambda v: ProgramConfig(max_length=v), "program.max_length"),
        (lambda v: TeamConfig(max_team_size=v), "team.max_team_size"),
        (lambda v: TeamConfig(min_elite_total=v), "team.min_elite_total"),
        (lambda v: RunConfig(seed=v), "seed"),
        (lambda v: RunConfig(workers=v), "workers"),
    ],
)
def test_hard_limits_accept_the_limit_and_refuse_one_more(make, key) -> None:
    from mtpg.limits import LIMITS

    limit = LIMITS[key]
    make(limit)  # the limit itself is allowed
    with pytest.raises(ConfigError) as err:
        make(limit + 1)
    assert str(err.value) == f"{key} must be <= {limit:,} (hard limit), got {limit + 1}"


def test_team_size_bound_against_initial_teams() -> None:
    assert TeamConfig(init_team_size=5, max_team_size=5).max_team_size == 5
    with pytest.raises(ConfigError) as err:
        TeamConfig(init_team_size=5, max_team_size=4)
    assert str(err.value) == "team.max_team_size must be >= team.init_team_size, got 4"


def test_backend_and_dask_workers_are_validated() -> None:
    assert RunConfig(backend="dask").backend == "dask"
    assert RunConfig(backend="local", dask_workers=0).dask_workers == 0
    with pytest.raises(ConfigError) as err:
        RunConfig(backend="slurm")
    assert str(err.value) == "backend must be local or dask, got 'slurm'"
    with pytest.raises(ConfigError) as err:
        RunConfig(dask_workers=-1)
    assert str(err.value) == "dask_workers must be >= 0, got -1"


@pytest.mark.parametrize("text", ["=1", "team..p_add=1", "team.=1", ".seed=1", "a b..c=1"])
def test_overrides_with_an_empty_key_part_are_refused(text: str) -> None:
    with pytest.raises(ConfigError) as err:
        parse_override(text)
    assert str(err.value) == f"override {text!r} must look like section.field=value"


def test_override_nested_too_deeply_is_one_message() -> None:
    text = "evaluation.tasks=" + "[" * 5000 + "]" * 5000
    with pytest.raises(ConfigError) as err:
        parse_override(text)
    assert str(err.value) == f"override {text!r}: value is nested too deeply"


def _read_error(path) -> str:
    from mtpg.config import read_toml

    with pytest.raises(ConfigError) as err:
        read_toml(path)
    return str(err.value)


def test_unreadable_settings_files_are_one_message_naming_the_file(tmp_path) -> None:
    assert _read_error(tmp_path) == f"{tmp_path}: is a directory, not a TOML file"
    missing = tmp_path / "missing.toml"
    assert _read_error(missing) == f"{missing}: no such file"
    afile = tmp_path / "afile"
    afile.write_text("seed = 1\n")
    inside = afile / "x.toml"  # a path through a file: an OSError other than "not found"
    assert _read_error(inside) == f"{inside}: cannot read: Not a directory"
    binary = tmp_path / "binary.toml"
    binary.write_bytes(b"seed = 1\n\xff\n")
    assert _read_error(binary) == f"{binary}: not UTF-8 text (invalid start byte at byte 9)"
    deep = tmp_path / "deep.toml"
    deep.write_text("v = " + "[" * 5000 + "]" * 5000 + "\n")
    assert _read_error(deep) == f"{deep}: not valid TOML: nested too deeply"


def test_settings_file_size_limit_is_exact(tmp_path) -> None:
    from mtpg.config import MAX_TOML_BYTES, read_toml

    tail = "seed = 17\n"
    path = tmp_path / "big.toml"
    path.write_text("#" + " " * (MAX_TOML_BYTES - len(tail) - 2) + "\n" + tail)
    assert path.stat().st_size == MAX_TOML_BYTES
    assert read_toml(path) == {"seed": 17}  # exactly the limit: read whole
    path.write_text("#" + " " * (MAX_TOML_BYTES - len(tail) - 1) + "\n" + tail)
    assert _read_error(path) == (f"{path}: larger than {MAX_TOML_BYTES} bytes; not a settings file")


def test_settings_file_is_read_with_a_bounded_read(tmp_path, monkeypatch) -> None:
    """An endless file (a device, a pipe) is refused after MAX_TOML_BYTES + 1 bytes."""
    import mtpg.config.resolve as config_module

    class Endless:
        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

        def read(self, n=-1):
            assert n is not None and n >= 0, "unbounded read of a settings file"
            return b"#" * n

    monkeypatch.setattr(config_module, "open", lambda *a, **k: Endless(), raising=False)
    message = _read_error(tmp_path / "endless.toml")
    assert message.endswith("bytes; not a settings file")


def test_toml_strings_round_trip_every_control_character() -> None:
    import tomllib

    texts = ["".join(map(chr, range(0x80))), 'a"b\\c\td\ne\r\x7f', "π ≠ 3 \u2028", ""]
    for text in texts:
        cfg = merge(RunConfig(), {"address": text})
        assert from_dict(tomllib.loads(to_toml(cfg))) == cfg
        assert tomllib.loads(to_toml(cfg))["address"] == text


def test_a_reference_source_with_odd_characters_trains_resumes_and_reports(tmp_path) -> None:
    """A [[task]] reference source with a newline, a quote, a backslash and a tab."""
    import tomllib

    from stopruns import mtpg
    from tinyruns import tiny_overrides

    source = 'line one\nsaid "x" \\ y\tz'
    escaped = source.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")
    conf = tmp_path / "run.toml"
    conf.write_text(
        '[[task]]\nbase = "CartPole"\nmax_steps = 401\n'
        f'reference = {{ best = 401, random = 21.0, source = "{escaped}" }}\n'
        '[[task]]\nbase = "Acrobot"\n'
    )
    run = tmp_path / "run"
    sets = [a for t in tiny_overrides(12, 2, checkpoint_interval=1) for a in ("--set", t)]
    common = ["--quiet", *sets]
    done = mtpg("train", "--config", str(conf), *common, "--generations", "2", "--out", str(run))
    assert done.returncode == 0, done.stderr
    stored = tomllib.loads((run / "config.toml").read_text())
    assert stored["evaluation"]["references"] == [
        f"CartPole[max_steps=401]: best=401, random=21.0, source={source}"
    ]
    done = mtpg("train", "--resume", str(run), "--quiet", "--generations", "3")
    assert done.returncode == 0, done.stderr
    done = mtpg("report", str(run), "--out", str(tmp_path / "report"))
    assert done.returncode == 0, done.stderr


def test_fields_are_coerced_by_their_type_hints_optional_included() -> None:
    from dataclasses import dataclass

    from mtpg.config.resolve import _apply

    @dataclass(frozen=True)
    class Section:
        limit: int | None = None
        names: tuple[str, ...] = ()
        rate: float = 0.5

    assert _apply(Section(), {"limit": 3, "rate": 1}, "s.") == Section(3, (), 1.0)
    assert _apply(Section(3), {"limit": None}, "s.") == Section(None)
    assert _apply(Section(), {"names": ["a", "b"]}, "s.").names == ("a", "b")
    with pytest.raises(ConfigError, match=r"^s\.limit must be int \| None, got str 'x'$"):
        _apply(Section(), {"limit": "x"}, "s.")
    with pytest.raises(ConfigError, match=r"^s\.limit must be int \| None, got bool True$"):
        _apply(Section(), {"limit": True}, "s.")
