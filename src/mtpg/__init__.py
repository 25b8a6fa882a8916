"""mtpg: Tangled Program Graphs with temporal memory for multi-task reinforcement learning."""

__version__ = "0.1.0"
