"""The import graph: no circles anywhere, and every package imports only the layers below it;
and no module sorts a reason by its words (issue 23, item 3).

Read from the source (``tests/import_graph.py``): imports at module level, inside functions and
under ``TYPE_CHECKING`` all count. ``docs/ARCHITECTURE.md`` draws the same layers. A reason's
kind is given where the outcome is decided (:mod:`planner.reasons`); whoever sorts reasons
reads that kind, never the English text.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from tests.import_graph import Edge, cycles, edges, modules, text_sorts, text_sorts_in

#: The jobs: one package (or the demo module) each, called by the CLI, the UI and scripts.
#: ``check`` is the verdict every other job must give the program the robot will run (one
#: program, many faces): it sits below them, and is the only job another job imports.
CHECK = "planner.check"
JOB_NAMES = ("validate", "suggest", "calibrate", "export_plan", "sweep", "demo")
JOBS = tuple(f"planner.{name}" for name in JOB_NAMES)
#: Everything below the jobs: what a job may import.
BELOW_JOBS = {
    "calib",
    "planner.errors",
    "planner.reasons",
    "planner.memo",
    "planner.builtins",
    "planner.robot",
    "planner.parts",
    "planner.faces",
    "planner.cad",
    "planner.cell",
    "planner.program",
    "planner.sim",
    "planner.export",
    "planner.results",
    "planner.plan_cell",
}
#: What every package of ``planner`` may import: ``calib``, the errors, the reasons (why a
#: pose, a search or a move fails, with its kind: ``planner.reasons``, which imports nothing)
#: and the memo of values computed from content (``planner.memo``, which imports nothing).
BASE = {"calib", "planner.errors", "planner.reasons", "planner.memo"}
ALLOWED: dict[str, set[str]] = {
    "calib": set(),
    "planner": {"calib"},  # the version
    "planner.errors": {"calib"},
    "planner.reasons": set(),
    "planner.memo": set(),
    "planner.builtins": BASE,
    "planner.robot": BASE | {"planner.builtins"},
    "planner.parts": BASE,
    "planner.faces": BASE,
    "planner.cad": BASE | {"planner.faces"},
    "planner.cell": BASE | {"planner.builtins", "planner.robot", "planner.cad"},
    "planner.program": BASE,
    "planner.sim": BASE | {"planner.parts", "planner.faces", "planner.program"},
    "planner.export": BASE | {"planner.program"},
    "planner.results": BASE | {"planner.export", "planner.plan_cell"},
    "planner.plan_cell": BASE
    | {"planner.builtins", "planner.robot", "planner.cell", "planner.export"},
    CHECK: BELOW_JOBS,
    **{job: BELOW_JOBS | {CHECK} for job in JOBS},
    "planner.cli": BELOW_JOBS | {CHECK, *JOBS},
    "planner.__main__": {"planner.cli"},
    "webui": BELOW_JOBS | {CHECK, *JOBS},
}
SUBPACKAGES = (
    "robot", "cad", "cell", "faces", "program", "sim", "parts", "export", "results", "cli",
)  # fmt: skip
TOP_MODULES = ("errors", "reasons", "memo", "builtins", "plan_cell", "__main__")
#: The one allowed upward import: ``wobjcal ui`` starts the web app, lazily, in one function.
LAZY_UI = ("planner.cli.misc", "webui", "cmd_ui")
#: At most this many modules directly in ``planner/`` (``__init__`` and ``__main__`` included).
MAX_TOP_MODULES = 8


def part_of(module: str) -> str:
    """The layer a module belongs to (a key of :data:`ALLOWED`)."""
    top, _, rest = module.partition(".")
    if top in ("calib", "webui"):
        return top
    if not rest:
        return "planner"
    first = rest.split(".")[0]
    if first in (*SUBPACKAGES, *TOP_MODULES, "check", *JOB_NAMES):
        return f"planner.{first}"
    raise AssertionError(f"{module}: a module of no known layer (add it to the layers above)")


@pytest.fixture(scope="module")
def graph() -> list[Edge]:
    return edges()


@pytest.mark.slow
def test_no_import_circles(graph: list[Edge]) -> None:
    assert cycles(graph) == []


def test_every_package_imports_only_the_layers_below(graph: list[Edge]) -> None:
    bad = []
    for e in graph:
        src, dst = part_of(e.source), part_of(e.target)
        if src == dst:
            continue
        if (e.source.startswith(LAZY_UI[0]) and dst == LAZY_UI[1]) and e.function == LAZY_UI[2]:
            continue
        if dst not in ALLOWED[src]:
            bad.append(f"{e.source}:{e.line} imports {e.target} ({src} -> {dst})")
    assert bad == []


def test_calib_imports_no_simulator_and_no_ui(graph: list[Edge]) -> None:
    assert [e for e in graph if e.source.startswith("calib") and part_of(e.target) != "calib"] == []


def test_every_subpackage_says_what_it_owns() -> None:
    """Each package's ``__init__`` has a docstring that names its modules."""
    import ast

    for name, path in modules().items():
        if path.name != "__init__.py":
            continue
        doc = ast.get_docstring(ast.parse(path.read_text())) or ""
        assert len(doc) > 80 and "TODO" not in doc, f"{name}: no docstring saying what it owns"


def test_the_checker_finds_a_circle_and_an_upward_import() -> None:
    """The checks above can fail: a made-up circle and a made-up upward import are caught."""
    fake = [
        Edge("planner.cell.a", "planner.cell.b", "", 1),
        Edge("planner.cell.b", "planner.cell.a", "f", 2),
    ]
    assert cycles(fake) == [["planner.cell.a", "planner.cell.b"]]
    assert part_of("planner.cell.cell") == "planner.cell"
    assert part_of("planner.check.job") == CHECK
    assert part_of("planner.validate.job") == "planner.validate"
    assert CHECK not in ALLOWED[part_of("planner.cell.cell")]  # the cell may not import a job
    assert "planner.suggest" not in ALLOWED[part_of("planner.validate.job")]  # nor a job another


def test_jobs_are_packages_and_the_top_level_is_small() -> None:
    """Each job is its own package; ``planner/`` holds at most :data:`MAX_TOP_MODULES` modules."""
    planner = Path(__file__).resolve().parents[1] / "planner"
    top = sorted(p.name for p in planner.glob("*.py"))
    assert len(top) <= MAX_TOP_MODULES, top
    for name in ("check", *JOB_NAMES):
        if name != "demo":
            assert (planner / name / "__init__.py").is_file(), name
    known = {f"{m}.py" for m in (*TOP_MODULES, "__init__", "demo")}
    assert set(top) <= known, f"a module of no known layer: {sorted(set(top) - known)}"


#: Modules that may still look for words in a message, and why: neither sorts a feasibility or
#: search outcome, and neither message has a kind to read instead. Each must still do so (a
#: stale entry fails).
READS_WORDS = {
    # msgspec's own validation errors (a library's words) turned into plan-field paths
    "calib.plan.json_io",
    # the layout's messages (the procedures' role_problem, the dry run) name their points and
    # roles in words; the layout problem is not one of the outcomes given a kind, and what is
    # read is which points it names (until planner.check.job.layout_problem returns them)
    "webui.role_check",
}


def test_no_module_sorts_a_reason_by_its_words() -> None:
    """Reasons are sorted by kind (``planner.reasons``): no module outside
    :data:`READS_WORDS` searches, compares, splits or case-folds a reason's text."""
    found = text_sorts()
    bad = [f"{t.module}:{t.line}: {t.code}" for t in found if t.module not in READS_WORDS]
    assert bad == [], "sort reasons by Reason.kind, not by their words"
    assert {t.module for t in found} >= READS_WORDS, "an entry of READS_WORDS no longer applies"


#: Text-sorting code (most of it what the heat map, suggest, the check and the status table
#: did before reasons had kinds): each snippet must be caught.
SORTS_BY_WORDS = (
    'r = reason.lower()\nif "reach" in r or "no ik" in r:\n    pass',
    'def f(status, reason):\n    text = reason.lower()\n    return "hit" in text',
    'about = "out of reach" in reason or "from the surface" in reason',
    'parts = check.reason.split("; ")',
    "note = PART_NOTE.search(reason)",
    'short = PART_NOTE.sub("", reason)',
    're.match(r"^joint \\d", why)',
    'if x.pose_reason.startswith("joint"):\n    pass',
    'if cause.text.endswith("mm)"):\n    pass',
    'if reasons[0] == "singular wrist":\n    pass',
    'if str(p.cause) != "singular wrist":\n    pass',
    'stuck = [p for p, problem in notes.items() if "added" not in problem]',
    'if why in ("singular wrist", "near a singularity"):\n    pass',
    'hit = f"{pair[0]} hits" in message',
    'k = path_reason.find("at ")',
    # validate's failures, keyed by their words: what a reader of the report did before the
    # simulated searches' reasons had kinds
    'missed = {k: v for k, v in report.failures.items() if "no detection" in k}',
    'bad = [label for label in sorted(report.failures) if label.startswith("x-offset")]',
    'for w in reasons:\n    if w.endswith("mm"):\n        pass',
    'for label in failures.keys():\n    if "unreachable" in label.lower():\n        pass',
)
#: Code that reads a reason's kind and pair, or builds its words: none may be caught.
SORTS_BY_KIND = (
    'if cause.kind == "reach":\n    pass',
    'if "table" in reason.pair:\n    pass',
    "counts = {r.kind for r in check.causes}",
    'text = "; ".join(str(r) for r in reasons)',
    'why = f"search path: {path_reason}"',
    "if not reason:\n    pass",
    'if key.endswith("2") or flags.upper(j) > 0 or name.lower() == "x":\n    pass',
    "if p.id in why:\n    pass",
    'label = REJECTED_AS.get(cause.kind, "other")',
    # validate's failures read by kind; a loop over their words that only writes them out
    "kinds = Counter(f.failed.cause.kind for f in report.failure_counts if f.failed)",
    'pairs = [f.failed.cause.pair for f in counts if f.failed.cause.kind == "collision"]',
    'lines = [f"- {k}: {v}" for k, v in sorted(report.failures.items())]',
)


@pytest.mark.parametrize("code", SORTS_BY_WORDS)
def test_the_rule_catches_a_reason_sorted_by_its_words(code: str) -> None:
    assert len(text_sorts_in(ast.parse(code))) >= 1, code


@pytest.mark.parametrize("code", SORTS_BY_KIND)
def test_the_rule_lets_kinds_and_pairs_be_read(code: str) -> None:
    assert text_sorts_in(ast.parse(code)) == [], code


#: ``planner.cell`` by concept (issue 23, item 5), lowest first: a module of one layer imports
#: only modules of its own layer and of those before it. A layer is a subpackage or one of the
#: two modules directly in ``planner/cell/`` (``docs/ARCHITECTURE.md``).
CELL_LAYERS = ("disk_cache", "kernels", "scene", "broad", "probe", "moves", "cell")


def cell_layer(module: str) -> str | None:
    """The layer of a module of ``planner.cell`` (``None``: outside it, or its ``__init__``)."""
    parts = module.split(".")
    if parts[:2] != ["planner", "cell"] or len(parts) < 3:
        return None
    assert parts[2] in CELL_LAYERS, f"{module}: a module of no known layer of planner.cell"
    return parts[2]


def test_cell_layers_import_only_the_layers_below(graph: list[Edge]) -> None:
    bad = []
    for e in graph:
        src, dst = cell_layer(e.source), cell_layer(e.target)
        if src is None or dst is None or src == dst:
            continue
        if CELL_LAYERS.index(dst) > CELL_LAYERS.index(src):
            bad.append(f"{e.source}:{e.line} imports {e.target} ({src} -> {dst})")
    assert bad == []
    cell = Path(__file__).resolve().parents[1] / "planner" / "cell"
    found = {p.stem for p in cell.iterdir() if p.suffix == ".py" or (p / "__init__.py").is_file()}
    assert found - {"__init__"} == set(CELL_LAYERS)


def _public(package: str) -> set[str]:
    """The names in ``__all__`` of ``package``'s ``__init__``, read from the source."""
    tree = ast.parse(modules()[package].read_text())
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(
            isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets
        ):
            return set(ast.literal_eval(node.value))
    raise AssertionError(f"{package}: no __all__")


def test_code_outside_a_cell_subpackage_imports_its_public_names(graph: list[Edge]) -> None:
    """The modules of ``planner.cell``'s subpackages are private: from outside one, code imports
    the subpackage (its ``__all__``), or a module its ``__all__`` names (the kernels')."""
    bad = []
    for e in graph:
        parts = e.target.split(".")
        if parts[:2] != ["planner", "cell"] or len(parts) < 4:
            continue
        package = ".".join(parts[:3])
        if e.source == package or e.source.startswith(package + "."):
            continue
        if parts[3] not in _public(package):
            bad.append(f"{e.source}:{e.line} imports {e.target}, private to {package}")
    assert bad == []


def test_every_public_name_of_a_cell_subpackage_is_there() -> None:
    import importlib

    for name in CELL_LAYERS:
        package = f"planner.cell.{name}"
        if package not in modules() or modules()[package].name != "__init__.py":
            continue
        module = importlib.import_module(package)
        for public in sorted(_public(package)):
            if not hasattr(module, public):
                importlib.import_module(f"{package}.{public}")  # a public module
