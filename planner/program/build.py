"""A plan plus a controller gives exactly one measuring program: :func:`measuring_program`.

The program is adaptive when the controller computes the plan's procedure's frame update
(:attr:`planner.program.controllers.Controller.adaptive_methods`) and the plan has every role
the procedure steers by; else every search runs once, in plan order, in the nominal frame, and
``wobjcal calibrate`` computes the frame from the recorded points. An adaptive program's order
(retakes included) and where it updates its estimate come from a dry run of the procedure itself
on the ideal nominal part, never from a second copy of its logic.

Also here, because every face needs them from the same place: the misplacement tolerance the
safe starts are computed for (:func:`safety_spec`), the A-H specifics an adaptive RAPID program
is written from (:func:`adaptive_spec`), and the orders in which any exported program probes the
points (:func:`probe_orders`, :func:`predecessors`: the moves ``wobjcal check`` walks).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from calib.errors import InputError, ProbeFailedError
from calib.frames import small_motion
from calib.paper.settings import Hultman2013
from calib.plan.file import Plan
from calib.plane_probe import PlaneProbe
from calib.probing import ProbeResult, SearchCommand
from calib.procedures import RolePoint, procedure_kind
from calib.procedures.base import edge_offset_of
from planner.program.controllers import CONTROLLERS, Controller, controller
from planner.program.model import (
    FACE_APPROACH,
    FrameStep,
    MeasuringProgram,
    MoveStep,
    SearchStep,
    Step,
    UpdateStep,
    search_keys,
)
from planner.program.safety import SafetySpec
from planner.program.settings import resolved_settings
from planner.program.steering import STEERED_METHODS, layout_pivot_scale, update_groups


def safety_spec(plan: Plan) -> SafetySpec:
    """The misplacement tolerance and sensing distance of ``plan``'s validation settings.

    The rotation pivot is the centroid of the probe points, as in ``wobjcal validate``. A plan
    whose searches are sized for an adaptive program (``search_sizing: "steered"``) gets the
    bounds of its later searches (:func:`planner.program.steered_searches.steered_safety`).
    """
    from planner.program.steered_searches import steered_safety

    v = plan.validation
    pivot = np.mean([p.position_m for p in plan.points], axis=0) if plan.points else np.zeros(3)
    whole = SafetySpec(
        max_translation_m=v.misplacement.max_translation_m,
        max_angle_rad=v.misplacement.max_angle_rad,
        pivot_wobj_m=(float(pivot[0]), float(pivot[1]), float(pivot[2])),
        sensing_distance_m=v.sensor.standoff_m,
    )
    return steered_safety(plan, whole) if plan.steered_searches else whole


def plan_settings(plan: Plan) -> Any:
    """The plan's procedure settings as every program computes with them: an unset edge-event
    offset resolved from the plan's sensor (:func:`planner.program.settings.resolved_settings`).
    """
    return resolved_settings(plan.procedure, plan.validation.sensor)


def measuring_program(plan: Plan, controller_name: str | None = None) -> MeasuringProgram:
    """The program ``controller_name`` (default :data:`~planner.program.controllers.
    DEFAULT_CONTROLLER`) runs for ``plan``.

    Raises:
        InputError: unknown controller; or an adaptive program whose procedure refuses the
            plan's layout on the ideal part (the message says why).
    """
    vias = {p.id: len(p.via_points) for p in plan.points}
    return build_program(
        plan.role_points(),
        plan_settings(plan),
        safety_spec(plan),
        controller(controller_name),
        vias,
    )


def build_program(
    points: Sequence[RolePoint],
    settings: object,
    safety: SafetySpec,
    target: Controller,
    vias: Mapping[str, int] | None = None,
) -> MeasuringProgram:
    """The program ``target`` runs for ``points`` with the procedure of ``settings``.

    Args:
        points: the plan's points with their roles, wobj frame.
        settings: the procedure's settings struct (its type names the procedure).
        safety: the misplacement tolerance the safe starts are computed for.
        target: the controller.
        vias: ``{point id: number of vias}``.
    """
    kind = procedure_kind(settings)  # type: ignore[arg-type]
    steers = kind.method in target.adaptive_methods
    why = target.why_nominal
    pivot: tuple[float, float, float] | None = None
    scale = 0.0
    if kind.method in STEERED_METHODS:
        edges = [rp.point.id for rp in points if rp.point.search.kind == "edge"]
        adaptive = steers and not edges
        if steers and edges:
            why = f"its frame update takes approach searches only (edge searches: {edges})"
        if adaptive:
            ordered = kind.assign(points)
            c, scale = layout_pivot_scale([rp.point for rp in ordered])
            pivot = (float(c[0]), float(c[1]), float(c[2]))
            steps = _steered_steps(ordered, kind.method, vias or {})
    else:
        adaptive = steers and kind.adaptive_layout(points) is not None
        if steers and not adaptive:
            why = "the plan lacks a role the update needs"
        if adaptive:
            steps = _adaptive_steps(points, kind.method, settings, vias or {})
    if safety.steered and not (adaptive and kind.method in STEERED_METHODS):
        runs = (
            f"the {target.label} program runs every search in the nominal frame ({why})"
            if not adaptive
            else f"its {kind.label} program is not steered search by search"
        )
        raise InputError(
            "the plan's searches are sized for an adaptive best-fit or 3-2-1 program "
            f'(search_sizing "steered": later searches start nearer), but {runs}: set '
            'search_sizing to "whole" and give each search the start offset and overtravel '
            "wobjcal check then asks for (or wobjcal suggest --objective accuracy)"
        )
    note = "" if adaptive else f"every search once, in the nominal frame: {why}"
    if not adaptive:
        steps = _nominal_steps(points, vias or {})
    steps.append(FrameStep(on_controller=adaptive, method_label=kind.label))
    return MeasuringProgram(
        controller=target,
        method=kind.method,
        method_label=kind.label,
        steering="adaptive" if adaptive else "nominal",
        steps=tuple(steps),
        safety=safety,
        points=tuple(points),
        settings=settings,
        note=note,
        pivot_m=pivot,
        scale_m=scale,
    )


def _point_steps(
    point_id: str, key: str, kind: str, frame: Literal["nominal", "estimate"], n_vias: int
) -> list[Step]:
    """The move into a point and its searches (an edge point approaches its face first)."""
    f = frame
    steps: list[Step] = [MoveStep(point_id, n_vias)]
    if kind == "edge":
        steps.append(
            SearchStep(key + FACE_APPROACH, point_id, "approach", f, "safe start", recorded=False)
        )
        steps.append(SearchStep(key, point_id, "edge", f, "measured face point"))
    else:
        steps.append(SearchStep(key, point_id, "approach", f, "safe start"))
    return steps


def _steered_steps(
    ordered: Sequence[RolePoint], method: str, vias: Mapping[str, int]
) -> list[Step]:
    """The program of a procedure it steers itself (:mod:`planner.program.steering`): the
    points in ``ordered`` order, each search in the estimate so far, its updates between."""
    ids = [rp.point.id for rp in ordered]
    after = {len(g): g for g in update_groups(method, ids)}
    steps: list[Step] = []
    since: list[str] = []
    for k, rp in enumerate(ordered, start=1):
        frame: Literal["nominal", "estimate"] = "estimate" if len(since) < k - 1 else "nominal"
        steps += _point_steps(rp.point.id, rp.point.id, "approach", frame, vias.get(rp.point.id, 0))
        since.append(rp.point.id)
        if k in after:
            steps.append(UpdateStep(tuple(since), uses=after[k]))
            since = []
    return steps


def _nominal_steps(points: Sequence[RolePoint], vias: Mapping[str, int]) -> list[Step]:
    steps: list[Step] = []
    for rp in points:
        p = rp.point
        steps += _point_steps(p.id, p.id, p.search.kind, "nominal", vias.get(p.id, 0))
    return steps


#: The small misplacement of the dry run (m, rad): well inside any plan's bound.
_DRY_RUN_MOTION = np.array([4e-4, -3e-4, 5e-4, 2e-3, -1.5e-3, 1e-3])


@dataclass
class _Recorder:
    """A probe on the ideal nominal part that records each command (the dry run)."""

    ideal: PlaneProbe
    commands: list[SearchCommand]

    def __call__(self, cmd: SearchCommand) -> ProbeResult:
        self.commands.append(cmd)
        return self.ideal(cmd)


def _adaptive_steps(
    points: Sequence[RolePoint], method: str, settings: object, vias: Mapping[str, int]
) -> list[Step]:
    """The steps of the procedure run adaptively: its own dry run on the ideal part, each
    command a search (an estimate update wherever the commanded frame changed)."""
    kind = procedure_kind(method)
    T = np.eye(4)
    # the part a little off its nominal pose: every update moves the estimate (on the nominal
    # part some would leave it bit for bit where it was, and go unseen)
    rec = _Recorder(PlaneProbe(small_motion(_DRY_RUN_MOTION), edge_offset_of(settings)), [])
    try:
        kind.run(list(points), T, rec, settings)
    except (InputError, ProbeFailedError) as exc:
        raise InputError(f"the adaptive {kind.label} program refuses the layout: {exc}") from exc
    keys = search_keys(points)
    by_id = {rp.point.id: rp.point for rp in points}
    steps: list[Step] = []
    since: list[str] = []
    last = T
    for cmd in rec.commands:
        if not np.array_equal(cmd.T_base_wobj_estimate, last) and since:
            steps.append(UpdateStep(tuple(since)))
            since = []
        last = cmd.T_base_wobj_estimate
        pid = keys.get(cmd.point_id, cmd.point_id)
        point = by_id[pid]
        plan_start = SearchCommand.from_point(point, last).start_m
        updated = any(isinstance(s, UpdateStep) for s in steps)
        frame: Literal["nominal", "estimate"] = "estimate" if updated else "nominal"
        if point.search.kind == "edge" and not np.allclose(cmd.start_m, plan_start, atol=1e-9):
            steps += [
                MoveStep(pid, vias.get(pid, 0)),
                SearchStep(cmd.point_id, pid, "edge", frame, "measured point"),
            ]
        else:
            steps += _point_steps(pid, cmd.point_id, point.search.kind, frame, vias.get(pid, 0))
        since.append(cmd.point_id)
    return steps


def programs(plan: Plan) -> list[MeasuringProgram]:
    """The program of every controller for ``plan`` (those whose procedure refuses the layout
    left out: no program runs it)."""
    out = []
    for name in CONTROLLERS:
        try:
            out.append(measuring_program(plan, name))
        except InputError:
            continue
    return out


@dataclass(frozen=True)
class AdaptiveSpec:
    """A procedure the program runs adaptively: the paper's A-H (``hultman2013`` plans).

    Attributes:
        index: ``{role: i}`` the target index (0-based, plan order) of each role ``A``..``H``.
        settings: the plan's A-H settings, an unset edge-event offset resolved
            (:func:`planner.program.settings.resolved_settings`, as every face resolves it).
        face_coords_wobj: x of the side face, y of the short side, z of the top, wobj, m.
    """

    index: dict[str, int]
    settings: Hultman2013
    face_coords_wobj: tuple[float, float, float]


#: Why an adaptive A-H program is refused on a controller whose base is turned other than by
#: 0 or 180 deg about z from the robot's base link (:func:`ah_base_sign`).
AH_TURNED_BASE = (
    "the adaptive A-H program computes P3 (eq. 11-12) from the side face's lean towards the "
    "controller's base +x, and this controller's base frame is turned from the robot's base "
    "link other than by 180 deg about z, so its searches would not be the ones check and "
    "validate judge; use a best-fit or 3-2-1 procedure"
)


def ah_base_sign(T_base_controller: ArrayLike) -> float | None:
    """The sign ``beta1`` takes in the controller's base frame, for the adaptive A-H program.

    Eq. 11-12's P3 is the one step of the procedure that reads the base's axes (the side face
    leans by ``beta1`` towards base +x); every other step is built from the measured points
    alone, the same in any frame turned about z or shifted. ``1.0``: the controller's base is
    the robot's base link turned by nothing (shifted at most); ``-1.0``: turned 180 deg about z
    (a UR arm's Base: the face leans towards its -x); ``None``: turned otherwise (the adaptive
    A-H program cannot run its searches there: :data:`AH_TURNED_BASE`).
    """
    R = np.asarray(T_base_controller, dtype=np.float64)[:3, :3]
    if np.allclose(R, np.eye(3), rtol=0.0, atol=1e-9):
        return 1.0
    if np.allclose(R, np.diag([-1.0, -1.0, 1.0]), rtol=0.0, atol=1e-9):
        return -1.0
    return None


def ah_base_problem(program: MeasuringProgram, T_base_controller: ArrayLike) -> str:
    """:data:`AH_TURNED_BASE` when ``program`` is an adaptive A-H program (its frame updates
    are the procedure's steps) and the controller's base is turned so that it cannot run it
    (:func:`ah_base_sign`); ``""`` otherwise. Check and export refuse by this one rule."""
    ah = program.adaptive and not program.steers_itself
    return AH_TURNED_BASE if ah and ah_base_sign(T_base_controller) is None else ""


def adaptive_spec(plan: Plan) -> AdaptiveSpec | None:
    """The A-H specifics an adaptive program is written from, or ``None``: the procedure has
    no adaptive layout, or the plan lacks a role."""
    layout = procedure_kind(plan.procedure).adaptive_layout(plan.role_points())
    if layout is None or not isinstance(plan.procedure, Hultman2013):
        return None
    face = layout.face_coords_wobj
    return AdaptiveSpec(
        index={p.role: i for i, p in enumerate(plan.points)},
        settings=plan_settings(plan),
        face_coords_wobj=(float(face[0]), float(face[1]), float(face[2])),
    )


def probe_orders(plan: Plan) -> list[list[int]]:
    """Every order (point indices, plan order numbering) in which an exported program probes
    the plan's points: the :attr:`~MeasuringProgram.probe_order` of every controller's program
    (plan order for a nominal one; A-H with the C and D retakes for the adaptive RAPID one).
    The moves into a point's vias come from the point before it in each of these orders
    (``wobjcal check`` checks them all)."""
    index = {p.id: i for i, p in enumerate(plan.points)}
    orders = [list(range(len(plan.points)))]
    for prog in programs(plan):
        order = [index[i] for i in prog.probe_order]
        if order not in orders:
            orders.append(order)
    return orders


def predecessors(plan: Plan) -> dict[int, list[int | None]]:
    """``{point index: [the index of each point a program probes just before it]}`` over
    :func:`probe_orders` (``None``: the point starts a program)."""
    before: dict[int, list[int | None]] = {}
    for order in probe_orders(plan):
        for k, i in enumerate(order):
            prev = order[k - 1] if k else None
            if prev not in before.setdefault(i, []):
                before[i].append(prev)
    return before
