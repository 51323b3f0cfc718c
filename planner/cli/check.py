"""``wobjcal check``: reachability and collision of every probe point and its search path."""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from rich.table import Table

from calib.frames import invert_transform
from calib.plan.file import Plan
from calib.probing import SearchCommand
from planner.cli.common import print_json, read_plan, stdout
from planner.export.job import ExportJob, build_job
from planner.plan_cell import nominal_T_base_wobj, open_cell, tool_data

FloatArray = np.ndarray


def register(sub: Any, add: Callable[..., argparse.ArgumentParser]) -> None:
    """Add ``check`` to the subparsers ``sub``."""
    p = add(
        sub,
        "check",
        "check that the robot reaches every probe point and runs every search path",
        "Check every probe point of the plan (IK, joint limits, collisions, clearance) and\n"
        "its search path from start to end of travel, in the plan's cell. Prints a table,\n"
        "or JSON with --json.\n\n"
        "exit codes: 0 all feasible (marginal points are reported but pass), 1 any point or\n"
        "path infeasible (each named with the reason), 2 bad input",
        "wobjcal check assets/plans/stator_section_ah.json\n"
        "wobjcal check plan.json --json > check.json",
    )
    p.add_argument("plan", metavar="PLAN", help="plan file (wobjcal.plan/1)")
    p.add_argument("--json", action="store_true", help="print the results as JSON")
    p.set_defaults(handler=cmd_check)


@dataclass(frozen=True)
class CheckRow:
    """The check of one point.

    Attributes:
        point_id: the point id.
        role: its role.
        kind: ``approach`` or ``edge``.
        status: ``feasible``, ``marginal`` or ``infeasible`` (the pose at the point).
        reason: why not feasible (or what is marginal); ``""`` when feasible.
        clearance_m: smallest distance of the robot and tool to obstacles at the point, m.
        path_feasible: the search path from start to end of travel is feasible.
        path_reason: why the path is not feasible.
        confdata: ABB ``(cf1, cf4, cf6, cfx)`` of the chosen IK branch, or ``None``.
        T_base_flange: ``(4, 4)`` flange pose chosen at the point, or ``None``.
    """

    point_id: str
    role: str
    kind: str
    status: str
    reason: str
    clearance_m: float
    path_feasible: bool
    path_reason: str
    confdata: tuple[int, int, int, int] | None
    T_base_flange: FloatArray | None

    @property
    def feasible(self) -> bool:
        """The point and its path are both feasible (marginal counts as feasible)."""
        return self.status != "infeasible" and self.path_feasible

    @property
    def overall_status(self) -> str:
        """``status`` of the point, or ``infeasible`` when its search path is blocked."""
        return self.status if self.path_feasible else "infeasible"

    def to_json(self) -> dict[str, Any]:
        """A JSON-ready dict (distances in metres)."""
        return {
            "id": self.point_id,
            "role": self.role,
            "kind": self.kind,
            "status": self.status,
            "reason": self.reason,
            "clearance_m": self.clearance_m if math.isfinite(self.clearance_m) else None,
            "clearance_is_lower_bound": math.isfinite(self.clearance_m)
            and _clearance_capped(self.clearance_m),
            "path_feasible": self.path_feasible,
            "path_reason": self.path_reason,
            "confdata": list(self.confdata) if self.confdata else None,
            "feasible": self.feasible,
        }


def _confdata(cell: Any, q: Any) -> tuple[int, int, int, int] | None:
    """ABB confdata of joint values ``q``; ``None`` for robots that are not OPW arms."""
    from planner.robot.kinematics.opw_from_urdf import NotOPWError

    if q is None or cell.solver.opw is None:
        return None
    try:
        cf1, cf4, cf6, cfx = cell.solver.abb_confdata(np.asarray(q, float))
    except NotOPWError:
        return None
    return int(cf1), int(cf4), int(cf6), int(cfx)


def check_plan(plan: Plan, plan_dir: Path) -> list[CheckRow]:
    """Check every point and search path of ``plan`` in its cell (opens a PyBullet cell)."""
    from planner.faces.checks import plan_face_reasons

    T_nom = nominal_T_base_wobj(plan)
    rows = []
    with open_cell(plan, plan_dir) as cell:
        wo = cell.work_object  # planar faces: a probe measures a plane
        if wo is None:  # open_cell always loads the plan's work object
            raise RuntimeError("the plan's cell has no work object")
        faces = plan_face_reasons(wo.mesh, [p.to_probe_point() for p in plan.points], name=wo.name)
        pts = np.array([p.position_m for p in plan.points], dtype=float).reshape(-1, 3)
        normals = np.array([p.normal for p in plan.points], dtype=float).reshape(-1, 3)
        results = cell.check_probes(pts, normals, tcp=plan.cell.tool.tcp) if len(pts) else []
        paths = [  # start each path from the probe pose's solution when there is one
            cell.check_search(SearchCommand.from_point(p.to_probe_point(), T_nom), q_ref=res.q)
            for p, res in zip(plan.points, results, strict=True)
        ]
        for p, res, path, why in zip(plan.points, results, paths, faces, strict=True):
            T_flange = getattr(res, "T_base_flange", None)
            rows.append(
                CheckRow(
                    point_id=p.id,
                    role=p.role,
                    kind=p.search.kind,
                    status="infeasible" if why else str(res.status),
                    reason="; ".join(x for x in (str(res.reason or ""), why) if x),
                    clearance_m=float(getattr(res, "clearance_m", math.nan)),
                    path_feasible=bool(path.feasible),
                    path_reason=str(path.reason or ""),
                    confdata=_confdata(cell, getattr(res, "q", None)) if res.feasible else None,
                    T_base_flange=None if T_flange is None else np.asarray(T_flange, float),
                )
            )
    return rows


def export_job_for(plan: Plan, plan_dir: Path, run_check: bool = True) -> tuple[ExportJob, str]:
    """The export job of ``plan``, with orientations and confdata from the check when possible.

    Returns:
        The job and a note for the user (``""`` when everything came from the check).
    """
    T_nom = nominal_T_base_wobj(plan)
    tool, note = tool_data(plan, plan_dir)
    rotations: dict[str, FloatArray] = {}
    confs: dict[str, tuple[int, int, int, int]] = {}
    if run_check:
        rows = check_plan(plan, plan_dir)
        T_wobj_base = invert_transform(T_nom)
        for r in rows:
            if r.T_base_flange is not None and r.status != "infeasible":  # the chosen pose
                T_wobj_tcp = T_wobj_base @ r.T_base_flange @ tool.T_flange_tcp
                rotations[r.point_id] = T_wobj_tcp[:3, :3]
            if r.confdata is not None:
                confs[r.point_id] = r.confdata
        no_pose = [r.point_id for r in rows if r.point_id not in rotations]
        blocked = [r.point_id for r in rows if not r.feasible and r.point_id in rotations]
        notes = [note] if note else []
        if no_pose:
            notes.append(f"no feasible pose for {no_pose}: default orientation, no confdata")
        if blocked:
            notes.append(f"points {blocked} are not feasible (see 'wobjcal check')")
        note = "; ".join(notes)
    else:
        note = (note + "; " if note else "") + "no check: default orientations, no confdata"
    return build_job(plan, T_nom, tool, rotations, confs), note


def _clearance_capped(clearance_m: float) -> bool:
    """True when the clearance is the query's look-ahead distance (nothing nearer found)."""
    from planner.cell.collision import DEFAULT_MARGIN_M, report_distance_m

    return clearance_m >= report_distance_m(DEFAULT_MARGIN_M) - 1e-6


def _clearance_text(clearance_m: float) -> str:
    if not math.isfinite(clearance_m):
        return "-"
    return ("≥ " if _clearance_capped(clearance_m) else "") + f"{clearance_m * 1e3:.1f} mm"


def _table(rows: list[CheckRow], title: str) -> Table:
    table = Table(title=title)
    for col in ("point", "role", "search", "status", "clearance", "path", "confdata", "reason"):
        table.add_column(col)
    colour = {"feasible": "green", "marginal": "yellow", "infeasible": "red"}
    for r in rows:
        reason = "; ".join(x for x in (r.reason, r.path_reason) if x)
        table.add_row(
            r.point_id,
            r.role,
            r.kind,
            f"[{colour.get(r.status, 'white')}]{r.status}[/]",
            _clearance_text(r.clearance_m),
            "ok" if r.path_feasible else "[red]blocked[/]",
            str(list(r.confdata)) if r.confdata else "-",
            reason,
        )
    return table


def cmd_check(args: argparse.Namespace) -> int:
    """Run the check; exit 0 when all points and paths are feasible, else 1."""
    from planner.faces.detection import NoPlanarFaceError  # trimesh: not for ``wobjcal --help``

    plan, plan_dir = read_plan(args.plan)
    try:
        rows = check_plan(plan, plan_dir)
    except NoPlanarFaceError as exc:  # the plan cannot work on this part: a failed check
        print(f"wobjcal check: {exc}", file=sys.stderr)
        if args.json:
            print_json({"plan": args.plan, "feasible": False, "error": str(exc), "points": []})
        return 1
    bad = [r for r in rows if not r.feasible]
    if args.json:
        print_json({"plan": args.plan, "feasible": not bad, "points": [r.to_json() for r in rows]})
    else:
        out = stdout()
        if not out.is_terminal:
            out.width = 160
        out.print(_table(rows, f"wobjcal check {args.plan}"))
        for r in bad:
            reason = "; ".join(x for x in (r.reason, r.path_reason) if x) or "not feasible"
            out.print(f"[red]point {r.point_id}: {r.overall_status}: {reason}[/]")
        out.print(
            f"{len(rows) - len(bad)} of {len(rows)} points feasible"
            + ("" if not bad else f"; not feasible: {', '.join(r.point_id for r in bad)}")
        )
    return 1 if bad else 0
