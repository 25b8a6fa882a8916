"""Benchmarks: the engine benchmark behind ``mtpg bench engine`` and its workload."""
