"""The core reads as plain numerical Python: short functions, named offsets, numba in one package.

Issue 22's rules for the Kalman core, checked on the source: no function in ``footzoo/filters`` is longer than
90 lines, and no correction or filter indexes the nominal state, a model's constants or its memory with a bare
number (``nav[7 + i]``, ``par[3]``, ``mem[0]``): each position has a name (``V``, ``GYRO_BOUND``, ``FLOOR`` …)
documented next to the function that uses it. (That numba is imported only in ``footzoo.kernels`` is an
import-linter contract, checked by ``lint-imports``.)
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import footzoo

ROOT = Path(footzoo.__file__).parent
MAX_LINES = 90


def _code_lines(path: Path) -> list[tuple[int, str]]:
    """The lines of a module that are code, not docstrings or comments."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    doc = set()
    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if isinstance(body, list) and body and isinstance(body[0], ast.Expr) and isinstance(
                getattr(body[0], "value", None), ast.Constant) and isinstance(body[0].value.value, str):
            doc.update(range(body[0].lineno, body[0].end_lineno + 1))
    lines = path.read_text(encoding="utf-8").splitlines()
    return [(i, line.split("#")[0]) for i, line in enumerate(lines, 1) if i not in doc]


def test_no_function_in_the_filters_is_longer_than_90_lines():
    long = []
    for path in sorted((ROOT / "filters").glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                n = node.end_lineno - node.lineno + 1
                if n > MAX_LINES:
                    long.append(f"{path.name}:{node.lineno} {node.name} ({n} lines)")
    assert not long, long


def test_no_literal_offsets_into_the_state_the_constants_or_the_memory():
    pattern = re.compile(r"\b(nav|par|mem)\[\s*\d")
    found = [f"{path.relative_to(ROOT)}:{i}: {line.strip()}"
             for folder in ("filters", "corrections") for path in sorted((ROOT / folder).glob("*.py"))
             for i, line in _code_lines(path) if pattern.search(line)]
    assert not found, found


def test_the_check_sees_a_literal_offset():
    """The pattern catches what it is meant to catch (so the test above can fail)."""
    pattern = re.compile(r"\b(nav|par|mem)\[\s*\d")
    assert pattern.search("z[m] = nav[7 + i]") and pattern.search("R[m] = par[0] * par[0]")
    assert not pattern.search("z[m] = nav[V + i]")
