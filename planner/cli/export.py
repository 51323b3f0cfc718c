"""``wobjcal export``: write the plan as a robot program (RAPID, KRL, URScript) or as JSON."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path
from typing import Any

from calib.atomic_io import write_text_atomic
from calib.plan.file import plan_to_json
from planner.cli.common import read_plan, stderr
from planner.export import FORMAT_CHOICES, FORMATS, export_files


def register(sub: Any, add: Callable[..., argparse.ArgumentParser]) -> None:
    """Add ``export`` to the subparsers ``sub``."""
    p = add(
        sub,
        "export",
        "write the plan as a robot program (rapid, krl, urscript) or canonical JSON",
        "Write the plan as a robot program that probes every point with the proximity sensor\n"
        "and records the measured points, or as canonical plan JSON. The sensor orientation\n"
        "and the ABB confdata of each target come from the same reachability check as\n"
        "'wobjcal check' (when the cell is available; else a default orientation and no\n"
        "confdata, noted in the program). rapid: one .mod; krl: FILE (.src) and a .dat next\n"
        "to it; urscript: one .script. Exit 1 (nothing written) when the check finds an\n"
        "infeasible point, naming it; --force writes the program anyway.",
        "wobjcal export plan.json --format rapid -o WobjcalStator.mod\n"
        "wobjcal export plan.json --format krl -o wobjcal_stator.src",
    )
    p.add_argument("plan", metavar="PLAN", help="plan file (wobjcal.plan/1)")
    p.add_argument(
        "--format",
        required=True,
        choices=FORMAT_CHOICES,
        help="output format: "
        + ", ".join(f"{f.name} ({f.vendor} {f.label})" for f in FORMATS.values())
        + ", json (the canonical plan)",
    )
    p.add_argument("-o", "--output", required=True, metavar="FILE", help="output file")
    p.add_argument(
        "--no-check",
        action="store_true",
        help="do not run the reachability check (default orientations, no confdata)",
    )
    p.add_argument(
        "--force",
        action="store_true",
        help="write the program even when the check finds infeasible points (exit 0)",
    )
    p.set_defaults(handler=cmd_export)


def cmd_export(args: argparse.Namespace) -> int:
    """Write the export file(s)."""
    plan, plan_dir = read_plan(args.plan)
    out = Path(args.output)
    if args.format == "json":
        write_text_atomic(out, plan_to_json(plan))
        stderr().print(f"wrote {out}")
        return 0
    from planner.cli.check import check_plan, export_job_for

    if not args.no_check and not args.force:
        bad = [r for r in check_plan(plan, plan_dir) if not r.feasible]
        if bad:
            for r in bad:
                why = "; ".join(x for x in (r.reason, r.path_reason) if x) or r.status
                stderr().print(f"error: point {r.point_id} is not feasible: {why}")
            stderr().print("nothing written; fix the plan, or export anyway with --force")
            return 1
    job, note = export_job_for(plan, plan_dir, run_check=not args.no_check)
    if note:
        stderr().print(f"note: {note}")
    files = export_files(job, args.format)
    written = []
    for i, (suffix, text) in enumerate(files.items()):
        target = out if i == 0 else out.with_suffix(suffix)
        write_text_atomic(target, text)
        written.append(str(target))
    stderr().print("wrote " + ", ".join(written))
    return 0
