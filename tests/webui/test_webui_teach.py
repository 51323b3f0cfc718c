"""Jog and teach, server side (issue 14, item 2): sliders within the URDF limits, limits and
clearance live, the TCP gizmo through the IK keeping the branch, teaching a pose as a point's
approach."""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from calib.errors import InputError
from calib.frames import transform_points
from calib.plan.file import load_plan
from planner.demo import DEMO_PLAN
from webui.app import WobjcalApp
from webui.teach_panel import NEW_POINT


def test_sliders_follow_the_urdf_limits(demo_app: WobjcalApp) -> None:
    chain = demo_app.view.chain
    panel = demo_app.teach_panel
    assert len(panel.sliders) == chain.n_joints == 6
    for s, lo, hi in zip(panel.sliders, chain.lower, chain.upper, strict=True):
        assert s.min == pytest.approx(np.degrees(lo), abs=1e-3)
        assert s.max == pytest.approx(np.degrees(hi), abs=1e-3)


def test_jog_to_a_point_is_clear_and_the_tcp_is_on_it(demo_app: WobjcalApp) -> None:
    demo_app.select("A")
    status = demo_app.teach_panel.jog_to_selected()
    check = demo_app.check_of("A")
    assert status.status in {"feasible", "marginal"}, status.describe()
    np.testing.assert_allclose(demo_app.robot.q, check.q)
    a = demo_app.state.doc.get("A").probe
    T = demo_app.teach_panel.T_world_tcp()
    np.testing.assert_allclose(
        T[:3, 3], transform_points(demo_app.view.T_world_wobj, a.position_m), atol=1e-6
    )
    np.testing.assert_allclose(
        T[:3, 2], -(demo_app.view.T_world_wobj[:3, :3] @ a.normal), atol=1e-6
    )


def test_limits_and_collisions_show_at_once(demo_app: WobjcalApp) -> None:
    panel = demo_app.teach_panel
    chain = demo_app.view.chain
    q = np.clip(np.zeros(6), chain.lower, chain.upper)
    q[2] = chain.upper[2] + 0.1  # beyond joint 3's limit
    status = panel.jog(q)
    assert status.status == "infeasible" and chain.joint_names[2] in status.outside
    assert "beyond the limits" in panel.status_md.content
    q = demo_app.check_of("A").q.copy()
    q[1] += 0.2  # lean the arm forward: the sensor goes into the table
    status = panel.jog(q)
    assert not status.clear and "hits" in status.clearance, status.describe()


def test_tcp_gizmo_moves_through_the_ik_keeping_the_branch(demo_app: WobjcalApp) -> None:
    panel = demo_app.teach_panel
    q0 = demo_app.check_of("A").q
    panel.jog(q0)
    T = panel.T_world_tcp()
    T_up = T.copy()
    T_up[:3, 3] += T[:3, 2] * -0.05  # 50 mm back along the sensor axis
    status = panel.move_tcp(T_up)
    assert status is not None
    np.testing.assert_allclose(panel.T_world_tcp(), T_up, atol=1e-6)
    assert np.max(np.abs(panel.q - q0)) < 0.5, "the nearest solution: same branch"
    far = T.copy()
    far[:3, 3] += [5.0, 0, 0]
    before = panel.q.copy()
    assert panel.move_tcp(far) is None and "out of reach" in panel.status_md.content
    np.testing.assert_array_equal(panel.q, before)


def test_teach_makes_the_pose_a_points_approach(demo_app: WobjcalApp) -> None:
    panel = demo_app.teach_panel
    a = demo_app.state.doc.get("A").probe
    panel.jog(demo_app.check_of("A").q)
    T = panel.T_world_tcp()
    T_back = T.copy()
    T_back[:3, 3] -= 0.04 * T[:3, 2]  # 40 mm out from A along its normal
    assert panel.move_tcp(T_back) is not None
    pid = panel.teach(NEW_POINT)
    try:
        taught = demo_app.state.doc.get(pid).probe
        np.testing.assert_allclose(taught.position_m, a.position_m, atol=1e-6)
        np.testing.assert_allclose(taught.normal, a.normal, atol=1e-5)  # the mesh face
        assert taught.search.start_offset_m == pytest.approx(0.04, abs=1e-6)
        assert demo_app.selected == pid
    finally:
        demo_app.state.undo()
    q_up = demo_app.check_of("A").q.copy()
    q_up[0] += np.pi / 2  # axis 1 turned a quarter: the sensor points away from the part
    panel.jog(q_up)
    before = demo_app.state.doc
    with pytest.raises(InputError, match="does not meet the work object"):
        panel.teach(NEW_POINT)
    assert demo_app.state.doc is before


def test_moves_between_points_are_drawn_and_checked(demo_app: WobjcalApp) -> None:
    panel = demo_app.teach_panel
    panel.show_moves.value = True  # draws at once
    try:
        checks = demo_app.checks()
        posed = [pid for pid in demo_app.state.doc.ids if checks[pid].status != "infeasible"]
        want = [f"{a}->{b}" for a, b in itertools.pairwise(posed)]
        assert list(panel.moves) == want and len(want) >= 3
        for key in want:
            a, b = key.split("->")
            assert demo_app.server.scene.get_handle_by_name(f"/moves/{a}_{b}_0") is not None
            assert f"{a} → {b}" in panel.moves_md.content
        # a move through the part is caught: A's pose to A's pose with the arm leaned in
        qa = demo_app.check_of("A").q
        q_in = qa.copy()
        q_in[1] += 0.2
        tcp = demo_app.state.doc.source.cell.tool.tcp
        move = demo_app.worker.call(lambda s: s.check_move(qa, q_in, tcp))
        assert "hits" in move.problem and move.tcp_path_world.shape == (20, 3)
        clear = demo_app.worker.call(lambda s: s.check_move(qa, qa, tcp))
        assert clear.problem == ""
    finally:
        panel.show_moves.value = False
    assert demo_app.server.scene.get_handle_by_name("/moves") is None


def test_shown_moves_follow_the_plan(demo_app: WobjcalApp) -> None:
    """While "Show moves" is ticked, an edit redraws the moves of the plan as it now is (a
    deleted point's moves go, the move across it appears), and undo brings them back."""
    from webui import plan_doc

    panel = demo_app.teach_panel
    panel.show_moves.value = True
    try:
        before = list(panel.moves)
        a, b, c = demo_app.state.doc.ids[:3]
        assert f"{a}->{b}" in before and f"{b}->{c}" in before
        demo_app.state.update(lambda d: plan_doc.delete_point(d, b), f"delete {b}")
        wait = list(panel.moves)
        assert f"{a}->{b}" not in wait and f"{a}->{c}" in wait
        assert demo_app.server.scene.get_handle_by_name(f"/moves/{a}_{b}_0") is None
        demo_app.state.undo()
        assert list(panel.moves) == before
    finally:
        panel.show_moves.value = False


def test_teach_as_via_point_adds_one_undoable_autosaved_via(demo_app: WobjcalApp) -> None:
    import json

    panel, state = demo_app.teach_panel, demo_app.state
    qa = demo_app.check_of("A").q
    lifted = qa + np.array([0.0, -0.2, 0.0, 0.0, 0.0, 0.0])  # retracted above the part
    panel.jog(lifted)
    demo_app.select("B")
    undo_depth = len(state._undo)
    assert panel.teach_via() == 1
    assert len(state._undo) == undo_depth + 1  # one undo step
    via = state.doc.get("B").vias[0]
    np.testing.assert_allclose(via.q_rad, lifted, atol=1e-12)
    T_wobj_tcp = np.linalg.solve(demo_app.view.T_world_wobj, panel.T_world_tcp())
    np.testing.assert_allclose(via.tcp_wobj.matrix(), T_wobj_tcp, atol=1e-9)
    saved = json.loads(demo_app.state._autosave_path.read_text())
    b = next(p for p in saved["points"] if p["id"] == "B")
    np.testing.assert_allclose(b["vias"][0]["q_rad"], lifted, atol=1e-12)
    shipped = {p.id: [list(v.q_rad) for v in p.via_points] for p in load_plan(DEMO_PLAN).points}
    for p in saved["points"]:  # the others keep the vias they had (the shipped plan's)
        if p["id"] != "B":
            assert [v["q_rad"] for v in p.get("vias", [])] == shipped[p["id"]], p["id"]
    # drawn: a marker at the via's TCP and the path to B
    marker = demo_app.server.scene.get_handle_by_name("/vias/B/v1")
    assert marker is not None
    np.testing.assert_allclose(marker.position, panel.T_world_tcp()[:3, 3], atol=1e-6)
    assert demo_app.server.scene.get_handle_by_name("/vias/B/path") is not None
    panel.show_moves.value = True
    try:
        assert panel.moves["A->B"] == "", panel.moves_md.content
        assert "A → B (through 1 via): clear" in panel.moves_md.content
    finally:
        panel.show_moves.value = False
    state.undo()
    assert state.doc.get("B").vias == ()
    assert demo_app.server.scene.get_handle_by_name("/vias/B/v1") is None
    assert demo_app.server.scene.get_handle_by_name("/vias/C/v1") is not None  # shipped vias


def test_remove_last_via_keeps_the_others(demo_app: WobjcalApp) -> None:
    panel, state = demo_app.teach_panel, demo_app.state
    qa = demo_app.check_of("A").q
    first, second = (qa + np.array([0.0, d, 0.0, 0.0, 0.0, 0.0]) for d in (-0.2, -0.1))
    demo_app.select("B")
    for q in (first, second):
        panel.jog(q)
        panel.teach_via()
    assert demo_app.server.scene.get_handle_by_name("/vias/B/v2") is not None
    undo_depth = len(state._undo)
    assert panel.remove_via() == 1
    assert len(state._undo) == undo_depth + 1  # one undo step
    np.testing.assert_allclose(state.doc.get("B").vias[0].q_rad, first, atol=1e-12)
    assert demo_app.server.scene.get_handle_by_name("/vias/B/v2") is None
    assert demo_app.server.scene.get_handle_by_name("/vias/B/v1") is not None
    assert panel.remove_via() == 0
    with pytest.raises(InputError, match="point B has no via to remove"):
        panel.remove_via()
    state.undo()
    state.undo()
    state.undo()
    state.undo()
    assert state.doc.get("B").vias == ()


def test_teach_as_via_point_needs_a_selected_point(demo_app: WobjcalApp) -> None:
    demo_app.select(None)
    with pytest.raises(InputError, match="select the point the via leads to"):
        demo_app.teach_panel.teach_via()
