"""A commit renders each distinct champion (and each shared program) once, same bytes.

``write_champions`` and the test-point writer pass one cache of rendered graphs to every
file of a commit; the files must be byte for byte those written without it.
"""

import numpy as np

from mtpg.engine.random_populations import tangled_population
from mtpg.io._readable import dumps_readable
from mtpg.io.serialize import graph_text, graph_to_dict


def test_cached_text_equals_plain_text_for_every_root_and_meta():
    rng = np.random.default_rng(3)
    pop = tangled_population(rng, 8, 30, 12, 5, 0.6)
    bodies: dict = {}
    for k, root in enumerate(sorted(pop.teams) * 2):  # every root twice: from the cache
        meta = {"tasks": ["CartPole"], "k": k, "score": 0.1 * k, "flag": k % 2 == 0}
        plain = dumps_readable(graph_to_dict(pop, root, meta))
        assert graph_text(pop, root, meta, bodies) == plain
        assert graph_text(pop, root, meta) == plain


def test_flat_int_rows_render_as_the_generic_writer():
    value = {"a": [1, 2, 3], "b": [True, 2], "c": [[0, -1, 2**70]], "d": [1.5, 2]}
    text = dumps_readable(value)
    assert '"a": [1, 2, 3]' in text and "[true, 2]" in text and "1180591620717411303424" in text
