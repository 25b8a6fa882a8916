"""Hypothesis strategy shared by the engine tests: random tangled populations."""

import numpy as np
from hypothesis import strategies as st

from mtpg.engine.random_populations import tangled_population
from mtpg.model.graph import Population


@st.composite
def tangled_cases(draw) -> tuple[np.random.Generator, Population, bool]:
    """``(rng, population, no_memory)``: a random tangled graph population (cycles, shared
    banks and programs, pointers of every density), the generator that drew it, for the
    test's further draws, and a memory mode."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    pop = tangled_population(
        rng,
        draw(st.integers(1, 8)),  # teams
        draw(st.integers(2, 30)),  # programs
        draw(st.integers(1, 40)),  # instructions per program, at most
        draw(st.integers(1, 6)),  # memory banks
        draw(st.sampled_from([0.0, 0.3, 0.7, 0.95])),  # pointer probability
    )
    return rng, pop, draw(st.booleans())
