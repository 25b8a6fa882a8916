"""Analysis of runs and graphs, by what it serves in the paper.

- :mod:`mtpg.analysis.runs`: section 5, many runs (``mtpg report``): loading and grouping
  runs, which champion is reported, the reported numbers, statistics across seeds, and
  Figs. 4-8.
- :mod:`mtpg.analysis.graph`: section 6, one graph (``mtpg analyze``, ``mtpg replay``):
  traced replays, what they measure, task decomposition, Figs. 9-12, the page and videos.
- :mod:`mtpg.analysis.description`: a graph's stable numbering, text listing, DOT and
  layout (``mtpg show``, and every picture of a graph).
- :mod:`mtpg.analysis.results`: the committed results pages, written from the committed runs
  (``mtpg report --results``).
- Shared: :mod:`mtpg.analysis.html` (pages), :mod:`mtpg.analysis.plotting` (matplotlib),
  :mod:`mtpg.analysis.palette` (colours).

The test protocol every score comes from is :mod:`mtpg.evolve.heldout_test`.
"""
