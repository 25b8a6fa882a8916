"""The ablations of paper section 5.2, in one table.

Each ablation switches off one part of the algorithm by changing exactly one setting. Its
paper name (``TPG-NoXover``, ...) is also the experiment label of its runs: the prefix of
their run directories in ``mtpg experiment`` (``TPG-NoXover-seed1``) and the label of their
group in ``mtpg report``. Everything else derives from :data:`ABLATION_TABLE`:

- the ``mtpg train`` flags (``--no-crossover``, ...) and their help texts;
- the ``section.field=value`` override each flag stands for (:data:`ABLATIONS`);
- the runs ``mtpg experiment`` plans;
- the label a loaded run gets (:func:`experiment_label`), and the settings a report may
  see differ between groups without calling them a mixture (:data:`ABLATION_FIELDS`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

#: Experiment label of the full algorithm (no ablation).
FULL_ALGORITHM = "TPG"


@dataclass(frozen=True)
class Ablation:
    """One ablation of section 5.2.

    Attributes:
        name: The paper's name, also the experiment and report label and the run-directory
            prefix (``TPG-NoXover``).
        switch: The ``mtpg train`` switch without dashes (``no-crossover``).
        setting: The one setting it changes, ``section.field``.
        value: The value it sets.
        effect: What it does, in words (for ``--help``).
    """

    name: str
    switch: str
    setting: str
    value: Any
    effect: str

    @property
    def flag(self) -> str:
        """The command-line flag, ``--no-crossover``."""
        return f"--{self.switch}"

    @property
    def dest(self) -> str:
        """The argparse destination of the flag, ``no_crossover``."""
        return self.switch.replace("-", "_")

    @property
    def override(self) -> str:
        """The ``section.field=value`` override the flag stands for."""
        return f"{self.setting}={str(self.value).lower()}"

    @property
    def help(self) -> str:
        """The flag's help text."""
        shown = str(self.value).lower() if isinstance(self.value, bool) else f"{self.value:g}"
        return f"ablation {self.name}: {self.effect} ({self.setting}={shown})"

    def is_on(self, config: Any) -> bool:
        """True when ``config`` (a :class:`mtpg.config.RunConfig`) has this ablation on."""
        section, field = self.setting.split(".")
        return getattr(getattr(config, section), field) == self.value


#: The three ablations, in the order ``mtpg experiment`` runs them.
ABLATION_TABLE: tuple[Ablation, ...] = (
    Ablation(
        "TPG-NoXover",
        "no-crossover",
        "team.p_crossover",
        0.0,
        "children are mutated copies of one parent, never crossovers",
    ),
    Ablation(
        "TPG-NoMemory",
        "no-memory",
        "evaluation.no_memory",
        True,
        "memory banks zeroed before every program execution",
    ),
    Ablation(
        "TPG-NoHierarchy",
        "no-hierarchy",
        "team.p_atomic",
        1.0,
        "action pointers always atomic, no graphs",
    ),
)
#: Each switch's setting and value, ``{"no-crossover": ("team.p_crossover", 0.0), ...}``.
ABLATIONS: dict[str, tuple[str, Any]] = {a.switch: (a.setting, a.value) for a in ABLATION_TABLE}
#: The settings the ablations change (groups differing only in these are comparable).
ABLATION_FIELDS: tuple[str, ...] = tuple(a.setting for a in ABLATION_TABLE)
#: Which ablation names a configuration with several switched on: memory, then hierarchy,
#: then crossover.
_LABEL_PRECEDENCE = ("no-memory", "no-hierarchy", "no-crossover")


def ablation(switch: str) -> Ablation:
    """The ablation of a switch name (``"no-crossover"``).

    Raises:
        KeyError: For an unknown switch.
    """
    for a in ABLATION_TABLE:
        if a.switch == switch:
            return a
    raise KeyError(f"unknown ablation {switch!r}; choose from {', '.join(ABLATIONS)}")


def ablations_on(config: Any) -> tuple[Ablation, ...]:
    """The ablations a configuration has on, in table order."""
    return tuple(a for a in ABLATION_TABLE if a.is_on(config))


def experiment_label(config: Any) -> str:
    """The experiment a configuration stands for: an ablation's name, or ``"TPG"``."""
    on = {a.switch for a in ablations_on(config)}
    for switch in _LABEL_PRECEDENCE:
        if switch in on:
            return ablation(switch).name
    return FULL_ALGORITHM


def label_of(switch: str | None) -> str:
    """The experiment label of a planned run's switch (None: the full algorithm)."""
    return FULL_ALGORITHM if switch is None else ablation(switch).name
