"""The task table of a run: its tasks' ids, specs, parameter rows and given reference scores.

A :class:`TaskTable` is one immutable value, built once from task names (registered names
or variants, :mod:`mtpg.envs.taskset.variants`) and the reference scores given for variants
(:class:`GivenReference`). Everything that plays or scores a task takes the table: the
trainer, the episode tables, the test protocol, evaluation, export and the analyses. Nothing
about tasks is held by the process: two tables with different variants live side by side.

Ids: a registered task's id is its index in the registry (:data:`mtpg.envs.specs.registry.TASKS`)
in every table; the table's variants get ``VARIANT_ID_BASE + k`` in order of first
appearance, so an id past the registry stays unknown until a task is registered under it.
Ids are table-local; names are what runs, checkpoints and graph files store.

The table's ``params`` is the float64 parameter table the compiled kernels index by id:
the registered rows (:data:`mtpg.envs.specs.param_table.TASK_PARAMS`), padding up to
``VARIANT_ID_BASE`` (rows whose kind has no branch), then one row per variant.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from mtpg.envs.specs.compiled_task import CompiledTask, is_compiled_name
from mtpg.envs.specs.compiled_task import load as load_compiled
from mtpg.envs.specs.gym_task import GymTask, is_gym
from mtpg.envs.specs.param_table import TASK_PARAMS, param_row, params_table
from mtpg.envs.specs.registry import TASK_NAMES, TASKS
from mtpg.envs.specs.task_spec import TaskSpec
from mtpg.envs.taskset.variants import canonical, is_variant, variant_row, variant_spec

#: The first variant id of a table (registered tasks keep 0..).
VARIANT_ID_BASE = 256
#: The first id of a compiled task of a user's module (:mod:`mtpg.envs.specs.compiled_task`).
USER_ID_BASE = 512
#: The first Gymnasium task id of a table (:mod:`mtpg.envs.specs.gym_task`): tasks that step in
#: Python, never in the compiled kernels.
GYM_ID_BASE = 1 << 20
#: The interface of the registered tasks: two observed inputs, three atomic actions and
#: one continuous output (``m[0]``).
BUILTIN_SHAPE = (2, 3, 1)


class GivenReference(NamedTuple):
    """Reference scores of a variant given by the user, with their source.

    Attributes:
        task: The variant's canonical name.
        best: The reference best score (Fig. 6 normalisation).
        source: Where ``best`` comes from (a paper, a leaderboard, a measurement).
        random: The random agent's mean score, or None to measure it on demand.
    """

    task: str
    best: float
    source: str
    random: float | None = None

    def text(self) -> str:
        """The entry as ``evaluation.references`` holds it (:func:`parse_given`)."""
        random = "" if self.random is None else f", random={self.random!r}"
        return f"{self.task}: best={self.best!r}{random}, source={self.source}"


def parse_given(text: str) -> GivenReference:
    """Reads one entry of ``evaluation.references``.

    The entry is ``"TASK: best=NUMBER[, random=NUMBER], source=TEXT"``; ``source`` comes
    last and takes the rest of the entry (commas included). ``TASK`` must be a variant
    spelled canonically: a registered task's reference scores are the registry's.

    Raises:
        ValueError: One line naming the fault.
    """
    # a gym:ID task holds colons of its own: its entry is split at the first ": "
    task, sep, rest = (s.strip() for s in text.partition(": " if ": " in text else ":"))
    if not sep or not task:
        raise ValueError(f"{text!r}: write TASK: best=NUMBER[, random=NUMBER], source=TEXT")
    if is_gym(task) or is_compiled_name(task):
        pass  # a Gymnasium or compiled task's scores are given or raw
    elif not is_variant(task):
        raise ValueError(f"{task}: a registered task's reference scores are the registry's")
    if not is_compiled_name(task) and canonical(task) != task:
        raise ValueError(f"{task}: spell it {canonical(task)!r}")
    head, sep, source = rest.partition("source=")
    if not sep or not source.strip():
        raise ValueError(f"{task}: needs source=TEXT (where the best score comes from), last")
    values: dict[str, float] = {}
    for item in filter(None, (i.strip() for i in head.split(","))):
        key, eq, raw = (s.strip() for s in item.partition("="))
        if key not in ("best", "random") or not eq:
            raise ValueError(f"{task}: unknown setting {item!r}; allowed: best, random, source")
        if key in values:
            raise ValueError(f"{task}: {key} given twice")
        try:
            values[key] = float(raw)
        except ValueError:
            raise ValueError(f"{task}: {key}: {raw!r} is not a number") from None
        if not np.isfinite(values[key]):
            raise ValueError(f"{task}: {key}: must be finite, got {raw!r}")
    if "best" not in values:
        raise ValueError(f"{task}: needs best=NUMBER")
    if values["best"] == values.get("random"):
        raise ValueError(f"{task}: best equals random; nothing could be normalised")
    return GivenReference(task, values["best"], source.strip(), values.get("random"))


@dataclass(frozen=True, eq=False)
class TaskTable:
    """The tasks of a run as one value (build it with :meth:`from_names`).

    Attributes:
        names: The run's tasks, canonical names, in the order given.
        ids: Their ids in this table.
        variants: The table's variant specs; variant ``k`` has id ``VARIANT_ID_BASE + k``.
        params: float64 ``[ids, N_PARAMS]`` read-only parameter table the kernels index.
        given: Reference scores given for variants of the table, one per variant at most.
        gym: The table's Gymnasium tasks; task ``k`` has id ``GYM_ID_BASE + k``.
        user: The table's compiled tasks of users' modules; task ``k`` has id
            ``USER_ID_BASE + k``.
    """

    names: tuple[str, ...]
    ids: tuple[int, ...]
    variants: tuple[TaskSpec, ...]
    params: np.ndarray
    given: tuple[GivenReference, ...] = ()
    gym: tuple[GymTask, ...] = ()
    user: tuple[CompiledTask, ...] = ()

    @classmethod
    def from_names(
        cls, names: Iterable[str] = (), references: Iterable[str | GivenReference] = ()
    ) -> TaskTable:
        """The table of ``names`` (any spelling; stored canonically) and their references.

        Args:
            names: Registered task names or variants.
            references: Given reference scores of variants among ``names``, as
                :class:`GivenReference` or as ``evaluation.references`` entries.

        Raises:
            ValueError: One line naming the fault: an unknown task or a bad variant, a bad
                reference entry, one for a task not among ``names``, or two for one task.
        """
        names = tuple(n if is_compiled_name(n) else canonical(n) for n in names)
        variants: list[TaskSpec] = []
        gym: list[GymTask] = []
        user: list[CompiledTask] = []
        for name in dict.fromkeys(names):
            if is_compiled_name(name):
                user.append(load_compiled(name))
            elif is_gym(name):
                gym.append(GymTask.from_name(name))
            elif is_variant(name):
                variants.append(variant_spec(name))
        var_ids = {v.name: VARIANT_ID_BASE + k for k, v in enumerate(variants)}
        var_ids.update({t.name: GYM_ID_BASE + k for k, t in enumerate(gym)})
        var_ids.update({t.name: USER_ID_BASE + k for k, t in enumerate(user)})
        ids = tuple(var_ids[n] if n in var_ids else TASK_NAMES.index(n) for n in names)
        given: dict[str, GivenReference] = {}
        for entry in references:
            ref = parse_given(entry) if isinstance(entry, str) else entry
            if ref.task not in var_ids:  # variants and Gymnasium tasks
                raise ValueError(f"{ref.task}: reference scores given for a task not in the run")
            if ref.task in given:
                raise ValueError(f"{ref.task}: reference scores given twice")
            given[ref.task] = ref
        params = TASK_PARAMS
        if variants or user:
            padding = [param_row((1.0, 0.0), -1)] * (VARIANT_ID_BASE - len(TASK_PARAMS))
            rows = [*TASK_PARAMS, *padding, *(variant_row(v) for v in variants)]
            if user:
                rows += [param_row((1.0, 0.0), -1)] * (USER_ID_BASE - len(rows))
                rows += [param_row(t.row(), USER_ID_BASE + k) for k, t in enumerate(user)]
            params = params_table(rows)
        compiled = [n for n in names if not is_gym(n) and not is_compiled_name(n)]
        many = [t.name for t in (*gym, *user) if t.n_actions > BUILTIN_SHAPE[1]]
        if compiled and many:
            raise ValueError(
                f"{many[0]} takes more than {BUILTIN_SHAPE[1]} discrete actions, which the "
                f"registered tasks ({compiled[0]}) cannot play; train it without them"
            )
        table = (names, ids, tuple(variants), params, tuple(given.values()), tuple(gym))
        return cls(*table, tuple(user))

    def id_of(self, name: str) -> int:
        """The id of a registered task, or of a variant of this table (any spelling).

        Raises:
            ValueError: For an unknown task, a bad variant, or a variant not in the table.
        """
        if name in TASK_NAMES:
            return TASK_NAMES.index(name)
        for k, task in enumerate(self.user):
            if task.name == name:
                return USER_ID_BASE + k
        key = canonical(name)
        for k, spec in enumerate(self.variants):
            if spec.name == key:
                return VARIANT_ID_BASE + k
        for k, task in enumerate(self.gym):
            if task.name == key:
                return GYM_ID_BASE + k
        raise ValueError(f"task {key!r} is not in this task table ({', '.join(self.names)})")

    def spec(self, task: int | str) -> TaskSpec | GymTask | CompiledTask:
        """The spec of a task id or name of this table (a Gymnasium task's :class:`GymTask`).

        Raises:
            ValueError: For an id or name the table does not know.
        """
        i = self.id_of(task) if isinstance(task, str) else int(task)
        if not self.valid_id(i):
            raise ValueError(f"unknown task id {i}; valid ids are {self.id_ranges()}")
        if i >= GYM_ID_BASE:
            return self.gym[i - GYM_ID_BASE]
        if i >= USER_ID_BASE:
            return self.user[i - USER_ID_BASE]
        return TASKS[i] if i < len(TASKS) else self.variants[i - VARIANT_ID_BASE]

    @property
    def specs(self) -> tuple[TaskSpec | GymTask | CompiledTask, ...]:
        """The specs of the run's tasks, in ``names`` order."""
        return tuple(self.spec(i) for i in self.ids)

    def valid_id(self, task: int) -> bool:
        """Whether an id names a registered task, a variant or a Gymnasium task of this table."""
        return (
            0 <= task < len(TASKS)
            or 0 <= task - VARIANT_ID_BASE < len(self.variants)
            or 0 <= task - GYM_ID_BASE < len(self.gym)
            or 0 <= task - USER_ID_BASE < len(self.user)
        )

    def is_gym(self, task: int) -> bool:
        """Whether a task id of this table is a Gymnasium task (it steps in Python)."""
        return task >= GYM_ID_BASE

    def is_user(self, task: int) -> bool:
        """Whether a task id of this table is a compiled task of a user's module."""
        return USER_ID_BASE <= task < GYM_ID_BASE

    @property
    def shape(self) -> tuple[int, int, int]:
        """The run's interface: observed inputs, atomic actions, continuous outputs.

        The largest over the run's tasks (the registered tasks: 2, 3 and 1). A task with
        fewer inputs leaves the rest at 0; one with fewer discrete actions folds atomic
        action ``a`` onto ``a mod n`` (:mod:`mtpg.envs.specs.gym_task`).
        """
        shapes = [
            (t.n_obs, t.n_actions, t.n_continuous)
            if self.is_gym(i) or self.is_user(i)
            else BUILTIN_SHAPE
            for i, t in zip(self.ids, self.specs, strict=True)
        ]
        n_obs, n_act, n_cont = (max(column) for column in zip(*shapes, strict=True))
        return n_obs, max(n_act, 1), n_cont

    def id_ranges(self) -> str:
        """The valid ids, as text (``0..5`` or ``0..5, 256..257``)."""
        text = f"0..{len(TASKS) - 1}"
        if self.variants:
            text += f", {VARIANT_ID_BASE}..{VARIANT_ID_BASE + len(self.variants) - 1}"
        if self.user:
            text += f", {USER_ID_BASE}..{USER_ID_BASE + len(self.user) - 1}"
        if self.gym:
            text += f", {GYM_ID_BASE}..{GYM_ID_BASE + len(self.gym) - 1}"
        return text

    def given_reference(self, name: str) -> GivenReference | None:
        """The reference scores given for a variant of the table, or None."""
        return next((g for g in self.given if g.task == name), None)


#: The table of the registered tasks alone (no variants, no given references).
REGISTERED = TaskTable.from_names(TASK_NAMES)
