"""Check a plan: can the robot reach every probe point and run every search, on a planar face?

The one plan check. ``wobjcal check`` (table and ``--json``), the web UI's colours and reasons,
``wobjcal export`` (orientations and confdata of the targets) and scripts all call
:func:`check_plan` (a whole plan, in its own cell or a given one) or :func:`check_points` (some
points, in an open cell, as the UI does after an edit); the rules below hold for all of them.

Per point, three checks:

1. the probe pose (:func:`planner.cell.probe.check_probes`): IK, joint limits, wrist
   singularity, collisions with clearance; ``marginal`` when little clearance or near a limit;
2. the search path (:func:`planner.check.paths.check_program_path`): the searches the exported
   program runs, from the point's safe start to the end of travel, with the pose's orientation
   and IK branch (what the program writes), in the nominal work-object frame;
3. the planar face (:func:`planner.faces.checks.plan_face_reasons`): the point lies on a planar
   face with the plan's sensor footprint on it.

A point is ``infeasible`` when any of the three fails, ``marginal`` when only the pose is
marginal, else ``feasible``.

A point with via points (``points[i].vias``) has a fourth check in :func:`check_plan`
(:func:`check_via_moves`): every via within the joint limits, and the joint moves from the previous
point's safe start (none for the first point, or after a point without a pose) through the vias, in
order, to the point's safe start clear of collisions (:func:`planner.cell.moves.check_via_path`, the
move check the Teach tab draws). A via that fails makes the point ``infeasible`` and names the via
and the clearance pair. :func:`check_points` (one edited point, in the UI) leaves the vias out:
their moves depend on the neighbours' poses.

Per plan, the procedure's own preconditions (:func:`layout_problem`): the plan has points, every
role the procedure needs, and the procedure computes the nominal frame from exact measurements
of the nominal points (a dry run of the same ``estimate`` that ``wobjcal calibrate`` runs), so
a plan that ``calibrate`` would refuse fails at ``check``, before the robot has measured.
Then which points' gross errors ``calibrate``'s screen could see at all
(:func:`plan_detectability`; a plain 3-2-1 has no redundancy: none), and how many points to
add so it sees one in every point: said, not failed. Last, the program's estimated cycle time
(:func:`planner.check.cycle.plan_cycle_time`, the model of :mod:`planner.program.cycle_time`).
"""

from __future__ import annotations

import math
import time
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from calib.errors import InputError, ProbeFailedError
from calib.frames import invert_transform, transform_points
from calib.plan.file import Plan, PlanPoint
from calib.plane_probe import PlaneProbe
from calib.procedures import procedure_kind
from calib.procedures.base import edge_offset_of
from calib.tolerances import FACE_MAX_DEVIATION_M
from planner.check.cycle import plan_cycle_time
from planner.check.paths import ProgramPath, check_program_path, measured_starts_wobj
from planner.check.results import ConfData, PlanCheck, PointCheck, Status
from planner.memo import Memo
from planner.plan_cell import nominal_T_base_wobj, open_cell
from planner.program.build import (
    ah_base_problem,
    measuring_program,
    plan_settings,
    safety_spec,
)
from planner.program.controllers import controller
from planner.program.execute import execute
from planner.program.reach import search_problems
from planner.reasons import Reason

if TYPE_CHECKING:
    import trimesh

    from calib.estimators.gross_errors import Detectability
    from planner.cell.cell import Cell
    from planner.cell.probe import ProbeFeasibility
    from planner.faces.detection import PlanarFaces
    from planner.faces.outline import FaceOutlines
    from planner.sim.landing import LandingRisk
    from planner.sim.quality import LayoutQuality
    from planner.sim.raycast import MeshRayCaster

FloatArray = NDArray[np.float64]

__all__ = [
    "ConfData",
    "PlanCheck",
    "PointCheck",
    "Status",
    "base_in_part",
    "check_plan",
    "check_points",
    "check_via_moves",
    "layout_problem",
    "plan_detectability",
    "plan_quality",
]


def check_plan(
    plan: Plan, plan_dir: Path | None = None, *, cell: Cell | None = None, fmt: str | None = None
) -> PlanCheck:
    """Check every point and search path of ``plan`` (see the module docstring).

    Args:
        plan: the plan.
        plan_dir: folder the plan's relative file references resolve against (default: the
            current folder); used only when ``cell`` is ``None``.
        cell: an open cell of the plan (the UI's); ``None`` opens the plan's cell and closes
            it afterwards.
        fmt: the controller whose program the quality, the landing risk and the cycle time
            (:mod:`planner.check.cycle`) judge (``None``: the default, RAPID); the poses, paths
            and moves are those of every program.

    Raises:
        InputError: a file of the plan cannot be loaded (named in the message).
    """
    controller(fmt)  # an unknown controller: one clear error, before any work
    if cell is None:
        with open_cell(plan, plan_dir or Path.cwd()) as own:
            return check_plan(plan, cell=own, fmt=fmt)
    checks, error = _check(plan, list(plan.points), cell)
    # a robot standing inside the part makes every point fail: the cause, said once, first
    error = "; ".join(e for e in (base_in_part(cell), error) if e)
    checks = check_via_moves(cell, plan, checks)
    layout = layout_problem(plan, fmt) or controller_base_problem(
        plan, fmt, cell.controller_base.T_base_controller
    )
    quality, note = None, ""
    landing = None
    if not layout and cell.work_object is not None:
        quality, note = plan_quality(plan, cell.work_object.mesh, fmt)
        if quality is not None and quality.rating == "unobservable":
            layout = quality.problem
        if not layout:
            landing = plan_landing_risk(plan, cell.work_object.mesh, fmt)
    if landing is not None:
        checks = _with_landing(checks, landing.point_problems())
    return PlanCheck(
        checks,
        cell.solver.kind,
        cell.solver.why_not_opw or "",
        error,
        layout,
        quality,
        note,
        landing,
        None if layout else plan_detectability(plan),
        plan_cycle_time(plan, checks, cell, fmt),
        *_part_units(cell),
    )


def _part_units(cell: Cell) -> tuple[str, str]:
    """The unit the cell's work object was read in and how it was chosen (``("", "")``
    without one)."""
    wobj = cell.work_object
    report = None if wobj is None else getattr(wobj, "report", None)
    if report is None:
        return "", ""
    return str(report.units), str(report.units_note)


def base_in_part(cell: Cell) -> str:
    """Why the robot's base lies inside the cell's work object, or ``""``: its origin within
    the part's bounds (wobj frame), or a robot link no joint moves (the base link) overlapping
    the part. Every point then fails, each for a reason of its own (a joint at its limit, the
    base hitting the tool); this names the one cause."""
    from planner.cell.scene import pb

    wo = cell.work_object
    if wo is None or cell.checker.wobj_body is None:
        return ""
    o = invert_transform(cell.T_base_wobj)[:3, 3]
    lo, hi = np.asarray(wo.mesh.bounds, dtype=np.float64)
    what = []
    if bool(np.all(o >= lo) and np.all(o <= hi)):
        at = ", ".join(f"{v * 1e3:.1f}" for v in o)
        what.append(f"its origin is at ({at}) mm in the work-object frame, within the part")
    checker = cell.checker
    robot = checker.robot.body_id
    for i in sorted(checker.static_links):
        hits = pb.getClosestPoints(
            robot, checker.wobj_body, 0.0, linkIndexA=i, physicsClientId=cell.client
        )
        if hits:
            depth = -min(float(h[8]) for h in hits) * 1e3
            what.append(f"{checker.names(robot, i)} overlaps the part by {depth:.1f} mm")
    if not what:
        return ""
    return (
        f"the robot's base lies inside the work object {wo.name} ({'; '.join(what)}): check "
        "cell.robot.T_world_base and work_object.T_world_wobj (one world frame, metres); the "
        "points fail because of it"
    )


def plan_detectability(plan: Plan) -> Detectability | None:
    """Which points' gross errors ``wobjcal calibrate`` could see once they are measured, and
    how many points to add so it sees one in every point
    (:func:`calib.estimators.gross_errors.detectability`); ``None`` when the plan's points
    fix no frame (the layout check says why)."""
    from calib.estimators.gross_errors import detectability

    if not plan.points:
        return None
    try:
        edge_rows = procedure_kind(plan.method).edge_rows
        d = detectability([p.to_probe_point() for p in plan.points], edge_rows)
    except InputError:
        return None
    if d.add is None and not d.unseen:
        return None
    if why := plan.fixed_points():
        d = replace(d, fixed=why)
    return d


def plan_landing_risk(
    plan: Plan, mesh: trimesh.Trimesh, fmt: str | None = None
) -> LandingRisk | None:
    """How often each search of the program of ``fmt`` (``None``: the default) misses, starts
    too close or lands off its face under the plan's misplacement (:mod:`planner.sim.landing`),
    on the work object ``mesh`` (wobj, metres); ``None`` when the plan cannot be simulated."""
    from planner.cell import disk_cache
    from planner.check.simulatable import check_simulatable
    from planner.check.simulation_setup import prediction_setup
    from planner.faces.checks import check_plan_faces
    from planner.faces.detection import NoPlanarFaceError, find_planar_faces, mesh_digest
    from planner.sim.landing import landing_risk

    try:
        setup = prediction_setup(plan, check_simulatable(plan), fmt)
        r = max(float(plan.validation.sensor.footprint_radius_m), 1e-4)
        faces = find_planar_faces(
            mesh, min_area_m2=math.pi * r**2, footprint_radius_m=r, cache=disk_cache
        )
    except (InputError, NoPlanarFaceError):
        return None
    sensor = plan.validation.sensor
    standoff, radius = float(sensor.standoff_m), float(sensor.footprint_radius_m)
    key = (
        setup.program,
        setup.T_base_wobj_nominal.tobytes(),
        setup.misplacement,
        setup.pivot_wobj_m.tobytes(),
        standoff,
        radius,
        digest := mesh_digest(mesh),
    )
    kept = _RISKS.get(key)
    if kept is not None:
        return kept
    probes = [rp.point for rp in setup.points]
    face_of = {
        p.id: int(c.face_id)
        for p, c in zip(probes, check_plan_faces(faces, probes, footprint_radius_m=r), strict=True)
        if c.ok
    }
    risk = landing_risk(
        setup.program,
        setup.T_base_wobj_nominal,
        setup.misplacement,
        setup.pivot_wobj_m,
        _outlines(faces, r),
        face_of,
        caster=_caster(mesh, digest),
        standoff_m=standoff,
        footprint_radius_m=radius,
        triangle_face=np.asarray(faces.face_id, dtype=np.int64),
    )
    return _RISKS.put(key, risk)


#: Landing risks of recent programs on recent parts (the same plan is checked again after
#: every export and edit, and each check without an open cell loads the part again):
#: ``{(program, nominal pose, misplacement, pivot, sensor standoff and footprint radius, content
#: hash of the mesh): risk}``; the risk is seeded, so a cached one is the one computed again.
_RISKS: Memo[tuple[object, ...], LandingRisk] = Memo(32)


#: The ray casters of recent parts: ``{content hash of the mesh: caster}``.
_CASTERS: Memo[str, MeshRayCaster] = Memo(4)


def _caster(mesh: trimesh.Trimesh, digest: str) -> MeshRayCaster:
    """The ray caster of the part ``mesh`` whose :func:`~planner.faces.detection.mesh_digest`
    is ``digest`` (kept for the next check of a mesh with the same content)."""
    from planner.sim.raycast import MeshRayCaster

    caster = _CASTERS.get(digest)
    return caster if caster is not None else _CASTERS.put(digest, MeshRayCaster(mesh))


def _outlines(faces: PlanarFaces, radius_m: float) -> FaceOutlines:
    """The outlines of ``faces`` with a footprint of ``radius_m``: kept for the next check,
    and the ones a design on the same faces built
    (:func:`planner.faces.outline.shared_outlines`)."""
    from planner.faces.outline import shared_outlines

    return shared_outlines(faces, radius_m)


def _with_landing(
    checks: Sequence[PointCheck], problems: dict[str, Reason]
) -> tuple[PointCheck, ...]:
    """``checks`` with the points whose searches go wrong too often made infeasible."""
    out = []
    for c in checks:
        why = problems.get(c.point_id)
        if why is not None:
            c = replace(c, status="infeasible", landing_cause=why)
        out.append(c)
    return tuple(out)


def plan_quality(
    plan: Plan, mesh: trimesh.Trimesh, fmt: str | None = None
) -> tuple[LayoutQuality | None, str]:
    """The predicted quality of ``plan``'s layout (:mod:`planner.sim.quality`), or why none.

    The measuring program of the controller ``fmt`` (``None``: the default) linearised with the
    plan's noise figures (the program validate executes), its points of interest on the
    work object ``mesh`` (wobj, metres; the default point is the farthest surface point).
    The check and the UI's live panel call this.

    Returns:
        ``(quality, "")``, or ``(None, reason)`` when the plan cannot be predicted (e.g. a
        role missing, a touch probe asked for an edge search).
    """
    from calib.estimators.layout import search_constraint_set
    from calib.estimators.observability import analyze_layout
    from planner.check.simulatable import check_simulatable
    from planner.check.simulation_setup import prediction_setup
    from planner.sim.quality import layout_quality, unobservable_quality
    from planner.sim.report_points import poi_rows

    try:
        probes = [p.to_probe_point() for p in plan.points]
        obs = analyze_layout(search_constraint_set(probes))
        if not obs.observable:  # the quality names the free motions
            return unobservable_quality(obs.messages), ""
        models = check_simulatable(plan)
    except InputError as exc:  # PlanError included
        return None, str(exc)
    try:
        setup = prediction_setup(plan, models, fmt)
        quality = layout_quality(setup, poi_rows(plan.validation.report, mesh))
        return replace(quality, program=setup.program.name), ""
    except (InputError, ProbeFailedError) as exc:
        return None, _named(plan.method, exc)


def _named(method: str, exc: Exception) -> str:
    """``exc``'s message under the procedure's name, once (the procedure's own errors, e.g.
    :func:`calib.procedures.hultman2013.points_by_role`'s, already carry it)."""
    text = str(exc)
    return text if text.startswith(f"{method}: ") else f"{method}: {text}"


def controller_base_problem(plan: Plan, fmt: str | None, T_base_controller: FloatArray) -> str:
    """Why the controller ``fmt``'s program cannot run on a robot whose controller measures
    from ``T_base_controller`` (on the chain's base link), ``""`` when it can: an adaptive A-H
    program on a base turned other than by 0 or 180 deg about z
    (:func:`planner.program.build.ah_base_sign`), as the export refuses it."""
    try:
        program = measuring_program(plan, fmt)
    except InputError:
        return ""  # layout_problem says it
    why = ah_base_problem(program, T_base_controller)
    return f"{plan.method}: {why}" if why else ""


def layout_problem(plan: Plan, fmt: str | None = None) -> str:
    """Why the plan's procedure would refuse its points, ``""`` when it would not.

    A dry run of the measuring program of the controller ``fmt`` (``None``: the default) on the
    nominal part with an exact sensor (:class:`calib.plane_probe.PlaneProbe`, a search that
    finds nothing within its length failing as on the robot): every search commanded as the
    program does (nominal or in the frame estimated so far), and answered where it meets the
    nominal face or edge (an edge search started off the face by ``edge_start_offset_m``
    switches that far off it; the sensor's edge-event offset is added).
    It must accept them (roles, faces, observability) and give back the nominal frame: a
    layout that breaks the procedure's assumptions (e.g. A and B of the A-H procedure not at
    one height) shows as the distance, at the worst point, between the two frames; more than
    :data:`calib.tolerances.FACE_MAX_DEVIATION_M` is a problem.
    """
    if not plan.points:
        return "the plan has no points: nothing to measure"
    kind = procedure_kind(plan.procedure)
    problem = kind.role_problem([p.role for p in plan.points], True)
    if problem:
        return problem
    T = nominal_T_base_wobj(plan)
    try:
        program = measuring_program(plan, fmt)
        probe = PlaneProbe(T, edge_offset_of(program.settings), within_length=True)
        T_est = execute(program, T, probe).T_base_wobj
    except (InputError, ProbeFailedError) as exc:
        return _named(plan.method, exc)
    positions = np.array([p.position_m for p in plan.points], dtype=np.float64)
    off = np.linalg.norm(
        transform_points(T_est, positions) - transform_points(T, positions), axis=1
    )
    worst = int(np.argmax(off))
    if off[worst] > FACE_MAX_DEVIATION_M:
        return (
            f"{plan.method}: from exact measurements of the nominal points the procedure's "
            f"frame moves point {plan.points[worst].id} by {off[worst] * 1e3:.3f} mm: the layout "
            "breaks the procedure's assumptions (see docs/paper_method.md)"
        )
    return ""


def check_points(cell: Cell, plan: Plan, points: Sequence[PlanPoint]) -> tuple[PointCheck, ...]:
    """Check ``points`` (of ``plan``, or edited versions of them) in the plan's open ``cell``.

    The same rules as :func:`check_plan`; a part without any planar face shows as every
    point's ``face_reason``.
    """
    return _check(plan, list(points), cell)[0]


def check_via_moves(cell: Cell, plan: Plan, checks: Sequence[PointCheck]) -> tuple[PointCheck, ...]:
    """``checks`` (of all of ``plan``'s points, in plan order) with the moves between points
    checked.

    For each point: the joint moves into it, from the safe start (where the program leaves a
    point) of every point an exported program probes just before it
    (:func:`planner.program.build.probe_orders`: plan order, and the adaptive RAPID program's A-H
    order with the C and D retakes), through the point's vias if it has any, to its safe start;
    in the open ``cell``. Every exporter moves between points this way (joint moves, fine
    points). The first point of a program has no previous pose and its first leg is not
    checked. A problem makes the point ``infeasible``, with ``via_reason`` (and ``reason``)
    naming the previous point, the via and the pair; a point without vias is told to get one.
    """
    from planner.cell.moves import check_via_path
    from planner.program.build import predecessors

    ids = [p.id for p in plan.points]
    before = predecessors(plan)
    out = list(checks)
    tcp = plan.cell.tool.tcp
    for i, (p, c) in enumerate(zip(plan.points, checks, strict=True)):
        vias = p.via_points
        q_point = c.q_safe if c.pose_status != "infeasible" else None
        problem: Reason | None = None
        for prev in before.get(i, [None]):
            q_prev = None
            if prev is not None and checks[prev].pose_status != "infeasible":
                q_prev = checks[prev].q_safe
            name = "previous point" if prev is None else ids[prev]
            qs = [v.q_rad for v in vias]
            path = check_via_path(cell, q_prev, qs, q_point, tcp, name, point_name=p.id)
            if path.cause is not None:
                problem = path.cause
                break
        if not vias and problem is None:
            continue
        out[i] = replace(
            c,
            n_vias=len(vias),
            via_cause=problem,
            status="infeasible" if problem is not None else c.status,
        )
    return tuple(out)


def _check(plan: Plan, points: list[PlanPoint], cell: Cell) -> tuple[tuple[PointCheck, ...], str]:
    from planner.cell import disk_cache  # the faces' footprint test, kept across commands
    from planner.faces.checks import plan_face_reasons
    from planner.faces.detection import NoPlanarFaceError

    if not points:
        return (), ""
    t0 = time.perf_counter()
    wo = cell.work_object
    if wo is None:
        raise RuntimeError("the plan's cell has no work object")
    probes = [p.to_probe_point() for p in points]
    radius = plan.validation.sensor.footprint_radius_m
    error = ""
    try:
        faces = plan_face_reasons(
            wo.mesh, probes, name=wo.name, footprint_radius_m=radius, cache=disk_cache
        )
    except NoPlanarFaceError as exc:  # the plan cannot work on this part
        error = str(exc)
        faces = [Reason("footprint", error, about_part=True)] * len(points)
    P = np.array([p.position_m for p in points], dtype=float).reshape(-1, 3)
    N = np.array([p.normal for p in points], dtype=float).reshape(-1, 3)
    poses = cell.check_probes(P, N, tcp=plan.cell.tool.tcp)
    T_nom = nominal_T_base_wobj(plan)
    ik_kind = cell.solver.kind
    out = []
    T_flange_tcp = cell.T_flange_tcp(plan.cell.tool.tcp)
    part = f"work object {wo.name}: {wo.report.size_text}"
    safety = safety_spec(plan)
    tcp = plan.cell.tool.tcp
    measured = measured_starts_wobj(plan)
    reach = search_problems(probes, safety, edge_offset_of(plan_settings(plan)))
    for p, probe, pose, face in zip(points, probes, poses, faces, strict=True):
        path = check_program_path(
            cell, probe, pose, T_nom, safety, T_flange_tcp, tcp, measured.get(p.id)
        )
        check = _point_check(cell, p, pose, path, face, ik_kind, t0, T_flange_tcp)
        if p.id in reach:
            check = replace(check, status="infeasible", search_cause=reach[p.id])
        out.append(_with_part_size(check, wo.name, part))
        t0 = time.perf_counter()
    return tuple(out), error


def _point_check(
    cell: Cell,
    p: PlanPoint,
    pose: ProbeFeasibility,
    path: ProgramPath,
    face: Reason | None,
    ik_kind: str,
    t0: float,
    T_flange_tcp: FloatArray,
) -> PointCheck:
    from planner.cell.scene import DEFAULT_MARGIN_M, report_distance_m

    status: Status = pose.status
    if face is not None or not path.feasible:
        status = "infeasible"
    clearance = float(pose.clearance_m)
    capped = math.isfinite(clearance) and clearance >= report_distance_m(DEFAULT_MARGIN_M) - 1e-6
    return PointCheck(
        point_id=p.id,
        role=p.role,
        kind=p.search.kind,
        status=status,
        pose_status=pose.status,
        pose_cause=pose.cause,
        path_feasible=bool(path.feasible),
        path_cause=path.cause,
        path_fail_at_m=float(path.fail_at_m),
        face_cause=face,
        clearance_m=clearance,
        clearance_pair=None if capped else pose.clearance_pair,
        clearance_is_lower_bound=capped,
        confdata=_confdata(cell, pose.q) if pose.feasible else None,
        ik_kind=ik_kind,
        q=None if pose.q is None else np.asarray(pose.q, dtype=float),
        q_path=np.asarray(path.q_path, dtype=float),
        q_safe=path.q_safe,
        T_base_flange=None if pose.T_base_flange is None else np.asarray(pose.T_base_flange),
        elapsed_s=time.perf_counter() - t0,
        T_base_tcp=None
        if pose.T_base_flange is None
        else np.asarray(pose.T_base_flange) @ T_flange_tcp,
        branch=int(pose.branch),
    )


def _with_part_size(check: PointCheck, name: str, part: str) -> PointCheck:
    """The check with the part's size and units added to reasons about the part (out of
    reach, off its surface, no planar face on it: ``about_part``; a collision with it: its
    pair): a part read in the wrong units shows as such."""

    def add(reason: Reason | None) -> Reason | None:
        if reason is None or not (reason.about_part or name in (reason.pair or ())):
            return reason
        return reason.noted(part)

    pose, path, face = add(check.pose_cause), add(check.path_cause), add(check.face_cause)
    if (pose, path, face) == (check.pose_cause, check.path_cause, check.face_cause):
        return check
    return replace(check, pose_cause=pose, path_cause=path, face_cause=face)


def _confdata(cell: Cell, q: FloatArray | None) -> ConfData | None:
    """ABB confdata of joint values ``q``; ``None`` for robots that are not OPW arms."""
    from planner.robot.kinematics.opw_from_urdf import NotOPWError

    if q is None or cell.solver.opw is None:
        return None
    try:
        cf1, cf4, cf6, cfx = cell.solver.abb_confdata(np.asarray(q, float))
    except NotOPWError:
        return None
    return int(cf1), int(cf4), int(cf6), int(cfx)
