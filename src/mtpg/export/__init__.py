"""Standalone code from a program graph: C99 and plain Python, persistent memory included.

:mod:`mtpg.export.common` reduces a graph to what its root executes (introns and
unreachable teams removed) with its provenance; :mod:`mtpg.export.c` and
:mod:`mtpg.export.python` print it; :mod:`mtpg.export.harness` drives exported C against
the engine; :mod:`mtpg.export.bench` times it. The command is ``mtpg export``.
"""
