"""The architecture's rules, checked on the source: one replan loop, no hidden state, no cycles.

These are the structural promises of ``docs/architecture.md``. Each test reads the code as text
(``ast``), runs nothing of it, and names the offending file and line.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

import networkx as nx
import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGES = ("fcplan", "solvers")
MAX_MODULE_LINES = 600
MAX_FUNCTION_LINES = 100


def _modules() -> dict[str, Path]:
    out = {}
    for pkg in PACKAGES:
        for path in sorted((ROOT / pkg).rglob("*.py")):
            parts = list(path.relative_to(ROOT).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join(parts)] = path
    return out


MODULES = _modules()
TREES = {name: ast.parse(path.read_text(), str(path)) for name, path in MODULES.items()}


def _is_fast(name: str) -> bool:
    return name.startswith("fcplan._fast")


def _nodes(*, outside_fast: bool) -> Iterator[tuple[Path, ast.AST]]:
    """(file, node) for every syntax node of the packages (outside fcplan/_fast if asked)."""
    for name, tree in TREES.items():
        if not (outside_fast and _is_fast(name)):
            for node in ast.walk(tree):
                yield MODULES[name], node


def _type_checking_nodes(tree: ast.Module) -> set[int]:
    """ids of import nodes under ``if TYPE_CHECKING:`` (they never run)."""
    skip = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            for sub in node.body:
                for inner in ast.walk(sub):
                    skip.add(id(inner))
    return skip


def _resolve(target: str) -> str | None:
    """The fcplan/solvers module an import of ``target`` loads (longest known prefix)."""
    parts = target.split(".")
    while parts:
        name = ".".join(parts)
        if name in MODULES:
            return name
        parts.pop()
    return None


def import_graph() -> nx.DiGraph:
    """Module -> module edges for every import that runs, at module level or inside functions."""
    g = nx.DiGraph()
    for name, tree in TREES.items():
        g.add_node(name)
        is_pkg = MODULES[name].name == "__init__.py"
        skip = _type_checking_nodes(tree)
        for node in ast.walk(tree):
            if id(node) in skip:
                continue
            targets: list[str] = []
            if isinstance(node, ast.Import):
                targets = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    anchor = name.split(".") if is_pkg else name.split(".")[:-1]
                    anchor = anchor[: len(anchor) - (node.level - 1)]
                    base = ".".join(anchor + ([base] if base else []))
                targets = [f"{base}.{a.name}" for a in node.names] + [base]
            for t in targets:
                mod = _resolve(t)
                if mod is not None and mod != name:
                    g.add_edge(name, mod, line=node.lineno)
    return g


def test_no_import_cycles():
    """No import cycle inside fcplan/ and solvers/, counting function-level imports too."""
    g = import_graph()
    cycles = [sorted(c) for c in nx.strongly_connected_components(g) if len(c) > 1]
    assert cycles == [], f"import cycles: {cycles}"


CORE = (
    "fcplan.scenario", "fcplan.farsite", "fcplan.fire", "fcplan.team", "fcplan.world",
    "fcplan.trace", "fcplan.metrics",
)  # fmt: skip
ABOVE_CORE = (
    "fcplan.belief", "fcplan.taskgraph", "fcplan.plan", "fcplan.scheduling", "fcplan.mission",
    "fcplan.episode", "fcplan.env", "fcplan.experiments", "fcplan.cli", "fcplan.game",
    "fcplan.render", "fcplan.recording", "solvers",
)  # fmt: skip


def test_core_imports_nothing_above_it():
    """The core (scenario, fire, team, world, metrics) imports no module that builds on it."""
    g = import_graph()
    bad = [
        f"{a} -> {b} (line {d['line']})"
        for a, b, d in g.edges(data=True)
        if a.startswith(CORE) and b.startswith(ABOVE_CORE)
    ]
    assert bad == []


def test_solvers_use_only_public_fcplan():
    """Built-in schedulers import no private fcplan module (their names start with ``_``)."""
    g = import_graph()
    bad = [
        f"{a} -> {b}"
        for a, b in g.edges()
        if a.startswith("solvers") and b.startswith("fcplan") and "._" in b
    ]
    assert bad == []


@pytest.mark.parametrize("name", [n for n in MODULES if not _is_fast(n)])
def test_module_size(name):
    """Modules outside fcplan/_fast hold at most 600 lines (one concept each)."""
    n = MODULES[name].read_text().count("\n")
    assert n <= MAX_MODULE_LINES, f"{MODULES[name]} has {n} lines"


def test_function_size():
    """No function outside fcplan/_fast is longer than 100 lines."""
    long = [
        f"{path}:{node.lineno} {node.name} ({node.end_lineno - node.lineno + 1} lines)"
        for path, node in _nodes(outside_fast=True)
        if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
        and node.end_lineno - node.lineno + 1 > MAX_FUNCTION_LINES
    ]
    assert long == []


def test_no_identity_keyed_state():
    """No code keys state on ``id()`` (state lives in objects with a lifetime)."""
    calls = [
        f"{path}:{node.lineno}"
        for path, node in _nodes(outside_fast=False)
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and node.func.id == "id"
    ]
    assert calls == []


def test_object_new_only_in_fast_kernels():
    """``object.__new__`` (building objects around their constructor) only in fcplan/_fast."""
    uses = [
        f"{path}:{node.lineno}"
        for path, node in _nodes(outside_fast=True)
        if isinstance(node, ast.Attribute)
        and node.attr == "__new__"
        and ast.unparse(node.value) == "object"
    ]
    assert uses == []


def test_world_steps_only_in_the_mission():
    """``World.step`` is called only by fcplan/mission.py: there is one replan loop."""
    calls = [
        f"{path}:{node.lineno} {ast.unparse(node.func)}"
        for path, node in _nodes(outside_fast=False)
        if path != MODULES["fcplan.mission"]
        and isinstance(node, ast.Call)
        and isinstance(node.func, ast.Attribute)
        and node.func.attr == "step"
        and "world" in ast.unparse(node.func.value).lower()
    ]
    assert calls == []


def test_py_typed_is_shipped():
    """``py.typed`` marks both import packages as typed (PEP 561) and is package data."""
    assert (ROOT / "fcplan" / "py.typed").exists() and (ROOT / "solvers" / "py.typed").exists()
    text = (ROOT / "pyproject.toml").read_text()
    assert '"py.typed"' in text


def test_every_package_is_listed_for_the_wheel():
    """Every folder of fcplan/ and solvers/ with an ``__init__.py`` is in pyproject's package list
    (the list is explicit, so a package left out would be missing from an installed wheel)."""
    import tomllib

    listed = set(
        tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]["packages"]
    )
    found = {name for name, path in MODULES.items() if path.name == "__init__.py"}
    assert found - listed == set()
