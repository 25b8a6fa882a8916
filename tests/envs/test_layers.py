"""The layers of ``mtpg.envs`` import downwards only (docs/architecture.md).

``specs`` (what a task is, as data) < ``dynamics`` (the compiled kernels) < ``taskset`` (a
run's tasks: variants, table, reference scores, episodes, seeds) < ``gym_api`` (Gymnasium).
No module of ``mtpg.envs`` imports from outside the package but ``mtpg.envs`` itself.
"""

from __future__ import annotations

from test_import_cycles import import_graph

LAYERS = ("specs", "dynamics", "taskset", "gym_api")


def _layer(module: str) -> str | None:
    parts = module.split(".")
    return parts[2] if len(parts) > 3 and parts[2] in LAYERS else None


def test_every_envs_module_sits_in_a_layer() -> None:
    modules = [m for m in import_graph() if m.startswith("mtpg.envs.")]
    assert modules
    assert all(m.split(".")[2] in LAYERS for m in modules), modules


def test_layers_import_downwards_only() -> None:
    upward = []
    for module, targets in import_graph().items():
        low = _layer(module)
        if low is None:
            continue
        for target in targets:
            high = _layer(target)
            if high is not None and LAYERS.index(high) > LAYERS.index(low):
                upward.append((module, target))
    assert upward == []


def test_envs_stands_alone() -> None:
    graph = import_graph()
    outside = {
        (m, t)
        for m, targets in graph.items()
        if m.startswith("mtpg.envs")
        for t in targets
        if not t.startswith("mtpg.envs")
    }
    assert outside == set()
