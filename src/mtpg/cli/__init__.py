"""Command-line interface of mtpg."""
