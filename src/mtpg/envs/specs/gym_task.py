"""Any Gymnasium environment as a task: ``gym:CartPole-v1``, ``gym:mymodule:MyEnv-v0``.

A task named ``gym:ID`` is the environment ``gymnasium.make(ID, **kwargs)``; ``ID`` is any
id ``gymnasium.make`` accepts, including its ``module:EnvName-v0`` form, which imports the
user's module first (so a researcher's own environment needs no edit to mtpg). Keyword
arguments for ``make`` are written after the id, ``gym:Pendulum-v1[g=9.81;max_episode_steps=100]``,
each value a Python literal (number, string, bool); the canonical name sorts them.

The interface, decided here:

- **Observations**: a ``Box`` of any shape, flattened. An input with finite bounds is scaled
  linearly from ``[low, high]`` to the programs' ``[-1, 1]``; an input with an infinite
  bound (a velocity, say) is passed through ``tanh``, which keeps its sign and order and
  maps it into ``(-1, 1)``. An observation that is not finite or lies outside its declared
  finite bounds (beyond a relative tolerance of 1e-6, for float32 rounding) stops the
  episode with an error naming the task and the episode's seed.
- **Actions**: ``Discrete(n)``: atomic action ``a`` plays ``start + a mod n`` (in a run
  whose largest task has more atomic actions, a smaller task folds them onto its own);
  ``Box`` of shape ``(d,)``: dimension ``j`` reads memory cell ``m[j]`` of the final
  program's bank, clipped to ``[-1, 1]`` and mapped linearly onto ``[low_j, high_j]`` (where
  both bounds are finite; else ``m[j]`` as it is); ``Tuple(Discrete, Box)``: both.
- **Episodes** end when the environment terminates or truncates; an environment needs a
  time limit (its registered ``max_episode_steps`` or one given as a keyword).
- **Reference scores**: random play is measured by mtpg (:data:`N_RANDOM_EPISODES`
  episodes of actions sampled from the action space; see :func:`measure_random`); the best
  score is the one given in ``evaluation.references`` or, when none is given, scores are
  reported raw (the report says so).

Only the names are data: :meth:`GymTask.from_name` makes the environment once to read
its spaces, so every failure is one line at configuration time.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from functools import cache
from typing import Any

import numpy as np

#: Prefix of a Gymnasium task's name.
PREFIX = "gym:"
#: Episodes of the random-play measurement of a Gymnasium task.
N_RANDOM_EPISODES = 100
#: First reset seed of the random-play measurement (the protocol's random-agent base).
RANDOM_SEED = 2_000_000
#: First seed of the random player's actions: a stream apart from the resets'. Seeded with
#: the reset's own seed, the action space drew the same numbers as the environment, so
#: random play could depend on the episode (a cue drawn by ``reset`` and an action sampled
#: after it always disagreed: random play read -1 where it is 0).
RANDOM_ACTION_SEED = 3_000_000
#: Training episode seeds of the protocol below this are offset by it for a Gymnasium
#: task, so that ``mtpg evaluate --seed S`` with ``S + k < 10**9`` never replays one.
TRAIN_RESET_OFFSET = 10**9
#: Relative tolerance of the bounds check on observations.
BOUND_TOL = 1e-6


class GymTaskError(ValueError):
    """A Gymnasium task cannot be used as asked; the message is one line."""


def is_gym(name: str) -> bool:
    """Whether a task name names a Gymnasium environment (``gym:...``)."""
    return name.startswith(PREFIX)


def _literal(name: str, key: str, raw: str) -> Any:
    try:
        return ast.literal_eval(raw)
    except (ValueError, SyntaxError):
        if raw.replace("_", "").replace("-", "").replace(".", "").isalnum():
            return raw  # a bare word is a string
        raise GymTaskError(f"task {name!r}: {key}={raw!r} is not a Python literal") from None


def parse(name: str) -> tuple[str, dict[str, Any]]:
    """The environment id and the ``make`` keywords of a ``gym:`` task name.

    Raises:
        GymTaskError: For a name that is not ``gym:ID`` or ``gym:ID[key=value;...]``.
    """
    if not is_gym(name):
        raise GymTaskError(f"task {name!r}: a Gymnasium task is written gym:ID")
    body = name[len(PREFIX) :]
    env_id, bracket, rest = body.partition("[")
    kwargs: dict[str, Any] = {}
    if bracket:
        if not rest.endswith("]"):
            raise GymTaskError(f"task {name!r}: write gym:ID[key=value;key=value]")
        for item in filter(None, (i.strip() for i in rest[:-1].split(";"))):
            key, eq, raw = (s.strip() for s in item.partition("="))
            if not eq or not key.isidentifier():
                raise GymTaskError(f"task {name!r}: {item!r} is not key=value")
            if key in kwargs:
                raise GymTaskError(f"task {name!r}: {key} given twice")
            kwargs[key] = _literal(name, key, raw)
    if not env_id.strip():
        raise GymTaskError(f"task {name!r}: no environment id after {PREFIX}")
    return env_id.strip(), kwargs


def canonical(name: str) -> str:
    """The canonical spelling of a ``gym:`` name (keywords sorted, values as ``repr``)."""
    env_id, kwargs = parse(name)
    if not kwargs:
        return PREFIX + env_id
    return f"{PREFIX}{env_id}[{';'.join(f'{k}={kwargs[k]!r}' for k in sorted(kwargs))}]"


def _bounds(low: np.ndarray, high: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    low = np.asarray(low, dtype=np.float64).ravel()
    high = np.asarray(high, dtype=np.float64).ravel()
    return low, high, np.isfinite(low) & np.isfinite(high)


@dataclass(frozen=True, eq=False)
class GymTask:
    """One Gymnasium environment as a task of a run (build it with :meth:`from_name`).

    Attributes:
        name: Canonical task name (``gym:ID[...]``).
        env_id: The id given to ``gymnasium.make``.
        kwargs: The keywords given to ``gymnasium.make``.
        n_obs: Observed inputs (the flattened observation).
        obs_low: float64 ``[n_obs]`` declared low bounds.
        obs_high: float64 ``[n_obs]`` declared high bounds.
        n_actions: Discrete actions (0: the task takes no discrete action).
        action_start: The first discrete action (``Discrete.start``).
        cont_low: float64 ``[d]`` low bounds of the continuous action (empty: none).
        cont_high: float64 ``[d]`` high bounds of the continuous action.
        action_kind: ``"discrete"``, ``"box"`` or ``"tuple"``.
        max_steps: The environment's time limit in steps.
    """

    name: str
    env_id: str
    kwargs: dict[str, Any]
    n_obs: int
    obs_low: np.ndarray
    obs_high: np.ndarray
    n_actions: int
    action_start: int
    cont_low: np.ndarray
    cont_high: np.ndarray
    action_kind: str
    max_steps: int

    @classmethod
    def from_name(cls, name: str) -> GymTask:
        """Makes the environment once and reads its spaces.

        Raises:
            GymTaskError: One line: an unknown id, a module that does not import, an
                unsupported space (named, with what is supported) or no time limit.
        """
        name = canonical(name)
        env_id, kwargs = parse(name)
        env = _make(name, env_id, kwargs)
        try:
            return cls._from_env(name, env_id, kwargs, env)
        finally:
            env.close()

    @classmethod
    def _from_env(cls, name: str, env_id: str, kwargs: dict[str, Any], env: Any) -> GymTask:
        from gymnasium import spaces

        obs_space, act = env.observation_space, env.action_space
        if not isinstance(obs_space, spaces.Box):
            raise GymTaskError(
                f"task {name!r}: observation space {type(obs_space).__name__} is not "
                "supported (supported: Box)"
            )
        low, high, _ = _bounds(obs_space.low, obs_space.high)
        n_actions, start = 0, 0
        cont = (np.zeros(0), np.zeros(0))
        supported = "supported: Discrete, Box of shape (d,), Tuple(Discrete, Box)"
        parts = act.spaces if isinstance(act, spaces.Tuple) else (act,)
        kinds = tuple(type(p).__name__ for p in parts)
        if kinds == ("Discrete",):
            kind = "discrete"
        elif kinds == ("Box",) and len(act.shape) == 1:
            kind = "box"
        elif kinds == ("Discrete", "Box") and len(parts[1].shape) == 1:
            kind = "tuple"
        else:
            raise GymTaskError(f"task {name!r}: action space {act} is not supported ({supported})")
        if kind != "box":
            n_actions, start = int(parts[0].n), int(parts[0].start)
        if kind != "discrete":
            cont = _bounds(parts[-1].low, parts[-1].high)[:2]
        limit = getattr(env.spec, "max_episode_steps", None) if env.spec else None
        if not limit:
            raise GymTaskError(
                f"task {name!r}: the environment has no time limit; give one, "
                f"{PREFIX}{env_id}[max_episode_steps=N]"
            )
        return cls(name, env_id, kwargs, len(low), low, high, n_actions, start, *cont, kind, limit)

    # ------------------------------------------------------------------ interface
    @property
    def n_continuous(self) -> int:
        """Dimensions of the continuous action (0: none)."""
        return len(self.cont_low)

    @property
    def continuous(self) -> bool:
        """Whether the task reads a continuous action."""
        return self.n_continuous > 0

    def make(self) -> Any:
        """A new instance of the environment."""
        return _make(self.name, self.env_id, self.kwargs)

    def flat(self, obs: Any, seed: int) -> np.ndarray:
        """The raw observation as float64 ``[n_obs]``.

        Raises:
            GymTaskError: For an observation of another size than the space declares.
        """
        o = np.asarray(obs, dtype=np.float64).ravel()
        if o.shape != self.obs_low.shape:
            raise GymTaskError(
                f"task {self.name}: episode seed {seed}: observation of {o.size} values, "
                f"the space declares {self.n_obs}"
            )
        return o

    def scale(self, obs: Any, seed: int) -> np.ndarray:
        """The observation in the programs' range (see the module docstring).

        Raises:
            GymTaskError: For an observation that is not finite or outside its bounds.
        """
        o = self.flat(obs, seed)
        return self.scale_rows(o.reshape(1, -1), np.array([seed]))[0]

    def scale_rows(self, raw: np.ndarray, seeds: np.ndarray) -> np.ndarray:
        """Scales many raw observations at once (rows of ``raw``, episode seeds ``seeds``).

        Raises:
            GymTaskError: For the first row that is not finite or outside its bounds.
        """
        finite = np.isfinite(raw)
        if not finite.all():
            row, col = np.argwhere(~finite)[0]
            raise GymTaskError(
                f"task {self.name}: episode seed {int(seeds[row])}: observation[{col}] = "
                f"{float(raw[row, col])!r} is not finite"
            )
        return scale_obs(raw, self.obs_low, self.obs_high, self.name, seeds)

    def action(self, a_d: int, a_c: np.ndarray) -> Any:
        """The environment action of an atomic action and the continuous outputs."""
        if self.action_kind == "discrete":
            return self.action_start + int(a_d) % self.n_actions
        box = continuous_action(a_c[: self.n_continuous], self.cont_low, self.cont_high)
        if self.action_kind == "box":
            return box
        return (self.action_start + int(a_d) % self.n_actions, box)

    @property
    def short(self) -> str:
        """A short name for progress lines (:func:`short`)."""
        return short(self.name)

    @property
    def action_text(self) -> str:
        """The action, as text."""
        parts = []
        if self.n_actions:
            parts.append(f"a_d mod {self.n_actions}")
        if self.continuous:
            parts.append(f"m[0..{self.n_continuous}) onto the Box")
        return ", ".join(parts)


def short(name: str) -> str:
    """A Gymnasium task's short label: the capitals of its environment's name (``CP``)."""
    base = parse(name)[0].rsplit(":", 1)[-1].split("-")[0]
    caps = "".join(c for c in base if c.isupper()) or base[:2].upper()
    return caps[:3]


def _make(name: str, env_id: str, kwargs: dict[str, Any]) -> Any:
    import gymnasium

    try:
        return gymnasium.make(env_id, **kwargs)
    except ImportError as exc:  # the user's module is missing or fails to import
        module = env_id.split(":", 1)[0] if ":" in env_id else exc.name
        first = str(exc).split(". ")[0]
        raise GymTaskError(f"task {name!r}: module {module!r} does not import ({first})") from None
    except gymnasium.error.Error as exc:
        raise GymTaskError(f"task {name!r}: {str(exc).splitlines()[0]}") from None
    except Exception as exc:  # the user's module or constructor failed: say how, in one line
        what = str(exc).splitlines()[0] if str(exc) else ""
        raise GymTaskError(
            f"task {name!r}: making it raised {type(exc).__name__}: {what}"
        ) from None


def scale_obs(
    o: np.ndarray, low: np.ndarray, high: np.ndarray, name: str, seed: int | np.ndarray
) -> np.ndarray:
    """Scales finite-bounded inputs to [-1, 1], passes the others through ``tanh``.

    ``o`` is one observation or a matrix of them (one row per episode, ``seed`` then an
    array of their seeds).

    Raises:
        GymTaskError: For the first input outside its finite bounds, naming its seed.
    """
    finite = np.isfinite(low) & np.isfinite(high)
    span = np.where(finite, high - low, 1.0)
    tol = BOUND_TOL * (1.0 + np.abs(np.where(finite, span, 0.0)))
    outside = finite & ((o < low - tol) | (o > high + tol))
    if outside.any():
        at = np.argwhere(outside)[0]
        i = int(at[-1])
        which = int(np.asarray(seed).reshape(-1)[at[0]] if o.ndim == 2 else seed)
        raise GymTaskError(
            f"task {name}: episode seed {which}: observation[{i}] = {float(o[tuple(at)])!r} "
            f"is outside its declared bounds [{float(low[i])!r}, {float(high[i])!r}]"
        )
    scaled = np.where(finite, 2.0 * (o - np.where(finite, low, 0.0)) / span - 1.0, np.tanh(o))
    return np.clip(scaled, -1.0, 1.0)


def continuous_action(m: np.ndarray, low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """Memory cells onto a Box: clipped to [-1, 1], mapped linearly where bounds are finite."""
    finite = np.isfinite(low) & np.isfinite(high)
    c = np.clip(m, -1.0, 1.0)
    mapped = np.where(
        finite, np.where(finite, low, 0.0) + (c + 1.0) / 2.0 * np.where(finite, high - low, 0.0), m
    )
    return mapped.astype(np.float32)


@cache
def measure_random(name: str, n: int = N_RANDOM_EPISODES) -> tuple[float, float]:
    """Mean and standard deviation of random play on a Gymnasium task.

    Episode ``i`` resets with seed ``RANDOM_SEED + i``, and its actions are sampled from
    the action space seeded with ``RANDOM_ACTION_SEED + i`` (a stream apart from the
    environment's): a pure function of the name (memoised).
    """
    task = GymTask.from_name(name)
    env = task.make()
    returns = np.zeros(n)
    try:
        for i in range(n):
            env.reset(seed=RANDOM_SEED + i)
            env.action_space.seed(RANDOM_ACTION_SEED + i)
            total, done = 0.0, False
            while not done:
                _, reward, terminated, truncated, _ = env.step(env.action_space.sample())
                total += float(reward)
                done = terminated or truncated
            returns[i] = total
    finally:
        env.close()
    return float(returns.mean()), float(returns.std())
