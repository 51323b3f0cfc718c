"""``wobjcal check`` walks the searches the exported program runs (:mod:`planner.check.paths`):
from the safe start, with the probe pose's orientation and configuration."""

from __future__ import annotations

from collections.abc import Iterator
from pathlib import Path

import msgspec
import numpy as np
import pytest

from calib.frames import transform_points
from calib.plan import Plan, load_plan
from planner.check.job import check_plan
from planner.check.paths import check_program_path, measured_starts_wobj
from planner.export_plan.job import export_job_for, with_arm_poses
from planner.plan_cell import nominal_T_base_wobj, open_cell
from planner.program.build import safety_spec
from planner.program.searches import program_searches, safe_and_face_wobj

ROOT = Path(__file__).resolve().parents[3]
DEMO = ROOT / "assets/plans/stator_section_ah.json"


@pytest.fixture(scope="module")
def demo() -> Plan:
    return load_plan(DEMO)


@pytest.fixture(scope="module")
def demo_cell(demo: Plan) -> Iterator[object]:
    with open_cell(demo, DEMO.parent) as cell:
        yield cell


@pytest.mark.slow
def test_the_checked_path_is_the_programs(demo: Plan, demo_cell) -> None:  # type: ignore[no-untyped-def]
    """Every demo point: the checked path starts at the program's safe start, keeps the probe
    pose's sensor orientation all along, and its first joint values are the exported program's
    safe-start joint values."""
    check = check_plan(demo, DEMO.parent, cell=demo_cell)
    T_nom = nominal_T_base_wobj(demo)
    safety = safety_spec(demo)
    job, _ = export_job_for(demo, DEMO.parent, check)
    job = with_arm_poses(job, demo_cell, check, demo.cell.tool.tcp)
    arms = {t.point_id: t.arm for t in job.targets}
    T_ft = demo_cell.T_flange_tcp(demo.cell.tool.tcp)
    for p, c in zip(demo.points, check.points, strict=True):
        assert c.feasible and c.q_safe is not None and c.q_path is not None, c.reason
        T = demo_cell.chain.fk(c.q_path) @ T_ft
        safe_base = transform_points(T_nom, safe_and_face_wobj(p.to_probe_point(), safety)[0])
        np.testing.assert_allclose(T[0, :3, 3], safe_base, atol=1e-6)
        np.testing.assert_allclose(c.q_safe, c.q_path[0])
        assert c.T_base_tcp is not None
        R_pose = c.T_base_tcp[:3, :3]
        assert np.abs(T[:, :3, :3] - R_pose).max() < 1e-6, p.id  # the pose's orientation
        assert arms[p.id] is not None
        np.testing.assert_allclose(arms[p.id]["safe"].q_rad, c.q_safe, atol=1e-6)
        kinds = [s.command.kind for s in program_searches(p.to_probe_point(), T_nom, safety)]
        edge = ["approach", "edge", "approach"]  # face approach, edge search, retreat
        assert kinds == (edge if p.search.kind == "edge" else ["approach"])


@pytest.mark.slow
def test_a_safe_start_out_of_reach_makes_the_point_infeasible(demo: Plan, demo_cell) -> None:  # type: ignore[no-untyped-def]
    """A misplacement tolerance of 0.6 m puts every safe start more than half a metre off the
    part: the plan's own searches (5 cm out) are reachable, the program's are not, and the
    check says so naming the safe start (it used to pass: the program was never checked)."""
    v = demo.validation
    loose = msgspec.structs.replace(
        v, misplacement=msgspec.structs.replace(v.misplacement, max_translation_m=0.6)
    )
    plan = msgspec.structs.replace(demo, validation=loose)
    check = check_plan(plan, DEMO.parent, cell=demo_cell)
    bad = [c for c in check.points if not c.path_feasible]
    assert bad, "no search from a safe start 0.6 m out failed"
    for c in bad:
        assert c.status == "infeasible"
        assert "from the safe start" in c.path_reason, c.path_reason
    # the poses themselves are untouched by the tolerance
    assert [c.pose_status for c in check.points] == [
        c.pose_status for c in check_plan(demo, DEMO.parent, cell=demo_cell).points
    ]


@pytest.mark.slow
def test_an_edge_points_path_is_approach_edge_and_retreat(demo: Plan, demo_cell) -> None:  # type: ignore[no-untyped-def]
    """F: the face approach from the safe start down to the nominal face (not its overtravel
    into the part), the edge search from the edge start up to the edge (where it stops), and
    the straight retreat back to the safe start: never into the part, no jump."""
    check = check_plan(demo, DEMO.parent, cell=demo_cell)
    T_nom = nominal_T_base_wobj(demo)
    (p,) = [p for p in demo.points if p.id == "F"]
    (c,) = [c for c in check.points if c.point_id == "F"]
    approach, edge, retreat = (
        s.command for s in program_searches(p.to_probe_point(), T_nom, safety_spec(demo))
    )
    tcp = (demo_cell.chain.fk(c.q_path) @ demo_cell.T_flange_tcp(demo.cell.tool.tcp))[:, :3, 3]
    depth = (tcp - edge.start_m) @ (-approach.direction)  # height over the nominal face
    assert depth.min() > -1e-6  # never into the part
    assert np.linalg.norm(np.diff(tcp, axis=0), axis=1).max() < 1.5e-3  # 1 mm samples, no jump
    np.testing.assert_allclose(tcp[0], approach.start_m, atol=1e-6)
    np.testing.assert_allclose(tcp[-1], approach.start_m, atol=1e-6)  # back at the safe start
    np.testing.assert_allclose(retreat.start_m, edge.nominal_m, atol=1e-9)  # from the edge
    run = (tcp - edge.start_m) @ edge.direction
    assert run.max() == pytest.approx(
        float((edge.nominal_m - edge.start_m) @ edge.direction), abs=1e-3
    )


@pytest.mark.slow
def test_the_adaptive_programs_edge_start_at_the_measured_point_is_walked_too(
    demo: Plan,
    demo_cell,  # type: ignore[no-untyped-def]
) -> None:
    """With ``edge_start_from_measured`` the adaptive RAPID program moves F from its safe start
    straight to the measured E (plus the offset) and searches from there; the check walks that
    too, and names it when it fails (here: a start put out of reach)."""
    proc = msgspec.structs.replace(
        demo.procedure, edge_start_from_measured=True, edge_start_offset_m=0.004
    )
    plan = msgspec.structs.replace(demo, procedure=proc)
    starts = measured_starts_wobj(plan)
    pts = {p.id: p for p in plan.points}
    assert set(starts) == {"F", "H"}
    np.testing.assert_allclose(
        starts["F"], np.add(pts["E"].position_m, 0.004 * np.asarray(pts["F"].normal))
    )
    check = check_plan(plan, DEMO.parent, cell=demo_cell)
    assert check.feasible, [(c.point_id, c.reason) for c in check.points if not c.feasible]
    T_nom = nominal_T_base_wobj(plan)
    safety = safety_spec(plan)
    F = pts["F"].to_probe_point()
    move, edge, _ = (s.command for s in program_searches(F, T_nom, safety, starts["F"]))
    np.testing.assert_allclose(move.start_m + move.length_m * move.direction, edge.start_m)
    np.testing.assert_allclose(edge.start_m, transform_points(T_nom, starts["F"]))
    pose = demo_cell.check_probes(
        np.array([F.position_m]), np.array([F.normal]), tcp=plan.cell.tool.tcp
    )[0]
    T_ft = demo_cell.T_flange_tcp(plan.cell.tool.tcp)
    tcp = plan.cell.tool.tcp
    far = starts["F"] + 0.25 * np.asarray(F.normal) - 0.9 * np.asarray(F.search.edge_direction)
    path = check_program_path(demo_cell, F, pose, T_nom, safety, T_ft, tcp, far)
    assert not path.feasible
    assert path.reason.startswith(
        "adaptive RAPID program (edge search from the measured point): move from the safe start"
    ), path.reason
    assert path.q_safe is not None  # the face-approach program's, which passes


@pytest.mark.slow
def test_a_point_without_a_usable_pose_has_no_safe_start(demo: Plan, demo_cell) -> None:  # type: ignore[no-untyped-def]
    far = msgspec.structs.replace(demo.points[0], position_m=(3.0, 3.0, 3.0))
    plan = msgspec.structs.replace(demo, points=[far, *demo.points[1:]])
    c = check_plan(plan, DEMO.parent, cell=demo_cell).points[0]
    assert c.pose_status == "infeasible" and c.q_safe is None
