"""The committed results pages, written from the committed runs (``mtpg report --results``).

- :mod:`~mtpg.analysis.results.pages`: every page and how it is regenerated.
- ``results/README.md``: :mod:`~mtpg.analysis.results.readme`, with its tables
  (:mod:`~mtpg.analysis.results.tables`) and its TPG-robust section
  (:mod:`~mtpg.analysis.results.robust_section`).
- The study pages: the demo-scale candidates (:mod:`~mtpg.analysis.results.candidates`),
  the interface study (:mod:`~mtpg.analysis.results.variants`), the memorisation probes
  (:mod:`~mtpg.analysis.results.memorisation_page`) and the TPG-robust audit
  (:mod:`~mtpg.analysis.results.audit`, tables by :mod:`~mtpg.analysis.results.audit_page`).
"""
