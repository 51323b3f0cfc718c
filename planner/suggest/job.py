"""Suggest a probe layout: the one entry point ``wobjcal suggest``, the UI and scripts share.

:func:`suggest_plan` takes a plan (its cell, part, sensor, noise figures, misplacement and
points of interest) and proposes the points:

1. candidates on the part's planar faces whose sensor footprint lies on the face with a
   floor of margin (:mod:`planner.faces.candidates`); approach
   searches started and run long enough for the misplacement
   (:class:`planner.program.safety.SafetySpec`, as the exported programs and the validation's
   preflight size them), so they still hit their face;
   with a sensor that runs edge searches, when the approach candidates together leave a
   motion free or weak, also edge searches toward the straight outer edges of those faces
   (:mod:`planner.faces.edges`; each counts by its edge coordinate only, measured after the
   approaches);
2. feasible in the cell: the probe pose (:meth:`planner.cell.cell.Cell.check_probes`, six
   spread samples per face first, a face whose samples all fail is dropped with the reason)
   and, for every point the design picks, the search path
   (:meth:`~planner.cell.cell.Cell.check_search`; a blocked one is dropped and the design redone);
3. chosen by :func:`calib.estimators.design.select` (greedy plus exchange on the information
   matrix, minimising the largest error over the points of interest), ordered for measuring
   (:mod:`planner.suggest.order`: each point's footprint, grown by the in-plane shift left by
   the points measured before it, the whole misplacement for the first ones, stays on its
   face; points that fit in no order are set aside and the design redone), growing the number of
   points until the predicted error at every point of interest holds ``target_m`` at the
   confidence, or ``max_points`` is reached: the procedure's
   :class:`~calib.procedures.base.LayoutDesign` (its registry entry) says how, a *grown* design
   (best fit, iterative best fit: any number of points, one role) or a *face* design (3-2-1:
   3, 2 and 1 points on every ordered triple of faces far from parallel);
4. via points where a joint move between two of the points would collide
   (:func:`planner.check.vias.plan_with_vias`: retract, or turn the shoulder or elbow);
5. the written plan's quality predicted exactly (:func:`planner.check.job.plan_quality`: the
   program of the chosen format linearised), which is what the result reports;
6. the written plan checked as ``wobjcal check --format`` checks it (poses, paths, moves, search
   reach, landing risk): anything it refuses is named in the message and the result does not
   count as met (``wobjcal suggest`` exits 1).

``add=N`` keeps the plan's points and adds the ``N`` best, for a procedure whose design grows
(a 3-2-1 or A-H plan becomes a plan of that procedure with all its points: those procedures
take exactly their own).

``objective="time"`` (a grown design, with a target) writes instead the plan of least
estimated cycle time whose predicted error holds the target: every size from 6 to
``max_points`` designed, each in its landing order and in the order of least joint-move time,
all written, checked and timed (:mod:`planner.suggest.front`); ``front=True`` returns that
front with either objective.
"""

from __future__ import annotations

import copy
import dataclasses
import math
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import msgspec
import numpy as np
from numpy.typing import NDArray

from calib.errors import InputError
from calib.estimators.design import Design
from calib.estimators.layout import COINCIDENT_TOL_M, search_constraint_set
from calib.plan.bundle import rebased_plan
from calib.plan.file import Plan, PlanError, PlanPoint
from calib.plan.report_spec import PointOfInterest
from calib.probing import ProbePoint, SearchSpec
from calib.procedures import DESIGNED, GROWN, ProcedureKind
from calib.procedures import PROCEDURES as ALL_PROCEDURES
from calib.registry import lookup
from planner.cell import disk_cache
from planner.check.job import check_plan
from planner.check.results import PlanCheck
from planner.check.vias import plan_with_vias
from planner.faces.candidates import Candidates, FaceTried, face_candidates
from planner.faces.detection import find_planar_faces
from planner.faces.edges import edge_candidates
from planner.faces.outline import shared_outlines
from planner.plan_cell import open_cell
from planner.program.controllers import CONTROLLERS, controller
from planner.program.safety import SafetySpec
from planner.sim.report_points import poi_rows
from planner.sim.rows import RowSpec, z_values
from planner.suggest.front import (
    OBJECTIVES,
    FrontRow,
    checked_quality,
    design_front,
    fastest,
    row_of,
    with_written,
)
from planner.suggest.order import FLOOR_M, Sequencer
from planner.suggest.steps import (
    Context,
    SuggestProgress,
    best_fit_design,
    face_design,
    faces_text,
    feasible_poses,
    fixed_rows,
    nothing_message,
    suggested_plan,
)

if TYPE_CHECKING:
    from planner.cell.cell import Cell
    from planner.sim.quality import LayoutQuality

FloatArray = NDArray[np.float64]
#: The procedures suggest designs for: those whose registry entry has a
#: :class:`~calib.procedures.base.LayoutDesign` (:data:`calib.procedures.DESIGNED`).
PROCEDURES = DESIGNED
#: Candidates per planar face (after thinning).
PER_FACE = 40


class SuggestError(PlanError):
    """No layout can be suggested: the message names the faces tried and what stopped them."""


@dataclass(frozen=True)
class SuggestResult:
    """A suggested layout.

    Attributes:
        plan: the plan with the suggested points (and procedure).
        quality: its predicted quality (the procedure linearised), or None.
        target_m: the target half-width at the points of interest, metres (None: none).
        confidence_percent: the level the target and ``worst_m`` are at, percent.
        worst_m: the largest predicted half-width over the points of interest, metres.
        met: the target holds (always True without a target).
        history: ``(points, worst half-width m)`` of the design at each size tried (the
            least-squares model of the searches, before the exact prediction; with
            ``objective="time"``, the exact prediction of each size's plan).
        faces: every planar face tried and what its samples met.
        n_candidates: candidates whose grown footprint lies on their face.
        n_feasible: of those, feasible probe poses in the cell.
        rejected: why the others were dropped: ``{"reach": n, "collision": n, ...}``.
        message: one line for humans: met, or the best reached and why not better.
        elapsed_s: wall time, s.
        pool: the candidates with a feasible probe pose (search paths checked only for the
            ones a design picked).
        problems: what ``wobjcal check`` (of the program of the chosen format) refuses in the
            written plan, one line per point: a move between points not cleared, a search that
            lands off its face too often; ``()`` when it passes. ``met`` is False then.
        objective: ``"accuracy"`` or ``"time"``: what chose the plan.
        front: the accuracy-versus-time front (:mod:`planner.suggest.front`), ``()`` when not
            asked for.
        cycle_s: the written plan's estimated cycle time, s (NaN: not timed).
        check: the written plan's check (``wobjcal check --format``), or None.
    """

    plan: Plan
    quality: LayoutQuality | None
    target_m: float | None
    confidence_percent: float
    worst_m: float
    met: bool
    history: tuple[tuple[int, float], ...]
    faces: tuple[FaceTried, ...] = field(repr=False)
    n_candidates: int
    n_feasible: int
    rejected: dict[str, int]
    message: str
    elapsed_s: float
    pool: Candidates | None = field(default=None, repr=False)
    problems: tuple[str, ...] = ()
    objective: str = "accuracy"
    front: tuple[FrontRow, ...] = field(default=(), repr=False)
    cycle_s: float = math.nan
    check: PlanCheck | None = field(default=None, repr=False)


def _pois(plan: Plan, mesh: object, at_m: FloatArray | None) -> list[RowSpec]:
    spec = plan.validation.report
    if at_m is not None:
        pts = [
            PointOfInterest(name=f"at{i + 1}", position_m=tuple(float(c) for c in p))  # type: ignore[arg-type]
            for i, p in enumerate(np.asarray(at_m, dtype=np.float64).reshape(-1, 3))
        ]
        spec = msgspec.structs.replace(spec, points_of_interest=pts)
    return poi_rows(spec, mesh)  # type: ignore[arg-type]


def _event_var(plan: Plan) -> float:
    """The event variance of one approach search, m^2 (as the design's rows)."""
    s = plan.validation.sensor.search_noise("approach", 0.003).sensor_sigma_m
    return float(s**2 + plan.validation.robot_error.repeatability_sigma_m**2)


def _approaches_weak(pool: Candidates) -> bool:
    """All the approach candidates together leave a motion free or weak (the check's
    rating): edge searches are then worth offering."""
    from calib.estimators.observability import analyze_layout

    if len(pool) == 0:
        return True
    pts = [
        ProbePoint(f"c{i}", tuple(p), tuple(n), SearchSpec("approach"))
        for i, (p, n) in enumerate(zip(pool.positions_m, pool.normals, strict=True))
    ]
    return analyze_layout(search_constraint_set(pts)).rating != "ok"


def suggest_plan(
    plan: Plan,
    plan_dir: Path | None = None,
    *,
    target_m: float | None = None,
    confidence_percent: float | None = None,
    at_m: FloatArray | None = None,
    max_points: int = 8,
    procedure: str = GROWN[0],
    add: int = 0,
    progress: SuggestProgress | None = None,
    cell: Cell | None = None,
    per_face: int = PER_FACE,
    fmt: str | None = None,
    objective: str = "accuracy",
    front: bool = False,
) -> SuggestResult:
    """Suggest the probe points of ``plan`` (see the module docstring).

    Args:
        plan: the plan: cell, work object, validation models and report (its points are
            replaced, or kept with ``add``).
        plan_dir: folder the plan's files resolve against (default: the current folder).
        target_m: the largest predicted half-width at the points of interest, metres.
        confidence_percent: the level of the target (default: the first report level).
        at_m: ``(K, 3)`` points of interest, wobj frame, metres (default: the plan's).
        max_points: most points to suggest (a grown design; a face design takes its own
            number, 3-2-1 six).
        procedure: one of :data:`PROCEDURES` (a procedure with a layout design; default the
            first whose layout grows, the best fit).
        add: keep the plan's points and add this many (a procedure whose design grows; a plan
            of another procedure becomes one of ``procedure`` with all its points,
            :func:`as_procedure`).
        progress: ``progress(stage, done, total)``.
        cell: the plan's open cell (the UI's); ``None`` opens one.
        per_face: candidates per planar face.
        fmt: the controller whose program the layout is designed for (``None``: the
            default): a program that runs every search in the nominal frame lands each one
            anywhere the whole misplacement allows, so every footprint is grown by all of it;
            an adaptive one by what the earlier searches leave.
        objective: ``"accuracy"`` (the least error: points added until the target holds, in
            the order they land in) or ``"time"`` (the least cycle time under ``target_m``;
            a grown design only, not with ``add``).
        front: also return the accuracy-versus-time front (a grown design only, not with
            ``add``).

    Raises:
        SuggestError: no layout can be had (the message names faces and reasons).
        InputError: bad arguments, or a plan file that cannot load.
    """
    kind = designed_procedure(procedure)
    design = kind.design
    assert design is not None  # designed_procedure returns only procedures with a design
    if add and not design.grows:
        raise InputError(
            f"--add works with a procedure whose layout grows ({', '.join(grown_procedures())}; "
            f"{kind.label} takes exactly {design.n_points} points)"
        )
    if target_m is not None and not (math.isfinite(target_m) and target_m > 0):
        raise InputError(f"target: a positive distance, got {target_m!r} m")
    if max_points < 6 and not add:
        raise InputError(f"max_points: a 6-DOF frame needs at least 6 searches, got {max_points}")
    if objective not in OBJECTIVES:
        raise InputError(f"objective: one of {', '.join(OBJECTIVES)}, got {objective!r}")
    if objective == "time" and target_m is None:
        raise InputError(
            "--objective time: the least cycle time under an accuracy target needs the target "
            "(--target MM)"
        )
    if (objective == "time" or front) and (add or not design.grows):
        what = "--add" if add else f"--procedure {procedure}"
        raise InputError(
            f"--objective time and --front design a {kind.label} from 6 to --max-points points; "
            f"{what} fixes the points (leave it out, or use --objective accuracy)"
        )
    if cell is None:
        with open_cell(plan, plan_dir or Path.cwd()) as own:
            return suggest_plan(
                plan,
                target_m=target_m,
                confidence_percent=confidence_percent,
                at_m=at_m,
                max_points=max_points,
                procedure=procedure,
                add=add,
                progress=progress,
                cell=own,
                per_face=per_face,
                fmt=fmt,
                objective=objective,
                front=front,
            )
    converted = ""
    if add and (why := plan.fixed_points()):
        raise InputError(f"--add: {why}")
    if add and plan.method != kind.method:  # 3-2-1 and A-H take exactly their own points
        converted = (
            f"; the plan's procedure {plan.method} takes exactly its own points, so the plan "
            f"written is a {kind.label} of all {len(plan.points) + add}"
            if plan.method not in GROWN
            else f"; the plan written is a {kind.label} of all {len(plan.points) + add}"
        )
        plan = as_procedure(plan, kind)
    target_controller = controller(fmt)
    steered = procedure in target_controller.adaptive_methods
    t0 = time.perf_counter()
    say = progress or (lambda stage, done, total: None)
    wo = cell.work_object
    if wo is None:
        raise InputError("the plan's cell has no work object")
    mesh = wo.mesh
    sensor = plan.validation.sensor
    r = max(float(sensor.footprint_radius_m), 1e-4)
    say("planar faces", 0, 1)
    faces = find_planar_faces(
        mesh, min_area_m2=math.pi * r**2, footprint_radius_m=r, name=wo.name, cache=disk_cache
    )
    try:
        faces.require_any()
    except InputError as exc:
        raise SuggestError(f"no layout: {exc}") from None
    m = plan.validation.misplacement

    def shift(P: FloatArray) -> FloatArray:  # the least any search is off: the floor
        return np.full(len(P), FLOOR_M)

    say("candidates", 0, len(faces.faces))
    cands = face_candidates(faces, r, per_face, shift)
    feasible, rejected = feasible_poses(cell, plan, cands, say)
    tried = cands.faces
    pool = cands.subset(feasible)
    if len(pool) == 0:
        raise SuggestError(nothing_message(tried, rejected, len(cands)))
    outlines = shared_outlines(faces, r)  # the check of the written plan reads them too
    lo, hi = mesh.bounds
    # the most a point moves in its face when the part lies misplaced about its middle
    worst_shift = m.max_translation_m + m.max_angle_rad * float(np.linalg.norm(hi - lo))
    edge_start = r + 2.0 * worst_shift + 0.005
    edge_note = ""
    weak = _approaches_weak(pool)
    if sensor.runs_edge_searches and weak:
        edges = edge_candidates(
            outlines, sorted(set(pool.face.tolist())), r, edge_start, worst_shift + FLOOR_M
        )
        ok_e, rej_e = feasible_poses(cell, plan, edges, say)
        for k, v in rej_e.items():
            rejected[k] = rejected.get(k, 0) + v
        pool = pool.joined(edges.subset(ok_e))
        if not ok_e.any():
            shift_mm = (worst_shift + FLOOR_M) * 1e3
            why = ", ".join(f"{k} {v}" for k, v in sorted(rej_e.items()))
            edge_note = (
                f"; edge searches: {len(edges)} tracks, no feasible pose for any"
                + (f" ({why})" if why else "")
                if len(edges)
                else "; edge searches: none, as no straight square edge of these faces has a "
                f"band clear of holes and other edges from {edge_start * 1e3 + shift_mm:.0f} mm "
                f"inside it to the edge, {2 * shift_mm:.0f} mm wide (the track, moved "
                f"{shift_mm:.1f} mm either way by the misplacement; short or rounded edges get "
                "none)"
            )
    elif weak:
        edge_note = f"; edge searches: none, the {sensor.KIND} sensor runs none"
    if add and plan.points:  # a candidate where a kept point is: the layout refuses the pair
        kept = np.array([p.position_m for p in plan.points], dtype=np.float64)
        gap = np.linalg.norm(pool.positions_m[:, None, :] - kept[None, :, :], axis=-1)
        pool = pool.subset(gap.min(axis=1) >= COINCIDENT_TOL_M)
        if len(pool) == 0:
            raise SuggestError("every feasible candidate lies on a point the plan has already")
    if steered and bool(pool.is_edge.any()):  # its frame update takes approach searches only
        steered = False
    pivot = pool.positions_m.mean(axis=0)  # the probed region: the misplacement's pivot
    safety = SafetySpec(
        max_translation_m=m.max_translation_m,
        max_angle_rad=m.max_angle_rad,
        pivot_wobj_m=(float(pivot[0]), float(pivot[1]), float(pivot[2])),
        sensing_distance_m=sensor.standoff_m,
    )
    rows_poi = _pois(plan, mesh, at_m)
    level = (
        float(confidence_percent)
        if confidence_percent is not None
        else float(rows_poi[0].levels_percent[0])
    )
    z = float(z_values((level,))[0])
    corners = np.array(
        [[x, y, w] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for w in (lo[2], hi[2])]
    )
    fixed = fixed_rows(plan) if add else None
    old = [p.to_probe_point() for p in plan.points] if add else []
    sequencer = Sequencer(
        outlines,
        pool.positions_m,
        pool.normals,
        pool.face,
        m,
        _event_var(plan),
        np.array([p.position_m for p in old]).reshape(-1, 3),
        np.array([p.normal for p in old]).reshape(-1, 3),
        pool.is_edge,
        steered=steered,
    )
    ctx = Context(cell, plan, pool, safety, rows_poi, z, r, corners, sequencer, tuple(old))
    ctx.edge_start_m, ctx.edge_overtravel_m = edge_start, 2.0 * worst_shift + 0.02
    ctx.edge_note = edge_note
    if objective == "time":
        return _fastest_plan(
            ctx, plan, kind, target_m, max_points, at_m, level, fmt, t0, tried, len(cands),
            rejected, say,
        )  # fmt: skip
    new_plan, design_note, check, history = _design_until_checked(
        ctx, plan, kind, target_m, max_points, add, fixed, at_m, steered, fmt, tried, say
    )
    say("prediction", 0, 1)
    quality, note = checked_quality(new_plan, check, mesh, fmt)
    worst = quality.worst_poi_m(level) if quality is not None else math.nan
    met = target_m is None or (math.isfinite(worst) and worst <= target_m)
    n = len(new_plan.points)
    if met:
        msg = (
            f"{n} points: predicted error at the points of interest {worst * 1e3:.3f} mm "
            f"at {level:g} %"
        )
    else:
        msg = (
            f"target {(target_m or 0.0) * 1e3:.3f} mm at {level:g} % not reached: the best "
            "layout of "
            f"{n} points gives {worst * 1e3:.3f} mm ("
            + ("more points: --max-points; or " if design.grows else "")
            + "a smaller noise or misplacement)"
        )
    if note:
        msg += f" ({note})"
    msg += design_note + converted
    problems = check.refusals()
    if problems:
        met = False
        msg += (
            f"; wobjcal check refuses it for the {target_controller.label} program: "
            + "; ".join(problems)
        )
    rows: tuple[FrontRow, ...] = ()
    if front:  # the plan written marked (or added, when a redesign made it differ)
        drawn = design_front(
            ctx, plan, kind, max_points=max_points, fmt=fmt, at_m=at_m, level_percent=level,
            target_m=target_m, say=say,
        )  # fmt: skip
        rows = tuple(with_written(drawn, row_of(new_plan, check, quality, level, target_m)))
    return SuggestResult(
        plan=new_plan,
        quality=quality,
        target_m=target_m,
        confidence_percent=level,
        worst_m=worst,
        met=met,
        history=tuple(history),
        faces=tried,
        n_candidates=len(cands),
        n_feasible=len(pool),
        rejected=rejected,
        message=msg,
        elapsed_s=time.perf_counter() - t0,
        pool=pool,
        problems=problems,
        front=rows,
        cycle_s=check.cycle.total_s if check.cycle is not None else math.nan,
        check=check,
    )


def _fastest_plan(
    ctx: Context,
    plan: Plan,
    kind: ProcedureKind,
    target_m: float | None,
    max_points: int,
    at_m: FloatArray | None,
    level: float,
    fmt: str | None,
    t0: float,
    tried: tuple[FaceTried, ...],
    n_candidates: int,
    rejected: dict[str, int],
    say: SuggestProgress,
) -> SuggestResult:
    """``objective="time"``: the front, and its fastest row that meets the target (or, when
    none does, the usable row of least error, else the first, with ``met`` False and why)."""
    rows = design_front(
        ctx, plan, kind, max_points=max_points, fmt=fmt, at_m=at_m, level_percent=level,
        target_m=target_m, say=say,
    )  # fmt: skip
    if not rows:
        why = _no_layout(ctx, plan, ctx.sequencer is not None and ctx.sequencer.steered, fmt,
                         tried, {})  # fmt: skip
        raise SuggestError(why)
    best = fastest(rows)
    met = best is not None
    if best is None:  # the most accurate: of those check passes, else of those predicted
        pool = [r for r in rows if r.usable] or [r for r in rows if math.isfinite(r.worst_m)]
        best = min(pool or rows, key=lambda r: (r.worst_m, r.cycle_s, r.points))
    rows = with_written(rows, best)
    same = [r for r in rows if r.points == best.points and r.order == "landing"]
    was = (
        f" (in the order it lands in: {same[0].cycle_s:.1f} s)"
        if best.order == "time" and same and math.isfinite(same[0].cycle_s)
        else ""
    )
    tgt = f"{(target_m or 0.0) * 1e3:.3f} mm"
    if met:
        msg = (
            f"{best.points} points, the least cycle time under the target {tgt} at {level:g} %: "
            f"{best.cycle_s:.1f} s{was}, predicted error at the points of interest "
            f"{best.worst_m * 1e3:.3f} mm"
        )
    else:
        err = f"{best.worst_m * 1e3:.3f} mm" if math.isfinite(best.worst_m) else "no prediction"
        took = f" in {best.cycle_s:.1f} s" if math.isfinite(best.cycle_s) else ""
        msg = (
            f"target {tgt} at {level:g} % not reached by any of the {len(rows)} plans of 6 to "
            f"{max_points} points written, checked and timed: the most accurate "
            f"({best.points} points) gives {err}{took} (more points: --max-points; or a smaller "
            "noise or misplacement)"
        )
    problems = best.problems
    if problems:
        msg += f"; wobjcal check refuses it for the {controller(fmt).label} program: " + "; ".join(
            problems
        )
    history = tuple((r.points, r.worst_m) for r in rows if r.order == "landing")
    return SuggestResult(
        plan=best.plan,
        quality=best.quality,
        target_m=target_m,
        confidence_percent=level,
        worst_m=best.worst_m,
        met=met and not problems,
        history=history,
        faces=tried,
        n_candidates=n_candidates,
        n_feasible=len(ctx.pool),
        rejected=rejected,
        message=msg,
        elapsed_s=time.perf_counter() - t0,
        pool=ctx.pool,
        problems=problems,
        objective="time",
        front=tuple(rows),
        cycle_s=best.cycle_s,
        check=best.check,
    )


def designed_procedure(method: str) -> ProcedureKind:
    """The registry entry of a procedure suggest designs for (:data:`PROCEDURES`).

    Raises:
        InputError: no such procedure, or one without a layout design (the message lists the
            ones suggest designs for).
    """
    designed = {m: ALL_PROCEDURES[m] for m in PROCEDURES}
    return lookup(designed, method, "procedure to suggest (--procedure)")


def grown_procedures() -> tuple[str, ...]:
    """The procedures whose layout suggest grows point by point (``--add``, ``--objective
    time``): :data:`calib.procedures.GROWN`."""
    return GROWN


def as_procedure(plan: Plan, kind: ProcedureKind) -> Plan:
    """``plan`` with its points kept as they are, each with the role of ``kind``'s grown design
    and ``kind`` as its procedure (its default settings, the same edge-event offset): what
    ``--add`` grows a 3-2-1 or A-H plan into.

    Raises:
        InputError: ``kind``'s layout does not grow (it takes a fixed set of points).
    """
    if kind.design is None or not kind.design.grows:
        raise InputError(f"{kind.label} takes a fixed set of points: no plan grows into it")
    offset = getattr(plan.procedure, "edge_event_offset_m", None)
    return msgspec.structs.replace(
        plan,
        points=[msgspec.structs.replace(p, role=kind.design.role) for p in plan.points],
        procedure=kind.settings_type(edge_event_offset_m=offset),
    )


#: Designs redone, at most, with the candidates ``wobjcal check`` refused in the written plan
#: set aside (a search landing off its face, a move between points not cleared).
REDESIGNS = 3


def _design_until_checked(
    ctx: Context,
    plan: Plan,
    kind: ProcedureKind,
    target_m: float | None,
    max_points: int,
    add: int,
    fixed: tuple[FloatArray, FloatArray] | None,
    at_m: FloatArray | None,
    steered: bool,
    fmt: str | None,
    tried: tuple[FaceTried, ...],
    say: SuggestProgress,
) -> tuple[Plan, str, PlanCheck, list[tuple[int, float]]]:
    """Design, add the vias, check the written plan as ``wobjcal check --format`` does; while
    check refuses points of it, set their candidates aside and design again (at most
    :data:`REDESIGNS` times), so a suggestion never proposes a point check refuses when another
    layout exists.

    Returns:
        The last written plan, a note for the message (what was set aside, the moves not
        cleared), its check, and the design history.

    Raises:
        SuggestError: no layout fixes all six degrees of freedom with the candidates left.
    """
    set_aside: dict[str, str] = {}
    for attempt in range(REDESIGNS + 1):
        design, history = _design(ctx, kind, target_m, max_points, add, fixed, say)
        if design is None:
            why = _no_layout(ctx, plan, steered, fmt, tried, set_aside)
            change = _smallest_change(ctx, plan, kind, max_points, add, fixed, fmt)
            raise SuggestError(why + (f". {change}" if change else ""))
        new_plan = suggested_plan(plan, ctx, design, kind, add, at_m)
        say("moves between points", 0, 1)
        vias_before = {p.id: p.via_points for p in new_plan.points}
        new_plan, via_notes = plan_with_vias(new_plan, ctx.cell)
        say("check", 0, 1)
        check = check_plan(new_plan, cell=ctx.cell, fmt=fmt)
        say("check", 1, 1)
        kept = {p.id for p in plan.points} if add else set()
        refused = [c for c in check.infeasible if c.point_id not in kept]
        if not refused or attempt == REDESIGNS:
            break
        by_id = {p.id: p for p in new_plan.points}
        before = len(set_aside)
        for c in refused:
            i = _candidate_of(ctx.pool, by_id[c.point_id])
            if i is None:  # not a candidate (a kept point): nothing to set aside
                continue
            ctx.path_ok[i] = False  # the design never picks it again
            ctx.path_why[i] = c.reason
            set_aside[_where(ctx.pool, i)] = c.search_reason or c.reason
        if len(set_aside) == before:  # nothing new to leave out: the same design again
            break
    note = ""
    if set_aside:
        note = f"; {len(set_aside)} candidates check refused were set aside"
    # the moves not cleared: the points plan_with_vias named but gave no (new) vias
    stuck = [
        f"{p.id}: {via_notes[p.id]}"
        for p in new_plan.points
        if p.id in via_notes and p.via_points == vias_before[p.id]
    ]
    if stuck:
        note += "; moves between points not cleared: " + "; ".join(stuck)
    return new_plan, note, check, history


def _design(
    ctx: Context,
    kind: ProcedureKind,
    target_m: float | None,
    max_points: int,
    add: int,
    fixed: tuple[FloatArray, FloatArray] | None,
    say: SuggestProgress,
) -> tuple[Design | None, list[tuple[int, float]]]:
    """The design of ``kind``'s layout design: grown to the target, or over faces."""
    design = kind.design
    assert design is not None
    if design.grows:
        return best_fit_design(ctx, target_m, max_points, add, fixed, say)
    return face_design(ctx, design.face_roles, say)


#: Fractions of the plan's misplacement bound tried, largest first, to say at which bound a
#: layout exists when none does at the plan's.
BOUND_FRACTIONS = (0.75, 0.5, 0.35, 0.25, 0.15, 0.1)


def _smallest_change(
    ctx: Context,
    plan: Plan,
    kind: ProcedureKind,
    max_points: int,
    add: int,
    fixed: tuple[FloatArray, FloatArray] | None,
    fmt: str | None,
) -> str:
    """What would make a layout exist when none does: an adaptive program where the chosen
    controller's is nominal (another controller that steers the procedure), else the largest
    misplacement bound (a fraction of the plan's, :data:`BOUND_FRACTIONS`) at which the same
    candidates give one. Footprints and order are judged at that bound; the search paths keep
    the verdicts already found (sized for the plan's bound: a smaller bound only shortens them)
    and paths not yet walked count as clear, so a layout found there is the one to try, not yet
    checked."""
    assert ctx.sequencer is not None

    def exists(sequencer: Sequencer) -> bool:
        trial = dataclasses.replace(
            ctx, sequencer=sequencer, path_ok=dict(ctx.path_ok), path_why=dict(ctx.path_why),
            off_face=set(), check_paths=False,
        )  # fmt: skip
        quiet: SuggestProgress = lambda stage, done, total: None  # noqa: E731
        design, _ = _design(trial, kind, None, max_points, add, fixed, quiet)
        return design is not None

    base = ctx.sequencer
    m = plan.validation.misplacement
    label = f"the {controller(fmt).label} program"
    out = []
    if not base.steered and not bool(ctx.pool.is_edge.any()):
        adaptive = [c.name for c in CONTROLLERS.values() if kind.method in c.adaptive_methods]
        if adaptive and exists(_scaled(base, 1.0, steered=True)):
            out.append(
                f"An adaptive program has a layout at this bound: --format {adaptive[0]} "
                f"(the {controller(fmt).label} program runs every search in the nominal frame)"
            )
    # the largest fraction with a layout, by bisection (a smaller bound only shrinks the
    # footprints' growth): the smallest first, so a part with none costs one design
    fractions = sorted(BOUND_FRACTIONS)
    lo, hi = -1, len(fractions)  # fractions[lo] has a layout, fractions[hi] has none
    if exists(_scaled(base, fractions[0], steered=base.steered)):
        lo = 0
        while hi - lo > 1:
            mid = (lo + hi) // 2
            if exists(_scaled(base, fractions[mid], steered=base.steered)):
                lo = mid
            else:
                hi = mid
    if lo >= 0:
        f = fractions[lo]
        out.append(
            f"For {label} the footprints fit a layout at a misplacement bound of "
            f"{f * m.max_translation_m * 1e3:.1f} mm and "
            f"{math.degrees(f * m.max_angle_rad):.2f} deg ({f:.0%} of the plan's; its search "
            "paths not yet walked at that bound: run suggest with it): place the part more "
            "tightly, or measure it first coarsely (e.g. three touch-up points) and give that "
            "bound"
        )
    else:
        out.append(
            f"For {label} no layout exists even at {fractions[0]:.0%} of the plan's "
            "misplacement bound: the faces the sensor can reach are too small or too few for it"
        )
    return ". ".join(out)


def _scaled(base: Sequencer, f: float, *, steered: bool) -> Sequencer:
    """A copy of ``base`` for a misplacement bound ``f`` times its own."""
    out = copy.copy(base)
    out.a, out.b, out.steered = base.a * f, base.b * f, steered
    return out


def _candidate_of(pool: Candidates, point: PlanPoint) -> int | None:
    """The pool index of the candidate ``point`` was written from (same position and normal)."""
    d = np.linalg.norm(pool.positions_m - np.asarray(point.position_m), axis=1)
    i = int(np.argmin(d)) if len(d) else -1
    if i < 0 or d[i] > 1e-9 or float(pool.normals[i] @ np.asarray(point.normal)) < 1.0 - 1e-9:
        return None
    return i


def _where(pool: Candidates, i: int) -> str:
    p = pool.positions_m[i] * 1e3
    return f"({p[0]:.1f}, {p[1]:.1f}, {p[2]:.1f}) mm"


def _no_layout(
    ctx: Context,
    plan: Plan,
    steered: bool,
    fmt: str | None,
    tried: tuple[FaceTried, ...],
    set_aside: dict[str, str],
) -> str:
    """Why no layout exists: per face what removed its candidates, and what to change."""
    m = plan.validation.misplacement
    label = controller(fmt).label
    text = (
        "no layout fixes all 6 degrees of freedom with the feasible candidates (each "
        "footprint grown by the in-plane shift it has when measured: the whole "
        f"misplacement, {m.max_translation_m * 1e3:.1f} mm and "
        f"{math.degrees(m.max_angle_rad):.2f} deg, for "
        + (
            "the first points"
            if steered
            else f"every point, as the {label} program runs every search in the nominal frame"
        )
        + "): "
        + faces_text(tried, ctx.pool, ctx)
        + ctx.edge_note
    )
    if set_aside:
        text += "; set aside after wobjcal check refused them: " + "; ".join(
            f"{where}: {why}" for where, why in set_aside.items()
        )
    return text


def moved_plan(plan: Plan, from_dir: Path, to_dir: Path) -> Plan:
    """``plan`` with its file references (robot, its ROS package path, tool, work object,
    fixture meshes) made relative to ``to_dir`` instead of ``from_dir`` (``builtin:``
    references unchanged), so a plan written into another folder still finds its files:
    :func:`calib.plan.bundle.rebased_plan`, under the name the CLI and scripts know."""
    return rebased_plan(plan, from_dir, to_dir)
