"""``wobjcal calibrate``: the work-object frame from points measured on the real robot."""

from __future__ import annotations

import argparse
import math
import sys
from collections.abc import Callable
from typing import Any

import numpy as np
from rich.table import Table

from calib.estimators.gross_errors import K_SIGMA
from calib.frames import (
    invert_transform,
    motion_between,
    quat_wxyz_from_matrix,
    tait_bryan_zyx_from_matrix,
)
from calib.procedures import METHODS
from planner.calibrate.job import CalibrationOutput, calibrate_plan
from planner.cli.common import print_json, read_plan, stdout
from planner.export import FORMATS
from planner.plan_cell import nominal_T_base_wobj, plan_controller_base
from planner.results import KINDS, read_results


def register(sub: Any, add: Callable[..., argparse.ArgumentParser]) -> None:
    """Add ``calibrate`` to the subparsers ``sub``."""
    p = add(
        sub,
        "calibrate",
        "compute the work-object frame from points measured on the real robot",
        "Compute T_base_wobj from the points measured on the robot, read from what the\n"
        "controller wrote (RESULTS; which controller is detected from the contents, or\n"
        "given with --from):\n"
        "  rapid     the wobjcal.measurements/1 JSON the RAPID program writes\n"
        "            (HOME:/wobjcal_measured.json), or one written by hand:\n"
        '            {"schema": "wobjcal.measurements/1", "frame": "base", "units": "mm",\n'
        '             "points": {"A": [x, y, z], ...}}\n'
        "  krl       the program's .dat as the controller saved it after the run (xMeas[],\n"
        "            nFail[]: robot base, mm)\n"
        "  urscript  the controller's log (log_history.txt or a capture) with the program's\n"
        "            'wobjcal/1' lines; the last run in it is read\n"
        "  fanuc     POSREG.VA and NUMREG.VA backed up from MD: (two files, or their folder):\n"
        "            PR[11..] in the nominal user frame PR[1] (checked), R[11..] the codes\n"
        "A results file of another plan's program (its plan digest), or one that is partial or\n"
        "malformed, is refused naming the point, slot or register (exit 2).\n"
        "hultman2013 replays the paper's A-H procedure with the recorded points; three_two_one\n"
        "uses the plan's 3-2-1 roles (or picks them from the faces); best_fit fits all points.\n"
        "Text output: origin (mm), Tait-Bryan z-y'-x'' angles (deg, paper eq. 7-9 = KUKA A, B,\n"
        "C), quaternion (w, x, y, z), 1 sigma per degree of freedom, residuals (mm) and the lines\n"
        "to paste into each controller (--format: one): ABB RAPID wobjdata, KUKA KRL BASE_DATA,\n"
        "a URScript pose, the FANUC TP user frame, all in the controller's base frame (a UR\n"
        "arm's Base is turned 180 deg from its URDF's base_link). --json prints T_base_wobj\n"
        "(4x4, the URDF's base link), T_controller_wobj, and of it origin_m,\n"
        "tait_bryan_zyx_deg, quat_wxyz; residuals_m, covariance (6x6) and sigma.\n\n"
        "Every result is screened first: all points are fitted by least squares and a point off\n"
        "its face by more than K sigma of the noise the plan expects (its sensor and robot\n"
        "error models and the planar-face flatness) is flagged, the point to re-measure named\n"
        "by leave-one-out; a frame beyond the plan's misplacement bound is flagged too. Then\n"
        "nothing is printed to paste (and --json leaves out the frame) unless --force.\n\n"
        "exit codes: 0 ok, 1 gross error or frame beyond the misplacement bound (named on\n"
        "stderr), 2 bad input (file, missing point, layout the method cannot use)",
        "wobjcal calibrate plan.json wobjcal_measured.json\n"
        "wobjcal calibrate plan.json WobjcalPlate.dat --method best_fit --json\n"
        "wobjcal calibrate plan.json log_history.txt --from urscript\n"
        "wobjcal calibrate plan.json backup/POSREG.VA backup/NUMREG.VA",
    )
    p.add_argument("plan", metavar="PLAN", help="plan file (wobjcal.plan/1)")
    p.add_argument(
        "results",
        metavar="RESULTS",
        nargs="+",
        help="what the controller wrote: measurements JSON, KRL .dat, URScript log, or FANUC "
        "POSREG.VA and NUMREG.VA (or their folder)",
    )
    p.add_argument(
        "--from",
        dest="source_kind",
        choices=KINDS,
        help="the controller that wrote RESULTS (default: detected from the contents)",
    )
    p.add_argument("--method", choices=METHODS, help="method (default: the plan's procedure)")
    p.add_argument(
        "--format",
        choices=list(FORMATS),
        help="print the lines to paste for this controller only (default: every one)",
    )
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument(
        "--k-sigma",
        type=positive_float,
        default=K_SIGMA,
        metavar="K",
        help=f"flag points off their face by more than K sigma (default {K_SIGMA:g})",
    )
    p.add_argument(
        "--force",
        action="store_true",
        help="print the frame to paste even when the screen flags it (exit 0)",
    )
    p.set_defaults(handler=cmd_calibrate)


def positive_float(text: str) -> float:
    """An argparse ``type`` for a finite number > 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not (math.isfinite(value) and value > 0):
        raise argparse.ArgumentTypeError(f"must be a finite number > 0, got {text!r}")
    return value


def result_json(out: CalibrationOutput, with_frame: bool = True) -> dict[str, Any]:
    """The JSON of a calibration (metres, degrees).

    Args:
        out: the calibration.
        with_frame: include the frame (``T_base_wobj``, ``T_controller_wobj``, and of the
            latter ``origin_m``, angles, quaternion);
            ``False`` for an untrusted result printed without ``--force``.
    """
    T = out.T_base_wobj
    delta = motion_between(out.T_base_wobj_nominal, T)
    data: dict[str, Any] = {
        "method": out.method,
        "trusted": out.trusted,
        "problems": list(out.problems),
        "notes": list(out.notes),
        "residuals_m": out.residuals_m,
        "edge_residuals_m": out.edge_residuals_m,
        "used_points": list(out.used_ids),
        "skipped_points": list(out.skipped_ids),
        "change_from_nominal": {
            "translation_m": delta[:3].tolist(),
            "rotation_deg": float(np.degrees(np.linalg.norm(delta[3:]))),
        },
    }
    if out.screen is not None:
        s = out.screen
        data["screen"] = {
            "sigma_m": s.sigma_m,
            "k_sigma": s.k_sigma,
            "limit_m": s.limit_m,
            "redundancy": s.redundancy,
            "fit_residuals_m": {k: list(v) for k, v in s.residuals_m.items()},
            "flagged": list(s.flagged),
            "remeasure": list(s.remeasure),
        }
    if out.covariance is not None and out.sigma_dof is not None:
        sd = out.sigma_dof
        data["covariance"] = {
            "order": ["dx_m", "dy_m", "dz_m", "rx_rad", "ry_rad", "rz_rad"],
            "frame": "calibrated wobj axes",
            "matrix": out.covariance.tolist(),
        }
        data["sigma"] = {
            "x_m": sd[0],
            "y_m": sd[1],
            "z_m": sd[2],
            "rx_deg": float(np.degrees(sd[3])),
            "ry_deg": float(np.degrees(sd[4])),
            "rz_deg": float(np.degrees(sd[5])),
        }
    if with_frame:
        data["T_base_wobj"] = T.tolist()
        T = out.T_controller_wobj  # what the controller is given: its own base frame
        data["T_controller_wobj"] = T.tolist()
        data["origin_m"] = T[:3, 3].tolist()
        data["tait_bryan_zyx_deg"] = np.degrees(tait_bryan_zyx_from_matrix(T[:3, :3])).tolist()
        data["quat_wxyz"] = quat_wxyz_from_matrix(T[:3, :3]).tolist()
    return data


def _print_text(
    out: CalibrationOutput, paste: bool, fmt: str | None = None, controller_base: str | None = None
) -> None:
    con = stdout()
    T = out.T_controller_wobj  # the robot base frame, or the controller's where they differ
    o = T[:3, 3] * 1e3
    a, b, c = np.degrees(tait_bryan_zyx_from_matrix(T[:3, :3]))
    q = quat_wxyz_from_matrix(T[:3, :3])
    delta = motion_between(out.T_base_wobj_nominal, out.T_base_wobj)
    name = "T_base_wobj" if controller_base is None else "T_controller_wobj"
    con.print(f"[bold]{name}[/] by {out.method} from {', '.join(out.used_ids)}")
    if controller_base is not None:
        con.print(f"  ({controller_base})", markup=False)
    if out.skipped_ids:
        con.print(f"[yellow]not measured, left out: {', '.join(out.skipped_ids)}[/]")
    con.print(f"  origin       x {o[0]:.3f}  y {o[1]:.3f}  z {o[2]:.3f} mm")
    con.print(f"  z-y'-x''     alpha {a:.4f}  beta {b:.4f}  gamma {c:.4f} deg (KUKA A, B, C)")
    con.print(f"  quat_wxyz    {q[0]:.9f} {q[1]:.9f} {q[2]:.9f} {q[3]:.9f}")
    con.print(
        f"  vs nominal   {np.linalg.norm(delta[:3]) * 1e3:.3f} mm, "
        f"{np.degrees(np.linalg.norm(delta[3:])):.4f} deg"
    )
    sd = out.sigma_dof
    if sd is not None:
        con.print(
            f"  1 sigma      x {sd[0] * 1e3:.3f}  y {sd[1] * 1e3:.3f}  z {sd[2] * 1e3:.3f} mm, "
            f"rx {np.degrees(sd[3]):.4f}  ry {np.degrees(sd[4]):.4f}  rz {np.degrees(sd[5]):.4f} "
            "deg (noise the plan expects)"
        )
    table = Table(title="residuals (distance from the face of the calibrated part)")
    table.add_column("point")
    table.add_column("face [mm]", justify="right")
    table.add_column("edge face [mm]", justify="right")
    for pid, r in out.residuals_m.items():
        e = out.edge_residuals_m.get(pid)
        table.add_row(pid, f"{r * 1e3:+.3f}", "" if e is None else f"{e * 1e3:+.3f}")
    con.print(table)
    if not paste:
        con.print("[red]not trusted: nothing to paste (see stderr; --force prints it anyway)[/]")
        return
    if not out.trusted:
        con.print("[red]NOT TRUSTED (printed because of --force):[/]")
    for f in FORMATS.values() if fmt is None else (FORMATS[fmt],):
        lines = f.paste_lines(out.T_controller_wobj)
        con.print(f"{f.vendor} {f.label} ({lines.where}):", markup=False)
        for line in lines.lines:
            con.print(f"  {line}", markup=False)


def cmd_calibrate(args: argparse.Namespace) -> int:
    """Compute and print the calibrated frame."""
    plan, plan_dir = read_plan(args.plan)
    base = plan_controller_base(plan, plan_dir)
    T_controller_wobj = invert_transform(base.T_base_controller) @ nominal_T_base_wobj(plan)
    results = read_results(plan, args.results, args.source_kind, T_controller_wobj)
    for note in results.notes:
        print(f"wobjcal calibrate: note: {note}", file=sys.stderr)
    out = calibrate_plan(
        plan, results.measurements, args.method, k_sigma=args.k_sigma,
        T_base_controller=base.T_base_controller,
    )  # fmt: skip
    paste = out.trusted or args.force
    for note in out.notes:
        note = note.replace("wobjcal suggest PLAN ", f"wobjcal suggest {args.plan} ")
        print(f"wobjcal calibrate: note: {note}", file=sys.stderr)
    for problem in out.problems:
        print(f"wobjcal calibrate: {problem}", file=sys.stderr)
    if args.json:
        print_json(result_json(out, with_frame=paste))
    else:
        _print_text(out, paste, args.format, None if base.is_identity else base.describe())
    return 0 if paste else 1
