"""The module graph of footzoo, every import counted: no cycle, and the layers of pyproject.toml hold.

``lint-imports`` checks the contracts of ``[tool.importlinter]`` on the imports it sees; this test
parses every module with :mod:`ast` and collects every ``import`` statement, those inside
functions and methods too (a cycle or an upward arrow hidden in a function is still one), with
relative imports resolved. Imports under ``if TYPE_CHECKING:`` are left out (they never run).
The contracts are read from pyproject.toml, not copied here.
"""

from __future__ import annotations

import ast
import functools
from dataclasses import dataclass
from pathlib import Path

import pytest

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10
    tomllib = pytest.importorskip("tomli")

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "footzoo"


@dataclass(frozen=True)
class Import:
    """One import statement's target: ``source`` imports ``target`` at ``line`` (inside a function or not)."""

    source: str
    target: str
    line: int
    in_function: bool

    def __str__(self) -> str:
        where = "inside a function" if self.in_function else "at module level"
        return f"{self.source} -> {self.target} (line {self.line}, {where})"


def _modules() -> dict[str, tuple[Path, bool]]:
    """``{module name: (file, is a package)}`` of every module of footzoo."""
    out = {}
    for f in sorted(PACKAGE.rglob("*.py")):
        parts = list(f.relative_to(ROOT).with_suffix("").parts)
        package = parts[-1] == "__init__"
        out[".".join(parts[:-1] if package else parts)] = (f, package)
    return out


MODULES = _modules()


def _statements(node: ast.AST, in_function: bool = False):
    """``(import statement, inside a function?)`` under ``node``, leaving out those under ``if TYPE_CHECKING:``.

    One walk through the statements only (an import is a statement: expressions, lambdas included, hold none).
    """
    in_function = in_function or isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))
    type_checking = isinstance(node, ast.If) and ast.unparse(node.test) in ("TYPE_CHECKING", "typing.TYPE_CHECKING")
    for child in node.orelse if type_checking else ast.iter_child_nodes(node):  # its body never runs, an else does
        if isinstance(child, (ast.Import, ast.ImportFrom)):
            yield child, in_function
        elif isinstance(child, (ast.stmt, ast.excepthandler, ast.match_case)):
            yield from _statements(child, in_function)


def _targets(module: str, package: bool, node: ast.Import | ast.ImportFrom) -> list[str]:
    """The absolute names an import statement of ``module`` imports (a module, or a name in one)."""
    if isinstance(node, ast.Import):
        return [alias.name for alias in node.names]
    if node.level:
        base = module.split(".") if package else module.split(".")[:-1]
        base = base[:len(base) - (node.level - 1)]
        prefix = ".".join(base + ([node.module] if node.module else []))
    else:
        prefix = node.module or ""
    return [f"{prefix}.{alias.name}" if f"{prefix}.{alias.name}" in MODULES else prefix for alias in node.names]


def _nearest_module(name: str) -> str:
    """``footzoo.core.data.Recording`` -> ``footzoo.core.data``: the longest prefix that is a module."""
    while name not in MODULES and "." in name:
        name = name.rsplit(".", 1)[0]
    return name


def _imports() -> list[Import]:
    out = []
    for module, (path, package) in MODULES.items():
        tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
        for node, in_function in _statements(tree):
            for target in _targets(module, package, node):
                if target.split(".")[0] == "footzoo":
                    target = _nearest_module(target)
                    if target == module:
                        continue
                out.append(Import(module, target, node.lineno, in_function))
    return out


@functools.cache
def imports() -> tuple[Import, ...]:
    """Every import statement of the package (parsed once, when a test first asks, not at collection)."""
    return tuple(_imports())


@functools.cache
def internal() -> tuple[Import, ...]:
    """The imports of footzoo's own modules."""
    return tuple(i for i in imports() if i.target.split(".")[0] == "footzoo")


CONTRACTS = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["tool"]["importlinter"]["contracts"]


def _within(module: str, package: str) -> bool:
    return module == package or module.startswith(package + ".")


def _cycles(edges: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(edges.get(v, ())):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            component = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                component.append(w)
                if w == v:
                    break
            if len(component) > 1:
                found.append(sorted(component))

    for v in sorted(MODULES):
        if v not in index:
            visit(v)
    return found


def test_the_parser_sees_function_level_and_relative_imports():
    """The collection itself, on imports known to be there (a test of the test)."""
    assert len(MODULES) > 100 and len(internal()) > 300
    assert sum(i.in_function for i in internal()) > 50  # imports inside functions are counted
    assert any(i.source == "footzoo.runtime.pipeline" and i.target == "footzoo.core.data" for i in internal())
    assert any(i.source == "footzoo.apps.cli" and i.target == "footzoo.runtime.pipeline" and i.in_function
               for i in internal())
    assert not any(i.source == "footzoo" and i.target == "footzoo.apps.testing" for i in internal())  # TYPE_CHECKING


def test_no_cycle_among_footzoo_modules_counting_imports_inside_functions():
    edges: dict[str, set[str]] = {}
    for i in internal():
        edges.setdefault(i.source, set()).add(i.target)
    cycles = _cycles(edges)
    details = [f"{' <-> '.join(c)}: " + "; ".join(str(i) for i in internal() if i.source in c and i.target in c)
               for c in cycles]
    assert not cycles, "import cycles:\n" + "\n".join(details)


def _place(layers: list[list[list[str]]], module: str) -> tuple[int, int] | None:
    """(layer, independent group) of a module in a layers contract (None: in no layer)."""
    for n, groups in enumerate(layers):
        for g, group in enumerate(groups):
            if any(_within(module, m) for m in group):
                return n, g
    return None


def _layer_violations(contract: dict) -> list[str]:
    out = []
    for container in contract.get("containers") or [""]:
        # per layer, top first: its independent groups ("a | b"), each a list of siblings ("a : b")
        layers = [[[f"{container}.{m.strip()}" if container else m.strip() for m in group.split(":")]
                   for group in layer.split("|")] for layer in contract["layers"]]
        for i in internal():
            a, b = _place(layers, i.source), _place(layers, i.target)
            if a is None or b is None:
                continue
            if b[0] < a[0]:
                out.append(f"{i}: upward ({contract['name']})")
            elif b[0] == a[0] and b[1] != a[1]:
                out.append(f"{i}: between independent layers ({contract['name']})")
    return out


@pytest.mark.parametrize("contract", [c for c in CONTRACTS if c["type"] == "layers"], ids=lambda c: c["name"])
def test_each_layers_contract_holds_for_every_import(contract):
    violations = _layer_violations(contract)
    assert not violations, "\n".join(violations)
    assert not contract.get("ignore_imports"), "the contract ignores imports: remove the arrow instead"


@pytest.mark.parametrize("contract", [c for c in CONTRACTS if c["type"] == "forbidden"], ids=lambda c: c["name"])
def test_each_forbidden_contract_holds_for_every_direct_import(contract):
    bad = [str(i) for i in imports()
           if any(_within(i.source, s) for s in contract["source_modules"])
           and any(_within(i.target, f) for f in contract["forbidden_modules"])]
    assert not bad, "\n".join(bad)
