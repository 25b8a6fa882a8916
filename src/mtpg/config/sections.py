"""The configuration's sections: frozen dataclasses, one docstring per field, validated.

Every default is the paper's value (Table 3, section 4; the project's specification), with
``team.n_elite`` as in the published run (25 per task subset) rather than Table 3's 50.
Each dataclass checks its own fields when built and names the offending one on error;
:mod:`mtpg.config.resolve` builds them from presets, TOML files and overrides.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any

from mtpg.envs.specs.compiled_task import is_compiled_name
from mtpg.envs.specs.gym_task import is_gym
from mtpg.envs.specs.registry import PAPER_TASKS, TASK_NAMES
from mtpg.envs.taskset.task_table import TaskTable, parse_given
from mtpg.envs.taskset.variants import canonical, is_variant
from mtpg.limits import LIMITS
from mtpg.presets import BACKENDS, PARENT_SELECTIONS


class ConfigError(ValueError):
    """A configuration value or key is invalid; the message names the field."""


def _check(cond: bool, name: str, message: str, value: Any) -> None:
    if not cond:
        raise ConfigError(f"{name} {message}, got {value!r}")


def _probabilities(obj: Any, section: str) -> None:
    for f in fields(obj):
        if f.name.startswith("p_"):
            value = getattr(obj, f.name)
            _check(0.0 <= value <= 1.0, f"{section}.{f.name}", "must be in [0, 1]", value)


def _positive(obj: Any, section: str, names: tuple[str, ...], minimum: int = 1) -> None:
    """Checks ``minimum <= value <= LIMITS[field]`` (hard limits guard memory and time)."""
    for name in names:
        value = getattr(obj, name)
        key = name if section == "run" else f"{section}.{name}"
        _check(value >= minimum, key, f"must be >= {minimum}", value)
        if key in LIMITS:
            _check(value <= LIMITS[key], key, f"must be <= {LIMITS[key]:,} (hard limit)", value)


@dataclass(frozen=True, slots=True, kw_only=True)
class ProgramConfig:
    """Linear register programs and their mutation (Table 3, program population)."""

    n_registers: int = 8
    """Size of the private stateless bank ``r``."""
    n_memory: int = 8
    """Size of a shared stateful memory bank ``m``."""
    init_max_length: int = 10
    """``progSize_init``: initial lengths are uniform in 1..this."""
    max_length: int = 1000
    """Longest program allowed (the paper's is unbounded; this only guards memory)."""
    p_delete: float = 0.5
    """``p_delete``: probability of deleting a random instruction."""
    p_add: float = 0.4
    """``p_add``: probability of inserting a random instruction."""
    p_mutate: float = 1.0
    """``p_mutate``: probability of changing one field of one instruction."""
    p_swap: float = 0.2
    """``p_swap``: probability of swapping two instructions."""

    def __post_init__(self) -> None:
        _positive(self, "program", ("n_registers", "n_memory", "init_max_length", "max_length"))
        _check(
            self.max_length >= self.init_max_length,
            "program.max_length",
            "must be >= program.init_max_length",
            self.max_length,
        )
        _probabilities(self, "program")


@dataclass(frozen=True, slots=True, kw_only=True)
class TeamConfig:
    """Teams, graphs and their variation (Table 3, team population)."""

    root_size: int = 1000
    """``R_size``: root teams created at initialisation."""
    init_team_size: int = 10
    """``tmSize_init``: programs of each initial team (each new, with a new bank)."""
    n_elite: int = 25
    """``n_elite``: children created, and elites kept, per task subset and generation.

    25 follows the published run: 1575 new roots and 1575 elites per generation over the
    63 subsets of six tasks, from ``R_size = 1000`` initial roots. Table 3 prints 50,
    which matches when read as the roots a subset holds after breeding (25 elites + 25
    children); ``--set team.n_elite=50`` breeds and keeps 50 per subset instead (3150 new
    roots per generation, about twice the cost)."""
    min_elite_total: int = 0
    """Lower bound on elites summed over all subsets: when ``n_elite`` times the number
    of subsets is smaller, every subset keeps (and breeds) ``ceil(min_elite_total /
    subsets)`` instead. 0 (the paper) turns it off; it lets one preset serve single-task
    and six-task runs alike."""
    p_crossover: float = 0.2
    """``p_x``: probability that a child is a crossover of two parents (else a clone)."""
    p_delete: float = 0.7
    """``p_md``: probability of deleting a program (repeated with decaying probability)."""
    p_add: float = 0.6
    """``p_ma``: probability of adding a program from the population (repeated, decaying)."""
    p_new: float = 0.2
    """``p_mm``: per program, probability of replacing it by a mutated copy."""
    p_action: float = 0.1
    """``p_mn``: probability that a mutated program's action pointer changes."""
    p_memory: float = 0.1
    """``p_ms``: probability that a mutated program's memory pointer changes."""
    p_reorder: float = 0.1
    """Probability of moving one program to another position in the team."""
    p_atomic: float = 0.95
    """``p_atomic``: a changed action pointer becomes atomic with this probability."""
    max_team_size: int = 1000
    """Largest team allowed (the paper's is unbounded; this only guards memory)."""
    parent_selection: str = "uniform"
    """How parent 1 is drawn from a subset's elites: ``uniform`` (the paper) or, beyond
    the paper, ``lexicase``: epsilon-lexicase over the subset's training episodes
    (:mod:`mtpg.evolve.lexicase`)."""

    def __post_init__(self) -> None:
        _positive(self, "team", ("root_size", "n_elite", "max_team_size"))
        _positive(self, "team", ("init_team_size",), minimum=2)
        _positive(self, "team", ("min_elite_total",), minimum=0)
        _check(
            self.max_team_size >= self.init_team_size,
            "team.max_team_size",
            "must be >= team.init_team_size",
            self.max_team_size,
        )
        _probabilities(self, "team")
        _check(
            self.parent_selection in PARENT_SELECTIONS,
            "team.parent_selection",
            f"must be one of {', '.join(PARENT_SELECTIONS)}",
            self.parent_selection,
        )


@dataclass(frozen=True, slots=True, kw_only=True)
class EvaluationConfig:
    """Tasks, episodes and the test protocol (section 4.1 step 3, section 5)."""

    tasks: tuple[str, ...] = PAPER_TASKS
    """Active tasks, by name: registered names or canonical variants such as
    ``"CartPole[max_steps=500]"`` (``mtpg.envs.taskset.variants``); the power set of these drives
    selection."""
    train_episodes: int = 5
    """Episodes per task on which each new root is evaluated (seeds 0..n-1)."""
    test_episodes: int = 100
    """Episodes per task of each test (seeds disjoint from training)."""
    test_interval: int = 5
    """Generations between tests of the champions (0: never)."""
    no_memory: bool = False
    """Ablation: zero every memory bank before each program execution."""
    validation_episodes: int = 0
    """Beyond the paper: validation episodes per task (seeds disjoint from training and
    test); when > 0, each subset's champion is its best validated root among the best
    ``validation_top_k`` by training fitness (docs/training.md). 0 (the paper): off."""
    validation_top_k: int = 5
    """Beyond the paper: candidates per subset of the validated champion choice (its
    best surviving roots by training fitness); used only with ``validation_episodes``."""
    resample_interval: int = 0
    """Beyond the paper: every this many generations the training episodes are redrawn
    (seeds disjoint from validation and test) and every surviving root is evaluated
    again on them. 0 (the paper): one fixed set, each root evaluated once for life."""
    resample_mean: bool = False
    """Beyond the paper, with ``resample_interval``: a surviving root's training score is
    the mean of its scores on every training block it has played, each block weighing
    alike (explicit averaging over re-evaluations, Jin and Branke 2005), so the estimate
    sharpens the longer a root survives. False: its score on the current block alone."""
    references: tuple[str, ...] = ()
    """Reference scores given for variants among ``tasks``, one entry per variant:
    ``"TASK: best=NUMBER[, random=NUMBER], source=TEXT"`` (``[[task]]`` tables take
    ``reference = {best = ..., source = "..."}``). A variant without one is normalised
    against its base task's best with a measured random score
    (:func:`mtpg.envs.taskset.reference_scores.reference_of`, given the run's
    :meth:`task_table`)."""

    def __post_init__(self) -> None:
        _check(len(self.tasks) >= 1, "evaluation.tasks", "must name at least one task", self.tasks)
        for name in self.tasks:
            _check(isinstance(name, str), "evaluation.tasks", "must hold task names", name)
            if not is_variant(name) and not is_gym(name) and not is_compiled_name(name):
                _check(
                    name in TASK_NAMES,
                    "evaluation.tasks",
                    f"must be among {', '.join(TASK_NAMES)}",
                    name,
                )
            try:
                spelled = canonical(name)
            except ValueError as exc:
                raise ConfigError(f"evaluation.tasks: {exc}") from None
            _check(spelled == name, "evaluation.tasks", f"must spell it {spelled!r}", name)
        _check(
            len(set(self.tasks)) == len(self.tasks),
            "evaluation.tasks",
            "must not repeat a task",
            self.tasks,
        )
        _positive(self, "evaluation", ("train_episodes", "test_episodes"))
        _positive(
            self,
            "evaluation",
            ("test_interval", "validation_episodes", "resample_interval"),
            minimum=0,
        )
        _positive(self, "evaluation", ("validation_top_k",))
        _check(
            not self.resample_mean or self.resample_interval > 0,
            "evaluation.resample_mean",
            "needs evaluation.resample_interval > 0",
            self.resample_mean,
        )
        self._check_references()

    def _check_references(self) -> None:
        """Validates ``references`` (changing nothing: the task table holds them)."""
        seen = set()
        for text in self.references:
            _check(isinstance(text, str), "evaluation.references", "must hold text", text)
            try:
                given = parse_given(text)
            except ValueError as exc:
                raise ConfigError(f"evaluation.references: {exc}") from None
            _check(
                given.task in self.tasks,
                "evaluation.references",
                "must name a task of evaluation.tasks",
                given.task,
            )
            _check(given.task not in seen, "evaluation.references", "gives a task twice", text)
            seen.add(given.task)

    @property
    def n_subsets(self) -> int:
        """Number of non-empty task subsets."""
        return 2 ** len(self.tasks) - 1

    def task_table(self) -> TaskTable:
        """The task table of the active tasks and their given reference scores.

        A new value on every call: build it once per run and pass it on.
        """
        return TaskTable.from_names(self.tasks, self.references)

    @property
    def task_ids(self) -> tuple[int, ...]:
        """Task ids of the active tasks in their task table, in configuration order."""
        return self.task_table().ids


@dataclass(frozen=True, slots=True, kw_only=True)
class RunConfig:
    """A whole training run."""

    seed: int = 0
    """Run seed; every random draw derives from it."""
    generations: int = 1000
    """Generations to run (a resumed run continues up to this)."""
    workers: int = 1
    """Threads evaluating episodes (results do not depend on it)."""
    checkpoint_interval: int = 10
    """Generations between checkpoints (commits); one is also written when the run ends or
    is stopped by a signal, always of a complete generation (docs/runs.md)."""
    backend: str = "local"
    """Where new roots are evaluated: ``local`` (this machine's ``workers`` threads) or
    ``dask`` (a Dask cluster: ``address``, or a local one of ``dask_workers`` processes).
    Results do not depend on it."""
    address: str = ""
    """Scheduler address ``tcp://HOST:PORT`` of a running Dask cluster (backend ``dask``);
    empty to start a local cluster of ``dask_workers`` processes."""
    dask_workers: int = 0
    """Worker processes of a local Dask cluster started for the run (backend ``dask`` and
    no ``address``); 0 otherwise."""
    program: ProgramConfig = field(default_factory=ProgramConfig)
    """Program settings."""
    team: TeamConfig = field(default_factory=TeamConfig)
    """Team and graph settings."""
    evaluation: EvaluationConfig = field(default_factory=EvaluationConfig)
    """Task and episode settings."""

    def __post_init__(self) -> None:
        _positive(self, "run", ("seed",), minimum=0)
        _positive(self, "run", ("generations",))  # 0 would leave a run without a champion
        _positive(self, "run", ("workers", "checkpoint_interval"))
        _positive(self, "run", ("dask_workers",), minimum=0)
        _check(self.backend in BACKENDS, "backend", "must be local or dask", self.backend)
        # whether backend dask has an address or workers is checked when the run starts
        # (mtpg.evolve.backend.make_evaluator): overrides arrive one field at a time

    @property
    def elites_per_subset(self) -> int:
        """Elites kept, and children bred, per task subset each generation."""
        n = self.evaluation.n_subsets
        return max(self.team.n_elite, -(-self.team.min_elite_total // n))

    @property
    def ablations(self) -> tuple[str, ...]:
        """The switches of the ablations this configuration has on (:mod:`mtpg.ablations`)."""
        from mtpg.ablations import ablations_on

        return tuple(a.switch for a in ablations_on(self))
