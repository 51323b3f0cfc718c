"""The results of the one plan check (:mod:`planner.check.job`): a point's and a whole plan's.

Frozen dataclasses that the command line prints (table and ``--json``), the web UI colours its
markers and table with, and ``wobjcal export`` takes orientations and configurations from. A
point's reasons are :class:`planner.reasons.Reason` s, one per check that fails (the pose, its
search path, the face, the search under the misplacement, the moves into it, the landing),
each with its kind; the words (``reason``, ``pose_reason``, ...) are made from them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import NDArray

from planner.reasons import Reason, joined

if TYPE_CHECKING:
    from calib.estimators.gross_errors import Detectability
    from planner.program.cycle_time import CycleTime
    from planner.sim.landing import LandingRisk
    from planner.sim.quality import LayoutQuality

FloatArray = NDArray[np.float64]
Status = Literal["feasible", "marginal", "infeasible"]
#: ABB ``confdata`` (cf1, cf4, cf6, cfx).
ConfData = tuple[int, int, int, int]
#: What the point's words say after a move problem of a point without vias.
ADD_VIAS = " (add via points: Teach tab, or `wobjcal check --add-vias`)"


@dataclass(frozen=True)
class PointCheck:
    """The check of one probe point and its search.

    Attributes:
        point_id: the plan's point id.
        role: its role in the procedure.
        kind: ``"approach"`` or ``"edge"`` search.
        status: ``feasible``, ``marginal`` or ``infeasible``: the pose, the path and the face
            together (see the module docstring).
        pose_status: the probe pose alone.
        pose_cause: why the pose is marginal or infeasible (``None`` when feasible): ``reach``,
            ``joint_limit``, ``singularity`` or ``collision`` (with its pair).
        path_feasible: the whole search path can be run.
        path_cause: why not, with the distance along the path (``None`` when feasible), of
            the kinds a pose has.
        path_fail_at_m: distance of the first failing sample from the start of its search (the
            program's: from the safe start), m (NaN when the path is feasible).
        face_cause: why the point is not on a planar face with the sensor footprint on it, a
            ``footprint`` reason (``None`` when it is).
        clearance_m: clearance of the limiting pair at the chosen pose, m (NaN: no pose);
            nothing nearer than the query's look-ahead when ``clearance_is_lower_bound``.
        clearance_pair: ``(robot or tool link, obstacle)`` of that clearance, or ``None``.
        clearance_is_lower_bound: the clearance is the look-ahead distance (nothing nearer).
        confdata: ABB ``(cf1, cf4, cf6, cfx)`` of the chosen IK branch (OPW arms, feasible or
            marginal pose), else ``None``.
        ik_kind: the cell's IK: ``"opw"`` (analytic) or ``"numeric"``.
        q: ``(n,)`` joint values of the chosen (or least-bad) pose, rad; ``None`` when no IK.
        q_path: ``(M, n)`` joint values along the path samples that passed, rad, or ``None``:
            the program's searches in order (:mod:`planner.check.paths`).
        T_base_flange: ``(4, 4)`` flange pose of ``q``, robot base frame, m, or ``None``.
        elapsed_s: time this point's check took, s.
        T_base_tcp: ``(4, 4)`` the probing TCP at ``q`` (through the tool's mount), robot base
            frame, m, or ``None``.
        q_safe: ``(n,)`` joint values at the point's safe start (where the program arrives
            and leaves from), rad; ``None`` when it has none.
        n_vias: how many via points the plan gives the point (``points[i].vias``).
        via_cause: why the moves from the previous point through the vias to this point
            cannot be run (a via outside the joint limits, a leg that collides, naming the via
            and the clearance pair), a ``move`` reason; ``None`` when clear or not checked
            (:func:`planner.cell.moves.check_via_path`).
        search_cause: why the point's search cannot reach its face or edge wherever the
            part may lie (:func:`planner.program.reach.search_problems`), a ``search``
            reason; ``None`` when it can.
        landing_cause: how likely the point's search is to fail or land off its face under
            the misplacement (:meth:`planner.sim.landing.LandingRisk.point_problems`), a
            ``search`` reason; ``None`` when rarely enough.
        branch: the IK branch of ``q`` (OPW configuration 0-7; -1 unknown or none): the
            configuration every program runs the point in (ABB ``confdata``, KUKA ``S``/``T``).
    """

    point_id: str
    role: str
    kind: str
    status: Status
    pose_status: Status
    pose_cause: Reason | None
    path_feasible: bool
    path_cause: Reason | None
    path_fail_at_m: float
    face_cause: Reason | None
    clearance_m: float
    clearance_pair: tuple[str, str] | None
    clearance_is_lower_bound: bool
    confdata: ConfData | None
    ik_kind: str
    q: FloatArray | None
    q_path: FloatArray | None
    T_base_flange: FloatArray | None
    elapsed_s: float = 0.0
    T_base_tcp: FloatArray | None = None
    q_safe: FloatArray | None = None
    n_vias: int = 0
    via_cause: Reason | None = None
    search_cause: Reason | None = None
    landing_cause: Reason | None = None
    branch: int = -1

    @property
    def causes(self) -> tuple[Reason, ...]:
        """Every reason, in the order :attr:`reason` says them, worded as there: the pose's,
        ``"search path: ..."``, the face's, ``"search: ..."``, the moves' (``"vias: ..."``,
        or with the advice to add vias), ``"landing: ..."``."""
        via = self.via_cause
        if via is not None:
            via = via.worded("vias: ") if self.n_vias else via.worded(suffix=ADD_VIAS)
        out = (
            self.pose_cause,
            None if self.path_cause is None else self.path_cause.worded("search path: "),
            self.face_cause,
            None if self.search_cause is None else self.search_cause.worded("search: "),
            via,
            None if self.landing_cause is None else self.landing_cause.worded("landing: "),
        )
        return tuple(r for r in out if r is not None)

    @property
    def reason(self) -> str:
        """Why not feasible, every part joined with ``"; "`` (``""`` when feasible)."""
        return joined(self.causes)

    @property
    def pose_reason(self) -> str:
        """The words of :attr:`pose_cause` (``""`` when feasible)."""
        return joined([self.pose_cause])

    @property
    def path_reason(self) -> str:
        """The words of :attr:`path_cause` (``""`` when feasible)."""
        return joined([self.path_cause])

    @property
    def face_reason(self) -> str:
        """The words of :attr:`face_cause` (``""`` when on a planar face)."""
        return joined([self.face_cause])

    @property
    def via_reason(self) -> str:
        """The words of :attr:`via_cause` (``""`` when clear)."""
        return joined([self.via_cause])

    @property
    def search_reason(self) -> str:
        """The words of :attr:`search_cause` and :attr:`landing_cause` (``""`` for none)."""
        return joined([self.search_cause, self.landing_cause])

    @property
    def feasible(self) -> bool:
        """The point can be measured as planned (marginal counts as feasible)."""
        return self.status != "infeasible"

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict (distances in metres; NaN as ``null``); ``reasons``: every reason
        with its kind (:attr:`causes`: ``{"kind", "text", "pair"?}``, the texts joined with
        ``"; "`` being ``reason``)."""
        return {
            "id": self.point_id,
            "role": self.role,
            "kind": self.kind,
            "status": self.status,
            "reason": self.reason,
            "reasons": [r.to_json() for r in self.causes],
            "pose_status": self.pose_status,
            "pose_reason": self.pose_reason,
            "path_feasible": self.path_feasible,
            "path_reason": self.path_reason,
            "path_fail_at_m": _finite_or_none(self.path_fail_at_m),
            "face_reason": self.face_reason,
            "search_reason": self.search_reason,
            "clearance_m": _finite_or_none(self.clearance_m),
            "clearance_pair": list(self.clearance_pair) if self.clearance_pair else None,
            "clearance_is_lower_bound": self.clearance_is_lower_bound,
            "confdata": list(self.confdata) if self.confdata else None,
            "ik_kind": self.ik_kind,
            "feasible": self.feasible,
        } | (
            {"vias": {"count": self.n_vias, "reason": self.via_reason}}
            if self.n_vias or self.via_reason
            else {}
        )


@dataclass(frozen=True)
class PlanCheck:
    """The check of a whole plan.

    Attributes:
        points: one :class:`PointCheck` per plan point, in plan order.
        ik_kind: the cell's IK: ``"opw"`` (analytic) or ``"numeric"``.
        ik_note: why the analytic IK does not apply (``""`` for ``opw``).
        error: a problem of the whole plan on this part (e.g. the part has no planar face),
            ``""`` when none.
        layout: why the plan's procedure would refuse its points (:func:`layout_problem`:
            no points, a missing role, a layout that breaks the procedure's assumptions),
            ``""`` when none.
        quality: the layout's predicted quality (:mod:`planner.sim.quality`), ``None`` when
            it could not be predicted (``quality_note`` says why) or the layout is refused.
        quality_note: why there is no quality, ``""`` otherwise.
        landing: how often each search of the program goes wrong under the plan's
            misplacement (:mod:`planner.sim.landing`), ``None`` when not computed.
        detectability: which points' gross errors ``wobjcal calibrate``'s screen could see,
            and how many points to add so it sees one in every point
            (:func:`calib.estimators.gross_errors.detectability`); ``None`` when the points
            fix no frame. Said, not a failure: a plain 3-2-1 has no redundancy by design.
        cycle: the estimated cycle time of the judged program (:mod:`planner.check.cycle`),
            ``None`` when the controller has no program for the plan.
        part_units: the length unit the work object's file was read in (``"mm"``, ``"in"``,
            ...: as given, detected for ``auto``, or declared by a CAD file), ``""``: not known.
        part_note: how that unit was chosen and the part's size, in words
            (:attr:`planner.cell.scene.workobject.RepairReport.units_note`).
    """

    points: tuple[PointCheck, ...]
    ik_kind: str
    ik_note: str = ""
    error: str = ""
    layout: str = ""
    quality: LayoutQuality | None = None
    quality_note: str = ""
    landing: LandingRisk | None = None
    detectability: Detectability | None = None
    cycle: CycleTime | None = None
    part_units: str = ""
    part_note: str = ""

    @property
    def layout_status(self) -> Status:
        """``infeasible`` when the layout is refused (a degree of freedom free included),
        ``marginal`` when it is weak, else ``feasible``."""
        if self.layout:
            return "infeasible"
        if self.quality is not None and self.quality.rating == "weak":
            return "marginal"
        return "feasible"

    @property
    def feasible(self) -> bool:
        """Every point and path is feasible and the plan has no error or layout problem."""
        return not self.error and not self.layout and all(p.feasible for p in self.points)

    @property
    def infeasible(self) -> tuple[PointCheck, ...]:
        """The points that fail."""
        return tuple(p for p in self.points if not p.feasible)

    def problems(self) -> tuple[str, ...]:
        """Every problem the check found, one line each: the plan's error, the layout's, then
        ``"point <id>: <reason>"`` per infeasible point (``()`` when feasible)."""
        out = [f"error: {self.error}"] if self.error else []
        out += [f"layout: {self.layout}"] if self.layout else []
        out += [f"point {p.point_id}: {p.reason or p.status}" for p in self.infeasible]
        return tuple(out)

    def refusals(self) -> tuple[str, ...]:
        """Why the plan is refused, one line each, as suggest, the front and the UI's export
        show it: ``"<id>: <reason>"`` per infeasible point in plan order, then ``"layout:
        ..."`` and ``"error: ..."`` (``()`` when it passes)."""
        out = [f"{p.point_id}: {p.reason or p.status}" for p in self.infeasible]
        out += [f"layout: {self.layout}"] if self.layout else []
        out += [f"error: {self.error}"] if self.error else []
        return tuple(out)

    def point(self, point_id: str) -> PointCheck:
        """The check of ``point_id``.

        Raises:
            KeyError: no such point (the message lists the ids).
        """
        for p in self.points:
            if p.point_id == point_id:
                return p
        raise KeyError(f"no point {point_id!r}; points: {[p.point_id for p in self.points]}")

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict; ``ik_note``, ``error``, ``layout``, ``quality_note``,
        ``quality``, ``landing``, ``redundancy`` and ``cycle_time_s`` with its breakdown
        ``cycle_time`` appear only when set, ``work_object`` (``units``, ``note``) when the
        part was loaded; ``layout_status`` always."""
        out: dict[str, Any] = {
            "feasible": self.feasible,
            "ik_kind": self.ik_kind,
            "points": [p.to_json() for p in self.points],
        }
        for key in ("ik_note", "error", "layout", "quality_note"):
            if getattr(self, key):
                out[key] = getattr(self, key)
        out["layout_status"] = self.layout_status
        if self.quality is not None:
            out["quality"] = self.quality.to_json()
        if self.landing is not None:
            out["landing"] = self.landing.to_json()
        d = self.detectability
        if d is not None:
            out["redundancy"] = {
                "constraints": d.n_constraints,
                "redundant": d.redundancy,
                "unseen": list(d.unseen),
                "add": d.add,
                "note": d.message(),
            }
        if self.cycle is not None:
            out["cycle_time_s"] = self.cycle.total_s
            out["cycle_time"] = self.cycle.to_json()
        if self.part_units:
            out["work_object"] = {"units": self.part_units, "note": self.part_note}
        return out


def _finite_or_none(x: float) -> float | None:
    return x if math.isfinite(x) else None
