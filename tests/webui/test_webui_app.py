"""The UI app on the server side, without a browser: clicks, edits, undo, files, autosave."""

from __future__ import annotations

import json
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from calib.frames import transform_points
from calib.plan.file import plan_from_json
from webui.app import WobjcalApp
from webui.server import run
from webui.testing import T_WORLD_WOBJ_BOX, box_plan, free_port


@pytest.fixture(scope="module")
def app(tmp_path_factory: pytest.TempPathFactory) -> Iterator[WobjcalApp]:
    folder = tmp_path_factory.mktemp("app")
    a = run(box_plan(folder), port=free_port(), block=False, autosave_path=folder / "auto.json")
    a.files_panel.upload_dir = folder / "uploads"
    yield a
    a.stop()


def _ray_to(p_wobj: list[float]) -> tuple[np.ndarray, np.ndarray]:
    target = transform_points(T_WORLD_WOBJ_BOX, p_wobj)
    origin = target + np.array([0.3, -0.2, 1.0])
    return origin, target - origin


@pytest.mark.slow
def test_click_places_point_checks_it_and_autosaves(app: WobjcalApp) -> None:
    check = app.place_at_ray(*_ray_to([0.1, 0.05, 0.0]), point_id="A")
    assert check is not None and check.point_id == "A"
    assert check.status in {"feasible", "marginal", "infeasible"}
    a = app.state.doc.get("A")
    np.testing.assert_allclose(a.probe.position_m, [0.1, 0.05, 0.0], atol=1e-9)
    np.testing.assert_allclose(a.probe.normal, [0, 0, 1], atol=1e-12)
    saved = json.loads(app.state.autosave_path.read_text())  # type: ignore[union-attr]
    assert "A" in [p["id"] for p in saved["points"]]
    assert app.selected == "A" and "| A |" in app.points_panel.status_md.content


def test_miss_is_a_clear_error_and_changes_nothing(app: WobjcalApp) -> None:
    before = app.state.doc
    with pytest.raises(ValueError, match="missed the work object"):
        app.place_at_ray([10.0, 10.0, 10.0], [0.0, 0.0, 1.0])
    assert app.state.doc is before


def test_undo_redo_restore_points_and_checks(app: WobjcalApp) -> None:
    app.place_at_ray(*_ray_to([-0.1, 0.0, 0.0]), point_id="B")
    app.move_point_to("B", [-0.12, 0.02, 0.05])  # above the face: projected onto it
    np.testing.assert_allclose(
        app.state.doc.get("B").probe.position_m, [-0.12, 0.02, 0.0], atol=1e-12
    )
    app.state.undo()
    np.testing.assert_allclose(app.state.doc.get("B").probe.position_m, [-0.1, 0, 0], atol=1e-12)
    assert app.check_of("B") is not None, "undo re-checks the restored point"
    app.state.undo()
    assert "B" not in app.state.doc.ids and app.check_of("B") is None
    app.state.redo()
    assert "B" in app.state.doc.ids


def test_undo_and_redo_bring_back_the_checks_shown_without_checking_again(
    app: WobjcalApp, monkeypatch: pytest.MonkeyPatch
) -> None:
    """An undo or redo makes a plan current again: each point's check as it was shown in that
    very plan comes back with it (``webui.doc_memo``); an edit to a new place is checked."""
    from webui import plan_doc
    from webui.backend import CellSession

    app.place_at_ray(*_ray_to([0.05, -0.1, 0.0]), point_id="U")
    placed = app.check_of("U")
    app.move_point_to("U", [0.0, -0.05, 0.0])
    moved = app.check_of("U")
    assert placed is not None and moved is not None and moved is not placed
    checked: list[list[str]] = []
    check_points = CellSession.check_points

    def counted(self: CellSession, points: list, plan: object = None) -> list:
        checked.append([p.id for p in points])
        return check_points(self, points, plan)  # type: ignore[arg-type]

    monkeypatch.setattr(CellSession, "check_points", counted)
    app.state.undo()
    assert app.check_of("U") is placed and checked == []
    app.state.redo()
    assert app.check_of("U") is moved and checked == []
    assert "| U |" in app.points_panel.status_md.content
    app.move_point_to("U", [0.02, -0.05, 0.0])
    assert checked == [["U"]] and app.check_of("U") is not None
    app.state.update(lambda d: plan_doc.delete_point(d, "U"), "delete U")


def test_plan_download_is_the_strict_plan(app: WobjcalApp) -> None:
    from webui import plan_doc

    extra = [p.id for p in app.state.doc.points if p.role == plan_doc.NO_ROLE]
    if extra:  # points added with every 3-2-1 role full have none: refused, naming them
        with pytest.raises(ValueError, match=f"points? {', '.join(extra)} ha"):
            app.files_panel.plan_bytes()
        for pid in extra:
            app.state.update(lambda d, pid=pid: plan_doc.delete_point(d, pid), f"delete {pid}")
    name, data = app.files_panel.plan_bytes()
    plan = plan_from_json(data.decode(), source=name)
    assert [p.id for p in plan.points] == list(app.state.doc.ids)


def test_bad_uploads_change_nothing(app: WobjcalApp) -> None:
    before = app.state.doc
    cases = [
        ("plan.json", b'{"schema": "wobjcal.plan/1", "points": [}', "plan.json"),
        ("plan.txt", b"{}", "must end in .json"),
        ("part.stl", b"solid nothing\nendsolid\n", "part.stl"),
        ("robot.urdf", b"<robot name='x'><link name='a'/>", "robot.urdf"),
        ("big.json", b" " * (50 * 1024 * 1024 + 1), "50 MiB limit"),
        ("empty.stl", b"", "empty"),
    ]
    for name, content, expected in cases:
        upload = {
            ".json": app.files_panel.upload_plan,
            ".txt": app.files_panel.upload_plan,
            ".stl": app.files_panel.upload_mesh,
            ".urdf": app.files_panel.upload_urdf,
        }[Path(name).suffix]
        with pytest.raises(Exception, match=expected.replace(".", r"\.")):
            upload(name, content)
        assert app.state.doc is before, f"{name} changed the plan"


@pytest.mark.slow
def test_good_plan_upload_replaces_plan_and_undo_restores(app: WobjcalApp) -> None:
    before_ids = app.state.doc.ids
    # relative mesh references resolve against the session's plan folder
    text = box_plan(app.plan_dir, name="other").read_text()
    plan = plan_from_json(text, "other.json")
    fewer = text.replace('"name": "other"', '"name": "uploaded"')
    assert plan.name == "other"
    app.files_panel.upload_plan("uploaded.json", fewer.encode())
    assert app.state.doc.name == "uploaded"
    app.state.undo()
    assert app.state.doc.ids == before_ids


def test_heat_map_grows_in_chunks_and_colours_vertices(app: WobjcalApp) -> None:
    app.heatmap.start(n_samples=6, chunk=2)
    assert app.heatmap.done.wait(120)
    assert len(app.heatmap.scores) == 6
    assert set(app.heatmap.scores) <= {0.0, 0.5, 1.0}
    from webui.heatmap import CATEGORY_RGB

    assert len(app.heatmap.categories) == 6 and set(app.heatmap.categories) <= set(CATEGORY_RGB)
    assert app.server.scene.get_handle_by_name("/wobj/heat_mesh") is not None
    assert "surface samples usable" in app.heatmap.summary
    app.place_at_ray(*_ray_to([0.0, 0.1, 0.0]), point_id="H1")  # clicks still work after
    # helper-56 (D2): a validation that finished with "Show error on part" unticked cleared
    # the heat map (one overlay for all): each panel's colours are a layer of their own now
    panel = app.validate_panel
    assert not panel.show_error.value and not panel.paint_error()
    app.layout_panel.show_map.value = False
    app.layout_panel._paint()
    assert app.server.scene.get_handle_by_name("/wobj/heat_mesh") is not None
    n = len(app.view.wobj_mesh.vertices)
    app.scene.color_work_object(np.zeros((n, 3), np.uint8), layer="error")
    app.scene.color_work_object(None, layer="error")
    assert app.server.scene.get_handle_by_name("/wobj/error_mesh") is None
    assert app.server.scene.get_handle_by_name("/wobj/heat_mesh") is not None
    app.heatmap.stop()
    assert app.server.scene.get_handle_by_name("/wobj/heat_mesh") is None


def test_feasible_point_has_pose_and_search_path(app: WobjcalApp) -> None:
    check = app.place_at_ray(*_ray_to([0.05, 0.1, 0.0]), point_id="Q")
    assert check is not None
    assert check.status in {"feasible", "marginal"}, check.text
    assert check.q is not None and check.q_path is not None and len(check.q_path) >= 2
    app.select("Q")
    assert app.robot is not None
    assert not np.allclose(app.robot.q, check.q), "the robot moves to a point only when asked"
    app.robot_to_selected()
    np.testing.assert_allclose(app.robot.q, check.q)


@pytest.mark.slow
def test_exports_are_robot_programs(app: WobjcalApp) -> None:
    original = app.plan_dir / "box_plan.json"
    app.files_panel.upload_plan(original.name, original.read_bytes())  # drop the extra points
    rapid = app.files_panel.export("RAPID")
    (name, data), *_ = rapid.files
    assert name.endswith(".mod") and b"MODULE" in data
    krl = app.files_panel.export("KRL")
    assert {Path(n).suffix for n, _ in krl.files} == {".src", ".dat"}
    ur = app.files_panel.export("URScript")
    assert ur.files[0][0].endswith(".script")


@pytest.mark.slow
def test_downloads_are_named_after_the_loaded_plan(app: WobjcalApp) -> None:
    """Issue item 4: the downloads of an uploaded plan are named after that plan's name (as
    ``wobjcal export -o DIR`` names them), whatever the file it came in was called."""
    text = box_plan(app.plan_dir, name="other").read_text()
    app.files_panel.upload_plan("some_file.json", text.replace('"other"', '"My plan 2"').encode())
    try:
        assert app.files_panel.plan_bytes()[0] == "My_plan_2.json"
        names = {fmt: [n for n, _ in app.files_panel.export(fmt).files] for fmt in ("RAPID", "TP")}
        assert names == {"RAPID": ["My_plan_2.mod"], "TP": ["WOBJCALMYPLAN2.ls"]}
    finally:
        app.state.undo()


@pytest.mark.slow
def test_mesh_and_urdf_uploads_replace_the_cell(app: WobjcalApp) -> None:
    from webui.testing import box_mesh

    before = app.state.doc
    stl = box_mesh()
    stl.apply_scale(1000.0)  # millimetres
    app.files_panel.units.value = "mm"
    app.files_panel.upload_mesh("part_mm.stl", stl.export(file_type="stl"))
    assert app.view is not None
    np.testing.assert_allclose(app.view.wobj_mesh.extents, [0.6, 0.4, 0.3], atol=1e-9)
    assert app.state.doc.source.work_object.units == "mm"
    urdf = (Path(__file__).resolve().parents[2] / "assets/robots/irb4400/irb4400.urdf").read_bytes()
    app.files_panel.upload_urdf("my_robot.urdf", urdf)
    assert app.state.doc.source.cell.robot.urdf.endswith("my_robot.urdf")
    app.state.undo()
    app.state.undo()
    assert app.state.doc.source is before.source
    np.testing.assert_allclose(app.view.wobj_mesh.extents, [0.6, 0.4, 0.3], atol=1e-9)


def test_measurements_upload_draws_calibrated_frame(app: WobjcalApp) -> None:
    from calib.frames import make_transform
    from webui.plan_adapter import plan_from_ui

    original = app.plan_dir / "box_plan.json"
    app.files_panel.upload_plan(original.name, original.read_bytes())  # drop the extra points
    plan = plan_from_ui(app.state.doc)
    true = plan.work_object.T_world_wobj.matrix() @ make_transform(None, [0.002, -0.001, 0.0])
    pts = {p.id: transform_points(true, p.position_m).tolist() for p in plan.points}
    doc = {"schema": "wobjcal.measurements/1", "frame": "world", "units": "m", "points": pts}
    out = app.calibrate_panel.calibrate("meas.json", json.dumps(doc).encode())
    T_world_wobj = plan.cell.robot.T_world_base.matrix() @ out.T_base_wobj
    np.testing.assert_allclose(T_world_wobj, true, atol=1e-9)
    assert app.server.scene.get_handle_by_name("/wobj_calibrated") is not None
    content = app.calibrate_panel.result_md.content
    assert "residual" in content
    # a note (a 3-2-1 has no redundancy) is a list item of its own, not run into the next line
    # (helper-56, M6)
    assert out.notes and "\n\nshift from nominal" in content
    with pytest.raises(ValueError, match=r"bad\.json"):
        app.calibrate_panel.calibrate("bad.json", b'{"schema": "wobjcal.measurements/9"}')


def test_play_search_path_ends_at_its_last_pose(app: WobjcalApp) -> None:
    check = app.place_at_ray(*_ray_to([0.0, -0.05, 0.0]), point_id="PL")
    assert check is not None and check.q_path is not None, check
    assert app.robot is not None
    app.robot.play(check.q_path, duration_s=0.2)
    assert app.robot.wait(5.0)
    np.testing.assert_allclose(app.robot.q, check.q_path[-1])


@pytest.mark.slow
def test_plays_started_together_leave_one_animation_that_stops(app: WobjcalApp) -> None:
    """Eight plays of a long path started at once from eight threads (as button clicks of a
    thread pool), five rounds: one animation is left registered, and ``stop`` ends every one
    of them (before, a play could replace another's entry and leave it running for good)."""
    import threading

    assert app.robot is not None
    robot = app.robot
    path = np.repeat(robot.q[None, :], 400, axis=0)  # 400 poses over 60 s: runs until stopped
    for _ in range(5):
        go = threading.Event()

        def start(go: threading.Event = go) -> None:
            go.wait()
            robot.play(path, duration_s=60.0)

        starters = [threading.Thread(target=start) for _ in range(8)]
        for t in starters:
            t.start()
        go.set()
        for t in starters:
            t.join(30.0)
        players = [t for t in threading.enumerate() if t.name == "wobjcal-play" and t.is_alive()]
        assert len(robot._players) == 1
        robot.stop()
        for t in players:
            t.join(5.0)
        assert not any(t.is_alive() for t in players), "an animation nobody can stop"


def test_gizmo_drag_previews_then_projects_onto_surface(app: WobjcalApp) -> None:
    from types import SimpleNamespace

    app.place_at_ray(*_ray_to([0.0, 0.0, 0.0]), point_id="G1")
    app.select("G1")
    before = app.state.doc
    app.points_panel.drag.value = True  # shows the gizmo at the point
    target = SimpleNamespace(position=(0.08, -0.03, 0.04))  # dragged 4 cm above the top face
    drag = app.points_panel._on_gizmo
    drag(SimpleNamespace(phase="update", target=target, client=None))
    assert app.server.scene.get_handle_by_name("/wobj/drag_preview") is not None
    assert app.state.doc is before, "no plan edit while dragging"
    drag(SimpleNamespace(phase="end", target=target, client=None))
    moved = app.state.doc.get("G1").probe.position_m
    np.testing.assert_allclose(moved, [0.08, -0.03, 0.0], atol=1e-12)
    assert app.server.scene.get_handle_by_name("/wobj/drag_preview") is None
    app.points_panel.drag.value = False


def test_gizmo_sits_outside_the_part_and_a_drag_back_to_the_start_records_nothing(
    app: WobjcalApp,
) -> None:
    """Issue 14, item 10: the gizmo is sized for the part and held out along the normal; a
    drag that ends where it started (or a move onto the point itself) records no undo step and
    leaves every coordinate as it was."""
    from types import SimpleNamespace

    app.place_at_ray(*_ray_to([0.05, -0.02, 0.0]), point_id="G2")
    app.select("G2")
    panel = app.points_panel
    panel.drag.value = True
    gizmo = app.server.scene.get_handle_by_name("/wobj/gizmo")
    scale, offset = panel.gizmo_geometry()
    assert gizmo is not None and 0.05 <= scale <= 0.4 and offset > 0.01
    point = app.state.doc.get("G2").probe
    np.testing.assert_allclose(gizmo.position, np.add(point.position_m, [0, 0, offset]))
    before, undo_depth = app.state.doc, len(app.state._undo)
    start = SimpleNamespace(position=tuple(gizmo.position))
    for phase in ("start", "update", "end"):
        panel._on_gizmo(SimpleNamespace(phase=phase, target=start, client=None))
    assert app.state.doc is before and len(app.state._undo) == undo_depth
    app.move_point_to("G2", point.position_m)  # a move onto itself: nothing either
    assert app.state.doc is before and len(app.state._undo) == undo_depth
    assert app.state.doc.get("G2").probe.position_m == point.position_m
    panel.drag.value = False


@pytest.mark.slow
def test_the_points_table_says_when_the_layout_would_be_refused(app: WobjcalApp) -> None:
    """Issue 10, item 3: the UI shows what `wobjcal check` (and `calibrate`) would refuse, the
    same words as the check's ``layout``."""
    from planner.check.job import layout_problem
    from webui import plan_doc
    from webui.plan_adapter import plan_from_ui

    original = app.plan_dir / "box_plan.json"
    app.files_panel.upload_plan(original.name, original.read_bytes())  # drop the extra points
    assert app.cycle_future is not None
    app.cycle_future.result(60)  # the status table's cycle-time line comes after the rows
    before = app.points_panel.status_md.content
    app.state.apply(plan_doc.delete_point(app.state.doc, "T1"), "delete T1")
    try:
        want = layout_problem(plan_from_ui(app.state.doc))
        assert want and f"**Layout:** {want}" in app.points_panel.status_md.content
    finally:
        app.state.undo()
    app.cycle_future.result(60)
    deadline = time.monotonic() + 10.0  # its callback refreshes the table just after
    while app.points_panel.status_md.content != before and time.monotonic() < deadline:
        time.sleep(0.02)
    assert app.points_panel.status_md.content == before
