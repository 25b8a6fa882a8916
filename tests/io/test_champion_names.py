"""Champion file names of variant subsets: a ``+`` inside brackets, and names too long."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from mtpg.engine.random_populations import tangled_population
from mtpg.io.rundir import (
    MAX_FILENAME,
    champion_filename,
    read_champions,
    split_subset,
    write_champions,
)

PEND = "Pendulum[max_steps=300;observe=cos(theta)+sin(theta)]"
MC = (
    "MountainCar[noise_high=3.141592653589793;noise_low=-3.141592653589793;"
    "obs_high=1.0;obs_low=0.0]"
)
MCC = MC.replace("MountainCar[", "MountainCarContinuous[")


def test_a_plus_inside_brackets_does_not_split_a_subset() -> None:
    assert split_subset(f"CartPole+{PEND}+Acrobot") == ["CartPole", PEND, "Acrobot"]
    assert split_subset("CartPole") == ["CartPole"]


def test_long_subsets_get_short_names_and_read_back_in_full(tmp_path: Path) -> None:
    pop = tangled_population(np.random.default_rng(1), 4, 10, 6, 3, 0.5)
    root = next(iter(pop.teams))
    subsets = [(PEND,), (PEND, MC), ("CartPole", PEND, MC, MCC), ("CartPole", "Acrobot")]
    names = [champion_filename(s) for s in subsets]
    assert names[0] == f"{PEND}.json" and names[3] == "CartPole+Acrobot.json"  # short: as before
    assert all(len(n.encode()) <= MAX_FILENAME for n in names)
    assert names[2].startswith("CartPole+Pendulum[") and "MountainCar[" in names[2]
    assert len(set(names)) == len(names)
    write_champions(tmp_path, {s: (pop, root, None) for s in subsets})
    back = read_champions(tmp_path)
    assert sorted(back) == sorted(subsets)
    assert all(back[s][1] == root for s in subsets)
