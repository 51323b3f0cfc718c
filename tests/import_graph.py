"""The import graph of ``calib``, ``planner`` and ``webui``, read from the source (no imports run).

Every ``import`` counts: at module level, inside functions (lazy imports) and under
``if TYPE_CHECKING:``. ``from package import name`` is an edge to ``package.name`` when that
is a module, else to ``package``. Used by ``tests/test_import_graph.py``.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
PACKAGES = ("calib", "planner", "webui")


@dataclass(frozen=True)
class Edge:
    """One import: ``source`` imports ``target``; ``function`` is the enclosing function or ``""``.

    Attributes:
        source: importing module, dotted.
        target: imported module, dotted.
        function: name of the function the import sits in (``""`` at module level).
        line: line number in the source file.
    """

    source: str
    target: str
    function: str
    line: int


def modules(root: Path = ROOT) -> dict[str, Path]:
    """``{dotted name: file}`` of every module of :data:`PACKAGES` (packages by ``__init__``)."""
    out = {}
    for pkg in PACKAGES:
        for path in sorted((root / pkg).rglob("*.py")):
            parts = list(path.relative_to(root).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts.pop()
            out[".".join(parts)] = path
    return out


def _resolve(name: str, known: dict[str, Path]) -> str | None:
    """The longest known module that ``name`` is or lies in (``None``: not ours)."""
    while name:
        if name in known:
            return name
        name = name.rpartition(".")[0]
    return None


def edges(root: Path = ROOT) -> list[Edge]:
    """Every import between modules of :data:`PACKAGES`."""
    known = modules(root)
    out: list[Edge] = []
    for mod, path in known.items():
        is_pkg = path.name == "__init__.py"
        package = mod if is_pkg else mod.rpartition(".")[0]
        tree = ast.parse(path.read_text(), filename=str(path))
        scopes: list[tuple[ast.AST, str]] = [(tree, "")]
        while scopes:
            node, func = scopes.pop()
            for child in ast.iter_child_nodes(node):
                inner = (
                    child.name
                    if isinstance(child, ast.FunctionDef | ast.AsyncFunctionDef)
                    else func
                )
                targets: list[str] = []
                if isinstance(child, ast.Import):
                    targets = [a.name for a in child.names]
                elif isinstance(child, ast.ImportFrom):
                    base = child.module or ""
                    if child.level:
                        up = package.split(".")[: len(package.split(".")) - (child.level - 1)]
                        base = ".".join([*up, base] if base else up)
                    targets = [f"{base}.{a.name}" for a in child.names]
                for t in targets:
                    hit = _resolve(t, known)
                    if hit is not None and hit != mod:
                        out.append(Edge(mod, hit, func, child.lineno))
                scopes.append((child, inner))
    return out


def cycles(graph_edges: list[Edge]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan), each sorted."""
    graph: dict[str, set[str]] = {}
    for e in graph_edges:
        graph.setdefault(e.source, set()).add(e.target)
        graph.setdefault(e.target, set())
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []
    counter = [0]

    def visit(v: str) -> None:  # recursion depth is bounded by the module count (~200)
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return found
