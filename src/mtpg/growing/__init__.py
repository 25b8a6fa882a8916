"""Growing the committed experiments of ``results/`` from a plan file, sitting by sitting.

The experiments behind ``results/`` (the paper's five seeds and its ablations, TPG-robust,
TPG-authors, the demo-scale candidates and the interface study) take longer than one
sitting on a small machine, so their runs grow over many sittings, machines and commits.
``mtpg experiment --plan results/plan.toml --budget MINUTES`` grows them:

* :mod:`~mtpg.growing.plan` reads the plan file (TOML) into frozen dataclasses and gives
  every run's ``mtpg train`` command line;
* :mod:`~mtpg.growing.tidy` keeps a run small enough to commit and appends its
  ``provenance.csv`` row;
* :mod:`~mtpg.growing.checkout` checks that the mtpg that runs is a clean commit of the
  repository's history, and commits the grown runs with git;
* :mod:`~mtpg.growing.grow` runs the ``mtpg train`` processes for a wall-clock budget.
"""
