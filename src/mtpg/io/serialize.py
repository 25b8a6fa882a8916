"""Populations and single program graphs as JSON-native dicts and readable graph files.

Two forms:

* :func:`population_to_dict` — the whole population, compact, for checkpoints. Actions
  keep the model encoding (``>= 0`` team id, ``-1 - a`` atomic action ``a``).
* :func:`graph_to_dict` — one program graph (the teams reachable from a root and their
  programs), versioned and meant to be read by a person: actions are spelled
  ``{"atomic": a}`` or ``{"team": id}`` and each program carries its disassembly.

Both loaders validate everything (types, id uniqueness, pointers, operand ranges and the
population invariants of :func:`mtpg.model.check_invariants`) and raise
:class:`FormatError` naming the offending item.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

import numpy as np

from mtpg.io._atomic import atomic_write_bytes
from mtpg.io._bounded import MAX_GRAPH_BYTES, TooLargeError, check_depth, limit, read_file_bounded
from mtpg.io._readable import Encoded, dumps_readable, encode_at
from mtpg.model.graph import (
    InvariantError,
    Population,
    Program,
    Team,
    atomic,
    check_invariants,
)
from mtpg.model.instructions import RegisterLayout, disassemble, valid_instructions

#: Format tag and version of a population dict.
POPULATION_FORMAT = "mtpg-population"
POPULATION_VERSION = 2
#: Population versions this mtpg reads. Version 1 had no bank list: its banks are the
#: banks its programs point to (a version-1 population had no others).
POPULATION_VERSIONS = (1, 2)
#: Format tag and version of a graph file.
GRAPH_FORMAT = "mtpg-graph"
GRAPH_VERSION = 1

_LAYOUT_KEYS = ("n_registers", "n_memory", "n_obs")
#: Largest register-bank size a file may declare (``program.n_registers`` / ``n_memory``).
MAX_BANK_SIZE = 256
#: Largest number of observed inputs or atomic actions a file may declare.
MAX_INPUTS = 1 << 16
#: Integers in files must fit a signed 64-bit integer (ids become int64 arrays).
_INT64 = (-(2**63), 2**63 - 1)


class FormatError(ValueError):
    """Serialized data is malformed; the message names the file, item and problem."""


# --------------------------------------------------------------------------- validation


def _object(value: Any, where: str) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise FormatError(f"{where} must be a JSON object, got {type(value).__name__}")
    return value


def _key(obj: dict[str, Any], key: str, where: str) -> Any:
    if key not in obj:
        raise FormatError(f"{where} is missing key {key!r}")
    return obj[key]


def _int(value: Any, where: str, lo: int | None = None) -> int:
    if not isinstance(value, int) or isinstance(value, bool):
        raise FormatError(f"{where} must be an integer, got {value!r}")
    if lo is not None and value < lo:
        raise FormatError(f"{where} must be >= {lo}, got {value}")
    if not _INT64[0] <= value <= _INT64[1]:
        raise FormatError(f"{where} must fit a 64-bit integer, got {value}")
    return value


def _list(value: Any, where: str) -> list[Any]:
    if not isinstance(value, list):
        raise FormatError(f"{where} must be a list, got {type(value).__name__}")
    return value


def _check_tag(d: dict[str, Any], fmt: str, versions: tuple[int, ...], what: str) -> int:
    tag = _key(d, "format", what)
    if tag != fmt:
        raise FormatError(f"{what}: format is {tag!r}, expected {fmt!r}")
    found = _key(d, "version", what)
    if found not in versions or isinstance(found, bool):
        readable = " or ".join(str(v) for v in versions)
        raise FormatError(f"{what}: unsupported version {found!r} (this mtpg reads {readable})")
    return found


def _layout_from(value: Any) -> RegisterLayout:
    obj = _object(value, "layout")
    sizes = {k: _int(_key(obj, k, "layout"), f"layout.{k}", lo=1) for k in _LAYOUT_KEYS}
    if "n_actions" in obj:  # written only when not the paper's 3 (older files: 3)
        sizes["n_actions"] = _int(obj["n_actions"], "layout.n_actions", lo=1)
    extra = sorted(set(obj) - {*_LAYOUT_KEYS, "n_actions"})
    if extra:
        raise FormatError(f"layout has unknown keys {extra}")
    for key, top in (("n_obs", MAX_INPUTS), ("n_actions", MAX_INPUTS)):
        if sizes.get(key, 0) > top:
            raise FormatError(f"layout.{key} must be <= {top}, got {sizes[key]}")
    for key in ("n_registers", "n_memory"):
        if sizes[key] > MAX_BANK_SIZE:
            raise FormatError(f"layout.{key} must be <= {MAX_BANK_SIZE}, got {sizes[key]}")
    return RegisterLayout(**sizes)


def _instructions_from(value: Any, where: str, layout: RegisterLayout) -> np.ndarray:
    rows = _list(value, f"{where} instructions")
    if not rows:
        raise FormatError(f"{where} has no instructions")
    try:
        arr = np.asarray(rows)
    except (ValueError, TypeError, OverflowError) as exc:
        raise FormatError(f"{where} instructions are not [op, dst, src1, src2] rows") from exc
    if arr.ndim != 2 or arr.shape[1] != 4:
        raise FormatError(f"{where} instructions must be [op, dst, src1, src2] rows")
    if arr.dtype.kind not in "iu":
        raise FormatError(f"{where} instructions must hold integers, got {arr.dtype} values")
    problem = valid_instructions(arr, layout)
    if problem is not None:
        raise FormatError(f"{where}: {problem}")
    return arr.astype(np.int32)


def _check_population(pop: Population, what: str) -> None:
    try:
        check_invariants(pop)
    except InvariantError as exc:
        raise FormatError(f"{what}: {exc}") from exc


def _layout_dict(layout: RegisterLayout) -> dict[str, int]:
    out = {k: int(getattr(layout, k)) for k in _LAYOUT_KEYS}
    if layout.n_actions != 3:  # the paper's files stay as they were
        out["n_actions"] = int(layout.n_actions)
    return out


def _code(instructions: np.ndarray) -> list[list[int]]:
    return np.asarray(instructions, dtype=np.int64).tolist()


# --------------------------------------------------------------------------- population


def population_to_dict(pop: Population) -> dict[str, Any]:
    """Serializes a whole population exactly.

    Args:
        pop: The population.

    Returns:
        A JSON-native dict: ``format``, ``version``, ``layout``, the three id counters,
        ``banks`` (the bank population, ascending, banks no program points to included),
        ``programs`` (``id``, ``action``, ``bank``, ``instructions``) and ``teams``
        (``id``, ``programs``, ``birth``), both lists in the population's dict order.
    """
    return {
        "format": POPULATION_FORMAT,
        "version": POPULATION_VERSION,
        "layout": _layout_dict(pop.layout),
        "next_program_id": int(pop.next_program_id),
        "next_team_id": int(pop.next_team_id),
        "next_bank_id": int(pop.next_bank_id),
        "banks": [int(b) for b in pop.banks()],
        "programs": [
            {
                "id": int(p.id),
                "action": int(p.action),
                "bank": int(p.bank),
                "instructions": _code(p.instructions),
            }
            for p in pop.programs.values()
        ],
        "teams": [
            {"id": int(t.id), "programs": [int(x) for x in t.programs], "birth": int(t.birth)}
            for t in pop.teams.values()
        ],
    }


def _ids_list(value: Any, where: str) -> list[int]:
    return [_int(x, f"{where}[{i}]") for i, x in enumerate(_list(value, where))]


def population_from_dict(d: Any) -> Population:
    """Rebuilds a population from :func:`population_to_dict` output, validated.

    Args:
        d: The dict (as read from JSON).

    Returns:
        The population, with the same ids, counters and dict order.

    Raises:
        FormatError: Naming the first problem found.
    """
    d = _object(d, "population")
    version = _check_tag(d, POPULATION_FORMAT, POPULATION_VERSIONS, "population")
    pop = Population(layout=_layout_from(_key(d, "layout", "population")))
    for name in ("next_program_id", "next_team_id", "next_bank_id"):
        setattr(pop, name, _int(_key(d, name, "population"), f"population.{name}", lo=0))
    for i, item in enumerate(_list(_key(d, "programs", "population"), "population.programs")):
        where = f"population.programs[{i}]"
        obj = _object(item, where)
        pid = _int(_key(obj, "id", where), f"{where}.id", lo=0)
        where = f"program {pid}"
        if pid in pop.programs:
            raise FormatError(f"{where} appears twice")
        code = _instructions_from(_key(obj, "instructions", where), where, pop.layout)
        action = _int(_key(obj, "action", where), f"{where} action", lo=-pop.layout.n_actions)
        bank = _int(_key(obj, "bank", where), f"{where} bank", lo=0)
        pop.programs[pid] = Program(pid, code, action, bank)
    for i, item in enumerate(_list(_key(d, "teams", "population"), "population.teams")):
        where = f"population.teams[{i}]"
        obj = _object(item, where)
        tid = _int(_key(obj, "id", where), f"{where}.id", lo=0)
        where = f"team {tid}"
        if tid in pop.teams:
            raise FormatError(f"{where} appears twice")
        members = _ids_list(_key(obj, "programs", where), f"{where} programs")
        birth = _int(_key(obj, "birth", where), f"{where} birth")
        pop.teams[tid] = Team(tid, members, birth)
    if version == 1:
        pop.memory_banks = pop.banks_in_use()
    else:
        banks = _ids_list(_key(d, "banks", "population"), "population.banks")
        pop.memory_banks = set(banks)
        if len(pop.memory_banks) != len(banks):
            raise FormatError("population.banks repeats a bank")
    _check_population(pop, "population")
    return pop


# --------------------------------------------------------------------------- graph


def graph_to_dict(
    pop: Population, root_id: int, meta: dict[str, Any] | None = None, body: bool = True
) -> dict:
    """Serializes the program graph rooted at one team, for people and for reloading.

    Args:
        pop: The population holding the graph.
        root_id: Id of the root team.
        meta: JSON-native facts to store alongside (task scores, generation, seed ...).
        body: False leaves out ``teams`` and ``programs`` (for :func:`graph_text`'s cache).

    Returns:
        A JSON-native dict: ``format``, ``version``, ``root``, ``layout``, ``meta``,
        ``teams`` (depth-first from the root) and ``programs`` (in order of first use),
        each program with its ``action`` spelled out and its ``code`` disassembled.

    Raises:
        ValueError: When ``root_id`` is not a team of ``pop`` or ``meta`` is not a dict.
    """
    if root_id not in pop.teams:
        raise ValueError(f"root team {root_id} is not in the population")
    if meta is not None and not isinstance(meta, dict):
        raise ValueError(f"meta must be a dict, got {type(meta).__name__}")
    head = {
        "format": GRAPH_FORMAT,
        "version": GRAPH_VERSION,
        "root": int(root_id),
        "layout": _layout_dict(pop.layout),
        "meta": dict(meta or {}),
    }
    if not body:
        return head
    team_ids = pop.reachable(root_id)
    return {
        **head,
        "teams": [_team_dict(pop, tid) for tid in team_ids],
        "programs": [_program_dict(pop, pid) for pid in _graph_programs(pop, team_ids)],
    }


def _graph_programs(pop: Population, team_ids: list[int]) -> list[int]:
    """The programs of the teams, in order of first use."""
    return list(dict.fromkeys(pid for tid in team_ids for pid in pop.teams[tid].programs))


def _team_dict(pop: Population, tid: int) -> dict:
    team = pop.teams[tid]
    return {"id": int(tid), "programs": [int(x) for x in team.programs], "birth": int(team.birth)}


def _program_dict(pop: Population, pid: int) -> dict:
    p = pop.programs[pid]
    action = {"atomic": int(p.atomic_action)} if p.is_atomic else {"team": int(p.action)}
    return {
        "id": int(pid),
        "action": action,
        "bank": int(p.bank),
        "instructions": _code(p.instructions),
        "code": disassemble(p.instructions, pop.layout),
    }


def _action_from(value: Any, where: str, n_actions: int) -> int:
    obj = _object(value, f"{where} action")
    if len(obj) != 1 or next(iter(obj)) not in ("atomic", "team"):
        raise FormatError(f'{where} action must be {{"atomic": a}} or {{"team": id}}, got {obj}')
    if "atomic" in obj:
        a = _int(obj["atomic"], f"{where} atomic action", lo=0)
        if a >= n_actions:
            raise FormatError(f"{where} atomic action must be < {n_actions}, got {a}")
        return atomic(a)
    return _int(obj["team"], f"{where} team pointer", lo=0)


def graph_from_dict(d: Any) -> tuple[Population, int]:
    """Rebuilds a population holding one graph from :func:`graph_to_dict` output.

    Ids are kept; the counters are set one past the largest team, program and bank id.
    The population's banks are the banks the graph's programs point to. ``code`` lines
    are ignored (``instructions`` are authoritative).

    Args:
        d: The dict (as read from JSON).

    Returns:
        ``(population, root team id)``.

    Raises:
        FormatError: Naming the first problem (format, version, missing key, dangling
            pointer, bad instruction ...).
    """
    d = _object(d, "graph")
    _check_tag(d, GRAPH_FORMAT, (GRAPH_VERSION,), "graph")
    for key in ("root", "layout", "meta", "teams", "programs"):
        _key(d, key, "graph")
    _object(d["meta"], "graph meta")
    pop = Population(layout=_layout_from(d["layout"]))
    for i, item in enumerate(_list(d["programs"], "graph programs")):
        where = f"graph programs[{i}]"
        obj = _object(item, where)
        pid = _int(_key(obj, "id", where), f"{where}.id", lo=0)
        where = f"program {pid}"
        if pid in pop.programs:
            raise FormatError(f"{where} appears twice")
        code = _instructions_from(_key(obj, "instructions", where), where, pop.layout)
        action = _action_from(_key(obj, "action", where), where, pop.layout.n_actions)
        bank = _int(_key(obj, "bank", where), f"{where} bank", lo=0)
        pop.programs[pid] = Program(pid, code, action, bank)
    for i, item in enumerate(_list(d["teams"], "graph teams")):
        where = f"graph teams[{i}]"
        obj = _object(item, where)
        tid = _int(_key(obj, "id", where), f"{where}.id", lo=0)
        where = f"team {tid}"
        if tid in pop.teams:
            raise FormatError(f"{where} appears twice")
        members = _ids_list(_key(obj, "programs", where), f"{where} programs")
        for pid in members:
            if pid not in pop.programs:
                raise FormatError(f"{where} holds program {pid}, which the file does not define")
        birth = _int(_key(obj, "birth", where), f"{where} birth")
        pop.teams[tid] = Team(tid, members, birth)
    for pid, prog in pop.programs.items():
        if prog.action >= 0 and prog.action not in pop.teams:
            raise FormatError(f"program {pid} points to team {prog.action}, which is missing")
    root = _int(d["root"], "graph root", lo=0)
    if root not in pop.teams:
        raise FormatError(f"graph root {root} is not one of its teams")
    pop.next_team_id = max(pop.teams) + 1
    pop.next_program_id = max(pop.programs, default=-1) + 1
    pop.memory_banks = pop.banks_in_use()  # a graph's banks are those its programs use
    pop.next_bank_id = max(pop.memory_banks, default=-1) + 1
    _check_population(pop, "graph")
    return pop, root


def save_graph(
    path: str | os.PathLike[str],
    pop: Population,
    root_id: int,
    meta: dict | None = None,
    bodies: dict[int, dict[str, Encoded]] | None = None,
) -> None:
    """Writes one program graph as a readable JSON file, atomically.

    Args:
        path: Destination file (its directory must exist).
        pop: The population holding the graph.
        root_id: Id of the root team.
        meta: JSON-native facts to store alongside.
        bodies: A cache of rendered graphs shared by the files of one commit
            (:func:`graph_text`).

    Raises:
        FormatError: When ``meta`` cannot be written as JSON (naming the file).
        OSError: When the file cannot be written.
    """
    try:
        text = graph_text(pop, root_id, meta, bodies)
    except (TypeError, ValueError) as exc:
        raise FormatError(f"{path}: cannot write graph: {exc}") from exc
    atomic_write_bytes(path, text.encode("utf-8"))


def graph_text(
    pop: Population,
    root_id: int,
    meta: dict | None = None,
    bodies: dict[int, dict[str, Encoded]] | None = None,
) -> str:
    """The text of a graph file: ``dumps_readable(graph_to_dict(pop, root_id, meta))``.

    Args:
        pop: The population holding the graph.
        root_id: Id of the root team.
        meta: JSON-native facts to store alongside.
        bodies: A cache of rendered graphs by root, valid for one unchanged ``pop`` (a
            commit writes one file per task subset, many of them of the same champion:
            each distinct graph is then rendered once). None: no cache.

    Returns:
        The file's text.
    """
    if bodies is None:
        return dumps_readable(graph_to_dict(pop, root_id, meta))
    data = graph_to_dict(pop, root_id, meta, body=False)  # checks root and meta
    if root_id not in bodies:
        team_ids = pop.reachable(root_id)
        done = bodies.setdefault(-1, {})  # programs rendered for other graphs: shared
        programs = []
        for pid in _graph_programs(pop, team_ids):
            if pid not in done:
                done[pid] = encode_at(_program_dict(pop, pid), 2)
            programs.append(done[pid])
        teams = [_team_dict(pop, tid) for tid in team_ids]
        bodies[root_id] = {"teams": encode_at(teams, 1), "programs": encode_at(programs, 1)}
    data.update(bodies[root_id])
    return dumps_readable(data)


def load_graph(path: str | os.PathLike[str]) -> tuple[Population, int, dict[str, Any]]:
    """Reads a graph file written by :func:`save_graph`.

    Args:
        path: The file.

    Returns:
        ``(population, root team id, meta)``.

    Raises:
        FormatError: For any problem (unreadable, not JSON, invalid graph), naming the file.
    """
    if Path(path).is_dir():
        raise FormatError(f"{path}: is a directory, not a graph file")
    try:
        text = read_file_bounded(path, limit(MAX_GRAPH_BYTES, "MTPG_MAX_GRAPH_BYTES"))
        text = text.decode("utf-8")
    except TooLargeError as exc:
        raise FormatError(f"{path}: graph {exc}") from exc
    except (OSError, UnicodeDecodeError) as exc:
        why = exc.strerror if isinstance(exc, OSError) else f"not UTF-8 text ({exc.reason})"
        raise FormatError(f"{path}: cannot read graph file: {why or exc}") from exc
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise FormatError(f"{path}: not valid JSON: {exc}") from exc
    except RecursionError:
        raise FormatError(f"{path}: not a graph file: JSON nested too deeply") from None
    try:
        pop, root = graph_from_dict(data)
        check_depth(data["meta"])
    except (FormatError, ValueError) as exc:
        raise FormatError(f"{path}: {exc}") from exc
    return pop, root, data["meta"]
