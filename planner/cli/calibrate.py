"""``wobjcal calibrate``: the work-object frame from points measured on the real robot."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from typing import Any

import numpy as np
from rich.table import Table

from calib.frames import motion_between, quat_wxyz_from_matrix, tait_bryan_zyx_from_matrix
from calib.plan.measurements import load_measurements
from calib.procedures import METHODS
from planner.calibrate import CalibrationOutput, calibrate_plan
from planner.cli.common import print_json, read_plan, stdout
from planner.export.krl import BASE_NO, frame_text
from planner.export.rapid import pose_text


def register(sub: Any, add: Callable[..., argparse.ArgumentParser]) -> None:
    """Add ``calibrate`` to the subparsers ``sub``."""
    p = add(
        sub,
        "calibrate",
        "compute the work-object frame from points measured on the real robot",
        "Compute T_base_wobj from the points measured on the robot (MEASURED, a\n"
        "wobjcal.measurements/1 file, e.g. the HOME:/wobjcal_measured.json the RAPID export\n"
        "writes):\n"
        '  {"schema": "wobjcal.measurements/1", "frame": "base", "units": "mm",\n'
        '   "points": {"A": [x, y, z], ...}}\n'
        "hultman2013 replays the paper's A-H procedure with the recorded points; three_two_one\n"
        "uses the plan's 3-2-1 roles (or picks them from the faces); best_fit fits all points.\n"
        "Text output: origin (mm), Tait-Bryan z-y'-x'' angles (deg, paper eq. 7-9 = KUKA A, B,\n"
        "C), quaternion (w, x, y, z), residuals (mm) and the ABB wobjdata and KUKA BASE_DATA\n"
        "lines to paste. --json prints T_base_wobj (4x4), origin_m, tait_bryan_zyx_deg,\n"
        "quat_wxyz and residuals_m.\n\n"
        "exit codes: 0 ok, 2 bad input (file, missing point, layout the method cannot use)",
        "wobjcal calibrate plan.json measured.json\n"
        "wobjcal calibrate plan.json measured.json --method best_fit --json",
    )
    p.add_argument("plan", metavar="PLAN", help="plan file (wobjcal.plan/1)")
    p.add_argument("measured", metavar="MEASURED", help="measurements (wobjcal.measurements/1)")
    p.add_argument("--method", choices=METHODS, help="method (default: the plan's procedure)")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.set_defaults(handler=cmd_calibrate)


def result_json(out: CalibrationOutput) -> dict[str, Any]:
    """The JSON of a calibration (metres, degrees)."""
    T = out.T_base_wobj
    delta = motion_between(out.T_base_wobj_nominal, T)
    return {
        "method": out.method,
        "T_base_wobj": T.tolist(),
        "origin_m": T[:3, 3].tolist(),
        "tait_bryan_zyx_deg": np.degrees(tait_bryan_zyx_from_matrix(T[:3, :3])).tolist(),
        "quat_wxyz": quat_wxyz_from_matrix(T[:3, :3]).tolist(),
        "residuals_m": out.residuals_m,
        "edge_residuals_m": out.edge_residuals_m,
        "used_points": list(out.used_ids),
        "skipped_points": list(out.skipped_ids),
        "change_from_nominal": {
            "translation_m": delta[:3].tolist(),
            "rotation_deg": float(np.degrees(np.linalg.norm(delta[3:]))),
        },
    }


def _print_text(out: CalibrationOutput) -> None:
    con = stdout()
    T = out.T_base_wobj
    o = T[:3, 3] * 1e3
    a, b, c = np.degrees(tait_bryan_zyx_from_matrix(T[:3, :3]))
    q = quat_wxyz_from_matrix(T[:3, :3])
    delta = motion_between(out.T_base_wobj_nominal, T)
    con.print(f"[bold]T_base_wobj[/] by {out.method} from {', '.join(out.used_ids)}")
    if out.skipped_ids:
        con.print(f"[yellow]not measured, left out: {', '.join(out.skipped_ids)}[/]")
    con.print(f"  origin       x {o[0]:.3f}  y {o[1]:.3f}  z {o[2]:.3f} mm")
    con.print(f"  z-y'-x''     alpha {a:.4f}  beta {b:.4f}  gamma {c:.4f} deg (KUKA A, B, C)")
    con.print(f"  quat_wxyz    {q[0]:.9f} {q[1]:.9f} {q[2]:.9f} {q[3]:.9f}")
    con.print(
        f"  vs nominal   {np.linalg.norm(delta[:3]) * 1e3:.3f} mm, "
        f"{np.degrees(np.linalg.norm(delta[3:])):.4f} deg"
    )
    table = Table(title="residuals (distance from the face of the calibrated part)")
    table.add_column("point")
    table.add_column("face [mm]", justify="right")
    table.add_column("edge face [mm]", justify="right")
    for pid, r in out.residuals_m.items():
        e = out.edge_residuals_m.get(pid)
        table.add_row(pid, f"{r * 1e3:+.3f}", "" if e is None else f"{e * 1e3:+.3f}")
    con.print(table)
    con.print("ABB RAPID (world frame = robot base):")
    con.print(
        f'  PERS wobjdata wobjCalibrated:=[FALSE,TRUE,"",{pose_text(T)},[[0,0,0],[1,0,0,0]]];',
        markup=False,
    )
    con.print("KUKA KRL ($WORLD = $ROBROOT):")
    con.print(f"  BASE_DATA[{BASE_NO}]={frame_text(T)}", markup=False)


def cmd_calibrate(args: argparse.Namespace) -> int:
    """Compute and print the calibrated frame."""
    plan, _ = read_plan(args.plan)
    measurements = load_measurements(args.measured)
    out = calibrate_plan(plan, measurements, args.method)
    if args.json:
        print_json(result_json(out))
    else:
        _print_text(out)
    return 0
