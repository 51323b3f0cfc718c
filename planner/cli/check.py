"""``wobjcal check``: reachability and collision of every probe point and its search path.

A table or ``--json`` of :func:`planner.check.job.check_plan` (the same check the web UI runs).
"""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rich.table import Table

from planner.cli.common import print_json, read_plan, stdout
from planner.program.controllers import CONTROLLERS, DEFAULT_CONTROLLER

if TYPE_CHECKING:
    from calib.plan.file import Plan
    from planner.check.job import PlanCheck, PointCheck
    from planner.program.cycle_time import CycleTime
    from planner.sim.quality import LayoutQuality

_COLOUR = {"feasible": "green", "marginal": "yellow", "infeasible": "red"}


def register(sub: Any, add: Callable[..., argparse.ArgumentParser]) -> None:
    """Add ``check`` to the subparsers ``sub``."""
    p = add(
        sub,
        "check",
        "check that the robot reaches every probe point and runs every search path",
        "Check every probe point of the plan (IK, joint limits, collisions, clearance), its\n"
        "search path from start to end of travel, and that it lies on a planar face with the\n"
        "sensor footprint on it, in the plan's cell. Prints a table, or JSON with --json.\n\n"
        "The procedure's own preconditions are checked too: every role it needs, and a dry\n"
        "run of 'wobjcal calibrate' on exact measurements of the nominal points (so a plan the\n"
        "calibration would refuse fails here, before the robot measures).\n\n"
        "The layout's predicted quality follows: 1 sigma of each degree of freedom, noise gain,\n"
        "the weakest motion in words and the predicted error at the points of interest at the\n"
        "plan's confidence levels; a weak layout is marginal, one that leaves a degree of\n"
        "freedom free fails. Points whose gross error calibrate could not detect (no other\n"
        "point fixes what they fix; a plain 3-2-1: all six) are named, with how many points to\n"
        "add (wobjcal suggest PLAN --add N): said, not failed. Last, the program's estimated\n"
        "cycle time per visit (joint moves, linear moves, searches, settle, I/O; the search\n"
        "time to the nominal face, and in brackets over the whole search length), with the\n"
        "model's constants (docs/cycle_time.md).\n\n"
        "Both judge the measuring program the controller of --format runs (default rapid):\n"
        "every search from its safe start must reach its face wherever the part may lie, and\n"
        "executed on the ideal part misplaced as the validation misplaces it, no search may\n"
        "miss, start inside its face or land off it in more than 1 % of calibrations (each\n"
        "point named with the share and what to change).\n\n"
        "exit codes: 0 all feasible (marginal points and a weak layout are reported but pass),\n"
        "1 any point or path infeasible or the layout refused (each named with the reason),\n"
        "2 bad input",
        "wobjcal check assets/plans/stator_section_ah.json\n"
        "wobjcal check plan.json --json > check.json\n"
        "wobjcal check plan.json --add-vias plan_vias.json",
    )
    p.add_argument("plan", metavar="PLAN", help="plan file (wobjcal.plan/1)")
    p.add_argument("--json", action="store_true", help="print the results as JSON")
    p.add_argument(
        "--format",
        choices=list(CONTROLLERS),
        default=DEFAULT_CONTROLLER,
        help=f"the controller whose program is judged (default: {DEFAULT_CONTROLLER})",
    )
    p.add_argument(
        "--add-vias",
        metavar="OUT",
        help="where a joint move between points collides and the point has no vias, search via "
        "points that clear it (retract along the sensor axis, or turn the shoulder or elbow), "
        "write the plan with them to OUT (atomically) and check that plan",
    )
    p.set_defaults(handler=cmd_check)


def _with_vias(plan: Plan, plan_dir: Path, target: Path) -> tuple[Plan, Path, str]:
    """The plan with vias added (:func:`planner.check.vias.plan_with_vias`), written to
    ``target``; what was done is printed on stderr."""
    from calib.plan.file import save_plan
    from planner.check.vias import plan_with_vias
    from planner.plan_cell import open_cell
    from planner.suggest import moved_plan

    with open_cell(plan, plan_dir) as cell:
        new, done = plan_with_vias(plan, cell)
    for pid, what in done.items():
        print(f"wobjcal check: point {pid}: {what}", file=sys.stderr)
    if not done:
        print("wobjcal check: no move between points collides: nothing to add", file=sys.stderr)
    out_dir = target.resolve().parent
    written = new if out_dir == plan_dir.resolve() else moved_plan(new, plan_dir, out_dir)
    save_plan(written, target)
    print(f"wobjcal check: wrote {target}; checking it", file=sys.stderr)
    return written, out_dir, str(target)


def _clearance_text(p: PointCheck) -> str:
    if not math.isfinite(p.clearance_m):
        return "-"
    text = ("≥ " if p.clearance_is_lower_bound else "") + f"{p.clearance_m * 1e3:.1f} mm"
    if p.clearance_pair is not None:
        text += f" ({p.clearance_pair[0]} - {p.clearance_pair[1]})"
    return text


def _table(check: PlanCheck, title: str) -> Table:
    table = Table(
        title=title,
        caption=f"IK: {check.ik_kind}" + (f" ({check.ik_note})" if check.ik_note else ""),
    )
    for col in ("point", "role", "search", "status", "clearance", "path", "confdata", "reason"):
        table.add_column(col)
    for p in check.points:
        table.add_row(
            p.point_id,
            p.role,
            p.kind,
            f"[{_COLOUR[p.status]}]{p.status}[/]",
            _clearance_text(p),
            "ok" if p.path_feasible else "[red]blocked[/]",
            str(list(p.confdata)) if p.confdata else "-",
            p.reason,
        )
    return table


def quality_table(q: LayoutQuality, status: str) -> Table:
    """The layout quality as a table: 1 sigma per DOF, gains, weakest motion, points of
    interest at their levels."""
    from planner.sim.quality import DOF_NAMES

    table = Table(
        title="layout quality (predicted, "
        + (f"the program {q.program}" if q.program else "the procedure")
        + " linearised with the plan's noise)",
        caption=f"layout: [{_COLOUR[status]}]{status}[/]" + (f": {q.problem}" if q.problem else ""),
    )
    table.add_column("quantity")
    table.add_column("predicted", justify="right")
    for i, name in enumerate(DOF_NAMES):
        unit, scale = ("mm", 1e3) if i < 3 else ("deg", math.degrees(1.0))
        table.add_row(f"1 sigma {name}", f"{q.sigma[i] * scale:.4f} {unit}")
    table.add_row("noise per search (1 sigma)", f"{q.noise_sigma_m * 1e3:.4f} mm")
    table.add_row("noise gain / condition", f"{q.noise_gain:.2f} / {q.condition:.1f}")
    table.add_row("weakest motion", q.weakest_text)
    for p in q.poi:
        levels = ", ".join(
            f"{h * 1e3:.3f} mm at {lv:g} %"
            for lv, h in zip(p.levels_percent, p.half_width_m, strict=True)
        )
        table.add_row(p.label, levels)
    return table


def cycle_table(c: CycleTime) -> Table:
    """The cycle time per visit of the program (joint move, linear moves, searches, settle,
    I/O, total; s) and the total (:mod:`planner.program.cycle_time`)."""
    table = Table(
        title=f"cycle time (estimated, the program {c.program})",
        caption="model: " + c.model_text() + "".join(f"; {n}" for n in c.notes),
    )
    for col in ("visit", "searches", "move", "linear", "search", "settle", "I/O", "total"):
        table.add_column(col, justify="left" if col == "visit" else "right")

    def s(x: float | None) -> str:
        return "-" if x is None else f"{x:.1f}"

    for r in c.rows:
        search = f"{r.search_s:.1f} (<= {r.search_max_s:.1f})"
        table.add_row(
            r.key,
            str(r.searches),
            s(r.move_s),
            s(r.linear_s),
            search,
            s(r.settle_s),
            s(r.io_s),
            s(r.total_s),
        )
    rows = c.rows
    table.add_row(
        "total",
        str(sum(r.searches for r in rows)),
        s(sum(r.move_s or 0.0 for r in rows)),
        s(sum(r.linear_s for r in rows)),
        f"{sum(r.search_s for r in rows):.1f} (<= {sum(r.search_max_s for r in rows):.1f})",
        s(sum(r.settle_s for r in rows)),
        s(sum(r.io_s for r in rows)),
        f"{c.total_s:.1f} (<= {c.total_max_s:.1f})",
    )
    return table


def cmd_check(args: argparse.Namespace) -> int:
    """Run the check; exit 0 when all points and paths are feasible, else 1."""
    from planner.check.job import check_plan  # PyBullet: not for ``wobjcal --help``

    plan, plan_dir = read_plan(args.plan, "check")
    if args.add_vias:
        plan, plan_dir, shown = _with_vias(plan, plan_dir, Path(args.add_vias))
        args.plan = shown
    check = check_plan(plan, plan_dir, fmt=args.format)
    if check.error:
        print(f"wobjcal check: {check.error}", file=sys.stderr)
    if check.layout:
        print(f"wobjcal check: layout: {check.layout}", file=sys.stderr)
    bad = check.infeasible
    if args.json:
        print_json({"plan": args.plan, **check.to_json()})
        return 0 if check.feasible else 1
    out = stdout()
    if not out.is_terminal:
        out.width = 160
    out.print(_table(check, f"wobjcal check {args.plan}"))
    for p in bad:
        out.print(f"[red]point {p.point_id}: {p.status}: {p.reason or 'not feasible'}[/]")
    if check.layout:
        out.print(f"layout: {check.layout}", style="red", markup=False)
    if check.quality is not None and check.quality.rating != "unobservable":
        out.print(quality_table(check.quality, check.layout_status))
    elif check.quality_note:
        out.print(f"layout quality: not predicted: {check.quality_note}", markup=False)
    if check.detectability is not None and check.detectability.unseen:
        out.print(
            f"redundancy: {check.detectability.message(args.plan)}", markup=False, style="yellow"
        )
    if check.landing is not None:
        L = check.landing
        risky = [s for s in L.searches if s.worst > 0 or s.partly_off > 0]
        out.print(
            f"landing ({L.program}, {L.trials} misplaced calibrations): searches go wrong in "
            f"{L.failed:.1%} of them"
            + "".join(
                f"; {s.key}: off its face {s.off_face:.0%}, partly {s.partly_off:.0%}, "
                f"another surface first {s.other_surface:.0%}, misses {s.miss:.0%}, starts "
                f"inside {s.start_inside:.0%}"
                for s in risky
            ),
            markup=False,
            style="red" if L.point_problems() else None,
        )
    if check.cycle is not None:
        out.print(cycle_table(check.cycle))
    n = len(check.points)
    out.print(
        f"{n - len(bad)} of {n} points feasible"
        + ("" if not bad else f"; not feasible: {', '.join(p.point_id for p in bad)}")
        + ("; the layout is refused (see above)" if check.layout else "")
        + ("; the layout is weak (see above)" if check.layout_status == "marginal" else "")
    )
    return 0 if check.feasible else 1
