"""The plan file of the committed experiments: TOML read into frozen dataclasses.

A plan (``results/plan.toml``) lists groups of runs. Each group has a name (``--only``
picks groups by it), a ``preset``, a ``folder`` (its runs go to ``FOLDER/runs/NAME``;
relative to the plan file's directory), the target ``generations`` and its runs. Each
``[[groups.runs]]`` entry names its run directories with a ``{seed}`` pattern, lists its
seeds and says what it adds to ``mtpg train``: ``tasks`` (task names) and ``interface``
(a table of ``[interfaces.NAME]`` mapping task names to the task specs of that
observation interface; with no ``tasks``, every task of the interface in its order), then
``args`` (more ``mtpg train`` arguments, such as ``["--no-memory"]``). A group's runs are
listed entry by entry, seeds in order, or with ``by_seed = true`` seed by seed, so that
runs to compare grow together.

A plan that does not follow this is refused with :class:`PlanError`, one line naming the
field (``plan.toml: groups[2].runs[0].seeds: expected a list of integers >= 0``).
"""

from __future__ import annotations

import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Any

__all__ = ["Group", "Plan", "PlanError", "PlannedRun", "RunEntry", "load_plan", "parse_plan"]


class PlanError(ValueError):
    """A plan file that cannot be read or does not follow the format (one line)."""


@dataclass(frozen=True)
class RunEntry:
    """One ``[[groups.runs]]`` entry: runs that differ only in their seed.

    Attributes:
        name: Run directory name with ``{seed}`` in it (``"TPG-seed{seed}"``).
        seeds: The seeds, one run each.
        train_args: What the entry adds to ``mtpg train`` (``--tasks`` from its tasks and
            interface, then its ``args``).
    """

    name: str
    seeds: tuple[int, ...]
    train_args: tuple[str, ...]

    def run_name(self, seed: int) -> str:
        """The run directory name of one seed."""
        return self.name.replace("{seed}", str(seed))


@dataclass(frozen=True)
class PlannedRun:
    """One run of a plan: a run directory grown by ``mtpg train``.

    Attributes:
        group: The name of its group.
        name: Its run directory name.
        seed: Its seed.
        preset: The preset it is begun with.
        train_args: What it adds to ``mtpg train`` after ``--seed``.
        folder: The results folder it belongs to (its run is ``folder/runs/name``).
        generations: Its target generation.
    """

    group: str
    name: str
    seed: int
    preset: str
    train_args: tuple[str, ...]
    folder: Path
    generations: int

    @property
    def path(self) -> Path:
        """Its run directory."""
        return self.folder / "runs" / self.name

    def command(
        self,
        generations: int,
        workers: int,
        begun: bool,
        extra: tuple[str, ...] = (),
    ) -> list[str]:
        """The ``mtpg`` arguments that begin (or, once ``begun``, resume) the run.

        Args:
            generations: The generation to grow it to.
            workers: Threads of the ``mtpg train`` process.
            begun: Whether the run directory has its ``config.toml`` (then it resumes).
            extra: More ``mtpg train`` arguments for a run begun now (trials and tests).

        Returns:
            The arguments after ``python -m mtpg``.
        """
        common = ["--generations", str(generations), "--workers", str(workers), "--quiet"]
        if begun:
            return ["train", "--resume", str(self.path), *common]
        head = ["train", "--preset", self.preset, "--seed", str(self.seed), *self.train_args]
        return [*head, *common, *extra, "--out", str(self.path)]


@dataclass(frozen=True)
class Group:
    """One experiment of the plan: its runs share a preset, a folder and a target.

    Attributes:
        name: The group's name (``--only NAME``).
        preset: The preset its runs are begun with.
        folder: Its results folder (absolute once read by :func:`load_plan`).
        generations: The target generation of its runs.
        entries: Its ``[[groups.runs]]`` entries.
        by_seed: List its runs seed by seed (else entry by entry).
        description: What the group is, in words.
    """

    name: str
    preset: str
    folder: Path
    generations: int
    entries: tuple[RunEntry, ...]
    by_seed: bool = False
    description: str = ""

    def runs(self, folder: Path | None = None) -> tuple[PlannedRun, ...]:
        """The group's runs, in the order they grow.

        Args:
            folder: Another results folder for them (default: the group's).
        """
        where = folder if folder is not None else self.folder
        pairs = [(e, s) for e in self.entries for s in e.seeds]
        if self.by_seed:
            pairs.sort(key=lambda p: p[1])  # stable: entries keep their order within a seed
        return tuple(
            PlannedRun(
                self.name,
                e.run_name(s),
                s,
                self.preset,
                e.train_args,
                where,
                self.generations,
            )
            for e, s in pairs
        )


@dataclass(frozen=True)
class Plan:
    """A plan file's groups and observation interfaces.

    Attributes:
        groups: The groups, in the file's order.
        interfaces: Each interface's task specs by task name.
    """

    groups: tuple[Group, ...]
    interfaces: dict[str, dict[str, str]]

    def group(self, name: str) -> Group:
        """The group named ``name``.

        Raises:
            PlanError: No group has that name.
        """
        for g in self.groups:
            if g.name == name:
                return g
        known = ", ".join(g.name for g in self.groups)
        raise PlanError(f"no group {name!r} in the plan (groups: {known})")

    def select(self, names: list[str] | None) -> tuple[Group, ...]:
        """The groups named (all of them when ``names`` is empty or None), in plan order."""
        if not names:
            return self.groups
        wanted = {self.group(n).name for n in names}
        return tuple(g for g in self.groups if g.name in wanted)


_GROUP_KEYS = {"name", "preset", "folder", "generations", "runs", "by_seed", "description"}
_RUN_KEYS = {"name", "seeds", "tasks", "interface", "args"}


def _fail(where: str, text: str) -> PlanError:
    return PlanError(f"{where}: {text}")


def _str(table: dict[str, Any], key: str, where: str, default: str | None = None) -> str:
    value = table.get(key, default)
    if not isinstance(value, str) or not value:
        raise _fail(f"{where}.{key}", "expected a non-empty string")
    return value


def _strings(value: Any, where: str) -> tuple[str, ...]:
    if not isinstance(value, list) or not all(isinstance(v, str) and v for v in value):
        raise _fail(where, "expected a list of non-empty strings")
    return tuple(value)


def _unknown(table: dict[str, Any], keys: set[str], where: str) -> None:
    extra = sorted(set(table) - keys)
    if extra:
        raise _fail(f"{where}.{extra[0]}", f"unknown field (known: {', '.join(sorted(keys))})")


def _interfaces(data: dict[str, Any], where: str) -> dict[str, dict[str, str]]:
    raw = data.get("interfaces", {})
    if not isinstance(raw, dict):
        raise _fail(f"{where}: interfaces", "expected a table of interfaces")
    out = {}
    for name, table in raw.items():
        at = f"{where}: interfaces.{name}"
        if not isinstance(table, dict) or not table:
            raise _fail(at, "expected a table of task name = task spec")
        for task, spec in table.items():
            if not isinstance(spec, str) or not spec:
                raise _fail(f"{at}.{task}", "expected a task spec string")
        out[name] = dict(table)
    return out


def _entry(raw: Any, where: str, interfaces: dict[str, dict[str, str]]) -> RunEntry:
    if not isinstance(raw, dict):
        raise _fail(where, "expected a table")
    _unknown(raw, _RUN_KEYS, where)
    name = _str(raw, "name", where)
    if "{seed}" not in name:
        raise _fail(f"{where}.name", "expected a pattern with {seed} in it")
    seeds = raw.get("seeds")
    ok = isinstance(seeds, list) and seeds and len(set(seeds)) == len(seeds)
    if not ok or not all(type(s) is int and s >= 0 for s in seeds):
        raise _fail(f"{where}.seeds", "expected a list of distinct integers >= 0")
    args: list[str] = []
    interface = raw.get("interface")
    specs: dict[str, str] = {}
    if interface is not None:
        if interface not in interfaces:
            known = ", ".join(interfaces) or "none"
            raise _fail(f"{where}.interface", f"no interface {interface!r} (known: {known})")
        specs = interfaces[interface]
    if "tasks" in raw or interface is not None:
        tasks = _strings(raw["tasks"], f"{where}.tasks") if "tasks" in raw else tuple(specs)
        missing = [t for t in tasks if specs and t not in specs]
        if missing:
            raise _fail(f"{where}.tasks", f"{missing[0]!r} is not in interface {interface!r}")
        args += ["--tasks", ",".join(specs.get(t, t) for t in tasks)]
    if "args" in raw:
        args += _strings(raw["args"], f"{where}.args")
    return RunEntry(name, tuple(seeds), tuple(args))


def _group(raw: Any, where: str, base: Path, interfaces: dict[str, dict[str, str]]) -> Group:
    if not isinstance(raw, dict):
        raise _fail(where, "expected a table")
    _unknown(raw, _GROUP_KEYS, where)
    generations = raw.get("generations")
    if type(generations) is not int or generations < 1:
        raise _fail(f"{where}.generations", "expected an integer >= 1")
    by_seed = raw.get("by_seed", False)
    if not isinstance(by_seed, bool):
        raise _fail(f"{where}.by_seed", "expected true or false")
    entries = raw.get("runs")
    if not isinstance(entries, list) or not entries:
        raise _fail(f"{where}.runs", "expected one or more [[groups.runs]] tables")
    description = raw.get("description", "")
    if not isinstance(description, str):
        raise _fail(f"{where}.description", "expected a string")
    return Group(
        name=_str(raw, "name", where),
        preset=_str(raw, "preset", where),
        folder=(base / _str(raw, "folder", where, ".")).resolve(),
        generations=generations,
        entries=tuple(_entry(e, f"{where}.runs[{i}]", interfaces) for i, e in enumerate(entries)),
        by_seed=by_seed,
        description=description,
    )


def parse_plan(text: str, base: Path, source: str = "plan") -> Plan:
    """Reads a plan from its TOML text.

    Args:
        text: The plan file's text.
        base: The directory relative folders are resolved against.
        source: How errors name the plan (its file name).

    Returns:
        The plan, validated.

    Raises:
        PlanError: The text is not TOML or does not follow the format (one line).
    """
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise PlanError(f"{source}: not valid TOML: {exc}") from None
    _unknown(data, {"groups", "interfaces"}, source)
    interfaces = _interfaces(data, source)
    raw = data.get("groups")
    if not isinstance(raw, list) or not raw:
        raise _fail(f"{source}: groups", "expected one or more [[groups]] tables")
    groups = tuple(_group(g, f"{source}: groups[{i}]", base, interfaces) for i, g in enumerate(raw))
    names = [g.name for g in groups]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise PlanError(f"{source}: groups: the name {twice[0]!r} is given twice")
    runs = [(g.folder, r.name) for g in groups for r in g.runs()]
    same = sorted({r for r in runs if runs.count(r) > 1})
    if same:
        raise PlanError(f"{source}: groups: the run {same[0][1]!r} is planned twice")
    return Plan(groups, interfaces)


def load_plan(path: str | Path) -> Plan:
    """Reads a plan file; its folders are relative to the file's directory.

    Raises:
        PlanError: The file does not follow the format (one line naming the field).
        OSError: The file cannot be read.
    """
    path = Path(path)
    return parse_plan(path.read_text(encoding="utf-8"), path.resolve().parent, path.name)
