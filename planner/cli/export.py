"""``wobjcal export``: write the plan as a robot program (RAPID, KRL, URScript) or as JSON."""

from __future__ import annotations

import argparse
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from calib.atomic_io import write_text_atomic
from calib.plan.file import plan_to_json
from planner.cli.common import read_plan, stderr
from planner.export import FORMAT_CHOICES, FORMATS, export_file_stem


def register(sub: Any, add: Callable[..., argparse.ArgumentParser]) -> None:
    """Add ``export`` to the subparsers ``sub``."""
    p = add(
        sub,
        "export",
        "write the plan as a robot program (" + ", ".join(FORMATS) + ") or canonical JSON",
        "Write the plan as a robot program that probes every point with the proximity sensor\n"
        "and records the measured points, or as canonical plan JSON. The sensor orientation\n"
        "and the ABB confdata of each target come from the same reachability check as\n"
        "'wobjcal check' (when the cell is available; else a default orientation and no\n"
        "confdata, noted in the program). FILE gets the format's first file; further files\n"
        "(KRL's .dat) go beside it: "
        + "; ".join(f"{f.name}: {' + '.join(f.suffixes)}" for f in FORMATS.values())
        + ".\nWith -o DIR (an existing folder, or a path ending in /) or without -o (the current\n"
        "folder) the files are named after the plan's name (letters, digits, _ - . kept; KRL\n"
        "and FANUC files after the program's name, as their controllers want).\n"
        "Exit 1 (nothing written) when the check finds an infeasible point, or the plan's\n"
        "procedure refuses its points (e.g. an A-H plan without a role, which would run as a\n"
        "plain non-adaptive program), naming each; the same for every format. --force writes\n"
        "the program anyway, and its header says NOT CHECKED and names the refused points\n"
        "(every header names the wobjcal version, the plan and its digest, and what was\n"
        "checked). A file is written like cp writes it: through a symbolic link, never over\n"
        "a read-only file, never half (atomic, no temporary file left behind).",
        "wobjcal export plan.json --format rapid -o WobjcalStator.mod\n"
        "wobjcal export plan.json --format krl -o wobjcal_stator.src\n"
        "wobjcal export plan.json --format fanuc -o programs/",
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
    p.add_argument(
        "-o",
        "--output",
        metavar="FILE|DIR",
        help="output file, or a folder the files go into named after the plan "
        "(default: the current folder)",
    )
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


def output_paths(output: str | None, plan_name: str, fmt: str) -> list[Path]:
    """Where ``wobjcal export`` writes the files of ``fmt``, first file first.

    ``-o FILE``: the first file there, the others beside it with their suffix. ``-o DIR`` (an
    existing folder, or a path ending in a separator: created) and no ``-o`` (the current
    folder): ``DIR/<stem><suffix>``, the stem from the plan's name
    (:func:`planner.export.export_file_stem`).
    """
    suffixes = FORMATS[fmt].suffixes if fmt in FORMATS else (".json",)
    is_dir = output is None or output.endswith(("/", os.sep)) or Path(output).is_dir()
    if not is_dir:
        out = Path(output or "")
        return [out if i == 0 else out.with_suffix(s) for i, s in enumerate(suffixes)]
    folder = Path(output or ".")
    folder.mkdir(parents=True, exist_ok=True)
    stem = export_file_stem(plan_name, fmt)
    return [folder / f"{stem}{s}" for s in suffixes]


def cmd_export(args: argparse.Namespace) -> int:
    """Write the export file(s)."""
    plan, plan_dir = read_plan(args.plan, "export")
    if args.format == "json":
        (out,) = output_paths(args.output, plan.name, "json")
        write_text_atomic(out, plan_to_json(plan))
        stderr().print(f"wrote {out}")
        return 0
    from planner.export_plan.job import export_program  # PyBullet: not for ``wobjcal --help``

    result = export_program(plan, plan_dir, args.format, run_check=not args.no_check)
    refused = result.layout or (result.check is not None and not result.check.feasible)
    if refused and (not args.force or not result.files):  # no program: --force has none
        err = stderr()
        if result.layout:
            err.print(f"error: layout: {result.layout}", markup=False)
        if result.check is not None:
            if result.check.error:
                err.print(f"error: {result.check.error}", markup=False)
            for p in result.check.infeasible:
                err.print(
                    f"error: point {p.point_id} is not feasible: {p.reason or p.status}",
                    markup=False,
                )
        if result.files:
            err.print("nothing written; fix the plan, or export anyway with --force")
        else:
            err.print(f"nothing written: no {args.format} program for this plan; fix the plan")
        return 1
    if result.notes:
        stderr().print("note: " + "; ".join(result.notes), markup=False)
    targets = output_paths(args.output, plan.name, args.format)
    written = []
    for target, text in zip(targets, result.files.values(), strict=True):
        write_text_atomic(target, text)
        written.append(str(target))
    stderr().print("wrote " + ", ".join(written))
    return 0
