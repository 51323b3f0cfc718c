"""Cell setup in the UI, server side (issue 14, item 1): poses in mm/deg round trip, moves of
the work object, robot base and fixtures rebuild the cell, re-check, undo and autosave; the
part snaps onto the table."""

from __future__ import annotations

import json

import numpy as np
import pytest

from calib.errors import InputError
from calib.frames import transform_points
from webui import cell_edits
from webui.app import WobjcalApp


def test_fields_round_trip_in_mm_and_deg() -> None:
    rng = np.random.default_rng(14)
    for _ in range(20):
        p, a = rng.uniform(-2000, 2000, 3), rng.uniform([-180, -89, -180], [180, 89, 180])
        T = cell_edits.pose_from_fields(p, a)
        p2, a2 = cell_edits.fields_of(T)
        np.testing.assert_allclose(p2, p, atol=1e-6)
        np.testing.assert_allclose(a2, a, atol=1e-6)
    with pytest.raises(InputError, match="finite"):
        cell_edits.pose_from_fields([0, np.nan, 0], [0, 0, 0])


@pytest.mark.slow
def test_moving_the_work_object_rebuilds_rechecks_and_undoes(demo_app: WobjcalApp) -> None:
    panel = demo_app.cell_panel
    source = demo_app.state.doc.source
    T0 = source.work_object.T_world_wobj.matrix()
    panel.target.value = cell_edits.WORK_OBJECT
    p, _ = cell_edits.fields_of(T0)
    panel.position.value = (p[0], p[1] + 100.0, p[2])  # 100 mm along world y
    panel.apply_fields()
    T1 = demo_app.state.doc.source.work_object.T_world_wobj.matrix()
    np.testing.assert_allclose(T1[:3, 3] - T0[:3, 3], [0, 0.1, 0], atol=1e-9)
    np.testing.assert_allclose(demo_app.view.T_world_wobj, T1, atol=1e-12)  # the cell's own pose
    assert len(demo_app.checks()) == 8, "every point checked again in the moved cell"
    saved = json.loads(demo_app.state.autosave_path.read_text())
    assert saved["work_object"]["T_world_wobj"]["position_m"][1] == pytest.approx(T1[1, 3])
    depth = len(demo_app.state._undo)
    panel.apply_fields()  # the same pose again: nothing recorded
    assert len(demo_app.state._undo) == depth
    demo_app.state.undo()
    np.testing.assert_allclose(demo_app.view.T_world_wobj, T0, atol=1e-12)
    assert panel.position.value == pytest.approx(p)


@pytest.mark.slow
def test_robot_base_and_fixture_moves(demo_app: WobjcalApp) -> None:
    panel = demo_app.cell_panel
    assert "fixture: table" in panel.target.options
    T = cell_edits.pose_of(demo_app.state.doc.source, cell_edits.ROBOT_BASE)
    T_new = T.copy()
    T_new[:3, 3] += [-0.2, 0.0, 0.0]
    panel.move(cell_edits.ROBOT_BASE, T_new)
    np.testing.assert_allclose(demo_app.view.T_world_base, T_new, atol=1e-12)
    demo_app.state.undo()
    T_table = cell_edits.pose_of(demo_app.state.doc.source, "fixture: table")
    T_table2 = T_table.copy()
    T_table2[2, 3] -= 0.05
    panel.move("fixture: table", T_table2)
    np.testing.assert_allclose(demo_app.view.fixtures["table"][1], T_table2, atol=1e-12)
    demo_app.state.undo()
    with pytest.raises(InputError, match="nothing called"):
        panel.move("fixture: nope", T)


@pytest.mark.slow
def test_snap_puts_the_part_on_the_table(demo_app: WobjcalApp) -> None:
    demo_app.cell_panel.snap_part("table")
    try:
        view = demo_app.view
        part = transform_points(view.T_world_wobj, view.wobj_mesh.vertices)
        mesh, T_table = view.fixtures["table"]
        top = transform_points(T_table, mesh.vertices)[:, 2].max()
        assert part[:, 2].min() == pytest.approx(top, abs=1e-9)
        centre = 0.5 * (part.min(axis=0) + part.max(axis=0))
        np.testing.assert_allclose(centre[:2], T_table[:2, 3], atol=1e-9)
    finally:
        demo_app.state.undo()
    with pytest.raises(InputError, match="no fixture 'nope'"):
        demo_app.cell_panel.snap_part("nope")


@pytest.mark.slow
def test_cell_gizmo_drag_moves_the_target_and_a_still_drag_records_nothing(
    demo_app: WobjcalApp,
) -> None:
    from types import SimpleNamespace

    panel = demo_app.cell_panel
    panel.target.value = cell_edits.WORK_OBJECT
    panel.use_gizmo.value = True
    gizmo = demo_app.server.scene.get_handle_by_name("/cell_gizmo")
    assert gizmo is not None and not gizmo.depth_test
    depth = len(demo_app.state._undo)
    still = SimpleNamespace(wxyz=np.array(gizmo.wxyz), position=np.array(gizmo.position))
    panel._on_gizmo(SimpleNamespace(phase="end", target=still, client=None))
    assert len(demo_app.state._undo) == depth
    moved = SimpleNamespace(wxyz=still.wxyz, position=np.add(still.position, [0, 0, 0.02]))
    panel._on_gizmo(SimpleNamespace(phase="end", target=moved, client=None))
    assert len(demo_app.state._undo) == depth + 1
    assert demo_app.view.T_world_wobj[2, 3] == pytest.approx(still.position[2] + 0.02)
    demo_app.state.undo()
    panel.use_gizmo.value = False
    assert demo_app.server.scene.get_handle_by_name("/cell_gizmo") is None
