"""Task variants as data: ``CartPole[max_steps=500]``, ``Pendulum[observe=theta]``.

A variant is a registered task with some of its settings changed, written
``Base[key=value;key=value]``. The keys:

- any parameter of the base task by its name (``TaskSpec.param_names``, e.g. ``max_steps``,
  ``gravity``): the parameter's value (``max_steps`` a whole number >= 1);
- ``observe``: the one or two state variables the two inputs observe, joined by ``+``
  (``observe=x+theta``), each scaled from the base spec's ``state_low..state_high`` to
  [-1, 1] (angles wrapped into [-pi, pi) first) and clipped; with one variable the second
  input is the U[0, 1] noise input, as in the paper's one-observable tasks. An angle may
  be observed as its cosine or sine, ``cos(theta)`` / ``sin(theta)`` (range -1..1), as
  the authors' code observes the pendulum;
- ``obs_low`` / ``obs_high``: the range the observed state inputs are scaled to instead
  of [-1, 1] (the authors' code scales MountainCar's position to [0, 1]);
- ``noise_low`` / ``noise_high``: the noise input is ``U[noise_low, noise_high]``
  instead of U[0, 1] (the same draw, mapped linearly; not clipped: the authors' code
  feeds U[-pi, pi]). Only a task with a noise input takes them. These four keys, like
  ``observe``, make the variant observe through :func:`mtpg.envs.dynamics.dispatch.variant_observe`
  (the base's own observed variables when ``observe`` is not given); numbers may be
  written ``pi`` or ``-pi``;
- ``noise``: Gaussian observation noise: each input that observes the state gets
  ``sd * N(0, 1)`` added (in its [-1, 1] units) and is clipped again; ``sd >= 0``. The
  normal values are drawn per episode after its start state and U[0, 1] values
  (:func:`mtpg.envs.taskset.episodes.draw_episodes`), so a task without noise draws as before.

The dynamics are the base task's kernels on the variant's parameter row, so a variant
reproduces its base task step for step and runs in the compiled engine like it. The start
distribution is the base task's (parameters read only by the start sampler, such as
CartCentering's ``start_range``, keep their base value there).

A variant's name is canonical (keys sorted, values normalised): :func:`canonical` turns any
spelling into it, and the configuration stores it as the task's name. This module is pure
functions of names: a variant's id and parameter row belong to the task table it is in
(:class:`mtpg.envs.taskset.task_table.TaskTable`), its reference scores to
:func:`mtpg.envs.taskset.reference_scores.reference_of`.
"""

from __future__ import annotations

import math
import re
from dataclasses import replace

import numpy as np

from mtpg.envs.specs.compiled_task import is_compiled_name
from mtpg.envs.specs.gym_task import canonical as gym_canonical
from mtpg.envs.specs.gym_task import is_gym
from mtpg.envs.specs.param_table import OBS_AS_IS, OBS_COS, OBS_SIN, OBS_WRAP, param_row
from mtpg.envs.specs.registry import TASK_NAMES, TASKS
from mtpg.envs.specs.task_spec import NONE, Reference, TaskSpec, variant_gym_id

_NAME = re.compile(r"^(?P<base>[A-Za-z][A-Za-z0-9]*)\[(?P<body>[^\[\]]*)\]$")


def is_variant(name: str) -> bool:
    """Whether a task name is written as a variant (``Base[...]``; not a ``gym:`` task)."""
    return "[" in name and not is_gym(name)


def _fail(text: str, message: str) -> ValueError:
    return ValueError(f"task {text!r}: {message}")


#: The keys that change what the inputs observe (a variant with any of them observes
#: through ``variant_observe``).
INTERFACE_KEYS = ("noise_high", "noise_low", "obs_high", "obs_low", "observe")
#: The default of each range key.
_RANGE_DEFAULTS = {"obs_low": -1.0, "obs_high": 1.0, "noise_low": 0.0, "noise_high": 1.0}
_FUNCTION = re.compile(r"^(?P<fn>cos|sin)\((?P<name>[A-Za-z_0-9]+)\)$")


def allowed_keys(base: TaskSpec) -> tuple[str, ...]:
    """The keys a variant of ``base`` may set."""
    return (*base.param_names, "noise", *INTERFACE_KEYS)


def _observable(base: TaskSpec, name: str) -> bool:
    """Whether ``name`` is a state variable of ``base``, or cos/sin of one of its angles."""
    m = _FUNCTION.match(name)
    if m is None:
        return name in base.state_names
    return m["name"] in base.state_names and base.state_names.index(m["name"]) in base.angle_slots


def observe_column(base: TaskSpec, name: str) -> tuple[int, float, float, int]:
    """The ``(slot, low, high, fn)`` input of one observed name (see ``param_row``)."""
    m = _FUNCTION.match(name)
    if m is not None:
        fn = OBS_COS if m["fn"] == "cos" else OBS_SIN
        return base.state_names.index(m["name"]), -1.0, 1.0, fn
    s = base.state_names.index(name)
    fn = OBS_WRAP if s in base.angle_slots else OBS_AS_IS
    return s, base.state_low[s], base.state_high[s], fn


def _value(text: str, base: TaskSpec, key: str, raw: str) -> str:
    """The canonical spelling of one value (raises naming the key and what is allowed)."""
    if key == "observe":
        names = raw.split("+")
        bad = [n for n in names if not _observable(base, n)]
        if not raw or bad:
            angles = [base.state_names[a] for a in base.angle_slots]
            functions = (f"{f}({a})" for a in angles for f in ("cos", "sin"))
            allowed = ", ".join((*base.state_names, *functions))
            what = f"unknown state variable {bad[0]!r}" if bad and bad[0] else "empty"
            raise _fail(text, f"observe: {what}; allowed: {allowed} (one or two, joined by +)")
        if len(names) > 2 or len(set(names)) != len(names):
            raise _fail(text, "observe: one or two distinct state variables, joined by +")
        return "+".join(names)
    try:
        number = {"pi": math.pi, "-pi": -math.pi}.get(raw) or float(raw)
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
    _check_interface(text, base, settings)
    return base, settings


def _range(settings: dict[str, str], key: str) -> float:
    return float(settings.get(key, _RANGE_DEFAULTS[key]))


def _check_interface(text: str, base: TaskSpec, settings: dict[str, str]) -> None:
    """Refuses range keys that contradict each other or the task (one line, naming them)."""
    for low, high in (("obs_low", "obs_high"), ("noise_low", "noise_high")):
        if (low in settings or high in settings) and _range(settings, low) >= _range(
            settings, high
        ):
            raise _fail(
                text,
                f"{low} must be below {high} (defaults: {_RANGE_DEFAULTS[low]:g}, "
                f"{_RANGE_DEFAULTS[high]:g})",
            )
    if ("noise_low" in settings or "noise_high" in settings) and len(
        observed_names(base, settings)
    ) == 2:
        raise _fail(
            text,
            "noise_low/noise_high: the task observes two state variables and has no noise input",
        )
    ranged = "obs_low" in settings or "obs_high" in settings
    if float(settings.get("noise", 0.0)) > 0.0 and ranged:
        raise _fail(text, "noise (Gaussian, in [-1, 1] units) cannot go with obs_low/obs_high")


def observed_names(base: TaskSpec, settings: dict[str, str]) -> list[str]:
    """The names the inputs observe: ``observe``'s, or the base task's own variables."""
    if "observe" in settings:
        return settings["observe"].split("+")
    return [base.state_names[s] for s in base.observed_slots]


def canonical(text: str) -> str:
    """The canonical name of a task: a registered name as it is, a variant normalised.

    Raises:
        ValueError: For an unknown task or a bad variant (see :func:`parse`).
    """
    if is_gym(text):
        return gym_canonical(text)
    if is_compiled_name(text):  # module:ATTR of a compiled task, as written
        return text
    if not is_variant(text):
        if text not in TASK_NAMES:
            raise ValueError(
                f"unknown task {text!r}; choose from {', '.join(TASK_NAMES)} "
                "or a Gymnasium environment, gym:ID, or a compiled task, module:ATTR"
            )
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
    if is_gym(name):  # after every registered task and variant, by name
        return (len(TASK_NAMES), 1, name)
    if is_compiled_name(name):  # after every registered task and variant, before gym:
        return (len(TASK_NAMES), 0, name)
    base = name.split("[", 1)[0]
    return (TASK_NAMES.index(base), int(is_variant(name)), name)


def gym_id(name: str) -> str:
    """The Gymnasium id of a task or variant, e.g. ``mtpg/CartPole-max_steps_500-v0``."""
    name = canonical(name)
    return variant_gym_id(name) if is_variant(name) else f"mtpg/{name}-v0"


def task_spec(name: str) -> TaskSpec:
    """The spec of a task by name: the registry's, or a variant's (:func:`variant_spec`).

    For a name read back from a file (a replay's task); a run passes its task table.
    """
    if not is_variant(name):
        return TASKS[TASK_NAMES.index(canonical(name))]
    return variant_spec(name)


def variant_spec(name: str) -> TaskSpec:
    """The spec of a variant: the base spec with the settings applied."""
    base, settings = parse(name)
    params = list(base.params)
    for key, value in settings.items():
        if key in base.param_names:
            params[base.param_names.index(key)] = float(value)
    spec = replace(
        base,
        name=canonical(name),
        params=tuple(params),
        reference=Reference(NONE, NONE, NONE, NONE, "not measured"),
        base=base.name,
    )
    if any(k in settings for k in INTERFACE_KEYS):
        observed = observed_names(base, settings)
        slots = tuple(observe_column(base, v)[0] for v in observed)
        out = (_range(settings, "obs_low"), _range(settings, "obs_high"))
        scaled = "scaled" if out == (-1.0, 1.0) else f"scaled to [{out[0]:g}, {out[1]:g}]"
        text = ", ".join(
            v if "(" in v and scaled == "scaled" else f"{v} {scaled}" for v in observed
        )
        if len(slots) == 1:
            lo, hi = _range(settings, "noise_low"), _range(settings, "noise_high")
            text += ", noise" if (lo, hi) == (0.0, 1.0) else f", noise U[{lo:g}, {hi:g}]"
        spec = replace(spec, observed_slots=slots, observed=text)
    if float(settings.get("noise", 0.0)) > 0.0:
        spec = replace(spec, observed=f"{spec.observed}; observation noise sd {settings['noise']}")
    return spec


def obs_noise_sd(spec: TaskSpec) -> float:
    """The standard deviation of a task's observation noise (0 for none)."""
    return float(parse(spec.name)[1].get("noise", 0.0)) if spec.base else 0.0


def _observe_columns(spec: TaskSpec) -> tuple[tuple[int, float, float, int], ...] | None:
    base, settings = parse(spec.name)
    if any(k in settings for k in INTERFACE_KEYS):
        return tuple(observe_column(base, v) for v in observed_names(base, settings))
    return None


def _ranges(spec: TaskSpec, low: str, high: str) -> tuple[float, float]:
    settings = parse(spec.name)[1]
    return _range(settings, low), _range(settings, high)


def observation_bounds(spec: TaskSpec) -> tuple[np.ndarray, np.ndarray]:
    """The low and high bound of each of a task's two inputs (-1, 1 unless a range is set)."""
    low, high = np.full(2, -1.0), np.full(2, 1.0)
    if spec.base:
        settings = parse(spec.name)[1]
        n = len(spec.observed_slots)
        low[:n], high[:n] = _range(settings, "obs_low"), _range(settings, "obs_high")
        if n == 1 and ("noise_low" in settings or "noise_high" in settings):
            low[1], high[1] = _range(settings, "noise_low"), _range(settings, "noise_high")
    return low, high


def variant_row(spec: TaskSpec) -> np.ndarray:
    """The parameter row of a variant's spec (:func:`variant_spec`): its base's kernels."""
    return param_row(
        spec.params,
        TASK_NAMES.index(spec.base),
        _observe_columns(spec),
        obs_noise_sd(spec),
        len(spec.observed_slots),
        _ranges(spec, "obs_low", "obs_high"),
        _ranges(spec, "noise_low", "noise_high"),
    )
