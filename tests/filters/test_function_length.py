"""The numerical core reads in pieces: no function in ``footzoo/filters`` or ``footzoo/kernels`` is longer than 60
lines (docstring included), so each step of the filter is one short function a reader can hold at once."""

from __future__ import annotations

import ast
from pathlib import Path

import footzoo

LIMIT = 60
ROOT = Path(footzoo.__file__).parent


def test_no_function_of_the_core_is_longer_than_60_lines():
    long = []
    for folder in ("filters", "kernels"):
        for path in sorted((ROOT / folder).glob("*.py")):
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    lines = node.end_lineno - node.lineno + 1
                    if lines > LIMIT:
                        long.append(f"{folder}/{path.name}:{node.lineno} {node.name} ({lines} lines)")
    assert not long, long
