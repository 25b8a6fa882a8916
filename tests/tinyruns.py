"""Command-line arguments of tiny training runs shared by the end-to-end tests."""


def tiny_overrides(root_size: int = 12, n_elite: int = 2, **settings: object) -> list[str]:
    """``section.field=value`` settings of a run that takes a second or two.

    Args:
        root_size: Initial roots.
        n_elite: Elites (and children) per task subset.
        **settings: More ``section__field=value`` settings (``__`` stands for the dot).

    Returns:
        The settings (two training episodes, teams of three programs), for
        ``build_config(..., overrides=...)`` or ``--set``.
    """
    values = {
        "team.root_size": root_size,
        "team.n_elite": n_elite,
        "team.init_team_size": 3,
        "evaluation.train_episodes": 2,
        "team.min_elite_total": 0,
    }
    values.update({k.replace("__", "."): v for k, v in settings.items()})
    return [f"{key}={value}" for key, value in values.items()]


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
        The argument list (:func:`tiny_overrides` as ``--set`` options).
    """
    args = ["--tasks", tasks] + (["--quiet"] if quiet else [])
    for text in tiny_overrides(root_size, n_elite, **settings):
        args += ["--set", text]
    return args
