"""The colours of the section-6 figures, in one place so every figure agrees.

Each task keeps one colour in every figure (graph pies, register bars, time series,
videos); the section-5 figures of :mod:`mtpg.analysis.runs.score_figures` colour runs, not tasks.
"""

from __future__ import annotations

import zlib

from mtpg.envs.specs.compiled_task import is_compiled_name
from mtpg.envs.specs.contract import TASK_NAMES
from mtpg.envs.specs.gym_task import is_gym
from mtpg.envs.specs.registry import TASKS

#: One colour per task, each spec's ``colour`` (the six are matplotlib's colour-blind-safe
#: "tab10" picks).
TASK_COLOURS: dict[str, str] = {t.name: t.colour for t in TASKS}
#: Colours of Gymnasium tasks (``gym:...``) and compiled tasks (``module:ATTR``), none of
#: the six's: a task takes the one its name's CRC-32 picks, the same in every figure and
#: every run.
GYM_COLOURS: tuple[str, ...] = ("#e377c2", "#bcbd22", "#17becf", "#393b79", "#ad494a", "#637939")
#: Colours of the three atomic discrete actions (Fig. 10 style decompositions).
ACTION_COLOURS: tuple[str, ...] = ("#0072b2", "#e69f00", "#cc79a7")
#: Colormap of continuous actions.
CONTINUOUS_CMAP = "viridis"  # no grey anywhere: grey marks "passed on"
#: Points where a team was visited but passed execution on.
PASSED_COLOUR = "#b0b0b0"
#: The decision path in graph pictures and videos.
PATH_COLOUR = "#2ca02c"
#: Teams and edges off the path.
IDLE_COLOUR = "#d9d9d9"


def task_colour(task: str) -> str:
    """The colour of a task name.

    Raises:
        ValueError: For an unknown task.
    """
    if is_gym(task) or is_compiled_name(task):
        return GYM_COLOURS[zlib.crc32(task.encode()) % len(GYM_COLOURS)]
    base = task.split("[", 1)[0]  # a variant has its base task's colour
    if base not in TASK_COLOURS:
        raise ValueError(f"unknown task {task!r}; choose from {', '.join(TASK_NAMES)}")
    return TASK_COLOURS[base]
