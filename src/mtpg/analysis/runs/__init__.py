"""Paper section 5, many runs (``mtpg report``).

- :mod:`~mtpg.analysis.runs.loading`: run directories' test results, grouped by
  configuration; normalisation.
- :mod:`~mtpg.analysis.runs.champions`: which champion of a run is reported.
- :mod:`~mtpg.analysis.runs.reported_numbers`: every number the report and ``evaluate`` show.
- :mod:`~mtpg.analysis.runs.statistics`: IQM and stratified bootstrap intervals.
- :mod:`~mtpg.analysis.runs.score_figures`: Figs. 4-7 (learning curves, normalised scores,
  ablations).
- :mod:`~mtpg.analysis.runs.hierarchical_complexity`: Fig. 8 (teams per decision).
- :mod:`~mtpg.analysis.runs.statistics_figures`: IQM and performance-profile figures.
- :mod:`~mtpg.analysis.runs.report`: the report page.
"""
