"""Paper section 6, one graph (``mtpg analyze``, ``mtpg replay``).

- :mod:`~mtpg.analysis.graph.replay`: traced replays on test episodes and their ``.npz``
  format.
- :mod:`~mtpg.analysis.graph.measures`: visits, register access, complexity and memory
  window per step, velocity prediction (Figs. 9, 11, 12).
- :mod:`~mtpg.analysis.graph.decomposition`: where each team runs (Fig. 10).
- :mod:`~mtpg.analysis.graph.figures`: Figs. 9-12 drawn from those arrays.
- :mod:`~mtpg.analysis.graph.page`: the ``mtpg analyze`` page.
- :mod:`~mtpg.analysis.graph.video`: replay videos.
"""
