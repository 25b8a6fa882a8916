"""Command-line arguments of tiny training runs shared by the end-to-end tests."""


def tiny_args(
    tasks: str = "CartPole,CartCentering",
    root_size: int = 12,
    n_elite: int = 2,
    quiet: bool = True,
    **settings: object,
) -> list[str]:
    """``mtpg train`` options for a run that takes a second or two.

    Args:
        tasks: Comma-separated task names.
        root_size: Initial roots.
        n_elite: Elites (and children) per task subset.
        quiet: Add ``--quiet`` (an ``mtpg train`` option).
        **settings: More ``section__field=value`` settings (``__`` stands for the dot).

    Returns:
        The argument list (two training episodes, teams of three programs).
    """
    values = {
        "team.root_size": root_size,
        "team.n_elite": n_elite,
        "team.init_team_size": 3,
        "evaluation.train_episodes": 2,
        "team.min_elite_total": 0,
    }
    values.update({k.replace("__", "."): v for k, v in settings.items()})
    args = ["--tasks", tasks] + (["--quiet"] if quiet else [])
    for key, value in values.items():
        args += ["--set", f"{key}={value}"]
    return args
