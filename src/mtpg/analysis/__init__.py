"""Analyses of trained program graphs: test scores, hierarchy, memory, decomposition."""
