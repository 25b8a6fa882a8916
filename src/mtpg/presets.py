"""Named presets and the settings beyond the paper (data only; ablations: :mod:`mtpg.ablations`).

Re-exported by :mod:`mtpg.config`, which validates them like any other settings.
"""

from __future__ import annotations

from typing import Any

#: Names of the evaluation backends (``backend``): this machine's threads or a Dask
#: cluster.
BACKENDS = ("local", "dask")

#: Ways of drawing parent 1 from a subset's elites (``team.parent_selection``).
PARENT_SELECTIONS = ("uniform", "lexicase")

#: Named presets: ``paper`` is the published run on all six tasks (Table 3, with 25 elites
#: and 25 children per task subset: 1575 new roots per generation from 1000 initial
#: roots); ``demo`` is small and quick; ``robust`` is ``paper`` with the training episodes
#: redrawn every 10 generations (beyond the paper: on the ``demo`` scale this lifted the
#: all-task champion on unseen episodes from 0.33 to 0.70 of the reference best, 3 seeds,
#: docs/training.md; its effect at the paper's scale is not measured).
PRESETS: dict[str, dict[str, dict[str, Any] | Any]] = {
    "paper": {},
    "demo": {
        "generations": 250,
        "workers": 2,
        "team": {"root_size": 300, "n_elite": 4, "min_elite_total": 100},
        "evaluation": {"train_episodes": 3, "test_episodes": 20, "test_interval": 5},
    },
    "robust": {"evaluation": {"resample_interval": 10}},
}

#: Settings beyond the paper, by section: off at their defaults, where they are left out
#: of a run's identity so that runs made before they existed keep theirs.
EXTENSIONS: dict[str, tuple[str, ...]] = {
    "team": ("parent_selection",),
    "evaluation": (
        "validation_episodes",
        "validation_top_k",
        "resample_interval",
        "resample_mean",
        "references",
    ),
}
