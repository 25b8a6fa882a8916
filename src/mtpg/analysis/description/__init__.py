"""A program graph's description: numbering, text listing, DOT and layout.

- :mod:`~mtpg.analysis.description.numbering`: stable team, program and bank numbers.
- :mod:`~mtpg.analysis.description.listing`: the ``mtpg show`` listing and GraphViz DOT.
- :mod:`~mtpg.analysis.description.layout`: layered layout and drawing of the team graph.
"""
