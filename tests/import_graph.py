"""The import graph of ``calib``, ``planner`` and ``webui``, read from the source (no imports run).

Every ``import`` counts: at module level, inside functions (lazy imports) and under
``if TYPE_CHECKING:``. ``from package import name`` is an edge to ``package.name`` when that
is a module, else to ``package``. Used by ``tests/test_import_graph.py``.
"""

from __future__ import annotations

import ast
import re
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


# ---- reasons sorted by their words ------------------------------------------------------------
#: Names of a reason's words: a variable or attribute called so holds what a person reads.
REASON_NAME = re.compile(
    r"^(?:.*_)?(?:reasons?|why|causes?|problems?|refusals?|failures?|messages?|msg)(?:_.*)?$"
)
#: The words of a :class:`planner.reasons.Reason` (``cause.text``), under a reason's name.
WORDS = {"text", "note"}
#: ``str`` methods that look for words in a text.
SEARCHES = {
    "startswith", "endswith", "find", "rfind", "index", "rindex", "count",
    "split", "rsplit", "partition", "rpartition",
}  # fmt: skip
#: ``str`` methods whose only use on a reason is to compare its words.
CASES = {"lower", "upper", "casefold"}
#: ``re`` functions (and compiled patterns' methods) that look for words in a text.
REGEX = {"search", "match", "fullmatch", "findall", "finditer", "sub", "subn", "split"}
#: Calls looked through to the reason they are made on (``str(reason)``,
#: ``reason.lower().strip()``).
_THROUGH = CASES | {"strip", "lstrip", "rstrip"}


@dataclass(frozen=True)
class TextSort:
    """A place that sorts a reason by its words.

    Attributes:
        module: dotted module name.
        line: line number.
        code: the expression, as source.
    """

    module: str
    line: int
    code: str


def _chain(node: ast.AST) -> list[str] | None:
    """The names along ``node`` (``check.pose_cause.text`` -> ``["check", "pose_cause",
    "text"]``), looking through subscripts, ``str(...)`` and case or strip calls; ``None``
    for anything else (a literal, a computed value)."""
    names: list[str] = []
    while True:
        if isinstance(node, ast.Call):
            f = node.func
            if isinstance(f, ast.Attribute) and f.attr in _THROUGH and not node.args:
                node = f.value
            elif isinstance(f, ast.Name) and f.id == "str" and len(node.args) == 1:
                node = node.args[0]
            else:
                return None
        elif isinstance(node, ast.Subscript):
            node = node.value
        elif isinstance(node, ast.Attribute):
            names.append(node.attr)
            node = node.value
        elif isinstance(node, ast.Name):
            names.append(node.id)
            return names[::-1]
        else:
            return None


def is_reason_text(node: ast.AST, bound: frozenset[str] = frozenset()) -> bool:
    """``node`` holds a reason's words: its last name is a reason's (:data:`REASON_NAME`),
    or it is a reason's ``text`` or ``note`` (``cause.text``), or it is a name ``bound`` to
    a reason's words by a loop (:func:`_bound_words`); a reason's ``kind`` or ``pair`` is not
    words."""
    names = _chain(node)
    if not names:
        return False
    last = names[-1]
    if REASON_NAME.match(last) or (len(names) == 1 and last in bound):
        return True
    return last in WORDS and any(REASON_NAME.match(n) for n in names[:-1])


#: Calls looked through to the collection they are made on (``sorted(failures)``).
_COLLECTIONS = {"sorted", "list", "set", "tuple", "reversed"}


def _loop_words(iter_: ast.AST, target: ast.AST) -> set[str]:
    """The names ``target`` binds to a reason's words when a loop runs over ``iter_``: the
    items of a collection of words (``for why in reasons``), the keys of a mapping keyed by
    words (``for label in report.failures``, ``for label, n in failures.items()``, also
    through ``sorted(...)`` and the like)."""
    while (
        isinstance(iter_, ast.Call)
        and isinstance(iter_.func, ast.Name)
        and iter_.func.id in _COLLECTIONS
        and len(iter_.args) == 1
    ):
        iter_ = iter_.args[0]
    if is_reason_text(iter_):
        return {target.id} if isinstance(target, ast.Name) else set()
    f = iter_.func if isinstance(iter_, ast.Call) and not iter_.args else None
    if isinstance(f, ast.Attribute) and f.attr in ("keys", "items") and is_reason_text(f.value):
        if f.attr == "keys" and isinstance(target, ast.Name):
            return {target.id}
        if f.attr == "items" and isinstance(target, ast.Tuple) and target.elts:
            first = target.elts[0]
            return {first.id} if isinstance(first, ast.Name) else set()
    return set()


def _bound_words(node: ast.AST) -> frozenset[str]:
    """The names a ``for`` statement or a comprehension binds to a reason's words (over its
    body, or the comprehension: :func:`_loop_words`)."""
    names: set[str] = set()
    if isinstance(node, ast.For | ast.AsyncFor):
        names |= _loop_words(node.iter, node.target)
    elif isinstance(node, ast.ListComp | ast.SetComp | ast.GeneratorExp | ast.DictComp):
        for gen in node.generators:
            names |= _loop_words(gen.iter, gen.target)
    return frozenset(names)


def _words(node: ast.AST) -> bool:
    """A text literal with words in it (an f-string too); ``""`` is no words."""
    if isinstance(node, ast.Constant):
        return isinstance(node.value, str) and node.value != ""
    return isinstance(node, ast.JoinedStr)


def _texts(node: ast.AST) -> bool:
    """A tuple, list or set of text literals (``reason in ("a", "b")``)."""
    return isinstance(node, ast.Tuple | ast.List | ast.Set) and any(_words(e) for e in node.elts)


def _sorts(node: ast.AST, bound: frozenset[str]) -> bool:
    """``node`` sorts a reason by its words (see :func:`text_sorts_in`)."""
    hit = False
    if isinstance(node, ast.Compare):
        left = node.left
        for op, right in zip(node.ops, node.comparators, strict=True):
            if isinstance(op, ast.In | ast.NotIn):
                hit |= _words(left) and is_reason_text(right, bound)
                hit |= is_reason_text(left, bound) and _texts(right)
            elif isinstance(op, ast.Eq | ast.NotEq):
                hit |= _words(left) and is_reason_text(right, bound)
                hit |= _words(right) and is_reason_text(left, bound)
            left = right
    elif isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute):
        attr, owner, args = node.func.attr, node.func.value, node.args
        if attr in SEARCHES and is_reason_text(owner, bound):
            hit = any(_words(a) for a in args)
        elif attr in CASES and not args:
            hit = is_reason_text(owner, bound)
        if attr in REGEX and not hit:
            # re.search(pattern, text), re.sub(pattern, repl, text); compiled: one less
            is_re = isinstance(owner, ast.Name) and owner.id == "re"
            at = int(is_re) + int(attr in ("sub", "subn"))
            hit = len(args) > at and is_reason_text(args[at], bound)
    return hit


def text_sorts_in(tree: ast.AST, module: str = "<snippet>") -> list[TextSort]:
    """Where ``tree`` sorts a reason by its words: a literal searched for in it (``"reach" in
    reason``), compared with it (``reason == "singular wrist"``), looked for with a ``str``
    method (``why.startswith("joint")``, ``reason.split("; ")``), a regular expression run on
    it (``re.search(p, reason)``, ``PATTERN.sub("", reason)``), it put in one case
    (``reason.lower()``), or it looked up among literals (``reason in ("a", "b")``). A name a
    loop binds to a reason's words counts as one inside the loop (``for label in failures:
    if "no detection" in label``)."""
    found: dict[tuple[int, int, str], TextSort] = {}  # a node found twice counts once

    def scan(root: ast.AST, bound: frozenset[str]) -> None:
        for node in ast.walk(root):
            if _sorts(node, bound):
                line, code = getattr(node, "lineno", 0), ast.unparse(node)
                at = (line, getattr(node, "col_offset", 0), code)
                found.setdefault(at, TextSort(module, line, code))

    scan(tree, frozenset())
    for node in ast.walk(tree):
        bound = _bound_words(node)
        if bound:
            scan(node, bound)
    return [found[k] for k in sorted(found)]


def text_sorts(root: Path = ROOT) -> list[TextSort]:
    """:func:`text_sorts_in` over every module of :data:`PACKAGES`."""
    out = []
    for mod, path in modules(root).items():
        out += text_sorts_in(ast.parse(path.read_text(), filename=str(path)), mod)
    return out
