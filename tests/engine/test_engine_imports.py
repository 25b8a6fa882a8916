"""The engine depends on the model and the tasks only: no cycle, no run configuration."""

import ast
import subprocess
import sys
from pathlib import Path

import mtpg.engine

ENGINE = Path(mtpg.engine.__file__).parent
#: Packages above the engine, which it must not import (not even inside a function).
ABOVE = ("mtpg.config", "mtpg.evolve", "mtpg.cli", "mtpg.analysis")


def imports(path: Path) -> set[str]:
    """Every module a file imports, at the top or inside functions, by absolute name."""
    names = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom):
            assert node.level == 0, f"{path.name}: relative import"
            names.add(node.module)
            names.update(f"{node.module}.{alias.name}" for alias in node.names)
    return names


def engine_graph() -> dict[str, set[str]]:
    """The engine's modules and the engine modules each imports."""
    modules = {f"mtpg.engine.{p.stem}": p for p in ENGINE.glob("*.py") if p.stem != "__init__"}
    return {name: imports(path) & set(modules) - {name} for name, path in modules.items()}


def test_the_engine_imports_nothing_above_it():
    for path in sorted(ENGINE.glob("*.py")):
        bad = {m for m in imports(path) if m.startswith(ABOVE)}
        assert not bad, f"{path.name} imports {sorted(bad)}"


def test_the_engine_modules_import_one_another_without_a_cycle():
    graph = engine_graph()
    assert graph["mtpg.engine.dask_backend"] >= {"mtpg.engine.evaluator"}  # the test sees edges
    done: set[str] = set()

    def visit(name: str, path: tuple[str, ...]) -> None:
        assert name not in path, "import cycle: " + " -> ".join([*path, name])
        if name not in done:
            for dep in sorted(graph[name]):
                visit(dep, (*path, name))
            done.add(name)

    for name in sorted(graph):
        visit(name, ())


def test_importing_the_whole_engine_loads_nothing_above_it():
    names = ", ".join(f"mtpg.engine.{p.stem}" for p in sorted(ENGINE.glob("*.py")))
    code = f"import sys, {names}; print(sorted(m for m in sys.modules if m.startswith({ABOVE})))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == "[]"
