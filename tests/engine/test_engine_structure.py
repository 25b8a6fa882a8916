"""The engine's structure stays readable: short functions and kernels of few arguments.

Each function of ``src/mtpg/engine`` holds at most :data:`MAX_LINES` lines of code (its
docstring not counted), and each compiled kernel takes at most :data:`MAX_ARGS` arguments
(its arrays passed as named tuples of buffers, as ``Buffers``, ``Lanes`` and
``BatchResult`` are).
"""

import ast
from pathlib import Path

ENGINE = Path(__file__).parents[2] / "src" / "mtpg" / "engine"
MAX_LINES = 60
MAX_ARGS = 8
#: Functions allowed past MAX_LINES, each with the reason. None today: the scalar decision
#: kernel (episode_kernels.decide_bank), a deliberately flat loop nest, fits.
ALLOWED: dict[tuple[str, str], str] = {}


def _functions():
    for path in sorted(ENGINE.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef):
                yield path.name, node


def _code_lines(fn: ast.FunctionDef) -> int:
    """Lines from the first statement after the docstring to the function's end."""
    body = fn.body
    doc = isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant)
    if doc and len(body) == 1:
        return 0
    return fn.end_lineno - body[1 if doc else 0].lineno + 1


def test_no_engine_function_is_over_sixty_lines():
    long = {
        (name, fn.name): _code_lines(fn) for name, fn in _functions() if _code_lines(fn) > MAX_LINES
    }
    assert set(long) <= set(ALLOWED), long


def test_no_compiled_kernel_takes_more_than_eight_arguments():
    many = {
        (name, fn.name): len(fn.args.args)
        for name, fn in _functions()
        if any("njit" in ast.unparse(d) for d in fn.decorator_list)
        and len(fn.args.args) + len(fn.args.kwonlyargs) > MAX_ARGS
    }
    assert not many, many


def test_the_counts_see_the_functions():
    lines = {(name, fn.name): _code_lines(fn) for name, fn in _functions()}
    assert lines[("episode_kernels.py", "decide_bank")] > 40  # the long ones are measured
    assert lines[("bid_rule.py", "takes_lead")] == 1
