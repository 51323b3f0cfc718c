"""The same refusal everywhere (issue item 4): every format refuses an infeasible plan with exit 1
naming each refused point, ``--force`` writes every format (FANUC included: a target without a
checked pose keeps the robot's configuration, as KRL without S and T), file names come from the
plan's name (command line and UI), and every program header says what was checked, by which
wobjcal version, for which plan (its name and digest).

One mutated plate plan (P1 moved 1 m out of reach: no pose at all; S1's overtravel cut to
0.5 mm: a pose, but a search that may stop short of the part) is checked in one cell shared by
every export here: ``wobjcal export`` opens it through ``planner.export_plan.job.open_cell``.
"""

from __future__ import annotations

import contextlib
import json
import re
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from calib._version import __version__
from calib.plan.file import Plan, load_plan, plan_digest
from planner.cli.main import main
from planner.export import FORMATS, export_file_stem, export_files
from planner.export.job import CheckStatus, ToolData, build_job
from planner.export.text import file_stem

#: every test here runs a shipped plate plan, whose mesh is in ../shared/reference
pytestmark = pytest.mark.reference

PLANS = Path(__file__).resolve().parents[3] / "assets" / "plans"
NAME = "plate refused 1"
#: The points check refuses, per format: the adaptive programs P1 and S1; the nominal FANUC
#: program also S2 and T1, which land off the 12.7 mm side faces (tests/test_one_verdict.py).
REFUSED = {"rapid": ["P1", "S1"], "krl": ["P1", "S1"], "urscript": ["P1", "S1"]}
REFUSED["fanuc"] = ["P1", "S1", "S2", "T1"]
#: What the command line names the files of the plan ``NAME``: after the plan's name, KRL and
#: FANUC after the program's name (their controllers want the file named as the program).
FILES = {
    "rapid": ["plate_refused_1.mod"],
    "krl": ["WobjcalPlateRefused1.src", "WobjcalPlateRefused1.dat"],
    "urscript": ["plate_refused_1.script"],
    "fanuc": ["WOBJCALPLATEREFUSED1.ls"],
    "json": ["plate_refused_1.json"],
}


def _infeasible(folder: Path) -> Path:
    raw = json.loads((PLANS / "plate_holes_321.json").read_text())
    raw["name"] = NAME
    mesh = raw["work_object"]["mesh"]
    raw["work_object"]["mesh"] = str((PLANS / mesh).resolve())
    points = {p["id"]: p for p in raw["points"]}
    points["P1"]["position_m"][0] += 1.0  # 2.09 m from the shoulder, reach 1.89 m
    points["S1"]["search"]["overtravel_m"] = 0.0005
    path = folder / "refused.json"
    path.write_text(json.dumps(raw, indent=2))
    return path


@pytest.fixture(scope="module")
def infeasible(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Path, Plan, Any]]:
    """The plan file, the plan, and its open cell, which ``wobjcal export`` uses here."""
    from planner.plan_cell import open_cell

    path = _infeasible(tmp_path_factory.mktemp("plan"))
    plan = load_plan(path)
    with open_cell(plan, path.parent) as cell, pytest.MonkeyPatch.context() as mp:

        @contextlib.contextmanager
        def shared(*_: Any) -> Iterator[Any]:
            yield cell

        mp.setattr("planner.export_plan.job.open_cell", shared)
        yield path, plan, cell


#: A comment line of each language; group 1 its text.
COMMENT = {
    "rapid": r"^ *! ?(.*)$",
    "krl": r"^ *; ?(.*)$",
    "urscript": r"^ *# ?(.*)$",
    "fanuc": r"^ *\d+: *!(.*) ;$",
}


def _comments(text: str, fmt: str) -> str:
    """The program's comment text, its lines joined with single spaces (every writer wraps
    its comments; FANUC's at 32 characters)."""
    return " ".join(" ".join(re.findall(COMMENT[fmt], text, re.M)).split())


def _said(text: str, fmt: str) -> str:
    """``text`` as the writer of ``fmt`` words a comment (FANUC: TP comment characters)."""
    if fmt == "fanuc":
        from planner.export.fanuc_text import comment_lines

        return " ".join(comment_lines(text))
    return text


@pytest.mark.slow
@pytest.mark.parametrize("fmt", list(FORMATS))
def test_every_format_refuses_naming_each_point(
    fmt: str,
    infeasible: tuple[Path, Plan, Any],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """Before: RAPID, KRL and URScript exit 1 naming the points; FANUC exit 2 with 'no checked
    robot pose at its safe target', with or without --force."""
    path, _, _ = infeasible
    assert main(["export", str(path), "--format", fmt, "-o", str(tmp_path)]) == 1
    err = capsys.readouterr().err
    for pid in REFUSED[fmt]:
        assert f"error: point {pid} is not feasible: " in err, (pid, err)
    assert len(re.findall(r"^error: point ", err, re.M)) == len(REFUSED[fmt])
    assert "nothing written; fix the plan, or export anyway with --force" in err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("fmt", list(FORMATS))
def test_force_writes_every_format_and_its_header_says_not_checked(
    fmt: str,
    infeasible: tuple[Path, Plan, Any],
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    path, plan, _ = infeasible
    code = main(["export", str(path), "--format", fmt, "-o", str(tmp_path), "--force"])
    assert code == 0, capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(FILES[fmt])
    digest = plan_digest(plan)
    for name in FILES[fmt]:
        text = (tmp_path / name).read_text()
        head = _comments(text, fmt)
        assert f"wobjcal {__version__}" in head and NAME in head, name
        assert re.findall(r"plan digest ([0-9a-f]{16})", text)[:1] == [digest], name
        ids = ", ".join(REFUSED[fmt])
        assert _said("NOT CHECKED: exported with --force", fmt) in head, name
        assert _said(f"wobjcal check refuses points {ids}", fmt) in head, (name, head[:600])
        # and why, point by point (what "Export anyway" in the UI writes too)
        first = REFUSED[fmt][0]
        assert _said(f"({first}: ", fmt).split()[0] in head, (name, head[:900])
    if fmt == "fanuc":  # P1 has no checked pose: its targets keep the robot's configuration
        text = _comments((tmp_path / FILES[fmt][0]).read_text(), fmt)
        assert "NO CONFIG for points P1 (no checked robot pose)" in text
    if fmt == "krl":  # no S and T for P1, as before
        assert "No S and T for points P1" in (tmp_path / FILES[fmt][0]).read_text()


def test_the_krl_data_list_names_the_digest_on_one_line(
    infeasible: tuple[Path, Plan, Any], tmp_path: Path
) -> None:
    """A results reader looks for ``plan digest ([0-9a-f]{16})`` in the KRL .dat."""
    path, plan, _ = infeasible
    assert main(["export", str(path), "--format", "krl", "-o", str(tmp_path), "--force"]) == 0
    dat = (tmp_path / "WobjcalPlateRefused1.dat").read_text().splitlines()
    assert dat[3].startswith(f"; Generated by wobjcal {__version__} from plan '{NAME}'")
    assert re.search(r"plan digest ([0-9a-f]{16})", dat[3])[1] == plan_digest(plan)  # type: ignore[index]


def test_file_names_follow_the_plan_name(
    infeasible: tuple[Path, Plan, Any],
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """-o DIR (existing, or ending in /: made) and no -o (the current folder) name the files
    after the plan; -o FILE keeps the user's name."""
    path, _, _ = infeasible
    new = tmp_path / "new"
    assert main(["export", str(path), "--format", "json", "-o", f"{new}/"]) == 0
    assert [p.name for p in new.iterdir()] == FILES["json"]
    here = tmp_path / "here"
    here.mkdir()
    monkeypatch.chdir(here)
    assert main(["export", str(path), "--format", "urscript", "--force"]) == 0
    assert [p.name for p in here.iterdir()] == FILES["urscript"]
    assert main(["export", str(path), "--format", "krl", "--force", "-o", "mine.src"]) == 0
    assert {"mine.src", "mine.dat"} <= {p.name for p in here.iterdir()}
    capsys.readouterr()
    # names a file system takes, and a fallback
    assert file_stem("a/b c:d") == "a_b_c_d" and file_stem("../x.") == "_x"
    assert file_stem("") == file_stem("...") == "wobjcal_plan"
    assert export_file_stem("", "rapid") == "wobjcal_plan"
    assert export_file_stem("", "fanuc") == "WOBJCALPLAN"


@pytest.mark.slow
def test_ui_downloads_are_named_after_the_plan_and_say_not_checked(
    infeasible: tuple[Path, Plan, Any],
) -> None:
    """The UI's downloads of this plan (not the demo's) are named as the command line names
    them, and their headers say what check refuses."""
    from webui.exports import FORMATS as UI_FORMATS
    from webui.exports import export_program

    path, plan, cell = infeasible
    for label, fmt in UI_FORMATS.items():
        result = export_program(plan, label, path.parent, cell)
        assert [name for name, _ in result.files] == FILES[fmt]
        text = _comments(result.files[0][1].decode(), fmt)
        assert "NOT CHECKED" in text and f"plan digest {plan_digest(plan)}" in text
        assert "P1" in result.note


@pytest.mark.parametrize("fmt", list(FORMATS))
def test_headers_say_checked_or_built_without_a_check(fmt: str) -> None:
    """Every header: CHECKED with the points and controller when check passed; without a
    check, NOT CHECKED and what to run (no cell needed: the job's check status)."""
    plan = load_plan(PLANS / "plate_holes_best_fit.json")
    job = build_job(plan, np.eye(4), ToolData(T_flange_tcp=np.eye(4)))
    passed = build_job(
        plan, np.eye(4), ToolData(T_flange_tcp=np.eye(4)), check=CheckStatus(checked=True)
    )
    label = {"rapid": "ABB RAPID", "krl": "KUKA KRL", "urscript": "Universal Robots URScript"}
    label["fanuc"] = "FANUC TP"
    for j, want in (
        (
            job,
            f"NOT CHECKED: built without a cell check (wobjcal export --no-check, or a job "
            f"made in code): run wobjcal check --format {fmt} on the plan before the first run.",
        ),
        (
            passed,
            "CHECKED: wobjcal check passed for this program in the plan's cell "
            f"({len(plan.points)} points, controller {label[fmt]}).",
        ),
    ):
        files = export_files(j, fmt)
        for text in files.values():
            head = _comments(text, fmt).replace("`", "")
            assert _said(want, fmt) in head, (fmt, head[:800])
            assert f"plan digest {plan_digest(plan)}" in text and f"wobjcal {__version__}" in head
