"""Task variants as data: ``CartPole[max_steps=500]``, ``Pendulum[observe=theta]``.

A variant is a registered task with some of its settings changed, written
``Base[key=value;key=value]``. The keys:

- any parameter of the base task by its name (``TaskSpec.param_names``, e.g. ``max_steps``,
  ``gravity``): the parameter's value (``max_steps`` a whole number >= 1);
- ``observe``: the one or two state variables the two inputs observe, joined by ``+``
  (``observe=x+theta``), each scaled from the base spec's ``state_low..state_high`` to
  [-1, 1] (angles wrapped into [-pi, pi) first) and clipped; with one variable the second
  input is the U[0, 1] noise input, as in the paper's one-observable tasks;
- ``noise``: Gaussian observation noise: each input that observes the state gets
  ``sd * N(0, 1)`` added (in its [-1, 1] units) and is clipped again; ``sd >= 0``. The
  normal values are drawn per episode after its start state and U[0, 1] values
  (:func:`mtpg.envs.episodes.draw_episodes`), so a task without noise draws as before.

The dynamics are the base task's kernels on the variant's parameter row, so a variant
reproduces its base task step for step and runs in the compiled engine like it. The start
distribution is the base task's (parameters read only by the start sampler, such as
CartCentering's ``start_range``, keep their base value there).

A variant's name is canonical (keys sorted, values normalised): :func:`canonical` turns any
spelling into it, and the configuration stores it as the task's name. Its id is handed out
when the name is first resolved in a process (:func:`resolve`), from ``VARIANT_ID_BASE``
(256) on: ids are process-local; names are what runs, checkpoints and graph files store.
A variant's reference scores are measured on demand
(:func:`mtpg.envs.reference.reference_of`).
"""

from __future__ import annotations

import math
import re
from dataclasses import replace

import numpy as np

from mtpg.envs.registry import TASK_NAMES, TASKS
from mtpg.envs.taskspec import NONE, Reference, TaskSpec

_NAME = re.compile(r"^(?P<base>[A-Za-z][A-Za-z0-9]*)\[(?P<body>[^\[\]]*)\]$")

#: The first variant id: registered tasks keep 0.., variants get VARIANT_ID_BASE + k, so an
#: id past the registry stays unknown until a task is registered under it, whatever
#: variants a process has resolved (rows in between are padding whose kind has no branch).
VARIANT_ID_BASE = 256

_VARIANTS: list[TaskSpec] = []
_IDS: dict[str, int] = {name: i for i, name in enumerate(TASK_NAMES)}
_TABLE: list[np.ndarray] = []
_CACHE: dict[int, np.ndarray] = {}


def is_variant(name: str) -> bool:
    """Whether a task name is written as a variant (``Base[...]``)."""
    return "[" in name


def _fail(text: str, message: str) -> ValueError:
    return ValueError(f"task {text!r}: {message}")


def allowed_keys(base: TaskSpec) -> tuple[str, ...]:
    """The keys a variant of ``base`` may set."""
    return (*base.param_names, "noise", "observe")


def _value(text: str, base: TaskSpec, key: str, raw: str) -> str:
    """The canonical spelling of one value (raises naming the key and what is allowed)."""
    if key == "observe":
        names = raw.split("+")
        bad = [n for n in names if n not in base.state_names]
        if not raw or bad:
            allowed = ", ".join(base.state_names)
            what = f"unknown state variable {bad[0]!r}" if bad and bad[0] else "empty"
            raise _fail(text, f"observe: {what}; allowed: {allowed} (one or two, joined by +)")
        if len(names) > 2 or len(set(names)) != len(names):
            raise _fail(text, "observe: one or two distinct state variables, joined by +")
        return "+".join(names)
    try:
        number = float(raw)
    except ValueError:
        raise _fail(text, f"{key}: {raw!r} is not a number") from None
    if not math.isfinite(number):
        raise _fail(text, f"{key}: must be finite, got {raw!r}")
    if key == "noise" and number < 0:
        raise _fail(text, f"noise: a standard deviation >= 0, got {raw!r}")
    if key == "max_steps":
        if number != int(number) or number < 1:
            raise _fail(text, f"max_steps: a whole number >= 1, got {raw!r}")
        return str(int(number))
    return repr(number)


def parse(text: str) -> tuple[TaskSpec, dict[str, str]]:
    """Splits a variant string into its base spec and canonical ``key -> value`` settings.

    Raises:
        ValueError: One line naming the fault: an unknown base task, a malformed string, an
            unknown key (with the allowed keys) or a bad value (with what is allowed).
    """
    m = _NAME.match(text.strip())
    if m is None:
        raise _fail(text, "write a variant as Base[key=value;key=value]")
    if m["base"] not in TASK_NAMES:
        raise _fail(text, f"unknown base task {m['base']!r}; choose from {', '.join(TASK_NAMES)}")
    base = TASKS[TASK_NAMES.index(m["base"])]
    settings: dict[str, str] = {}
    for item in (i.strip() for i in m["body"].split(";")):
        if not item:
            continue
        key, sep, raw = (s.strip() for s in item.partition("="))
        if key not in allowed_keys(base):
            allowed = ", ".join(allowed_keys(base))
            raise _fail(text, f"unknown key {key!r}; allowed: {allowed}")
        if not sep:
            raise _fail(text, f"{key}: missing '=value'")
        if key in settings:
            raise _fail(text, f"{key}: set twice")
        settings[key] = _value(text, base, key, raw)
    if not settings:
        raise _fail(text, f"no settings; allowed keys: {', '.join(allowed_keys(base))}")
    return base, settings


def canonical(text: str) -> str:
    """The canonical name of a task: a registered name as it is, a variant normalised.

    Raises:
        ValueError: For an unknown task or a bad variant (see :func:`parse`).
    """
    if not is_variant(text):
        if text not in TASK_NAMES:
            raise ValueError(f"unknown task {text!r}; choose from {', '.join(TASK_NAMES)}")
        return text
    base, settings = parse(text)
    return f"{base.name}[{';'.join(f'{k}={settings[k]}' for k in sorted(settings))}]"


def from_table(table: dict) -> str:
    """The canonical name of a ``[[task]]`` TOML table: ``base`` plus the variant's keys.

    ``{"base": "Pendulum", "observe": ["theta"], "gravity": 9.81}`` (``observe`` a list of
    state variables or a ``+``-joined string) gives ``"Pendulum[gravity=9.81;observe=theta]"``;
    a table with ``base`` alone names the registered task.

    Raises:
        ValueError: Naming the fault (no ``base``, an unknown key, a bad value).
    """
    if not isinstance(table.get("base"), str):
        raise ValueError("needs base = the name of a registered task")
    items = []
    for key, value in table.items():
        if key == "base":
            continue
        if key == "observe" and isinstance(value, list):
            value = "+".join(str(v) for v in value)
        if isinstance(value, bool) or not isinstance(value, int | float | str):
            raise ValueError(f"{key}: must be a number (observe: state variable names)")
        items.append(f"{key}={value}")
    return canonical(f"{table['base']}[{';'.join(items)}]" if items else table["base"])


def known(name: str) -> bool:
    """Whether a name is a registered task or a canonically spelled valid variant."""
    try:
        return canonical(name) == name
    except ValueError:
        return False


def from_tables(tables: object) -> list[str]:
    """The canonical names of a TOML ``[[task]]`` array (see :func:`from_table`).

    Raises:
        ValueError: ``task[i]: ...`` naming the table at fault, or a non-array.
    """
    if not isinstance(tables, list) or not all(isinstance(t, dict) for t in tables):
        raise ValueError("task must be an array of tables ([[task]])")
    names = []
    for i, table in enumerate(tables):
        try:
            names.append(from_table(table))
        except ValueError as exc:
            raise ValueError(f"task[{i}]: {exc}") from None
    return names


def order_key(name: str) -> tuple[int, int, str]:
    """Sorts task names by registry id, each variant after its base, variants by name."""
    base = name.split("[", 1)[0]
    return (TASK_NAMES.index(base), int(is_variant(name)), name)


def gym_id(name: str) -> str:
    """The Gymnasium id of a task or variant, e.g. ``mtpg/CartPole-max_steps_500-v0``."""
    name = canonical(name)
    if not is_variant(name):
        return f"mtpg/{name}-v0"
    base, settings = parse(name)
    parts = [f"{k}_{settings[k].replace('+', '.')}" for k in sorted(settings)]
    return f"mtpg/{base.name}-{'-'.join(parts)}-v0"


def variant_spec(name: str) -> TaskSpec:
    """The spec of a variant: the base spec with the settings applied."""
    base, settings = parse(name)
    params = list(base.params)
    for key, value in settings.items():
        if key not in ("observe", "noise"):
            params[base.param_names.index(key)] = float(value)
    spec = replace(
        base,
        name=canonical(name),
        params=tuple(params),
        reference=Reference(NONE, NONE, NONE, NONE, "not measured"),
        base=base.name,
    )
    if "observe" in settings:
        observed = settings["observe"].split("+")
        slots = tuple(base.state_names.index(v) for v in observed)
        text = ", ".join(f"{v} scaled" for v in observed) + (", noise" if len(slots) == 1 else "")
        spec = replace(spec, observed_slots=slots, observed=text)
    if float(settings.get("noise", 0.0)) > 0.0:
        spec = replace(spec, observed=f"{spec.observed}; observation noise sd {settings['noise']}")
    return spec


def obs_noise_sd(spec: TaskSpec) -> float:
    """The standard deviation of a task's observation noise (0 for none)."""
    return float(parse(spec.name)[1].get("noise", 0.0)) if spec.base else 0.0


def _observe_columns(spec: TaskSpec) -> tuple[tuple[int, float, float, bool], ...] | None:
    if spec.base and "observe" in parse(spec.name)[1]:
        return tuple(
            (s, spec.state_low[s], spec.state_high[s], s in spec.angle_slots)
            for s in spec.observed_slots
        )
    return None


def resolve(name: str) -> int:
    """The id of a task or variant name (a variant gets the next free id on first use).

    Raises:
        ValueError: For an unknown task or a bad variant.
    """
    if name in _IDS:
        return _IDS[name]
    key = canonical(name)
    if key not in _IDS:
        from mtpg.envs.tasks import param_row

        spec = variant_spec(key)
        _VARIANTS.append(spec)
        _TABLE.append(
            param_row(
                spec.params,
                TASK_NAMES.index(spec.base),
                _observe_columns(spec),
                obs_noise_sd(spec),
                len(spec.observed_slots),
            )
        )
        _IDS[key] = VARIANT_ID_BASE + len(_VARIANTS) - 1
    _IDS[name] = _IDS[key]
    return _IDS[key]


def register(name: str) -> str:
    """Registers a task or variant with Gymnasium (idempotent); returns its id.

    ``gymnasium.make(register("CartPole[max_steps=500]"), action="native")`` then makes
    the variant's environment.
    """
    import gymnasium

    from mtpg.envs.registration import ENTRY_POINT

    env_id = gym_id(name)
    if env_id not in gymnasium.registry:
        gymnasium.register(id=env_id, entry_point=ENTRY_POINT, kwargs={"task": canonical(name)})
    return env_id


def spec_of(task: int | str) -> TaskSpec:
    """The spec of a task id or name, registered or variant."""
    i = resolve(task) if isinstance(task, str) else int(task)
    if not valid_id(i):
        raise ValueError(f"unknown task id {i}; valid ids are {id_ranges()}")
    return TASKS[i] if i < len(TASKS) else _VARIANTS[i - VARIANT_ID_BASE]


def valid_id(task: int) -> bool:
    """Whether an id names a registered task or a variant resolved in this process."""
    return 0 <= task < len(TASKS) or 0 <= task - VARIANT_ID_BASE < len(_VARIANTS)


def id_ranges() -> str:
    """The valid ids, as text (``0..5`` or ``0..5, 256..257``)."""
    text = f"0..{len(TASKS) - 1}"
    if _VARIANTS:
        text += f", {VARIANT_ID_BASE}..{VARIANT_ID_BASE + len(_VARIANTS) - 1}"
    return text


def task_params() -> np.ndarray:
    """The parameter table of every id so far: ``TASK_PARAMS`` then one row per variant."""
    from mtpg.envs.tasks import TASK_PARAMS, param_row, params_table

    if not _VARIANTS:
        return TASK_PARAMS
    if len(_VARIANTS) not in _CACHE:
        _CACHE.clear()
        padding = [param_row((1.0, 0.0), -1)] * (VARIANT_ID_BASE - len(TASK_PARAMS))
        _CACHE[len(_VARIANTS)] = params_table([*TASK_PARAMS, *padding, *_TABLE])
    return _CACHE[len(_VARIANTS)]
