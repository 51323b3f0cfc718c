"""Hostile plans and result files never crash wobjcal (issue 27, item 6).

A generator mutates the shipped plans and the measurement files the controllers write back
(types, magnitudes, missing and extra fields, units, ids, truncation, hostile paths), runs the
command line on each mutant in this process, and asserts what a user may rely on whatever they
give it: exit code 0, 1 or 2 only; never ``internal error``, never a traceback; and a bounded
peak of the memory Python and NumPy allocate for the command (``tracemalloc``).

The commands: ``export --no-check`` (plan loading, the layout and the measuring program of every
controller, no cell: fast, so many mutants), ``check --json`` (the cell, few mutants) and
``calibrate`` (measurements in every format the controllers write, against the plate plan).
Hypothesis runs derandomized (``tests/conftest.py``), so the mutants are the same every run.
"""

from __future__ import annotations

import contextlib
import copy
import io
import json
import tempfile
import tracemalloc
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from planner.cli.main import main
from tests.reference_data import plate_case

ROOT = Path(__file__).resolve().parents[1]
PLANS = {
    "plate_321": ROOT / "assets" / "plans" / "plate_holes_321.json",
    "plate_best_fit": ROOT / "assets" / "plans" / "plate_holes_best_fit.json",
    "stator_ah": ROOT / "assets" / "plans" / "stator_section_ah.json",
    "three_two_one": ROOT / "tests" / "data" / "plans" / "valid_three_two_one.json",
}
RESULTS = ROOT / "tests" / "data" / "results"
#: The plan the result samples were made from (``tests/make_results_samples.py``).
RESULTS_PLAN = PLANS["plate_321"]

#: Peak of the memory traced while one command runs: the plate's check needs ~50 MiB, a
#: mutant must not need ten times that (a refused size is refused before any work).
PEAK_BYTES = 512 * 2**20

#: Strings a user (or an attacker) may put where a name, a unit or a path belongs.
HOSTILE_STRINGS = (
    "",
    " ",
    "cm",
    "inch",
    "in",
    "M",
    "m ",
    "mm\n",
    "x" * 300,
    "P1",
    "é✓",
    "../../../../etc/passwd",
    "/etc/passwd",
    "/dev/zero",
    "/nonexistent/part.stl",
    "file:///etc/passwd",
    "package://../x.stl",
    "builtin:nothing",
    "builtin:",
    "NaN",
    "1e400",
)

#: Numbers at the edges: zero, signs, tiny, huge, non-finite, and integers past 64 bits.
EDGE_NUMBERS = st.sampled_from(
    [0, -1, 1e-300, -1e-9, 1e9, 1e300, float("inf"), float("-inf"), float("nan"), 2**64, -(2**70)]
)

#: Any JSON value, of any type, for a field whose type is replaced.
JSON_VALUES = st.recursive(
    st.none()
    | st.booleans()
    | st.integers(min_value=-(2**70), max_value=2**70)
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.sampled_from(HOSTILE_STRINGS),
    lambda inner: (
        st.lists(inner, max_size=4) | st.dictionaries(st.text(max_size=6), inner, max_size=3)
    ),
    max_leaves=6,
)


@dataclass(frozen=True)
class Run:
    """What one command did: exit code, standard error, traced memory peak (bytes)."""

    code: int
    stderr: str
    peak: int


def run_cli(argv: list[str]) -> Run:
    """Run ``wobjcal ARGV`` in this process, its output captured, its memory traced."""
    err, out = io.StringIO(), io.StringIO()
    tracemalloc.start()
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
            code = main(argv)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    return Run(code, err.getvalue(), peak)


def assert_handled(run: Run, what: str) -> None:
    """The contract of every command with any input: a documented exit code and one clear
    message, no crash, bounded memory."""
    assert run.code in (0, 1, 2), f"{what}: exit {run.code}\n{run.stderr}"
    assert "internal error" not in run.stderr, f"{what}:\n{run.stderr}"
    assert "Traceback" not in run.stderr, f"{what}:\n{run.stderr}"
    if run.code == 2:  # a refusal says what was wrong, on one line beginning with the command
        assert "error: " in run.stderr and run.stderr.strip(), f"{what}: exit 2 and no message"
    assert run.peak < PEAK_BYTES, f"{what}: {run.peak / 2**20:.0f} MiB traced"


# --- the mutations ----------------------------------------------------------------------


def _absolute_paths(doc: dict[str, Any], folder: Path) -> dict[str, Any]:
    """``doc`` with its relative file paths made absolute, so the mutant may live elsewhere."""
    doc = copy.deepcopy(doc)
    wobj = doc.get("work_object", {})
    mesh = wobj.get("mesh")
    if isinstance(mesh, str) and not mesh.startswith("builtin:") and not Path(mesh).is_absolute():
        wobj["mesh"] = str((folder / mesh).resolve())
    return doc


def _slots(doc: Any, where: str = "") -> Iterator[tuple[Any, Any, str]]:
    """Every (container, key, path) of a JSON document, depth first, in a fixed order."""
    items: Iterator[tuple[Any, Any]]
    if isinstance(doc, dict):
        items = iter(sorted(doc.items()))
    elif isinstance(doc, list):
        items = enumerate(doc)
    else:
        return
    for key, value in items:
        path = f"{where}/{key}"
        yield doc, key, path
        yield from _slots(value, path)


def _mutate_once(draw: Callable[[Any], Any], doc: Any) -> str:
    """Apply one mutation to ``doc`` in place; return what it did (for the failure message)."""
    slots = list(_slots(doc))
    if not slots:
        return "nothing to mutate"
    container, key, path = draw(st.sampled_from(slots))
    value = container[key]
    op = draw(st.sampled_from(_OPS[_kind(value)]))
    if op == "number":
        new = draw(EDGE_NUMBERS | st.sampled_from([value * 1000, value / 1000, -value, value + 1]))
        container[key] = new
        return f"{path}: {value!r} -> {new!r}"
    if op == "string":
        container[key] = draw(st.sampled_from(HOSTILE_STRINGS))
        return f"{path}: {value!r:.60} -> {container[key]!r:.60}"
    if op == "delete":
        del container[key]
        return f"{path}: deleted"
    if op == "extra":
        name = draw(st.sampled_from(["extra", "units", "id", "position_m", "Name"]))
        value[name] = draw(JSON_VALUES)
        return f"{path}/{name}: added {value[name]!r:.60}"
    if op == "duplicate" and value:
        value.append(copy.deepcopy(value[draw(st.integers(0, len(value) - 1))]))
        return f"{path}: an element repeated"
    if op == "shorten" and value:
        del value[draw(st.integers(0, len(value) - 1)) :]
        return f"{path}: shortened to {len(value)}"
    new = draw(JSON_VALUES)
    container[key] = new
    return f"{path}: {value!r:.60} -> {new!r:.60}"


def _kind(value: Any) -> str:
    if isinstance(value, bool) or value is None:
        return "other"
    if isinstance(value, int | float):
        return "number"
    if isinstance(value, str):
        return "string"
    return "object" if isinstance(value, dict) else "array" if isinstance(value, list) else "other"


#: The mutations that suit a value, the likelier ones repeated: a number is mostly given another
#: magnitude, a string another word, so that mutants get past the type checks into the work.
_OPS = {
    "number": ["number", "number", "number", "type", "delete"],
    "string": ["string", "string", "type", "delete"],
    "object": ["extra", "delete", "type"],
    "array": ["duplicate", "shorten", "delete", "type"],
    "other": ["type", "delete"],
}


@st.composite
def mutated_documents(draw: Callable[[Any], Any], base: dict[str, Any]) -> tuple[str, str]:
    """A JSON text made from ``base`` by 1 to 3 mutations, sometimes truncated; and what was
    done to it."""
    doc = copy.deepcopy(base)
    done = [_mutate_once(draw, doc) for _ in range(draw(st.integers(1, 3)))]
    text = json.dumps(doc, indent=1)  # NaN and Infinity stay as JSON's common extension
    if draw(st.integers(0, 9)) == 0:
        cut = draw(st.integers(len(text) // 2, len(text) - 2))
        text = text[:cut]
        done.append(f"cut at character {cut}")
    return text, "; ".join(done)


def _plan_bases() -> dict[str, dict[str, Any]]:
    return {
        name: _absolute_paths(json.loads(path.read_text()), path.parent)
        for name, path in PLANS.items()
    }


BASE_PLANS = _plan_bases()
PLAN_NAMES = sorted(BASE_PLANS)
#: The bases on built-in parts, and the plate's, whose mesh is in ``../shared/reference``
#: (without it every mutant of theirs is refused for the missing mesh: those cases skip).
BASES = [
    pytest.param([n for n in PLAN_NAMES if not n.startswith("plate")], id="built-in parts"),
    plate_case([n for n in PLAN_NAMES if n.startswith("plate")], id="plate"),
]


@st.composite
def mutated_plans(draw: Callable[[Any], Any], names: list[str]) -> tuple[str, str, str]:
    """(base plan name of ``names``, mutated plan text, what was done)."""
    name = draw(st.sampled_from(names))
    text, done = draw(mutated_documents(BASE_PLANS[name]))
    return name, text, done


def _write(folder: Path, name: str, text: str) -> Path:
    path = folder / name
    path.write_text(text, encoding="utf-8")
    return path


# --- plans --------------------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("names", BASES)
@settings(max_examples=75, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data(), fmt=st.sampled_from(["json", "rapid", "krl", "urscript", "fanuc"]))
def test_a_mutated_plan_exports_or_is_refused_with_a_message(
    names: list[str], data: st.DataObject, fmt: str
) -> None:
    name, text, done = data.draw(mutated_plans(names))
    with tempfile.TemporaryDirectory() as tmp:
        plan = _write(Path(tmp), "plan.json", text)
        out = Path(tmp) / "out"
        run = run_cli(["export", str(plan), "--format", fmt, "--no-check", "-o", str(out)])
        assert_handled(run, f"export --format {fmt} of {name} with {done}")
        if run.code == 0:
            assert any(out.iterdir()) if out.is_dir() else out.is_file(), "exit 0, nothing written"


@pytest.mark.slow
@pytest.mark.parametrize("names", BASES)
@settings(max_examples=4, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())  # a check takes ~3 s; not the stator's A-H (its check is longer)
def test_a_mutated_plan_is_checked_or_refused_with_a_message(
    names: list[str], data: st.DataObject
) -> None:
    name, text, done = data.draw(mutated_plans([n for n in names if n != "stator_ah"]))
    with tempfile.TemporaryDirectory() as tmp:
        plan = _write(Path(tmp), "plan.json", text)
        run = run_cli(["check", str(plan), "--json"])
        assert_handled(run, f"check of {name} with {done}")


# --- measurements and controller result files -------------------------------------------

MEASURED = json.loads((RESULTS / "wobjcal_measured.json").read_text())


@pytest.mark.reference  # without the plate mesh every case is refused for its absence
@pytest.mark.slow
@settings(max_examples=120, suppress_health_check=[HealthCheck.too_slow])
@given(case=mutated_documents(MEASURED))
def test_mutated_measurements_calibrate_or_are_refused(case: tuple[str, str]) -> None:
    text, done = case
    with tempfile.TemporaryDirectory() as tmp:
        meas = _write(Path(tmp), "measured.json", text)
        run = run_cli(["calibrate", str(RESULTS_PLAN), str(meas), "--json"])
        assert_handled(run, f"calibrate with measurements {done}")


#: The text files the controllers write (``--from`` and the file's name).
TEXT_RESULTS = {
    "krl": ("WOBJCALPLATEHOLES321.dat", (RESULTS / "WOBJCALPLATEHOLES321.dat").read_text()),
    "urscript": ("log_history.txt", (RESULTS / "log_history.txt").read_text()),
    "fanuc": ("POSREG.VA", (RESULTS / "fanuc" / "POSREG.VA").read_text()),
}
FANUC_NUMREG = (RESULTS / "fanuc" / "NUMREG.VA").read_text()

#: Tokens that replace a number or a word in a line of a controller's file.
HOSTILE_TOKENS = st.sampled_from(
    ["", "-", "1e999", "nan", "-0", "9" * 40, "0x1F", "{", "}", ",", "=", "P1", "end", "é"]
)


@st.composite
def mutated_text(draw: Callable[[Any], Any], text: str) -> tuple[str, str]:
    """``text`` with 1 to 3 line mutations: deleted, repeated, swapped, cut, or one
    whitespace- or comma-separated token replaced."""
    lines = text.splitlines()
    done = []
    for _ in range(draw(st.integers(1, 3))):
        if not lines:
            break
        i = draw(st.integers(0, len(lines) - 1))
        op = draw(st.sampled_from(["delete", "repeat", "swap", "cut", "token", "token"]))
        if op == "delete":
            del lines[i]
        elif op == "repeat":
            lines.insert(i, lines[i])
        elif op == "swap":
            j = draw(st.integers(0, len(lines) - 1))
            lines[i], lines[j] = lines[j], lines[i]
        elif op == "cut":
            lines[i] = lines[i][: draw(st.integers(0, len(lines[i])))]
            del lines[i + 1 :]
        else:
            tokens = lines[i].replace(",", " , ").split(" ")
            k = draw(st.integers(0, len(tokens) - 1))
            tokens[k] = draw(HOSTILE_TOKENS)
            lines[i] = " ".join(tokens).replace(" , ", ",")
        done.append(f"{op} line {i + 1}")
    return "\n".join(lines) + "\n", "; ".join(done)


@st.composite
def mutated_results(draw: Callable[[Any], Any]) -> tuple[str, str, str, str]:
    """(format, file name, mutated text, what was done)."""
    fmt = draw(st.sampled_from(sorted(TEXT_RESULTS)))
    name, text = TEXT_RESULTS[fmt]
    mutant, done = draw(mutated_text(text))
    return fmt, name, mutant, done


@pytest.mark.reference  # without the plate mesh every case is refused for its absence
@pytest.mark.slow
@settings(max_examples=60, suppress_health_check=[HealthCheck.too_slow])
@given(case=mutated_results())
def test_mutated_controller_files_calibrate_or_are_refused(case: tuple[str, str, str, str]) -> None:
    fmt, name, text, done = case
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        files = [_write(folder, name, text)]
        if fmt == "fanuc":
            files.append(_write(folder, "NUMREG.VA", FANUC_NUMREG))
        run = run_cli(["calibrate", str(RESULTS_PLAN), *map(str, files), "--from", fmt, "--json"])
        assert_handled(run, f"calibrate --from {fmt} with {name}: {done}")


@pytest.mark.reference
@pytest.mark.slow
def test_the_unmutated_inputs_pass() -> None:
    """The generator's bases are valid: a mutant's refusal is the mutation's doing."""
    with tempfile.TemporaryDirectory() as tmp:
        for name, doc in BASE_PLANS.items():
            plan = _write(Path(tmp), f"{name}.json", json.dumps(doc))
            run = run_cli(["export", str(plan), "--format", "json", "--no-check", "-o", tmp])
            assert run.code == 0, f"{name}: {run.stderr}"
        meas = _write(Path(tmp), "m.json", json.dumps(MEASURED))
        assert run_cli(["calibrate", str(RESULTS_PLAN), str(meas)]).code == 0
        for fmt, (name, text) in TEXT_RESULTS.items():
            files = [_write(Path(tmp), name, text)]
            if fmt == "fanuc":
                files.append(_write(Path(tmp), "NUMREG.VA", FANUC_NUMREG))
            run = run_cli(["calibrate", str(RESULTS_PLAN), *map(str, files), "--from", fmt])
            assert run.code == 0, f"{fmt}: {run.stderr}"


@pytest.mark.parametrize(
    "run",
    [
        Run(3, "", 0),
        Run(2, "wobjcal check: internal error: KeyError: 'x' (run again with --debug ...)", 0),
        Run(0, "Traceback (most recent call last):", 0),
        Run(2, "", 0),
        Run(0, "", PEAK_BYTES),
    ],
    ids=["exit 3", "internal error", "traceback", "silent refusal", "memory"],
)
def test_the_contract_rejects_a_crash(run: Run) -> None:
    """What the properties assert can fail: each way of breaking the contract is caught."""
    with pytest.raises(AssertionError):
        assert_handled(run, "a crash")
