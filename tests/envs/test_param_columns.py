"""Each task module's parameter columns are its spec's ``param_names``, in order.

The column constants are written out (the kernels read them as compile-time globals), and
their number is derived from the spec (``= range(len(spec.param_names))`` fails at import on
a count that differs); this test checks the names, so a parameter renamed or moved in one
place and not the other is caught.
"""

from __future__ import annotations

import ast
import importlib
import inspect

import pytest

from mtpg.envs.specs.registry import TASKS


def written_columns(module) -> list[str]:
    """The names bound by the module's ``(...) = range(len(<spec>.param_names))``."""
    tree = ast.parse(inspect.getsource(module))
    for node in tree.body:
        if (
            isinstance(node, ast.Assign)
            and isinstance(node.value, ast.Call)
            and getattr(node.value.func, "id", "") == "range"
            and "param_names" in ast.unparse(node.value)
        ):
            return [e.id for e in node.targets[0].elts]
    raise AssertionError(f"{module.__name__}: no column constants derived from param_names")


@pytest.mark.parametrize("spec", TASKS, ids=lambda s: s.name)
def test_column_constants_are_the_param_names(spec) -> None:
    module = importlib.import_module(spec.kernel_module)
    names = written_columns(module)
    assert names == [n.upper() for n in spec.param_names]
    assert [getattr(module, n) for n in names] == list(range(len(spec.param_names)))
