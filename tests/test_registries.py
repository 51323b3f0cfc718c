"""Contract tests over every entry of every registry.

- Every registry answers an unknown name the same way (:func:`calib.registry.lookup`):
  ``unknown <what> '<name>'; known: a, b``, naming the field or option, also where a caller
  checks a name before the registry does (suggest's ``--procedure``, the UI's procedure, sensor
  kind and download); every entry is reachable by its own name.
- Every plug-in an entry names (``"module:attribute"``) loads the one way,
  :func:`calib.registry.load`.
- Every procedure validates (a few trials on a shipped plan of it, or on the plate grown into
  it); every procedure with a layout design is suggested (on the plate, small) and gets points
  with its roles; its steering's last update fits every point.
- Every export format's paste lines parse with the language's grammar or interpreter in the
  tests and give back the calibrated frame's numbers.
- Every built-in part loads (mesh, and its exact geometry where it has one).
"""

from __future__ import annotations

import re
import sys
from collections.abc import Callable
from pathlib import Path

import msgspec
import numpy as np
import pytest

from calib.errors import InputError, PlanError
from calib.frames import (
    make_transform,
    matrix_from_quat_wxyz,
    matrix_from_tait_bryan_zyx,
)
from calib.plan.file import Plan, load_plan
from calib.procedures import DESIGNED, PROCEDURES, procedure_kind
from calib.registry import load, lookup
from planner.builtins import (
    BUILTIN_PARTS,
    BUILTIN_ROBOTS,
    BUILTIN_TOOLS,
    builtin_geometry,
    builtin_mesh,
    builtin_part,
    robot_urdf,
    tool_description,
)
from planner.errors import UnknownBuiltinError
from planner.export import FORMATS, export_files
from planner.export.paste import PasteLines
from planner.program.controllers import CONTROLLERS, controller
from planner.program.steering import STEERED_METHODS, update_groups
from planner.sim.sensors import SENSORS

PLANS = Path(__file__).resolve().parent.parent / "assets" / "plans"
ONE_ERROR = re.compile(r"^unknown [\w\- ]+( \([\w.\- ]+\))? '(builtin:)?nope'; known: [\w:, ]+$")


def _suggest_unknown() -> None:
    from planner.suggest.job import designed_procedure

    designed_procedure("nope")


def _ui_procedure() -> None:
    from webui.plan_adapter import ui_plan_from_plan, with_procedure

    with_procedure(
        ui_plan_from_plan(load_plan(PLANS / "plate_holes_321.json", check_files=False)), "nope"
    )


def _ui_sensor() -> None:
    from webui.cell_setup_edits import SensorFields, with_sensor
    from webui.plan_adapter import ui_plan_from_plan

    ui = ui_plan_from_plan(load_plan(PLANS / "plate_holes_321.json", check_files=False))
    with_sensor(ui, SensorFields("nope", 18.0, 8.0, 0.04, None))


def _ui_download() -> None:
    from webui.exports import export_program

    export_program(load_plan(PLANS / "plate_holes_321.json", check_files=False), "nope", PLANS)


@pytest.mark.parametrize(
    ("ask", "error"),
    [
        (lambda: procedure_kind("nope"), PlanError),
        (lambda: controller("nope"), InputError),
        (lambda: export_files(None, "nope"), InputError),  # type: ignore[arg-type]
        (lambda: lookup(SENSORS, "nope", "sensor simulator (validation.sensor.kind)"), InputError),
        (lambda: robot_urdf("builtin:nope"), UnknownBuiltinError),
        (lambda: tool_description("builtin:nope"), UnknownBuiltinError),
        (lambda: builtin_part("builtin:nope"), UnknownBuiltinError),
        (lambda: builtin_mesh("builtin:nope"), UnknownBuiltinError),
        pytest.param(_suggest_unknown, InputError, marks=pytest.mark.slow),  # imports suggest
        (_ui_procedure, PlanError),
        (_ui_sensor, InputError),
        (_ui_download, InputError),
    ],
    ids=[
        "procedure",
        "controller",
        "format",
        "sensor",
        "robot",
        "tool",
        "part",
        "part mesh",
        "suggest procedure",
        "ui procedure",
        "ui sensor kind",
        "ui download",
    ],
)
def test_an_unknown_name_gets_the_one_error(ask: Callable[[], object], error: type) -> None:
    with pytest.raises(error) as info:
        ask()
    assert ONE_ERROR.match(str(info.value)), str(info.value)


def test_every_entry_is_found_by_its_name() -> None:
    for registry in (PROCEDURES, CONTROLLERS, FORMATS, SENSORS):
        for name, entry in registry.items():
            assert lookup(registry, name, "entry") is entry
    assert {n for n in PROCEDURES} == {procedure_kind(n).method for n in PROCEDURES}
    assert {controller(n).name for n in CONTROLLERS} == set(CONTROLLERS)
    assert set(FORMATS) <= set(CONTROLLERS)
    for name in BUILTIN_ROBOTS:
        assert robot_urdf(f"builtin:{name}").is_file()
    for name in BUILTIN_TOOLS:
        assert tool_description(f"builtin:{name}").is_file()
    for name, part in BUILTIN_PARTS.items():
        assert builtin_part(f"builtin:{name}") is part is builtin_part(name)


def test_every_plug_in_loads_the_one_way() -> None:
    """Every ``"module:attribute"`` an entry names resolves through :func:`load`, to what the
    entry's own loader returns."""
    for f in FORMATS.values():
        assert callable(load(f.writer)) and load(f.writer) is f.load()
        assert callable(load(f.paste))
        if f.program_name:
            assert callable(load(f.program_name))
    for s in SENSORS.values():
        assert load(s.simulator) is s.load()
    for p in BUILTIN_PARTS.values():
        assert callable(load(p.mesh))
        if p.geometry:
            assert callable(load(p.geometry))
    with pytest.raises(ValueError, match="module:attribute"):
        load("no colon")


# ---------------------------------------------------------------- procedures


def _shipped() -> dict[str, Plan]:
    """The shipped plans by their procedure (the first of each)."""
    out: dict[str, Plan] = {}
    for path in sorted(PLANS.glob("*.json")):
        plan = load_plan(path)
        out.setdefault(plan.method, plan)
    return out


def _plan_of(method: str) -> Plan:
    """A plan of ``method``: a shipped one, else the plate's best fit grown into it (a procedure
    whose layout grows); a procedure with neither must ship a plan."""
    from planner.suggest import as_procedure

    shipped = _shipped()
    if method in shipped:
        return shipped[method]
    kind = PROCEDURES[method]
    if kind.design is not None and kind.design.grows:
        return as_procedure(load_plan(PLANS / "plate_holes_best_fit.json"), kind)
    pytest.fail(f"no plan to validate {method} with: ship one in assets/plans")


@pytest.mark.reference
@pytest.mark.slow
@pytest.mark.parametrize("method", list(PROCEDURES))
def test_every_procedure_validates(method: str) -> None:
    """A few trials of a plan of every procedure; the published table beside the built-in
    part's rows where the entry has one."""
    from planner.validate.job import validate_plan

    plan = _plan_of(method)
    report = validate_plan(plan, trials=4, seed=1, workers=1, plan_dir=PLANS)
    assert report.rows and all(np.isfinite(r.procedure) for r in report.rows)
    published = PROCEDURES[method].published
    shown = {(r.key, r.level_percent) for r in report.rows if np.isfinite(r.paper)}
    exact = plan.work_object.mesh_pose is None and builtin_geometry(plan.work_object.mesh)
    if published is not None and exact:
        assert shown and shown <= set(published)
    else:
        assert not shown


@pytest.fixture(scope="module")
def plate_cell():  # type: ignore[no-untyped-def]
    """The plate's best-fit plan with a tight misplacement bound (a layout for a nominal
    program too) and its open cell."""
    from planner.plan_cell import open_cell

    plan = load_plan(PLANS / "plate_holes_best_fit.json")
    tight = msgspec.structs.replace(
        plan.validation.misplacement, max_translation_m=0.001, max_angle_rad=np.radians(0.3)
    )
    plan = msgspec.structs.replace(
        plan, validation=msgspec.structs.replace(plan.validation, misplacement=tight)
    )
    with open_cell(plan, PLANS) as cell:
        yield plan, cell


@pytest.mark.reference
@pytest.mark.slow
@pytest.mark.parametrize("method", list(DESIGNED))
def test_every_designed_procedure_is_suggested(method: str, plate_cell) -> None:  # type: ignore[no-untyped-def]
    """suggest designs for every procedure whose entry has a layout design, through that
    design only: the plan written is of that procedure, its roles complete."""
    from planner.suggest import suggest_plan

    plan, cell = plate_cell
    kind = PROCEDURES[method]
    assert kind.design is not None
    res = suggest_plan(plan, PLANS, max_points=6, procedure=method, per_face=12, cell=cell)
    roles = [p.role for p in res.plan.points]
    assert res.plan.method == method
    assert kind.role_problem(roles, complete=True) == ""
    assert len(roles) == (kind.design.n_points or 6)
    assert set(roles) <= set(kind.roles)


def test_procedure_entries_are_consistent() -> None:
    """A design's roles are the procedure's and fill its limits; a steered program's last
    update fits every point; only steered procedures are steered."""
    for method, kind in PROCEDURES.items():
        d = kind.design
        if d is not None:
            n = d.n_points or 6
            roles = d.roles_of([c for _, c in d.face_roles for _ in range(c)] or [1] * n)
            assert kind.role_problem(roles, complete=True) == "", method
        if kind.steering is not None:
            n = (d.n_points if d is not None else None) or 6
            ids = [f"p{i}" for i in range(n)]
            groups = update_groups(method, ids)
            assert groups and groups[-1] == tuple(ids), method
            assert method in STEERED_METHODS
        else:
            assert update_groups(method, ["a"] * 6) == [] and method not in STEERED_METHODS
        assert kind.edge_rows in ("both", "edge"), method


@pytest.mark.parametrize("method", [m for m, k in PROCEDURES.items() if k.edge_rows == "edge"])
def test_a_procedure_that_counts_edge_coordinates_only_ignores_the_track_height(
    method: str,
) -> None:
    """``edge_rows == "edge"`` is what its ``estimate`` does: moving an edge search's recorded
    point across the face it slides over (the commanded track height) changes no frame."""
    from calib.frames import make_transform, transform_points
    from calib.paper.stator_layout import example_stator_points
    from calib.procedures import RolePoint

    kind = PROCEDURES[method]
    pts = list(example_stator_points().values())
    T = make_transform(None, [1.0, 0.2, 0.5])
    measured = {p.id: transform_points(T, p.position_m)[None] for p in pts}
    edge = next(p for p in pts if p.search.kind == "edge")
    moved = dict(measured)
    moved[edge.id] = measured[edge.id] + 0.002 * np.asarray(edge.normal)  # T has no rotation
    settings = kind.settings_type()
    rp = [RolePoint("fit", p) for p in pts]
    a = kind.estimate(rp, measured, T, settings).T_base_wobj
    b = kind.estimate(rp, moved, T, settings).T_base_wobj
    assert np.abs(a - b).max() < 1e-12, method


# ---------------------------------------------------------------- paste lines


T_CAL = make_transform(
    matrix_from_tait_bryan_zyx(*np.radians([23.5, -14.25, 171.125])), [1.0234, -0.4987, 0.9514]
)


def _rapid(p: PasteLines) -> np.ndarray:
    from tests.rapid_grammar import rapid_errors

    (line,) = p.lines
    assert rapid_errors(f"MODULE WobjcalPaste\n    {line}\nENDMODULE\n") == []
    m = re.fullmatch(r'PERS wobjdata \w+:=\[FALSE,TRUE,"",\[\[(.*?)\],\[(.*?)\]\],.*\];', line)
    assert m, line
    xyz = np.array([float(v) for v in m.group(1).split(",")]) / 1000.0
    q = np.array([float(v) for v in m.group(2).split(",")])
    return make_transform(matrix_from_quat_wxyz(q), xyz)


def _krl(p: PasteLines) -> np.ndarray:
    from tests.krl_grammar import krl_errors

    (line,) = p.lines
    assert krl_errors(f"DEFDAT wobjcal_paste\n{line}\nENDDAT\n") == []
    assert krl_errors(f"DEF wobjcal_paste()\n  {line}\nEND\n") == []
    m = re.fullmatch(r"BASE_DATA\[\d+\]=\{X (.*),Y (.*),Z (.*),A (.*),B (.*),C (.*)\}", line)
    assert m, line
    v = np.array([float(x) for x in m.groups()])
    return make_transform(matrix_from_tait_bryan_zyx(*np.radians(v[3:])), v[:3] / 1000.0)


def _urscript(p: PasteLines) -> np.ndarray:
    from tests.urscript_interp import UrMachine

    (line,) = p.lines
    name = line.split("=")[0].strip()
    machine = UrMachine(f"def paste():\n  {line}\n  textmsg({name})\nend\n", lambda *a: "none")
    machine.run()
    pose = machine.globals[name]
    return np.asarray(pose.matrix())


def _fanuc(p: PasteLines) -> np.ndarray:
    from tests.fanuc_interp import TPMachine

    body = [line.removesuffix(" ;") for line in p.lines]
    assert all(line.endswith(" ;") for line in p.lines)
    mn = "\n".join(f"{i:4d}:  {line} ;" for i, line in enumerate(body, start=1))
    text = f"/PROG  WOBJCAL_PASTE\n/ATTR\nLINE_COUNT\t= {len(body)};\n/MN\n{mn}\n/POS\n/END\n"
    machine = TPMachine(text, lambda *a: "none").run()
    (uf,) = [n for n in machine.uframe if n]
    return machine.uframe[uf]


#: Each format's reader of its paste lines: the language's grammar (RAPID, KRL) or the tests'
#: interpreter (URScript, FANUC TP), then the frame the lines give.
READERS: dict[str, Callable[[PasteLines], np.ndarray]] = {
    "rapid": _rapid,
    "krl": _krl,
    "urscript": _urscript,
    "fanuc": _fanuc,
}
#: The module (of the project's test extras) a format's reader needs beyond the tests' own
#: code: without it only that format's case is skipped.
READER_NEEDS: dict[str, str] = {"rapid": "rapidchecker", "krl": "antlr4"}


def test_every_format_has_a_reader() -> None:
    assert set(READERS) == set(FORMATS), "a new export format brings its paste-line reader"


@pytest.mark.parametrize("fmt", list(FORMATS))
def test_the_paste_lines_parse_and_give_the_frame(fmt: str) -> None:
    if fmt in READER_NEEDS:
        pytest.importorskip(READER_NEEDS[fmt])
    paste = FORMATS[fmt].paste_lines(T_CAL)
    assert paste.where and paste.lines
    T = READERS[fmt](paste)
    np.testing.assert_allclose(T[:3, 3], T_CAL[:3, 3], atol=1e-6)  # 0.001 mm
    np.testing.assert_allclose(T[:3, :3], T_CAL[:3, :3], atol=1e-6)  # about 6e-5 deg


@pytest.mark.parametrize("fmt", list(FORMATS))
def test_a_format_s_paste_lines_need_only_its_own_reader(
    fmt: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Without the other formats' checkers (as if not installed) a format's case still runs;
    without its own it is skipped (once, every format's case hung on rapidchecker)."""
    own = READER_NEEDS.get(fmt)
    if own is not None:
        pytest.importorskip(own)
    for other in set(READER_NEEDS.values()) - {own}:
        monkeypatch.setitem(sys.modules, other, None)  # its import now fails
    try:
        test_the_paste_lines_parse_and_give_the_frame(fmt)
    except pytest.skip.Exception as exc:
        pytest.fail(f"{fmt}: skipped without another format's checker: {exc}")
    if own is not None:
        monkeypatch.setitem(sys.modules, own, None)
        with pytest.raises(pytest.skip.Exception, match=own):
            test_the_paste_lines_parse_and_give_the_frame(fmt)


# ---------------------------------------------------------------- built-in parts


@pytest.mark.parametrize("name", sorted(BUILTIN_PARTS))
def test_every_builtin_part_loads(name: str) -> None:
    mesh = builtin_mesh(f"builtin:{name}")
    assert len(mesh.faces) and mesh.is_watertight and np.isfinite(mesh.vertices).all()
    geometry = builtin_geometry(f"builtin:{name}")
    assert (geometry is None) == (not BUILTIN_PARTS[name].geometry)
    if geometry is not None:  # the validation's true part: the same part as the mesh
        from planner.parts.stator_mesh import build_stator_mesh

        np.testing.assert_allclose(build_stator_mesh(geometry).bounds, mesh.bounds, atol=1e-9)
    assert builtin_geometry("part.stl") is None
